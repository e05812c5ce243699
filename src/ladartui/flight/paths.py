"""The poses of each kind of flight (report section 6, figures 1, 12 and 13):
manoeuvres that continue from a pose (``straight``, ``turn``) and presets that
place their own scans around a target (``orbit``, ``flypast``,
``standoff_sweep``), with the checks of their numbers.
"""

from __future__ import annotations

import math
from dataclasses import replace

from ladartui.checks import (
    MAX_COORDINATE,
    choice_field,
    integer_field,
    number_field,
    number_text,
    point_field,
)
from ladartui.errors import FieldError
from ladartui.flight.pose import (
    DIRECTIONS,
    MAX_FLIGHT_ALTITUDE,
    MAX_SCANS,
    ScanPose,
    _forward,
    aim_at,
    pose_field,
)


def _length(name, value):
    """A distance in metres, more than 0 and at most MAX_COORDINATE."""
    return number_field(name, value, 0.0, MAX_COORDINATE, low_open=True)


def _altitude(value):
    return altitude_field("altitude", value)


def altitude_field(name, value):
    """An altitude a person asked for: above the ground and at most MAX_FLIGHT_ALTITUDE."""
    return number_field(name, value, 0.0, MAX_FLIGHT_ALTITUDE, low_open=True)


def _scans(value):
    return integer_field("scans", value, 1, MAX_SCANS)


def _arc(value):
    """Degrees flown around a circle, more than 0 and at most a full turn."""
    return number_field("arc", value, 0.0, 360.0, low_open=True)


def _aimed(poses, target):
    return poses if target is None else [aim_at(p, target) for p in poses]


def _aimed_at_default(poses, target, altitude, field: str, value, what: str):
    """Aim at the segment's own ``target`` (no ``aim_at`` written): a point too near the
    horizon is blamed on the distance the user wrote (``field``), with its limit."""
    try:
        return _aimed(poses, target)
    except FieldError as error:
        if error.field != "aim_at":
            raise
        point = "centre" if field == "radius" else "target"
        reason = f"so the {point} is at least 1 degree below the horizon (or an aim_at point)"
        height = altitude - target[2]
        if height <= 0:  # no distance helps: the altitude is what to change
            raise FieldError(
                "altitude",
                altitude,
                f"an altitude above the {point}'s height of {target[2]:g} m, {reason}",
            ) from None
        limit = height / math.tan(math.radians(1.0))
        raise FieldError(
            field, value, f"{what} of at most {limit:.0f} m at altitude {altitude:g} m, {reason}"
        ) from None


def _within_bounds(build, field: str, value, what: str) -> list[ScanPose]:
    """``build()``'s poses; a scan placed past the coordinate limit is blamed on a field
    the user wrote (``field``), not on the pose's own x or y, which no file has."""
    try:
        return build()
    except FieldError as error:
        if error.field not in ("x", "y"):
            raise
        raise FieldError(
            field,
            value,
            f"{what} that puts every scan within {number_text(MAX_COORDINATE)} m of the "
            f"scene's origin in x and y (a scan would be at {error.field} = {error.value:.1f} m)",
        ) from None


def _blamed_distance(point, reach: float, field: str, value, what: str):
    """(field, value, what) of the field to blame for a scan past the coordinate limit:
    ``point`` (a preset's centre or target) when it lies farther from the origin in x
    or y than its scans ``reach`` from it (no shorter distance would help much), else
    the distance the user wrote."""
    if max(abs(point[0]), abs(point[1])) >= reach:
        name = "centre" if field == "radius" else "target"
        return name, point, f"a {name} (with scans {number_text(reach)} m from it)"
    return field, value, what


def _with_sensor(pose, azimuth, depression):
    changes = {}
    if azimuth is not None:
        changes["azimuth"] = azimuth
    if depression is not None:
        changes["depression"] = depression
    return replace(pose, **changes) if changes else pose


# -- manoeuvres (report section 6) ----------------------------------------------------


