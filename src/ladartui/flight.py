"""Flight paths as sequences of scan poses (report section 6, figures 1, 12, 13).

Frame: x east, y north, z up, metres. Heading is degrees clockwise from north;
sensor azimuth degrees clockwise from the aircraft nose; depression degrees
below the horizontal, 1..90 with 90 nadir.

Segments come in two families:

* relative manoeuvres (``Straight``, ``Turn``) start where the previous segment
  ended (or at the plan's start pose) and keep the heading continuous. As in the
  report's figures 12 and 13 the starting position is *not* a scan: ``scans``
  scans sit at evenly spaced intervals after it, the last one at the end of the
  manoeuvre, so the next segment starts on the last scan without repeating it.
* absolute presets (``Manual``, ``Orbit``, ``FlyPast``, ``Standoff``) place their
  own scans (report figure 1); a following manoeuvre continues from their last
  scan. Presets always aim the sensor at their target point (or ``aim_at``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import partial
from typing import ClassVar

from ladartui.checks import (
    MAX_COORDINATE,
    choice_field,
    integer_field,
    number_field,
    number_text,
    point_field,
)
from ladartui.errors import FieldError

MAX_ALTITUDE = 1e5  # metres; any pose (computed ones and cell-space test rays included)
MAX_FLIGHT_ALTITUDE = 20_000.0  # metres a person may ask to fly: above any UAV's ceiling (~18 km)
MAX_SCANS = 10_000
DIRECTIONS = ("left", "right")


def _heading(value):
    # -1e-20 % 360 is 360.0 in floating point: fold that back to 0.
    h = value % 360.0
    return 0.0 if h >= 360.0 else h


def _azimuth(value):
    a = value % 360.0
    return a - 360.0 if a > 180.0 else a


# -- poses ----------------------------------------------------------------------------


@dataclass(frozen=True)
class ScanPose:
    """One scan: aircraft (sensor) position in metres, heading, sensor azimuth and depression.

    Heading is stored in [0, 360) and azimuth in (-180, 180]; depression must be
    1..90 (90 nadir) and the aircraft above the ground (z > 0).
    """

    x: float
    y: float
    z: float
    heading: float = 0.0
    azimuth: float = 0.0
    depression: float = 90.0

    def __post_init__(self):
        set_ = partial(object.__setattr__, self)
        set_("x", number_field("x", self.x, -MAX_COORDINATE, MAX_COORDINATE))
        set_("y", number_field("y", self.y, -MAX_COORDINATE, MAX_COORDINATE))
        set_("z", number_field("z", self.z, 0.0, MAX_ALTITUDE, low_open=True))
        set_("heading", _heading(number_field("heading", self.heading)))
        set_("azimuth", _azimuth(number_field("azimuth", self.azimuth)))
        set_("depression", number_field("depression", self.depression, 1.0, 90.0))

    @property
    def position(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.z)

    def to_dict(self) -> dict:
        return {
            "x": self.x,
            "y": self.y,
            "z": self.z,
            "heading": self.heading,
            "azimuth": self.azimuth,
            "depression": self.depression,
        }


def _forward(heading):
    h = math.radians(heading)
    return math.sin(h), math.cos(h)


def _bearing(dx, dy):
    """Compass bearing of (dx, dy), degrees clockwise from north."""
    return _heading(math.degrees(math.atan2(dx, dy)))


def aim_at(pose: ScanPose, target_xyz) -> ScanPose:
    """``pose`` with azimuth and depression set so the central ray passes through the target.

    A target straight below gives depression 90 and keeps the pose's azimuth.
    A target less than 1 degree below the horizon cannot be aimed at (FieldError).
    """
    tx, ty, tz = point_field("aim_at", target_xyz)
    dx, dy, dz = tx - pose.x, ty - pose.y, tz - pose.z
    horizontal = math.hypot(dx, dy)
    if horizontal <= 1e-12 * max(1.0, abs(dz)):
        if dz >= 0:
            raise FieldError("aim_at", target_xyz, "a point below the aircraft")
        return replace(pose, depression=90.0)
    depression = math.degrees(math.atan2(-dz, horizontal))
    if depression < 1.0:
        raise FieldError(
            "aim_at",
            target_xyz,
            f"a point at least 1 degree below the horizon from scan position "
            f"({pose.x:g}, {pose.y:g}, {pose.z:g})",
        )
    return replace(pose, azimuth=_bearing(dx, dy) - pose.heading, depression=min(depression, 90.0))


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
        height = altitude - target[2]
        limit = height / math.tan(math.radians(1.0)) if height > 0 else 0.0
        raise FieldError(
            field,
            value,
            f"{what} of at most {limit:.0f} m at altitude "
            f"{altitude:g} m, so the {'centre' if field == 'radius' else 'target'} "
            "is at least 1 degree below the horizon (or an aim_at point)",
        ) from None


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
    distance = _length("distance", distance)
    scans = _scans(scans)
    fx, fy = _forward(start.heading)
    return [
        replace(start, x=start.x + fx * distance * k / scans, y=start.y + fy * distance * k / scans)
        for k in range(1, scans + 1)
    ]


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
    radius = _length("radius", radius)
    arc = _arc(arc)
    direction = choice_field("direction", direction, DIRECTIONS)
    scans = _scans(scans)
    clockwise = direction == "right"
    centre = _turn_centre(start, radius, clockwise)
    sign = 1.0 if clockwise else -1.0
    first_bearing = start.heading - sign * 90.0
    return [
        _on_circle(start, centre, radius, first_bearing + sign * arc * k / scans, clockwise)
        for k in range(1, scans + 1)
    ]


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
    poses = [_on_circle(template, centre, radius, start_bearing + step * k, clockwise) for k in range(scans)]
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
    poses = [replace(template, x=cx + fx * s, y=cy + fy * s) for s in offsets]
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
    poses = [replace(template, x=target[0] + bx * s, y=target[1] + by * s) for s in distances]
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


# -- segments and plans ---------------------------------------------------------------


def _optional_point(name, value):
    return None if value is None else point_field(name, value)


def _optional_number(name, value, low=None, high=None):
    return None if value is None else number_field(name, value, low, high)


def _set(obj, name, value):
    object.__setattr__(obj, name, value)


def _check_pointing(segment):
    """Check a relative manoeuvre's optional new sensor pointing and aim point."""
    _set(segment, "azimuth", _optional_number("azimuth", segment.azimuth))
    _set(segment, "depression", _optional_number("depression", segment.depression, 1.0, 90.0))
    _set(segment, "aim_at", _optional_point("aim_at", segment.aim_at))


