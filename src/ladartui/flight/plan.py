"""Flight plans: segments of the kinds in ``paths``, chained into one pose list.

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

import itertools
import math
import threading
import weakref
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import ClassVar

from ladartui.checks import (
    MAX_COORDINATE,
    choice_field,
    items_or_none,
    number_field,
    point_field,
)
from ladartui.errors import FieldError
from ladartui.flight.paths import (
    _aimed,
    _altitude,
    _arc,
    _arc_steps,
    _length,
    _scans,
    _turn_centre,
    _with_sensor,
    flypast,
    orbit,
    standoff_sweep,
    standoffs_field,
    straight,
    turn,
)
from ladartui.flight.pose import DIRECTIONS, MAX_SCANS, ScanPose, _forward, _heading, pose_field


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
    refuse_two_pointings(segment.aim_at, {"azimuth": segment.azimuth, "depression": segment.depression})


def refuse_two_pointings(aim_at, pointing: dict) -> None:
    """FieldError on ``aim_at`` when any of ``pointing`` (each named as its user wrote
    it: a key, a form's label) is given too: the aim point sets both, so what was given
    there would be dropped without a word."""
    given = [name for name, value in pointing.items() if value is not None]
    if aim_at is None or not given:
        return
    verb = "is" if len(given) == 1 else "are"
    raise FieldError(
        "aim_at", aim_at, f"no aim point while {' and '.join(given)} {verb} given (an aim point sets both)"
    )


def _pointed(segment, current, fly):
    """Scans of ``fly(start)``, the start re-pointed and the scans aimed as the segment asks."""
    start = _with_sensor(current, segment.azimuth, segment.depression)
    return _aimed(fly(start), segment.aim_at)


def _chords(poses):
    return [math.dist(a.position, b.position) for a, b in zip(poses, poses[1:])]


ARC_STEP_DEG = 5.0  # a drawn arc's pieces: a circle in 72 chords


def _along_arc(a: ScanPose, b: ScanPose, centre, clockwise: bool, degrees: float, step_deg: float):
    """Points strictly between ``a`` and ``b`` on the circle about ``centre`` (x, y) that
    runs ``degrees`` from ``a`` to ``b``, at most ``step_deg`` apart."""
    pieces = max(1, math.ceil(degrees / step_deg))
    radius = math.hypot(a.x - centre[0], a.y - centre[1])
    bearing = math.degrees(math.atan2(a.x - centre[0], a.y - centre[1]))
    sign = 1.0 if clockwise else -1.0
    points = []
    for k in range(1, pieces):
        fx, fy = _forward(bearing + sign * degrees * k / pieces)
        z = a.z + (b.z - a.z) * k / pieces
        points.append((centre[0] + radius * fx, centre[1] + radius * fy, z))
    return points


@dataclass(frozen=True)
class Manual:
    """Scans placed one by one (report section 6, "manually setting each of the parameters")."""

    poses: tuple[ScanPose, ...]
    kind: ClassVar[str] = "manual"
    relative: ClassVar[bool] = False

    def __post_init__(self):
        try:
            poses = () if isinstance(self.poses, (str, bytes)) else tuple(self.poses)
        except TypeError:
            poses = ()  # no list at all: refused below, named as given
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

    def circle(self, poses) -> tuple[tuple[float, float], bool, float]:
        """The circle its scans lie on: centre (x, y), clockwise, degrees between scans
        (from the turn's start to its first scan too)."""
        clockwise = self.direction == "right"
        return _turn_centre(poses[0], self.radius, clockwise), clockwise, self.arc / self.scans


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

    def circle(self, poses) -> tuple[tuple[float, float], bool, float]:
        """The circle its scans lie on: centre (x, y), clockwise, degrees between scans."""
        return (self.centre[0], self.centre[1]), self.direction == "right", _arc_steps(self.arc, self.scans)


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


# The scans of the plans used last, by identity: kept beside the plans, not in them, so
# that the plans an editor's undo history holds (a few MB each) do not keep theirs.
_KEPT_PLANS = 8
_made: OrderedDict[int, tuple[weakref.ref, tuple]] = OrderedDict()
_made_lock = threading.Lock()


def _made_scans(plan: FlightPlan) -> tuple:
    key = id(plan)
    with _made_lock:
        entry = _made.get(key)
        if entry is not None and entry[0]() is plan:  # (an id outlives its plan)
            _made.move_to_end(key)
            return entry[1]
    made = plan._build()  # unlocked: slow, and two threads building the same plan agree
    with _made_lock:
        _made[key] = (weakref.ref(plan), made)
        _made.move_to_end(key)
        while len(_made) > _KEPT_PLANS:
            _made.popitem(last=False)
    return made


SEGMENTS_EXPECTED = (
    "a list of flight segments (Manual, Straight, Turn, Orbit, FlyPast, Standoff "
    "or a flight log's LogSegment)"
)


@dataclass(frozen=True)
class FlightPlan:
    """A start pose and an ordered list of segments; each continues from the last one's end.

    ``start`` is needed only when a relative manoeuvre (straight, turn) comes
    before any absolute segment. It is not itself a scan.
    """

    start: ScanPose | None = None
    segments: tuple = field(default_factory=tuple)

    def __post_init__(self):
        if isinstance(self.segments, (str, bytes)):  # not walked a letter at a time
            raise FieldError("segments", self.segments, SEGMENTS_EXPECTED)
        try:
            segments = tuple(self.segments)
        except TypeError:
            raise FieldError("segments", self.segments, SEGMENTS_EXPECTED) from None
        for index, segment in enumerate(segments):
            if not callable(getattr(segment, "build", None)):  # the segments' one shared method
                raise FieldError(f"segments[{index}]", segment, SEGMENTS_EXPECTED)
        _set(self, "segments", segments)
        if self.start is not None and not isinstance(self.start, ScanPose):
            raise FieldError("start", self.start, "a ScanPose")

    @property
    def uses_start(self) -> bool:
        """Whether ``start`` shapes the path: only when the first segment is relative."""
        return bool(self.segments) and self.segments[0].relative

    @property
    def closed(self) -> bool:
        """Whether the scans go round a loop: one full orbit, its last scan a step before
        its first (so scans picked from it are spread around the circle, not its ends)."""
        return (
            len(self.segments) == 1 and isinstance(self.segments[0], Orbit) and self.segments[0].arc >= 360.0
        )

    def segment_poses(self) -> list[list[ScanPose]]:
        """The scans of each segment, in order: made once for a plan in use (the plan and
        its poses are immutable; a 10,000-scan path takes a sixth of a second, and one
        edit asked for it 16 times), handed out as new lists."""
        return [list(poses) for poses in _made_scans(self)]

    def _build(self) -> tuple[tuple[ScanPose, ...], ...]:
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
            result.append(tuple(poses))
            current = poses[-1]
        return tuple(result)

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

    def path_points(self, step_deg: float = ARC_STEP_DEG) -> list[tuple[float, float, float]]:
        """Positions along the path flown from the first scan to the last, as
        ``path_length`` measures it: every scan, with points at most ``step_deg`` apart
        along the arc between the scans of a turn or an orbit (and from the scan before a
        turn to its first); elsewhere the straight line between scans joins them."""
        points: list[tuple[float, float, float]] = []
        previous = None
        for segment, poses in zip(self.segments, self.segment_poses()):
            circle = segment.circle(poses) if isinstance(segment, (Turn, Orbit)) else None
            for index, pose in enumerate(poses):
                if previous is not None and circle is not None and (index or segment.relative):
                    points.extend(_along_arc(previous, pose, *circle, step_deg))
                points.append(pose.position)
                previous = pose
        return points

    def scan_distances(self) -> list[float]:
        """Metres flown from the first scan to each scan (0 for the first), in flying order.

        The one source of distance along the path: ``path_length`` is its last
        value and ``scan_times`` divides its steps by the speed.
        """
        return list(itertools.accumulate(metres for metres, _ in self._steps()))

    def _steps(self):
        """Per scan in flying order: the metres from the scan before, and the seconds
        where the segment keeps its own clock (a flight log's records), else None."""
        previous = None
        for segment, poses in zip(self.segments, self.segment_poses()):
            if previous is None:
                yield 0.0, 0.0
            else:
                yield (
                    (
                        segment.lead_in()
                        if segment.relative
                        else math.dist(previous.position, poses[0].position)
                    ),
                    None,
                )
            legs = segment.legs(poses)
            seconds = segment.leg_seconds(poses) if keeps_own_clock(segment) else [None] * len(legs)
            yield from zip(legs, seconds)
            previous = poses[-1]

    @property
    def one_log(self) -> bool:
        """Whether the plan is one flight log alone: its times are the log's whatever the speed."""
        return len(self.segments) == 1 and keeps_own_clock(self.segments[0])

    def scan_times(self, speed: float) -> list[float]:
        """Seconds flown from the first scan to each scan: a flight log's scans at the
        log's own times, every other step at ``speed`` metres per second."""
        speed = number_field("speed", speed, 0.0, None, low_open=True)  # scans or none
        times, metres_at_speed, clocked = [], 0.0, 0.0
        for metres, seconds in self._steps():
            if seconds is None:
                metres_at_speed += metres
            else:
                clocked += seconds
            # the metres summed, then divided: without a log, exactly scan_distances / speed
            times.append(metres_at_speed / speed + clocked)
        return times

    def flight_time(self, speed: float) -> float:
        """Seconds from the first scan to the last (``scan_times``)."""
        times = self.scan_times(speed)
        return times[-1] if times else 0.0


def keeps_own_clock(segment) -> bool:
    """Whether ``segment`` times its scans itself (a flight log, kind "log": its
    ``leg_seconds``), not by the plan's speed."""
    return segment.kind == "log"


def _prefixed(error: FieldError, prefix: str) -> FieldError:
    return FieldError(prefix + error.field, error.value, error.expected, limits=error.limits)


def path_length(poses: Sequence[ScanPose]) -> float:
    """Sum of straight distances (metres) between consecutive scan positions.

    This knows only the scan positions, so a turn counts its chords;
    ``FlightPlan.path_length`` measures turns and orbits along their arcs.
    """
    items = None if isinstance(poses, ScanPose) else items_or_none(poses)
    if items is None:
        raise FieldError("poses", poses, "a list of ScanPose")
    return sum(_chords([pose_field(f"poses[{i}]", pose) for i, pose in enumerate(items)]))


def flight_time(distance: float, speed: float) -> float:
    """Seconds to fly ``distance`` metres at ``speed`` metres per second."""
    speed = number_field("speed", speed, 0.0, None, low_open=True)
    return distance / speed