def straight(start: ScanPose, distance: float, scans: int) -> list[ScanPose]:
    """Fly ``distance`` metres along the start heading with ``scans`` evenly spaced scans.

    Following the report's figure 12 the start itself is not a scan: scan k
    (1..scans) sits ``distance * k / scans`` along the path, so the last scan is
    at the end of the manoeuvre. Sensor azimuth and depression are kept.
    """
    start = pose_field("start", start)
    distance = _length("distance", distance)
    scans = _scans(scans)
    fx, fy = _forward(start.heading)
    return _within_bounds(
        lambda: [
            replace(start, x=start.x + fx * distance * k / scans, y=start.y + fy * distance * k / scans)
            for k in range(1, scans + 1)
        ],
        "distance",
        distance,
        "a distance",
    )


def _turn_centre(start, radius, clockwise):
    # The centre lies on the side of the turn, perpendicular to the heading.
    fx, fy = _forward(start.heading)
    side = 1.0 if clockwise else -1.0
    return start.x + side * radius * fy, start.y - side * radius * fx


def _on_circle(template, centre, radius, bearing, clockwise):
    """A pose on a circle at compass ``bearing`` from ``centre``, heading along the tangent."""
    bx, by = _forward(bearing)
    heading = bearing + (90.0 if clockwise else -90.0)
    return replace(template, x=centre[0] + radius * bx, y=centre[1] + radius * by, heading=heading)


def turn(start: ScanPose, radius: float, arc: float, direction: str, scans: int) -> list[ScanPose]:
    """Turn ``arc`` degrees ``direction`` ("left"/"right") on a circle of ``radius`` metres.

    As in the report's figure 13 the start is not a scan: ``scans`` scans are
    evenly spaced along the arc (scan k after ``arc * k / scans`` degrees), each
    heading along the tangent. Sensor azimuth and depression are kept.
    """
    start = pose_field("start", start)
    radius = _length("radius", radius)
    arc = _arc(arc)
    direction = choice_field("direction", direction, DIRECTIONS)
    scans = _scans(scans)
    clockwise = direction == "right"
    centre = _turn_centre(start, radius, clockwise)
    sign = 1.0 if clockwise else -1.0
    first_bearing = start.heading - sign * 90.0
    return _within_bounds(
        lambda: [
            _on_circle(start, centre, radius, first_bearing + sign * arc * k / scans, clockwise)
            for k in range(1, scans + 1)
        ],
        "radius",
        radius,
        "a radius",
    )


# -- presets (report figure 1) --------------------------------------------------------


def _template(altitude, heading=0.0):
    return ScanPose(0.0, 0.0, altitude, heading, 0.0, 90.0)


def _arc_steps(arc, scans):
    # A full circle does not repeat its first scan; a partial arc includes both ends.
    if arc >= 360.0:
        return arc / scans
    return arc / (scans - 1) if scans > 1 else 0.0


def orbit(
    centre, radius, altitude, scans, *, direction="right", start_bearing=180.0, arc=360.0, aim_at=None
) -> list[ScanPose]:
    """Circle ``centre`` (a target point) at ``radius`` metres and ``altitude`` metres.

    The first scan is at compass ``start_bearing`` from the centre (180: south
    of it); ``direction`` "right" flies clockwise. Scans are evenly spaced over
    ``arc`` degrees (a full circle does not repeat its first scan; a partial arc
    includes both ends). Headings follow the tangent; the sensor aims at
    ``aim_at`` (default: the centre).
    """
    centre = point_field("centre", centre)
    radius = _length("radius", radius)
    altitude = _altitude(altitude)
    scans = _scans(scans)
    direction = choice_field("direction", direction, DIRECTIONS)
    start_bearing = number_field("start_bearing", start_bearing)
    arc = _arc(arc)
    clockwise = direction == "right"
    step = _arc_steps(arc, scans) * (1.0 if clockwise else -1.0)
    template = _template(altitude)
    poses = _within_bounds(
        lambda: [
            _on_circle(template, centre, radius, start_bearing + step * k, clockwise) for k in range(scans)
        ],
        *_blamed_distance(centre, radius, "radius", radius, "a radius"),
    )
    if aim_at is None:
        return _aimed_at_default(poses, centre, altitude, "radius", radius, "a radius")
    return _aimed(poses, aim_at)


