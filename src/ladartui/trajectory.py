"""Recorded trajectories: a CSV flight log as scan poses (optional).

Format: a header line naming the columns, then one record per line, times
increasing. Required: ``time`` (s), ``x``, ``y``, ``z`` (metres, scene
frame), ``heading`` (degrees clockwise from north); optional ``roll``,
``pitch`` (degrees). Instead of ``x, y, z`` a log may give ``latitude``,
``longitude`` (degrees, WGS84) and ``altitude`` (metres, same datum as the
origin): the segment's ``origin = [lat, lon, alt]`` is then the geographic
point of the scene frame's origin, and positions are converted to the local
east-north-up frame there exactly (geodetic to ECEF to ENU on the WGS84
ellipsoid). Blank lines and lines starting with ``#`` are skipped.
Scans are taken at ``rate`` Hz from the first record's time (or at given
``times``); between records positions are interpolated linearly and angles
along the shortest arc. Errors name ``file:line``.
"""

from __future__ import annotations

import csv
import re
import warnings
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from typing import ClassVar

import numpy as np

from ladartui.checks import MAX_COORDINATE, items_or_none, number_field, point_field
from ladartui.errors import FieldError, LadarError
from ladartui.fileprobe import (
    absolute_path,
    file_problem,
    not_utf8,
    other_code_points,
    path_field,
    refuse_special_file,
    text_lines,
)
from ladartui.fingerprint import Fingerprint, fingerprint_of
from ladartui.flight import MAX_ALTITUDE, MAX_SCANS, ScanPose
from ladartui.flight.pose import pose_field
from ladartui.number_text import plural

REQUIRED = ("time", "x", "y", "z", "heading")
GEODETIC = ("latitude", "longitude", "altitude")
OPTIONAL = ("roll", "pitch")
LOG_COLUMNS = (
    f"{', '.join(REQUIRED)}, or time, {', '.join(GEODETIC)}, heading (optional {', '.join(OPTIONAL)})"
)
# a unit written after a column's name: "time (s)", "roll [deg]", "pitch_rad"
UNIT_SUFFIX = re.compile(r"\s*(\(.*\)|\[.*\]|_(s|sec|m|ft|deg|degs|degrees|rad|radians))$")
LOG_SEPARATORS = (";", "\t", "|")  # what other exports separate columns with
WGS84_A = 6378137.0  # semi-major axis, metres
WGS84_F = 1 / 298.257223563  # flattening
WGS84_E2 = WGS84_F * (2 - WGS84_F)  # first eccentricity squared


def geodetic_to_ecef(lat_deg, lon_deg, alt_m) -> np.ndarray:
    """(N, 3) earth-centred, earth-fixed metres of WGS84 latitude, longitude, height."""
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    prime = WGS84_A / np.sqrt(1 - WGS84_E2 * np.sin(lat) ** 2)
    return np.stack(
        [
            (prime + alt_m) * np.cos(lat) * np.cos(lon),
            (prime + alt_m) * np.cos(lat) * np.sin(lon),
            (prime * (1 - WGS84_E2) + alt_m) * np.sin(lat),
        ],
        axis=-1,
    )


def geodetic_to_local(lat_deg, lon_deg, alt_m, origin) -> np.ndarray:
    """(N, 3) east, north, up metres of geodetic points, about ``origin`` (lat, lon, alt)."""
    lat0, lon0, alt0 = (float(v) for v in origin)
    offset = (
        geodetic_to_ecef(np.asarray(lat_deg, float), np.asarray(lon_deg, float), np.asarray(alt_m, float))
        - geodetic_to_ecef(np.array([lat0]), np.array([lon0]), np.array([alt0]))[0]
    )
    sl, cl = np.sin(np.radians(lat0)), np.cos(np.radians(lat0))
    so, co = np.sin(np.radians(lon0)), np.cos(np.radians(lon0))
    east = -so * offset[:, 0] + co * offset[:, 1]
    north = -sl * co * offset[:, 0] - sl * so * offset[:, 1] + cl * offset[:, 2]
    up = cl * co * offset[:, 0] + cl * so * offset[:, 1] + sl * offset[:, 2]
    return np.stack([east, north, up], axis=1)


