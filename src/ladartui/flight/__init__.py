"""Flight paths as sequences of scan poses (report section 6, figures 1, 12, 13).

``pose``: ScanPose, aiming and the limits of a flight; ``paths``: the poses of
each manoeuvre and preset; ``plan``: segments of those kinds chained into a
FlightPlan, its path length and flight time.
"""

from ladartui.flight.paths import (
    altitude_field,
    flypast,
    orbit,
    standoff_sweep,
    standoffs_field,
    straight,
    turn,
)
from ladartui.flight.plan import (
    SEGMENT_KINDS,
    FlightPlan,
    FlyPast,
    Manual,
    Orbit,
    Standoff,
    Straight,
    Turn,
    flight_time,
    path_length,
)
from ladartui.flight.pose import (
    DIRECTIONS,
    MAX_ALTITUDE,
    MAX_FLIGHT_ALTITUDE,
    MAX_SCANS,
    ScanPose,
    aim_at,
)

__all__ = [
    "DIRECTIONS",
    "MAX_ALTITUDE",
    "MAX_FLIGHT_ALTITUDE",
    "MAX_SCANS",
    "SEGMENT_KINDS",
    "FlightPlan",
    "FlyPast",
    "Manual",
    "Orbit",
    "ScanPose",
    "Standoff",
    "Straight",
    "Turn",
    "aim_at",
    "altitude_field",
    "flight_time",
    "flypast",
    "orbit",
    "path_length",
    "standoff_sweep",
    "standoffs_field",
    "straight",
    "turn",
]