def _pointed(segment, current, fly):
    """Scans of ``fly(start)``, the start re-pointed and the scans aimed as the segment asks."""
    start = _with_sensor(current, segment.azimuth, segment.depression)
    return _aimed(fly(start), segment.aim_at)


def _chords(poses):
    return [math.dist(a.position, b.position) for a, b in zip(poses, poses[1:])]


@dataclass(frozen=True)
class Manual:
    """Scans placed one by one (report section 6, "manually setting each of the parameters")."""

    poses: tuple[ScanPose, ...]
    kind: ClassVar[str] = "manual"
    relative: ClassVar[bool] = False

    def __post_init__(self):
        poses = tuple(self.poses)
        if not 1 <= len(poses) <= MAX_SCANS or not all(isinstance(p, ScanPose) for p in poses):
            # the count, not the list: 10,001 poses made a message of 300,000 characters
            shown = f"{len(poses):,} items" if len(poses) > 3 else self.poses
            raise FieldError("poses", shown, f"a list of 1 to {MAX_SCANS:,} scan poses")
        _set(self, "poses", poses)

    def build(self, current: ScanPose | None) -> list[ScanPose]:
        return list(self.poses)

    def legs(self, poses):
        return _chords(poses)


@dataclass(frozen=True)
class Straight:
    """Straight-line manoeuvre (report figure 12); optional new sensor pointing or aim point."""

    distance: float
    scans: int
    azimuth: float | None = None
    depression: float | None = None
    aim_at: tuple | None = None
    kind: ClassVar[str] = "straight"
    relative: ClassVar[bool] = True

    def __post_init__(self):
        _set(self, "distance", _length("distance", self.distance))
        _set(self, "scans", _scans(self.scans))
        _check_pointing(self)

    def build(self, current):
        return _pointed(self, current, lambda start: straight(start, self.distance, self.scans))

    def lead_in(self) -> float:
        """Metres from the start of the manoeuvre to its first scan."""
        return self.distance / self.scans

    def legs(self, poses):
        return _chords(poses)