class TrajectoryError(LadarError):
    """A flight log that cannot be read."""


@dataclass(frozen=True)
class FlightLog:
    time: np.ndarray
    xyz: np.ndarray  # (N, 3)
    heading: np.ndarray
    roll: np.ndarray
    pitch: np.ndarray
    fingerprint: Fingerprint | None = None  # of the file as read (a run records it)


def load_flight_log(path, origin=None) -> FlightLog:
    """The log at ``path``; ``origin`` (lat, lon, alt) places a geodetic log in the scene."""
    path = path_field("path", path, "a flight log file's path (CSV)")
    refuse_special_file(path, "expected a flight log (CSV)")
    try:
        data = path.read_bytes()
    except OSError as error:
        raise TrajectoryError(f"{path}: cannot read flight log ({error.strerror or error})") from None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        at, problem = not_utf8(data, error)
        raise TrajectoryError(f"{path}:{at}: {problem}; expected a flight log (CSV)") from None
    rows = [
        (n, line)
        for n, line in enumerate(text_lines(text), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not rows:
        raise TrajectoryError(f"{path}: empty flight log: expected a header and records")
    header_line, header = rows[0]
    names = [name.strip().lower() for name in next(csv.reader([header]))]
    separator = next((s for s in LOG_SEPARATORS if len(names) == 1 and s in header), None)
    if separator is not None:  # a spreadsheet's semicolon CSV, a tab-separated export
        raise TrajectoryError(
            f"{path}:{header_line}: header {header.strip()!r} is one column, separated by "
            f"{separator!r}: expected columns separated by commas: {LOG_COLUMNS}"
        )
    for column, name in enumerate(names):
        if name and name in names[:column]:
            raise TrajectoryError(
                f"{path}:{header_line}: header names {name} twice "
                f"(columns {names.index(name) + 1} and {column + 1})"
            )
    for name in names:  # "time (s)", "roll [deg]": not the column, and roll left out unseen
        bare = UNIT_SUFFIX.sub("", name)
        if bare != name and bare in (*REQUIRED, *GEODETIC, *OPTIONAL) and bare not in names:
            raise TrajectoryError(
                f"{path}:{header_line}: header column {name!r} is named with a unit: expected the "
                f"names alone, {LOG_COLUMNS}, in seconds, metres and degrees"
            )
    # a latitude or a longitude without x, y and z: a geodetic log, whatever else it lacks
    geodetic = all(c in names for c in GEODETIC) or (
        any(c in names for c in GEODETIC[:2]) and not all(c in names for c in ("x", "y", "z"))
    )
    required = ("time", *GEODETIC, "heading") if geodetic else REQUIRED
    missing = [c for c in required if c not in names]
    if missing:
        raise TrajectoryError(
            f"{path}:{header_line}: header {_quoted(header, len(names))} lacks {', '.join(missing)}: "
            f"expected columns {LOG_COLUMNS}"
        )
    if origin is not None and not geodetic:  # it would be taken and never used
        raise FieldError(
            "origin",
            tuple(origin),
            f"none: {path.name} is in scene metres (x, y, z); an origin places a log in "
            "latitude and longitude",
        )
    if geodetic and origin is None:
        raise TrajectoryError(
            f"{path}:{header_line}: a log in latitude and longitude needs "
            "the segment's origin = [lat, lon, alt] (the scene frame's "
            "origin on the earth)"
        )
    columns = {name: names.index(name) for name in (*required, *OPTIONAL) if name in names}
    table = _plain_records(rows[1:], len(names), columns)
    stop = None  # a record of another width, or a field no number: (index, field, problem)
    if table is None:  # quoted fields, irregular records: read record by record
        table, stop = _parsed_records(rows[1:], names, columns)
    _check_records(path, rows[1:], table, columns, geodetic, stop)
    got = dict(zip(columns, table.T))
    arr = {name: got.get(name, np.zeros(len(table))) for name in (*required, *OPTIONAL)}
    if len(arr["time"]) < 2:
        raise TrajectoryError(f"{path}: {plural(len(arr['time']), 'record')}: expected at least 2")
    if geodetic:
        xyz = geodetic_to_local(arr["latitude"], arr["longitude"], arr["altitude"], origin)
        far = np.flatnonzero(np.abs(xyz[:, :2]).max(axis=1) > MAX_COORDINATE)
        if far.size:  # first: so far away the earth's curve also takes it below the origin
            at = int(far[0])
            raise TrajectoryError(
                f"{path}:{rows[1 + at][0]}: latitude = {float(arr['latitude'][at])!r}, "
                f"longitude = {float(arr['longitude'][at])!r} put the aircraft "
                f"{xyz[at, 0] / 1000:.0f} km east and {xyz[at, 1] / 1000:.0f} km north of the "
                f"origin: expected within {MAX_COORDINATE / 1000:g} km of it each way"
            )
        high = int(np.argmax(xyz[:, 2]))
        if xyz[high, 2] > MAX_ALTITUDE:
            raise TrajectoryError(
                f"{path}:{rows[1 + high][0]}: altitude = "
                f"{float(arr['altitude'][high])!r} puts the aircraft "
                f"{xyz[high, 2]:.1f} m above the origin: expected at most {MAX_ALTITUDE:g} m above it"
            )
        low = int(np.argmin(xyz[:, 2]))
        if xyz[low, 2] <= 0:
            raise TrajectoryError(
                f"{path}:{rows[1 + low][0]}: altitude = "
                f"{float(arr['altitude'][low])!r} puts the aircraft at "
                f"{xyz[low, 2]:.1f} m above the origin: expected above it"
            )
    else:
        xyz = np.stack([arr["x"], arr["y"], arr["z"]], axis=1)
    return FlightLog(arr["time"], xyz, arr["heading"], arr["roll"], arr["pitch"], fingerprint_of(data))


def _quoted(header: str, columns: int, limit: int = 80) -> str:
    """The header line as found (a line an exporter wrote above it, "sep=,"), quoted; a
    long one cut to its start with its count of columns."""
    text = header.strip()
    return repr(text) if len(text) <= limit else f"{text[:limit]!r}... ({columns} columns)"


def _plain_records(records, width, columns) -> np.ndarray | None:
    """The ``columns`` of ``records`` ((line number, text) pairs) read at once, or None
    where any record is quoted, of another width or holds a value no number (for
    ``_parsed_records``): a million records read in a second or two, not twenty."""
    lines = [line for _, line in records]
    if not lines or any('"' in line or line.count(",") != width - 1 for line in lines):
        return None  # quoted fields, a record of another width: for the csv reading
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            table = np.loadtxt(
                lines,
                delimiter=",",
                comments=None,
                quotechar=None,
                usecols=list(columns.values()),
                dtype=np.float64,
                ndmin=2,
            )
        except ValueError:  # a value no number: named by the record-by-record reading
            return None
    return table if table.shape == (len(lines), len(columns)) else None


def _parsed_records(records, names, columns) -> tuple[np.ndarray, tuple[int, int, str] | None]:
    """The ``columns`` of ``records`` read one record at a time with the csv module, up to
    the first record of another width or with a field that is no number; then that
    stop, (record index, field index (-1: the whole record), what is wrong), else None.
    The stopped record's fields from the one that is no number on are NaN."""
    table = np.full((len(records), len(columns)), np.nan)
    for index, (_, line) in enumerate(records):
        fields = next(csv.reader([line]))
        if len(fields) != len(names):
            return table[: index + 1], (index, -1, f"{len(fields)} fields, expected {len(names)}")
        for field, (name, column) in enumerate(columns.items()):
            raw = fields[column].strip()
            try:
                table[index, field] = float(raw)
            except ValueError:
                return table[: index + 1], (index, field, f"{name} = {raw!r}: expected a number")
    return table, None


def _check_records(path, records, table, columns, geodetic, stop=None) -> None:
    """Raise for the first value of the log's ``table`` (a row per record, a column per
    one of ``columns``) out of bounds, or for ``stop`` (from ``_parsed_records``) where it
    comes first. Records in order; in a record, each field in turn (a number, finite,
    within bounds), then its time after the one before, then its latitude and longitude,
    or its height. The message names the record's line and the value as written."""
    found = []  # (record index, place in the record's order, what is wrong with it)

    def first(fails, place, problem) -> None:  # problem: of a record's index, its text
        at = np.flatnonzero(fails)
        if at.size:
            found.append((int(at[0]), place, problem))

    def written(name):  # a value as its record wrote it
        return lambda i: next(csv.reader([records[i][1]]))[columns[name]].strip()

    for field, name in enumerate(columns):
        value, text = table[:, field], written(name)
        problem = partial(_bound_problem, name, text)
        first(~np.isfinite(value), 3 * field + 1, partial(problem, "expected a finite number"))
        if name == "time":
            expected, limit = f"expected seconds within +-{MAX_LOG_TIME:g}", MAX_LOG_TIME
        elif name in LOG_ANGLE_LIMITS:
            limit = LOG_ANGLE_LIMITS[name]
            expected = f"expected degrees within +-{limit:g}"
        elif name in ("x", "y", "z"):
            expected, limit = (
                f"expected a coordinate within {MAX_COORDINATE:g} m of the scene's origin",
                MAX_COORDINATE,
            )
        else:
            continue
        first(np.abs(value) > limit, 3 * field + 2, partial(problem, expected))
    got, end = dict(zip(columns, table.T)), 3 * len(columns)
    time = got["time"]
    first(
        np.concatenate([[False], time[1:] <= time[:-1]]),
        end,
        lambda i: f"time = {float(time[i])!r}: expected times increasing (previous {float(time[i - 1])!r})",
    )
    if geodetic:
        lat, lon = got["latitude"], got["longitude"]
        first(np.abs(lat) > 90.0, end + 1, lambda i: f"latitude = {float(lat[i])!r}: expected -90..90")
        first(np.abs(lon) > 180.0, end + 2, lambda i: f"longitude = {float(lon[i])!r}: expected -180..180")
    else:
        z, text = got["z"], written("z")
        first(z <= 0, end + 1, lambda i: f"z = {float(z[i])!r}: expected > 0")
        first(z > MAX_ALTITUDE, end + 2, lambda i: f"z = {text(i)!r}: expected at most {MAX_ALTITUDE:g} m")
    if stop is not None:
        index, field, problem = stop
        found.append((index, 3 * field, lambda i: problem))
    if found:
        index, _, what = min(found, key=lambda f: f[:2])
        raise TrajectoryError(f"{path}:{records[index][0]}: {what(index)}")


def _bound_problem(name, written, expected, index) -> str:
    return f"{name} = {written(index)!r}: {expected}"


# A record's time, in seconds either way of 0: milliseconds since 1970 fit (1.7e12); past
# it a log's span could pass the float range (-1e308 to 1e308), which no scan count takes.
MAX_LOG_TIME = 1e15

# Angles a log may hold, in degrees: a heading unwrapped over up to a hundred turns, a
# roll or pitch either way round once; past them a value is no angle (1e20 was taken).
LOG_ANGLE_LIMITS = {"heading": 36_000.0, "roll": 360.0, "pitch": 360.0}


def _angle(times, angles, t):
    """Interpolate angles (degrees) along the shortest arc between records, in [-180, 180)."""
    unwrapped = np.degrees(np.unwrap(np.radians(angles)))
    return (np.interp(t, times, unwrapped) + 180.0) % 360.0 - 180.0


def log_poses(log: FlightLog, template: ScanPose, rate: float | None = None, times=None) -> list[ScanPose]:
    """Scan poses along the log; ``template`` gives the sensor azimuth and depression.

    Scans at ``rate`` Hz from the log's first record, or at ``times`` (seconds,
    increasing, within the log's span), not both; a bad value is a ``FieldError``
    naming it.
    """
    template = pose_field("template", template)
    return _poses_at(log, template, np.asarray(scan_times_field(log, rate, times), dtype=np.float64))


def _poses_at(log: FlightLog, template: ScanPose, times: np.ndarray) -> list[ScanPose]:
    """``log_poses`` at ``times`` already checked (a segment's), not checked again."""
    xyz = np.stack([np.interp(times, log.time, log.xyz[:, a]) for a in range(3)], axis=1)
    heading = _angle(log.time, log.heading, times)
    return [
        replace(template, x=float(p[0]), y=float(p[1]), z=float(p[2]), heading=float(h) % 360.0)
        for p, h in zip(xyz, heading)
    ]


def rate_field(log: FlightLog, rate) -> float:
    """``rate`` (Hz) checked: above 0, at most ``MAX_SCAN_RATE_HZ`` and ``MAX_SCANS`` over the log."""
    checked = number_field("rate", rate, 0.0, MAX_SCAN_RATE_HZ, low_open=True)
    count = rate_count(log, checked)
    if count > MAX_SCANS:  # the span shown: a log in milliseconds reads 1,000 times too long
        raise FieldError(
            "rate",
            rate,
            f"at most {MAX_SCANS} scans over the log, which spans "
            f"{log.time[-1] - log.time[0]:.15g} s ({_span(log)}): {count:,} at this rate",
        )
    return checked


def _span(log: FlightLog) -> str:
    """The log's first and last times to the decimal: a log in GPS seconds spans "from
    1400000000.5 to 1400000010.25 s", not "from 1.4e+09 to 1.4e+09 s"."""
    return f"from {log.time[0]:.15g} to {log.time[-1]:.15g} s"


def times_field(log: FlightLog, given) -> tuple[float, ...]:
    """Scan times (seconds) checked: 1 to ``MAX_SCANS`` numbers, increasing, within the log."""
    span = f"times {_span(log)} (the log's span)"
    expected = f"a list of 1 to {MAX_SCANS} {span}"
    items = items_or_none(given)
    if items is None or not 1 <= len(items) <= MAX_SCANS:
        raise FieldError("times", given, expected)
    try:
        times = tuple(number_field("times", t, log.time[0], log.time[-1]) for t in items)
    except FieldError:
        raise FieldError("times", given, expected) from None
    if any(later <= earlier for earlier, later in zip(times, times[1:])):  # it would fly backwards
        raise FieldError("times", given, f"{expected}, increasing")
    return times


def scan_times_field(log: FlightLog, rate, times):
    """The scan times of a ``rate`` or of ``times``, exactly one of them given, checked."""
    one_of_rate_or_times(rate, times)
    if times is not None:
        return times_field(log, times)
    return rate_times(log, rate_field(log, rate))


def one_of_rate_or_times(rate, times) -> None:
    """A ``FieldError`` unless exactly one of a scan ``rate`` and scan ``times`` is given."""
    if (rate is None) == (times is None):
        raise FieldError("rate", rate, "either a scan rate (Hz) or a list of scan times (s), not both")


def rate_times(log: FlightLog, rate: float) -> np.ndarray:
    """Scan times at ``rate`` Hz from the log's first record, as many as fit in its span.

    The count forgives rounding (records at 0.1 and 0.3 s span 0.9999999999999999
    periods of 5 Hz), and a time a rounding step past the last record is that
    record's time (0.1 + 1/5 is 0.30000000000000004).
    """
    return np.minimum(log.time[0] + np.arange(rate_count(log, rate)) / rate, log.time[-1])


def rate_count(log: FlightLog, rate: float) -> int:
    """How many scans ``rate_times`` gives (without making them: a rate may ask for millions)."""
    return int(np.floor((log.time[-1] - log.time[0]) * rate + 1e-9)) + 1


def log_attitude(log: FlightLog, times) -> tuple[np.ndarray, np.ndarray]:
    """Roll and pitch (degrees) at the given times, shortest-arc interpolation."""
    return _angle(log.time, log.roll, times), _angle(log.time, log.pitch, times)


MAX_SCAN_RATE_HZ = 1000.0
LOG_AZIMUTH, LOG_DEPRESSION = 0.0, 90.0  # a log segment's sensor pointing when none is given


@dataclass(frozen=True)
class LogSegment:
    """A recorded flight log as a flight-path segment (``kind = "log"``).

    ``file``: the CSV log, made absolute (the scenario reader resolves a relative
    one against the scenario's folder; given in code, against the working folder,
    as ``open`` would), so a scenario saved anywhere names the same file. Scans at
    ``rate`` Hz from the log's first record, or at the listed ``times`` (seconds,
    within the log), not both. The sensor points at ``azimuth`` and ``depression``
    relative to the aircraft (unset: 0 and 90, straight down), or at ``aim_at``,
    not both. Roll and pitch come
    from the log (used by a body-fixed sensor).
    """

    file: str
    rate: float | None = None
    times: tuple | None = None
    azimuth: float | None = None
    depression: float | None = None
    aim_at: tuple | None = None
    origin: tuple | None = None  # (lat, lon, alt) of the scene origin, for a geodetic log
    kind: ClassVar[str] = "log"
    relative: ClassVar[bool] = False

    def __post_init__(self):
        set_ = partial(object.__setattr__, self)
        if not isinstance(self.file, (str, Path)) or not str(self.file).strip():
            raise FieldError("file", self.file, "the flight log's file name (.csv)")
        set_("file", str(absolute_path(self.file)))
        problem = file_problem(Path(self.file))
        if problem:  # named on the segment's file line, not as the log's own error
            if problem == "not found":
                problem += other_code_points(self.file)
            raise FieldError(
                "file",
                self.file,
                f"a flight log file (CSV): {problem}",
            )
        one_of_rate_or_times(self.rate, self.times)
        if self.azimuth is not None:
            set_("azimuth", number_field("azimuth", self.azimuth))
        if self.depression is not None:
            set_("depression", number_field("depression", self.depression, 1.0, 90.0))
        if self.aim_at is not None:
            set_("aim_at", point_field("aim_at", self.aim_at))
            self._refuse_or_drop_pointing()
        else:  # the unset pointing as a value, so a log written either way reads alike
            set_("azimuth", LOG_AZIMUTH if self.azimuth is None else self.azimuth)
            set_("depression", LOG_DEPRESSION if self.depression is None else self.depression)
        if self.origin is not None:
            try:
                lat, lon, alt = (float(v) for v in self.origin)
            except (TypeError, ValueError):
                raise FieldError(
                    "origin", self.origin, "[latitude, longitude, altitude] of the scene frame's origin"
                ) from None
            parts = (
                ("latitude", lat, -90.0, 90.0, "degrees"),
                ("longitude", lon, -180.0, 180.0, "degrees"),
                ("altitude", alt, -1e4, 1e5, "metres"),
            )
            checked = []
            for i, (what, value, low, high, unit) in enumerate(parts):
                if not low <= value <= high:  # nan too
                    # named origin[i] so the scenario's error points at the origin line
                    raise FieldError(f"origin[{i}]", value, f"a {what} from {low:g} to {high:g} {unit}")
                checked.append(value)
            set_("origin", tuple(checked))
        log = load_flight_log(self.file, self.origin)
        set_("_log", log)
        if self.rate is not None:
            set_("rate", rate_field(log, self.rate))
        else:
            set_("times", times_field(log, self.times))

    def _refuse_or_drop_pointing(self):
        """Refuse a pointing beside the aim point, which sets both angles; drop the unset
        values themselves, which earlier versions wrote with every log."""
        from ladartui.flight.plan import refuse_two_pointings

        unset = {"azimuth": LOG_AZIMUTH, "depression": LOG_DEPRESSION}
        given = {
            name: getattr(self, name)
            for name, value in unset.items()
            if getattr(self, name) not in (None, value)
        }
        refuse_two_pointings(self.aim_at, given)
        object.__setattr__(self, "azimuth", None)
        object.__setattr__(self, "depression", None)

    @property
    def log(self) -> FlightLog:
        """The flight log read from ``file`` (read once, when the segment is made)."""
        return self.__dict__["_log"]

    def scan_times(self) -> np.ndarray:
        log = self.log
        if self.times is not None:
            return np.asarray(self.times, dtype=np.float64)
        rate = self.rate
        assert rate is not None  # __post_init__ requires a rate when there are no times
        return rate_times(log, rate)

    def build(self, current) -> list[ScanPose]:
        from ladartui.flight import ScanPose as Pose
        from ladartui.flight import aim_at

        azimuth = LOG_AZIMUTH if self.azimuth is None else self.azimuth
        depression = LOG_DEPRESSION if self.depression is None else self.depression
        template = Pose(0.0, 0.0, 1.0, 0.0, azimuth, depression)
        poses = _poses_at(self.log, template, self.scan_times())  # times checked when made
        return poses if self.aim_at is None else [aim_at(p, self.aim_at) for p in poses]

    def attitudes(self) -> list[tuple[float, float]]:
        roll, pitch = log_attitude(self.log, self.scan_times())
        return [(float(r), float(p)) for r, p in zip(roll, pitch)]

    def legs(self, poses):
        return [float(np.linalg.norm(np.subtract(a.position, b.position))) for a, b in zip(poses, poses[1:])]

    def leg_seconds(self, poses) -> list[float]:
        """Seconds between consecutive scans by the log's own clock, not the plan's speed."""
        return np.diff(self.scan_times()).tolist()


HEADING_TOLERANCE = 45.0  # degrees off the track: a crab in a strong wind stays well within it
MIN_TRACK_SPEED = 1.0  # m/s across the ground: slower, a heading says nothing of a track


def heading_note(log: FlightLog, name: str = "") -> str | None:
    """A sentence when the logged heading is more than ``HEADING_TOLERANCE`` off the
    direction of travel over most of the distance flown, saying whether the headings
    read as radians or as degrees counter-clockwise from east; None otherwise."""
    legs = np.diff(log.xyz[:, :2], axis=0)
    length = np.hypot(legs[:, 0], legs[:, 1])
    moving = length > MIN_TRACK_SPEED * np.diff(log.time)
    if not moving.any():
        return None
    length = length[moving]
    track = np.degrees(np.arctan2(legs[moving, 0], legs[moving, 1])) % 360.0
    first, turn = log.heading[:-1][moving], log.heading[1:][moving]

    def off_share(convert) -> float:
        start, end = convert(first), convert(turn)
        middle = start + ((end - start + 180.0) % 360.0 - 180.0) / 2  # along the shortest arc
        off = np.abs((middle - track + 180.0) % 360.0 - 180.0) > HEADING_TOLERANCE
        return float(length[off].sum() / length.sum())

    share = off_share(lambda h: h)
    if share <= 0.5:
        return None
    said = (
        f"{name or 'the log'}: the logged heading differs from the direction of travel by more than "
        f"{HEADING_TOLERANCE:g} degrees over {share:.0%} of the distance flown: "
    )
    expected = "expected degrees clockwise from north"
    value, along = float(first[0]), f"{track[0]:.0f}"
    if np.abs(log.heading).max() <= 2 * np.pi + 1e-6 and off_share(np.degrees) <= 0.5:
        return f"{said}the headings read as radians ({value:.4g} for {along} degrees): {expected}"
    if off_share(lambda h: 90.0 - h) <= 0.5:
        return (
            f"{said}the headings read as degrees counter-clockwise from east ({value:.4g} for {along} "
            f"degrees clockwise from north): {expected}"
        )
    return f"{said}{expected} (an aircraft flying sideways, as a multirotor can, gives this too)"