def flypast(
    target, standoff, altitude, length, scans, heading, *, side="right", aim_at=None
) -> list[ScanPose]:
    """Fly a straight line of ``length`` metres past ``target`` on ``heading``.

    The target is on the aircraft's ``side`` ("right" or "left") at horizontal
    ``standoff`` metres at the closest point, which is the middle of the line.
    Scans are evenly spaced over the line, both ends included; the sensor aims
    at ``aim_at`` (default: the target).
    """
    target = point_field("target", target)
    standoff = number_field("standoff", standoff, 0.0, MAX_COORDINATE)
    altitude = _altitude(altitude)
    length = number_field("length", length, 0.0, MAX_COORDINATE)
    scans = _scans(scans)
    heading = number_field("heading", heading)
    side = choice_field("side", side, DIRECTIONS)
    fx, fy = _forward(heading)
    # The aircraft is on the opposite side of the target: right of the nose is (fy, -fx).
    away = -1.0 if side == "right" else 1.0
    cx, cy = target[0] + away * standoff * fy, target[1] - away * standoff * fx
    template = _template(altitude, heading)
    offsets = [0.0] if scans == 1 else [length * (k / (scans - 1) - 0.5) for k in range(scans)]
    poses = _within_bounds(
        lambda: [replace(template, x=cx + fx * s, y=cy + fy * s) for s in offsets],
        *_blamed_distance(
            target,
            math.hypot(standoff, length / 2),
            "standoff",
            standoff,
            "a standoff (with the target and half the length)",
        ),
    )
    if aim_at is None:  # the line's ends are the farthest: blame the standoff and length
        return _aimed_at_default(
            poses, target, altitude, "standoff", standoff, "a standoff (with half the length)"
        )
    return _aimed(poses, aim_at)


def standoff_sweep(
    target, standoffs, altitude, *, bearing=180.0, heading=None, aim_at=None
) -> list[ScanPose]:
    """One scan at each horizontal distance in ``standoffs`` (metres) from ``target``.

    Scans lie along compass ``bearing`` from the target (180: south of it), in
    the order given; the aircraft heads ``heading`` (default: towards the
    target) and the sensor aims at ``aim_at`` (default: the target).
    """
    target = point_field("target", target)
    distances = standoffs_field("standoffs", standoffs)
    altitude = _altitude(altitude)
    bearing = number_field("bearing", bearing)
    heading = bearing + 180.0 if heading is None else number_field("heading", heading)
    bx, by = _forward(bearing)
    template = _template(altitude, heading)
    poses = _within_bounds(
        lambda: [replace(template, x=target[0] + bx * s, y=target[1] + by * s) for s in distances],
        *_blamed_distance(target, max(distances), "standoffs", list(distances), "a list of standoffs"),
    )
    if aim_at is None:
        return _aimed_at_default(poses, target, altitude, "standoffs", list(distances), "standoffs")
    return _aimed(poses, aim_at)


def standoffs_field(name, value):
    """A list of 1 to MAX_SCANS horizontal distances in metres, as a float tuple."""
    expected = f"a list of 1 to {MAX_SCANS} distances from 0 to {number_text(MAX_COORDINATE)} metres"
    try:
        items = None if isinstance(value, (str, bytes)) else list(value)
    except TypeError:
        items = None
    if items is None or not 1 <= len(items) <= MAX_SCANS:
        raise FieldError(name, value, expected)
    try:
        return tuple(number_field(name, v, 0.0, MAX_COORDINATE) for v in items)
    except FieldError:
        raise FieldError(name, value, expected) from None