@dataclass(frozen=True)
class Turn:
    """Turning manoeuvre (report figure 13); optional new sensor pointing or aim point."""

    radius: float
    arc: float
    direction: str
    scans: int
    azimuth: float | None = None
    depression: float | None = None
    aim_at: tuple | None = None
    kind: ClassVar[str] = "turn"
    relative: ClassVar[bool] = True

    def __post_init__(self):
        _set(self, "radius", _length("radius", self.radius))
        _set(self, "arc", _arc(self.arc))
        _set(self, "direction", choice_field("direction", self.direction, DIRECTIONS))
        _set(self, "scans", _scans(self.scans))
        _check_pointing(self)

    def build(self, current):
        return _pointed(
            self, current, lambda start: turn(start, self.radius, self.arc, self.direction, self.scans)
        )

    def lead_in(self) -> float:
        """Metres along the arc from the start of the turn to its first scan."""
        return math.radians(self.arc / self.scans) * self.radius

    def legs(self, poses):
        return [self.lead_in()] * (len(poses) - 1)


@dataclass(frozen=True)
class Orbit:
    """Circle a target point (report figure 1a), sensor aimed at it."""

    centre: tuple
    radius: float
    altitude: float
    scans: int
    direction: str = "right"
    start_bearing: float = 180.0
    arc: float = 360.0
    aim_at: tuple | None = None
    kind: ClassVar[str] = "orbit"
    relative: ClassVar[bool] = False

    def __post_init__(self):
        _set(self, "centre", point_field("centre", self.centre))
        _set(self, "radius", _length("radius", self.radius))
        _set(self, "altitude", _altitude(self.altitude))
        _set(self, "scans", _scans(self.scans))
        _set(self, "direction", choice_field("direction", self.direction, DIRECTIONS))
        _set(self, "start_bearing", _heading(number_field("start_bearing", self.start_bearing)))
        _set(self, "arc", _arc(self.arc))
        _set(self, "aim_at", _optional_point("aim_at", self.aim_at))

    def build(self, current):
        return orbit(
            self.centre,
            self.radius,
            self.altitude,
            self.scans,
            direction=self.direction,
            start_bearing=self.start_bearing,
            arc=self.arc,
            aim_at=self.aim_at,
        )

    def legs(self, poses):
        arc_between = math.radians(_arc_steps(self.arc, self.scans)) * self.radius
        return [arc_between] * (len(poses) - 1)


@dataclass(frozen=True)
class FlyPast:
    """Straight pass beside a target (report figure 1b), sensor aimed at it."""

    target: tuple
    standoff: float
    altitude: float
    length: float
    scans: int
    heading: float = 0.0
    side: str = "right"
    aim_at: tuple | None = None
    kind: ClassVar[str] = "flypast"
    relative: ClassVar[bool] = False

    def __post_init__(self):
        _set(self, "target", point_field("target", self.target))
        _set(self, "standoff", number_field("standoff", self.standoff, 0.0, MAX_COORDINATE))
        _set(self, "altitude", _altitude(self.altitude))
        _set(self, "length", number_field("length", self.length, 0.0, MAX_COORDINATE))
        _set(self, "scans", _scans(self.scans))
        _set(self, "heading", _heading(number_field("heading", self.heading)))
        _set(self, "side", choice_field("side", self.side, DIRECTIONS))
        _set(self, "aim_at", _optional_point("aim_at", self.aim_at))

    def build(self, current):
        return flypast(
            self.target,
            self.standoff,
            self.altitude,
            self.length,
            self.scans,
            self.heading,
            side=self.side,
            aim_at=self.aim_at,
        )

    def legs(self, poses):
        return _chords(poses)


@dataclass(frozen=True)
class Standoff:
    """Scans at several standoff ranges from a target (report figure 1c), aimed at it."""

    target: tuple
    standoffs: tuple
    altitude: float
    bearing: float = 180.0
    heading: float | None = None
    aim_at: tuple | None = None
    kind: ClassVar[str] = "standoff"
    relative: ClassVar[bool] = False

    def __post_init__(self):
        _set(self, "target", point_field("target", self.target))
        _set(self, "standoffs", standoffs_field("standoffs", self.standoffs))
        _set(self, "altitude", _altitude(self.altitude))
        _set(self, "bearing", _heading(number_field("bearing", self.bearing)))
        if self.heading is not None:
            _set(self, "heading", _heading(number_field("heading", self.heading)))
        _set(self, "aim_at", _optional_point("aim_at", self.aim_at))

    def build(self, current):
        return standoff_sweep(
            self.target,
            self.standoffs,
            self.altitude,
            bearing=self.bearing,
            heading=self.heading,
            aim_at=self.aim_at,
        )

    def legs(self, poses):
        return _chords(poses)


