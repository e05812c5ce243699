"""The scenario file's format: its sections and keys, and the reader that checks them
(``ladartui.scenario_writer`` writes what it reads).

``ScenarioReader(path, text).arguments(doc)`` turns a parsed document into a
Scenario's arguments (``ladartui.scenario.scenario_from_toml`` builds it);
every error names the file, the line and the key as the file writes it. The
checks a Scenario also makes when built in code (``check_flight``,
``checked_target_names``) live here, beside the keys they check.

The file format (every key is checked; an unknown key is an error, so typos
are caught; keys marked "default" may be left out)::

    [files]
    scene = "generated/small.txt"   # scene model X.txt, relative to this file's folder
    voxel_size = 0.25               # metres per voxel, 0.001..100 (default 1.0)

    [sensor]                        # report section 7.1; every key has a default
    grid = 64                       # n: n x n detectors, 1..1024
    ray_grid = 2                    # m: m x m rays per detector, 1..16
    fov_deg = 8.0                   # full field of view, degrees, 1e-14 up to 90 (not 90)
    depth_resolution_m = 1.0        # returns closer than this on one detector merge, 0..1000
                                    # (metres of range: a dead time t is c t / 2; the
                                    # report's c t counts the light's way there and back)
    pixel_pitch_um = 100.0          # detector pitch, micrometres, 0.1..10000
    mount = "stabilised"            # or "body-fixed": rays turn with roll and pitch

    [flight]
    speed_mps = 30.0                # for the flight time (default 30; a log's scans keep its clock)

    [flight.start]                  # needed only if a straight or turn comes first
    x = 0.0                         # metres east
    y = -100.0                      # metres north
    z = 60.0                        # metres up, > 0
    heading = 0.0                   # degrees clockwise from north
    azimuth = 0.0                   # sensor, degrees clockwise from the nose
    depression = 45.0               # sensor, degrees below horizontal, 1..90 (90 nadir)

    [[flight.segments]]             # one table per segment, flown in order
    kind = "orbit"                  # circle a target point, sensor aimed at it
    centre = [32.0, 32.0, 1.0]      # [x, y] or [x, y, z] metres
    radius = 60.0
    altitude = 60.0
    scans = 24
    direction = "right"             # default "right" (clockwise); or "left"
    start_bearing = 180.0           # default 180: first scan south of the centre
    arc = 360.0                     # default 360 degrees
    # aim_at = [x, y, z]            # default: the centre

Other segment kinds and their keys (``aim_at`` is optional on every kind but
``manual``, whose poses carry their own pointing):

* ``kind = "straight"``: ``distance`` (m), ``scans``; optional ``azimuth``,
  ``depression`` (new sensor pointing from here on; not with ``aim_at``, which
  sets both).
* ``kind = "turn"``: ``radius`` (m), ``arc`` (degrees), ``direction``
  ("left"/"right"), ``scans``; optional ``azimuth``, ``depression`` (not with
  ``aim_at``).
* ``kind = "manual"``: ``poses = [{ x = .., y = .., z = .., heading = ..,
  azimuth = .., depression = .. }, ...]`` (heading and azimuth default 0,
  depression 90).
* ``kind = "flypast"``: ``target``, ``standoff`` (m), ``altitude``, ``length``
  (m), ``scans``, ``heading`` (default 0), ``side`` (default "right").
* ``kind = "standoff"``: ``target``, ``standoffs = [100.0, 150.0, ...]`` (m),
  ``altitude``, ``bearing`` (default 180), ``heading`` (default: towards the
  target).
* ``kind = "log"``: a recorded flight log ``file`` (CSV, relative to this
  file's folder; see ``ladartui.trajectory``), scans at ``rate`` (Hz) or at
  ``times = [..]`` (s); ``azimuth`` (default 0), ``depression`` (default 90),
  or ``aim_at`` (not with them);
  ``origin = [lat, lon, alt]`` places a geodetic (latitude, longitude) log.
  Its scans are timed by the log's own clock, not by ``speed_mps``.

Straight and turn segments continue from the previous segment's last scan
(or from ``[flight.start]``); see ``ladartui.flight``. ::

    [simulation]                    # every key has a default
    backend = "auto"                # "auto" or a tracing backend name
    method = "exact"                # "exact" or "march" (the report's fixed step)
    step = 0.5                      # march step in voxels, 0.001..10
    precision = "f64"               # "f64" or "f32"
    fast_mode = false               # true: no progressive views during a run

    [detection]                     # optional; absent: the ideal sensor
    model = "geiger"                # see ladartui.detection.settings for every key

    [levels]                        # optional; detect / recognise / identify thresholds
    detect = 0.10                   # share of the target's visible voxels seen (default 0.10)
    recognise = 0.30                # (default 0.30)
    identify = 0.50                 # (default 0.50)
    detect_footprint = 0.10         # share of its footprint cells (x-y columns) seen (default 0.10)
    recognise_footprint = 0.50      # (default 0.50)
    identify_footprint = 0.75       # (default 0.75); see ladartui.levels for why
    [targets]                       # optional: names of the target model's targets
    names = { 1 = "truck", 2 = "van" }  # id -> name; an unnamed id reads "target N"

Turns and orbits bank as coordinated turns at ``speed_mps``; only a
``body-fixed`` sensor sees it (``ladartui.attitude``).

A run record (``S_Run.toml``, first line ``RECORD_HEADER``) is such a file
with ``[[run.inputs]]`` tables after the settings, the files its run read
(``ladartui.run_record``); in any other file ``[run]`` is an unknown section.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import re
import tomllib
from pathlib import Path

from ladartui.checks import number_field
from ladartui.detection.settings import DETECTION_KEYS, detection_from_table
from ladartui.errors import Described, FieldError, InputFileError
from ladartui.fileprobe import user_path
from ladartui.flight import (
    MAX_SCANS,
    SEGMENT_KINDS,
    FlightPlan,
    FlyPast,
    Manual,
    Orbit,
    ScanPose,
    Standoff,
    Straight,
    Turn,
)
from ladartui.levels import LEVEL_KEYS, level_below, levels_from_table
from ladartui.number_text import plural
from ladartui.sensor import MAX_PIXEL_PITCH, MIN_PIXEL_PITCH, Sensor
from ladartui.toml_lines import key_lines_from_text, toml_mistake
from ladartui.trajectory import LogSegment, rate_count

SENSOR_KEYS = {  # TOML key -> (Sensor field, file units per Sensor unit)
    "grid": ("grid", None),
    "ray_grid": ("ray_grid", None),
    "fov_deg": ("fov", None),
    "depth_resolution_m": ("depth_resolution", None),
    "pixel_pitch_um": ("pixel_pitch", 1e6),
    "mount": ("mount", None),
}
POSE_KEYS = ("x", "y", "z", "heading", "azimuth", "depression")
SECTIONS = {
    "files": ("scene", "voxel_size"),
    "sensor": tuple(SENSOR_KEYS),
    "flight": ("speed_mps", "start", "segments"),
    "simulation": ("backend", "method", "step", "precision", "fast_mode"),
    "detection": DETECTION_KEYS,
    "levels": LEVEL_KEYS,
    "targets": ("names",),
}
MAX_TARGET_NAME = 60
# The first line of a run record (ladartui.run_record): a scenario file that a run
# writes beside its outputs, saying which settings made them. No save replaces one.
RECORD_HEADER = "# ladartui run record"
RECORD_SUFFIX = "_Run.toml"  # S.toml's record is S_Run.toml
# A record's own section, after the settings: [[run.inputs]], the files the run read.
RECORD_SECTIONS = {"run": ("inputs", "outputs")}
# Segment kinds a scenario file may use: the flight plan's, and recorded logs.
SEGMENT_FILE_KINDS = {**SEGMENT_KINDS, LogSegment.kind: LogSegment}


# What a key left out is written as, where its name alone does not say.
MISSING_HINTS = {
    "flight.segments": (
        ": expected one or more [[flight.segments]] tables, each with its kind "
        f"({', '.join(SEGMENT_FILE_KINDS)}), as in the bundled scenarios ('ladartui validate "
        "default' writes one to copy)"
    ),
}


NESTED_TOO_DEEP = "not valid TOML: arrays or tables nested too deep to read"


def parse_document(text: str, path: Path) -> dict:
    """The TOML document of a scenario file; InputFileError with its line when it is not TOML."""
    try:
        return tomllib.loads(text)
    except RecursionError:
        raise InputFileError(path, NESTED_TOO_DEEP) from None
    except tomllib.TOMLDecodeError as error:
        message, line = toml_mistake(error, text)
        raise InputFileError(path, f"not valid TOML: {message}", line) from None


class ScenarioReader:
    """Turns the TOML document into a Scenario; every error names file, line and key."""

    def __init__(self, path: Path, text: str):
        self.path = path
        self.lines = key_lines_from_text(text)
        self.sections = {**SECTIONS, **(RECORD_SECTIONS if text.startswith(RECORD_HEADER) else {})}

    def line(self, key: str):
        # The exact key, else the nearest enclosing table or array item.
        while key:
            if key in self.lines:
                return self.lines[key]
            shorter = re.sub(r"(\.[^.\[]+|\[\d+\])$", "", key)
            if shorter == key:  # a part the pattern cannot take off ('a[b'): cut at its dot
                shorter = key.rpartition(".")[0]
            key = shorter
        return None

    def source(self, key):
        line = self.line(key)
        return f"{self.path}:{line}" if line else str(self.path)

    def field_error(self, key, value, expected):
        return FieldError(key, value, expected, source=self.source(key))

    def file_error(self, key, message):
        return InputFileError(self.path, message, self.line(key))

    @contextlib.contextmanager
    def located(self, prefix, table, rename=None):
        """Re-raise a FieldError from a constructor with the TOML key, raw value and line."""
        try:
            yield
        except FieldError as error:
            head = re.split(r"[.\[]", error.field, maxsplit=1)[0]
            rest = error.field[len(head) :]
            key = (rename or {}).get(head, head)
            value = table.get(key, error.value) if isinstance(table, dict) and not rest else error.value
            raise self.field_error(prefix + key + rest, value, error.expected) from None

    def table(self, doc, key, allowed, required=()):
        value = doc.get(key.rsplit(".", 1)[-1], {}) if isinstance(doc, dict) else {}
        if not isinstance(value, dict):
            raise self.file_error(key, f"'{key}' must be a table ([{key}]), not {type(value).__name__}")
        self.keys(value, key, allowed, required)
        return value

    def keys(self, table, where, allowed, required=(), what=""):
        for name in table:
            if name not in allowed:
                raise self.file_error(
                    f"{where}.{name}", f"unknown key '{where}.{name}'{what} (allowed: {', '.join(allowed)})"
                )
        for name in required:
            if name not in table:
                hint = MISSING_HINTS.get(f"{where}.{name}", "")
                raise self.file_error(where, f"missing key '{where}.{name}'{what}{hint}")

    def _levels_error(self, error: FieldError, table: dict) -> FieldError:
        """A [levels] error named by the key written: a default that falls below the
        level under it (``detect = 0.6`` alone, against recognise's 0.3) blames that
        level, the one in the file."""
        key = error.field.rpartition(".")[2]
        if key in table:
            return self.field_error(error.field, table[key], error.expected)
        below = level_below(key)
        if below is None or below not in table:
            return self.field_error(error.field, error.value, error.expected)
        return self.field_error(
            f"levels.{below}",
            table[below],
            f"at most levels.{key} ({error.value:g}, its default: set it too; "
            "a higher level needs at least as much)",
        )

    def arguments(self, doc) -> dict:
        """The Scenario's keyword arguments from the document (all but its path), each
        checked where its table or key can be named; ``constructed`` names the rest."""
        for name in doc:
            value = doc[name]
            tables = isinstance(value, list) and value and all(isinstance(v, dict) for v in value)
            if name not in self.sections and not (isinstance(value, dict) or tables):  # a key
                homes = [section for section, keys in self.sections.items() if name in keys]
                expected = f"it under [{homes[0]}]" if homes else f"a section ({', '.join(self.sections)})"
                raise self.file_error(name, f"key '{name}' outside any section: expected {expected}")
            if name == "sweep":  # a sweep spec given where a scenario goes
                raise self.file_error(
                    name, "a sweep spec ([sweep]), not a scenario: 'ladartui sweep FILE' runs it"
                )
            if name not in self.sections:
                raise self.file_error(name, f"unknown section [{name}] (allowed: {', '.join(self.sections)})")
        for name in RECORD_SECTIONS.keys() & doc.keys():  # read by ladartui.run_record
            self.table(doc, name, RECORD_SECTIONS[name])
        files = self.table(doc, "files", SECTIONS["files"], required=("scene",))
        sensor_table = self.table(doc, "sensor", SECTIONS["sensor"])
        flight = self.table(doc, "flight", SECTIONS["flight"], required=("segments",))
        sim = self.table(doc, "simulation", SECTIONS["simulation"])
        detection = None
        if "detection" in doc:
            table = self.table(doc, "detection", SECTIONS["detection"])
            try:
                detection = detection_from_table(table)
            except FieldError as error:
                key = error.field.rpartition(".")[2]
                raise self.field_error(error.field, table.get(key, error.value), error.expected) from None

        levels = None
        if "levels" in doc:
            table = self.table(doc, "levels", SECTIONS["levels"])
            try:
                levels = levels_from_table(table)
            except FieldError as error:
                raise self._levels_error(error, table) from None
        target_names: tuple = ()
        if "targets" in doc:
            names = self.table(doc, "targets", SECTIONS["targets"]).get("names", {})
            try:
                if not isinstance(names, dict):  # the file's form: a table (the API also takes pairs)
                    checked_target_names(None)
                target_names = checked_target_names(names)
            except FieldError as error:
                value = error.value if isinstance(names, dict) else names
                raise self.field_error("targets.names", value, error.expected) from None

        scene = files["scene"]
        if not isinstance(scene, str) or not scene.strip():
            raise self.field_error("files.scene", scene, "the scene model file name (X.txt)")

        if "pixel_pitch_um" in sensor_table:  # checked in the file's unit
            with self.located("sensor.", sensor_table):
                number_field(
                    "pixel_pitch_um",
                    sensor_table["pixel_pitch_um"],
                    MIN_PIXEL_PITCH * 1e6,
                    MAX_PIXEL_PITCH * 1e6,
                )
        sensor_args = {}
        for key, (name, scale) in SENSOR_KEYS.items():
            if key in sensor_table:
                value = sensor_table[key]
                if scale is not None and isinstance(value, (int, float)) and not isinstance(value, bool):
                    value = value / scale  # dividing by 1e6 is exact for 100 -> 1e-4
                sensor_args[name] = value
        rename = {name: key for key, (name, _) in SENSOR_KEYS.items()}
        with self.located("sensor.", sensor_table, rename):
            sensor = Sensor(**sensor_args)

        plan = self.flight_plan(flight)
        options = {"voxel_size": files.get("voxel_size", 1.0), "speed": flight.get("speed_mps", 30.0)}
        for key in SECTIONS["simulation"]:
            if key in sim:
                options[key] = sim[key]
        return {
            "scene_file": Path(scene),
            "sensor": sensor,
            "flight": plan,
            "detection": detection,
            "levels": levels,
            "target_names": target_names,
            **options,
        }

    @contextlib.contextmanager
    def constructed(self, doc):
        """Re-raise a FieldError of the Scenario built from ``arguments(doc)`` with the
        TOML key, the value as the file wrote it and its line."""
        try:
            yield
        except FieldError as error:
            files, flight, sim = (doc.get(name, {}) for name in ("files", "flight", "simulation"))
            raw = {"files.voxel_size": files.get("voxel_size"), "flight.speed_mps": flight.get("speed_mps")}
            table, _, key = error.field.rpartition(".")
            value = raw.get(error.field, sim.get(key, error.value) if table == "simulation" else error.value)
            raise self.field_error(error.field, value, error.expected) from None

    def pose(self, table, where) -> ScanPose:
        if not isinstance(table, dict):
            raise self.file_error(where, f"'{where}' must be a table of {', '.join(POSE_KEYS)}")
        self.keys(table, where, POSE_KEYS, required=("x", "y", "z"))
        with self.located(where + ".", table):
            return ScanPose(**table)

    def flight_plan(self, flight) -> FlightPlan:
        start = self.pose(flight["start"], "flight.start") if "start" in flight else None
        items = flight["segments"]
        if not isinstance(items, list) or not items or not all(isinstance(i, dict) for i in items):
            raise self.file_error(
                "flight.segments", "'flight.segments' must be one or more [[flight.segments]] tables"
            )
        segments = [self.segment(item, f"flight.segments[{index}]") for index, item in enumerate(items)]
        plan = FlightPlan(start, tuple(segments))
        try:
            check_flight(plan)
        except FieldError as error:
            raise self.field_error(error.field, error.value, error.expected) from None
        return plan

    def segment(self, item, where):
        if "kind" not in item:
            raise self.file_error(
                where, f"missing key '{where}.kind' (one of {', '.join(SEGMENT_FILE_KINDS)})"
            )
        kind = item["kind"]
        if not isinstance(kind, str) or kind not in SEGMENT_FILE_KINDS:
            raise self.field_error(
                f"{where}.kind", kind, "one of " + ", ".join(repr(k) for k in SEGMENT_FILE_KINDS)
            )
        cls = SEGMENT_FILE_KINDS[kind]
        fields = dataclasses.fields(cls)
        allowed = ("kind", *(f.name for f in fields))
        required = [
            f.name
            for f in fields
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        ]
        self.keys(item, where, allowed, required, what=f" ({kind} segment)")
        args = {k: v for k, v in item.items() if k != "kind"}
        if cls is Manual:
            poses = args["poses"]
            if not isinstance(poses, list) or not poses:
                raise self.field_error(
                    f"{where}.poses",
                    poses,
                    "a list of one or more poses "
                    "{ x = .., y = .., z = .., heading = .., "
                    "azimuth = .., depression = .. }",
                )
            args["poses"] = [self.pose(p, f"{where}.poses[{i}]") for i, p in enumerate(poses)]
        if cls is LogSegment and isinstance(args["file"], str) and args["file"].strip():
            args["file"] = str(resolve_path(self.path.parent, args["file"]))
        with self.located(where + ".", item):
            return cls(**args)


def checked_target_names(names) -> tuple[tuple[int, str], ...]:
    """``{id: name}`` (ids as TOML keys "1" or ints) as ((id, name), ...) by ascending id."""
    from ladartui.scene.voxels import MAX_TARGET_ID

    expected = (
        f'a table of target id (1..{MAX_TARGET_ID}) = "name", e.g. {{ 1 = "truck" }}, '
        f"names of 1 to {MAX_TARGET_NAME} printable characters"
    )
    items = names.items() if isinstance(names, dict) else names
    try:
        pairs = [(key, value) for key, value in items]
    except (TypeError, ValueError):
        raise FieldError("targets.names", names, expected) from None
    out = {}
    for key, value in pairs:
        text = str(key).strip()
        if not (text.isascii() and text.isdigit() and 1 <= int(text) <= MAX_TARGET_ID):
            raise FieldError("targets.names", key, expected)
        if (
            not isinstance(value, str)
            or not value.strip()
            or len(value) > MAX_TARGET_NAME
            or not value.isprintable()
        ):
            raise FieldError("targets.names", value, expected)
        if int(text) in out:  # "1" and "01": one id named twice
            raise FieldError("targets.names", key, f"each target id once (id {int(text)} is named twice)")
        out[int(text)] = value
    return tuple(sorted(out.items()))


def check_flight(plan: FlightPlan) -> None:
    """Every scan can be built, and there is at least one and at most MAX_SCANS."""
    if not plan.segments:
        raise FieldError("flight.segments", [], "at least one segment")
    declared = sum(declared_scans(segment) for segment in plan.segments)
    if declared > MAX_SCANS:  # refused before millions of scans are made only to be counted
        raise FieldError(
            "flight.segments", Described(plural(declared, "scan")), f"at most {MAX_SCANS:,} scans"
        )
    try:
        count = sum(len(p) for p in plan.segment_poses())
    except FieldError as error:
        raise FieldError("flight." + error.field, error.value, error.expected) from None
    if count > MAX_SCANS:  # each segment makes its declared scans: a guard, not met in use
        raise FieldError("flight.segments", Described(plural(count, "scan")), f"at most {MAX_SCANS:,} scans")


def declared_scans(segment) -> int:
    """The scans ``segment`` makes, counted without making them: its ``scans``, its poses,
    standoffs or listed times, a log's scans at its rate. ``TypeError`` for an object no
    segment."""
    if isinstance(segment, LogSegment):
        if segment.times is not None:
            return len(segment.times)
        assert segment.rate is not None  # a log scans at a rate or at times
        return rate_count(segment.log, segment.rate)
    if isinstance(segment, Manual):
        return len(segment.poses)
    if isinstance(segment, Standoff):
        return len(segment.standoffs)
    if isinstance(segment, (Straight, Turn, Orbit, FlyPast)):
        return segment.scans
    raise TypeError(f"no flight segment: {segment!r}")


def resolve_path(folder: Path, file) -> Path:
    file = user_path(file)
    return Path(os.path.normpath(file if file.is_absolute() else folder / file))


def is_record(path) -> bool:
    """Whether ``path`` is a run record (by its first line)."""
    if not Path(path).is_file():  # a pipe would wait for ever
        return False
    try:
        with open(path, encoding="utf-8-sig") as file:
            return file.readline().startswith(RECORD_HEADER)
    except (OSError, UnicodeDecodeError):
        return False


def record_owner(path) -> str:
    """The name of the scenario file whose runs write the record ``path``."""
    return Path(path).name.removesuffix(RECORD_SUFFIX) + ".toml"