SEGMENT_KINDS = {cls.kind: cls for cls in (Manual, Straight, Turn, Orbit, FlyPast, Standoff)}
Segment = Manual | Straight | Turn | Orbit | FlyPast | Standoff


@dataclass(frozen=True)
class FlightPlan:
    """A start pose and an ordered list of segments; each continues from the last one's end.

    ``start`` is needed only when a relative manoeuvre (straight, turn) comes
    before any absolute segment. It is not itself a scan.
    """

    start: ScanPose | None = None
    segments: tuple = field(default_factory=tuple)

    def __post_init__(self):
        _set(self, "segments", tuple(self.segments))
        if self.start is not None and not isinstance(self.start, ScanPose):
            raise FieldError("start", self.start, "a ScanPose")

    @property
    def uses_start(self) -> bool:
        """Whether ``start`` shapes the path: only when the first segment is relative."""
        return bool(self.segments) and self.segments[0].relative

    def segment_poses(self) -> list[list[ScanPose]]:
        """The scans of each segment, in order."""
        current = self.start
        result = []
        for index, segment in enumerate(self.segments):
            if segment.relative and current is None:
                raise FieldError(
                    "start", None, f"a start pose before the {segment.kind} segment (segment {index + 1})"
                )
            try:
                poses = segment.build(current)
            except FieldError as error:
                raise _prefixed(error, f"segments[{index}].") from None
            result.append(poses)
            current = poses[-1]
        return result

    def poses(self) -> list[ScanPose]:
        """Every scan of the plan, in flying order."""
        return [pose for poses in self.segment_poses() for pose in poses]

    def path_length(self) -> float:
        """Metres flown from the first scan to the last.

        Where the plan knows the path it follows it: along the arc within a
        turn or orbit and from a turn's start to its first scan. Elsewhere
        (straight runs, manual scans, the jump to an absolute segment's first
        scan) it is the straight distance. The lead-in from ``start`` to the
        very first scan is not counted: this is the length of the collection.
        """
        distances = self.scan_distances()
        return distances[-1] if distances else 0.0

    def scan_distances(self) -> list[float]:
        """Metres flown from the first scan to each scan (0 for the first), in flying order.

        The one source of distance along the path: ``path_length`` is its last
        value and ``scan_times`` divides it by the speed.
        """
        distances: list[float] = []
        total = 0.0
        previous = None
        for segment, poses in zip(self.segments, self.segment_poses()):
            if previous is not None:
                total += (
                    segment.lead_in() if segment.relative else math.dist(previous.position, poses[0].position)
                )
            distances.append(total)
            for leg in segment.legs(poses):
                total += leg
                distances.append(total)
            previous = poses[-1]
        return distances

    def scan_times(self, speed: float) -> list[float]:
        """Seconds flown from the first scan to each scan at ``speed`` metres per second."""
        return [flight_time(distance, speed) for distance in self.scan_distances()]

    def flight_time(self, speed: float) -> float:
        """Seconds to fly ``path_length()`` at ``speed`` metres per second."""
        return flight_time(self.path_length(), speed)


def _prefixed(error: FieldError, prefix: str) -> FieldError:
    return FieldError(prefix + error.field, error.value, error.expected, limits=error.limits)


def path_length(poses: Sequence[ScanPose]) -> float:
    """Sum of straight distances (metres) between consecutive scan positions.

    This knows only the scan positions, so a turn counts its chords;
    ``FlightPlan.path_length`` measures turns and orbits along their arcs.
    """
    return sum(_chords(list(poses)))


def flight_time(distance: float, speed: float) -> float:
    """Seconds to fly ``distance`` metres at ``speed`` metres per second."""
    speed = number_field("speed", speed, 0.0, None, low_open=True)
    return distance / speed
