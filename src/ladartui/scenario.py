"""Scenarios: the files, sensor, flight plan and run options, stored as TOML.

A scenario ``S.toml`` names a scene model ``X.txt``; the target model is
``X_Target.txt`` beside it, and a run writes ``S_Scene.txt``, ``S_Target.txt``
and ``S.cmf`` beside the scenario (report section 4.1 and table 2).

The file format (every key is checked; an unknown key is an error, so typos
are caught; keys marked "default" may be left out)::

    [files]
    scene = "generated/small.txt"   # scene model X.txt, relative to this file's folder
    voxel_size = 0.25               # metres per voxel (default 1.0)

    [sensor]                        # report section 7.1; every key has a default
    grid = 64                       # n: n x n detectors, 1..1024
    ray_grid = 2                    # m: m x m rays per detector, 1..16
    fov_deg = 8.0                   # full field of view, degrees, > 0 and < 90
    depth_resolution_m = 1.0        # returns closer than this on one detector merge, 0..1000
    pixel_pitch_um = 100.0          # detector pitch, micrometres, > 0 and <= 10000
    mount = "stabilised"            # or "body-fixed": rays turn with roll and pitch

    [flight]
    speed_mps = 30.0                # for the flight time (default 30)

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

Other segment kinds and their keys (``aim_at`` is optional on every kind):

* ``kind = "straight"``: ``distance`` (m), ``scans``; optional ``azimuth``,
  ``depression`` (new sensor pointing from here on).
* ``kind = "turn"``: ``radius`` (m), ``arc`` (degrees), ``direction``
  ("left"/"right"), ``scans``; optional ``azimuth``, ``depression``.
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
  ``times = [..]`` (s); ``azimuth`` (default 0), ``depression`` (default 90).

Straight and turn segments continue from the previous segment's last scan
(or from ``[flight.start]``); see ``ladartui.flight``. ::

    [simulation]                    # every key has a default
    backend = "auto"                # "auto" or a tracing backend name
    method = "exact"                # "exact" or "march" (the report's fixed step)
    step = 0.5                      # march step in voxels, > 0 and <= 10
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
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import re
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import tomli_w

from ladartui import defaults
from ladartui.atomic import write_text_atomic
from ladartui.checks import choice_field, number_field
from ladartui.detection.settings import DETECTION_KEYS, DetectionSettings, detection_from_table
from ladartui.errors import FieldError, InputFileError, LadarError
from ladartui.fileprobe import file_problem
from ladartui.flight import (
    MAX_SCANS,
    SEGMENT_KINDS,
    FlightPlan,
    Manual,
    ScanPose,
)
from ladartui.levels import LEVEL_KEYS, LEVELS, LevelThresholds, levels_from_table
from ladartui.scenario_style import restyle
from ladartui.sensor import MAX_PIXEL_PITCH, Sensor
from ladartui.toml_lines import key_lines, key_lines_from_text
from ladartui.tracing.backend import METHODS, PRECISIONS
from ladartui.trajectory import LogSegment

BUILTIN_BACKENDS = ("numba", "wgpu")
MAX_VOXEL_SIZE = 100.0
MAX_SPEED = 1000.0
MAX_STEP = 10.0

_SENSOR_KEYS = {  # TOML key -> (Sensor field, file units per Sensor unit)
    "grid": ("grid", None),
    "ray_grid": ("ray_grid", None),
    "fov_deg": ("fov", None),
    "depth_resolution_m": ("depth_resolution", None),
    "pixel_pitch_um": ("pixel_pitch", 1e6),
    "mount": ("mount", None),
}
_POSE_KEYS = ("x", "y", "z", "heading", "azimuth", "depression")
_SECTIONS = {
    "files": ("scene", "voxel_size"),
    "sensor": tuple(_SENSOR_KEYS),
    "flight": ("speed_mps", "start", "segments"),
    "simulation": ("backend", "method", "step", "precision", "fast_mode"),
    "detection": DETECTION_KEYS,
    "levels": LEVEL_KEYS,
    "targets": ("names",),
}
MAX_TARGET_NAME = 60
RUN_ONLY_FIELDS = ("path", "backend", "fast_mode")  # change no output (``same_outputs``)
# Segment kinds a scenario file may use: the flight plan's, and recorded logs.
_SEGMENT_KINDS = {**SEGMENT_KINDS, LogSegment.kind: LogSegment}


def _backend_choices():
    # Asking the registry imports every backend module (numba takes about a
    # second), so do it only once tracing is loaded anyway; a backend plugged
    # in from outside registers before that.
    names = []
    if "ladartui.tracing.backend" in sys.modules:
        names = sys.modules["ladartui.tracing.backend"].backend_names()
    return ("auto", *dict.fromkeys([*BUILTIN_BACKENDS, *names]))


@dataclass(frozen=True)
class Scenario:
    """A scenario: where its files are, the sensor, the flight plan and the run options.

    ``path`` is the scenario file ``S.toml``; ``scene_file`` the scene model
    (relative paths resolve against the scenario's folder). Construction
    checks every field (FieldError naming it).
    """

    path: Path
    scene_file: Path
    voxel_size: float
    sensor: Sensor
    flight: FlightPlan
    speed: float = 30.0
    backend: str = "auto"
    method: str = "exact"
    step: float = 0.5
    fast_mode: bool = False
    precision: str = "f64"
    detection: DetectionSettings | None = None  # None: no [detection] section (ideal)
    levels: LevelThresholds | None = None  # None: no [levels] section (the defaults)
    target_names: tuple[tuple[int, str], ...] = ()  # [targets] names: (id, name), ascending ids

    def __post_init__(self):
        set_ = object.__setattr__
        path = _absolute(self.path)
        set_(self, "path", path)
        set_(self, "scene_file", _resolve(path.parent, self.scene_file))
        set_(
            self,
            "voxel_size",
            number_field("files.voxel_size", self.voxel_size, 0.0, MAX_VOXEL_SIZE, low_open=True),
        )
        if not isinstance(self.sensor, Sensor):
            raise FieldError("sensor", self.sensor, "a Sensor")
        if not isinstance(self.flight, FlightPlan):
            raise FieldError("flight", self.flight, "a FlightPlan")
        set_(self, "speed", number_field("flight.speed_mps", self.speed, 0.0, MAX_SPEED, low_open=True))
        set_(self, "backend", choice_field("simulation.backend", self.backend, _backend_choices()))
        set_(self, "method", choice_field("simulation.method", self.method, METHODS))
        set_(self, "step", number_field("simulation.step", self.step, 0.0, MAX_STEP, low_open=True))
        set_(self, "precision", choice_field("simulation.precision", self.precision, PRECISIONS))
        if not isinstance(self.fast_mode, bool):
            raise FieldError("simulation.fast_mode", self.fast_mode, "true or false")
        _check_flight(self.flight)
        set_(self, "target_names", _checked_target_names(self.target_names))
        if self.detection is not None:
            if not isinstance(self.detection, DetectionSettings):
                raise FieldError("detection", self.detection, "a DetectionSettings")
            if self.detection.geiger:
                self.detection.bin_width(self.sensor.depth_resolution)
        if self.levels is not None and not isinstance(self.levels, LevelThresholds):
            raise FieldError("levels", self.levels, "a LevelThresholds")
        _check_work(self)

    @property
    def geiger(self) -> bool:
        """True when the [detection] section asks for the Geiger-mode model."""
        return self.detection is not None and self.detection.geiger

    @property
    def level_thresholds(self) -> LevelThresholds:
        """The [levels] thresholds, or their defaults when the section is absent."""
        return self.levels if self.levels is not None else LevelThresholds()

    def target_name(self, target_id: int) -> str:
        """The name ``[targets] names`` gives a target id, else "target N"."""
        return dict(self.target_names).get(int(target_id), f"target {int(target_id)}")

    def scan_count(self) -> int:
        """Scans of the flight plan, counted without building the poses where it can be."""
        return sum(_segment_scans(seg) for seg in self.flight.segments)

    # -- derived file names (report table 2) --

    @property
    def name(self) -> str:
        return self.path.stem

    @property
    def target_file(self) -> Path:
        """The target model ``X_Target.txt`` beside the scene model ``X.txt``."""
        return target_file_for(self.scene_file)

    @property
    def scene_output(self) -> Path:
        return self.path.with_name(f"{self.path.stem}_Scene.txt")

    @property
    def target_output(self) -> Path:
        return self.path.with_name(f"{self.path.stem}_Target.txt")

    @property
    def measures_file(self) -> Path:
        return self.path.with_name(f"{self.path.stem}.cmf")

    # -- use --

    def poses(self) -> list[ScanPose]:
        """Every scan of the flight plan, in flying order."""
        return self.flight.poses()

    def path_length(self) -> float:
        return self.flight.path_length()

    def flight_time(self) -> float:
        return self.flight.flight_time(self.speed)

    def load_scene(self):
        """The scene model and its target model as a ``ladartui.scene.model.Scene``."""
        from ladartui.scene.model import Scene

        return Scene.load(self.scene_file, self.voxel_size)

    def check_files(self) -> None:
        """InputFileError naming the first referenced model file that does not exist."""
        missing = None
        if problem := file_problem(self.scene_file):
            missing = f"scene model file {self.scene_file} {problem} (files.scene)"
        elif problem := file_problem(self.target_file):
            missing = (
                f"target model file {self.target_file} {problem} (the target model of "
                f"{self.scene_file.name} must sit beside it, named "
                f"{self.target_file.name})"
            )
        if missing:
            line = key_lines(self.path).get("files.scene") if self.path.is_file() else None
            raise InputFileError(self.path, missing, line)

    def with_changes(self, **fields) -> Scenario:
        """A copy with ``fields`` replaced (checked like a new scenario)."""
        return dataclasses.replace(self, **fields)

    def same_outputs(self, other: Scenario) -> bool:
        """Whether a run of ``other`` writes what a run of this scenario writes: every
        field equal but the file's name and what only changes how a run goes (the
        backend, whose answers are the same, and fast mode, which draws less)."""
        return all(
            getattr(self, f.name) == getattr(other, f.name)
            for f in dataclasses.fields(self)
            if f.name not in RUN_ONLY_FIELDS
        )

    @classmethod
    def new(cls, path, scene_file, voxel_size=1.0, *, sensor=None, flight=None, **options) -> Scenario:
        """A new scenario for ``scene_file``; without ``flight``, an orbit around its target.

        The default orbit (see ``ladartui.defaults.default_flight``) reads the
        target model to find the target centre; ``sensor`` defaults likewise.
        """
        path = _absolute(path)
        scene_file = _resolve(path.parent, scene_file)
        if sensor is None:
            sensor = defaults.DEFAULT_SENSOR
        if flight is None:
            target_file = target_file_for(scene_file)
            if not target_file.is_file():
                raise InputFileError(
                    target_file,
                    "target model not found (a new scenario's "
                    "default orbit circles the target of X_Target.txt)",
                )
            from ladartui.scene.target_model import load_target

            flight = defaults.default_flight(load_target(target_file)[0], voxel_size)
        return cls(path, scene_file, voxel_size, sensor, flight, **options)

    def summary(self) -> str:
        """A few lines describing the scenario, for ``ladartui validate`` and the UI."""
        poses = self.poses()
        s = self.sensor
        altitudes = [p.z for p in poses]
        depressions = [p.depression for p in poses]
        kinds = ", ".join(
            f"{seg.kind} ({len(ps)})" for seg, ps in zip(self.flight.segments, self.flight.segment_poses())
        )
        length = self.path_length()
        lines = [
            f"scenario   {self.path}",
            f"scene      {self.scene_file}  (voxel {self.voxel_size:g} m)",
            f"target     {self.target_file}",
            f"sensor     {s.grid}x{s.grid} detectors, {s.ray_grid}x{s.ray_grid} rays each, "
            f"FOV {s.fov:g} deg ({s.ifov:.3g} deg per detector), "
            f"depth resolution {s.depth_resolution:g} m, pitch {s.pixel_pitch * 1e6:g} um",
            f"flight     {len(poses)} scans: {kinds}",
            f"           altitude {min(altitudes):g}..{max(altitudes):g} m, depression "
            f"{min(depressions):.3g}..{max(depressions):.3g} deg",
            f"           path {length:.1f} m, {self.flight_time():.1f} s at {self.speed:g} m/s",
            f"rays       {s.rays_per_scan:,} per scan, {s.rays_per_scan * len(poses):,} in all",
            f"run        backend {self.backend}, method {self.method}"
            + (f" (step {self.step:g} voxel)" if self.method == "march" else "")
            + f", {self.precision}"
            + (", fast mode" if self.fast_mode else ""),
            *(
                [
                    f"attitude   body-fixed sensor: rays turn with the aircraft's roll and pitch "
                    f"(coordinated turns at {self.speed:g} m/s)"
                ]
                if s.mount == "body-fixed"
                else []
            ),
            *([f"detection  {self.detection.describe()}"] if self.detection is not None else []),
            "levels     " + _levels_text(self.level_thresholds, self.levels is None),
            *(
                ["targets    " + ", ".join(f"{i} {name!r}" for i, name in self.target_names)]
                if self.target_names
                else []
            ),
            f"outputs    {self.scene_output.name}, {self.target_output.name}, "
            f"{self.measures_file.name} in {self.path.parent}",
        ]
        return "\n".join(lines)

    # -- TOML --

    def to_dict(self) -> dict:
        """The TOML document as plain data (paths relative to the scenario's folder)."""
        s = self.sensor
        flight: dict[str, object] = {"speed_mps": self.speed}
        if self.flight.start is not None:
            flight["start"] = self.flight.start.to_dict()
        flight["segments"] = [_segment_to_dict(seg, self.path.parent) for seg in self.flight.segments]
        sensor: dict[str, object] = {
            "grid": s.grid,
            "ray_grid": s.ray_grid,
            "fov_deg": s.fov,
            "depth_resolution_m": s.depth_resolution,
            "pixel_pitch_um": _to_micrometres(s.pixel_pitch),
        }
        if s.mount != "stabilised":  # written only when chosen: older files stay as they were
            sensor["mount"] = s.mount
        data = {
            "files": {"scene": _relative(self.scene_file, self.path.parent), "voxel_size": self.voxel_size},
            "sensor": sensor,
            "flight": flight,
            "simulation": {
                "backend": self.backend,
                "method": self.method,
                "step": self.step,
                "precision": self.precision,
                "fast_mode": self.fast_mode,
            },
        }
        if self.detection is not None:
            data["detection"] = self.detection.to_dict()
        if self.levels is not None:
            data["levels"] = self.levels.to_dict()
        if self.target_names:
            data["targets"] = {"names": {str(i): name for i, name in self.target_names}}
        return data

    def to_toml(self) -> str:
        header = (
            f"# ladartui scenario. Check it with: ladartui validate {self.path.name}\n"
            f"# A run writes {self.scene_output.name}, {self.target_output.name} and "
            f"{self.measures_file.name} beside this file.\n\n"
        )
        return header + _compact_arrays(tomli_w.dumps(self.to_dict()))

    def save(self, path=None) -> Scenario:
        """Write the scenario atomically to ``path`` (default: its own path).

        Returns the scenario as saved (with ``path`` as its path, so its
        outputs sit beside the new file).
        """
        scenario = self if path is None else self.with_changes(path=Path(path))
        text = None
        if self.path.is_file():  # keep the analyst's comments, key order and layout
            text = restyle(self.path.read_text(encoding="utf-8"), scenario.to_dict(), _saved_data(self.path))
        write_text_atomic(scenario.path, text if text is not None else scenario.to_toml())
        return scenario


def _levels_text(thresholds: LevelThresholds, default: bool) -> str:
    shares = ", ".join(
        f"{level} {thresholds.voxel_share(level):.0%} / {thresholds.footprint_share(level):.0%}"
        for level in LEVELS
    )
    return f"{shares} of visible voxels / footprint" + (" (defaults)" if default else "")


def _saved_data(path: Path) -> dict | None:
    """What the file at ``path`` means (defaults filled in), or None if unreadable."""
    try:
        return load_scenario(path, check_files=False).to_dict()
    except (LadarError, OSError):
        return None


def target_file_for(scene_file) -> Path:
    """The target model ``X_Target.txt`` of scene model ``X.txt`` (report table 2)."""
    scene_file = Path(scene_file)
    return scene_file.with_name(f"{scene_file.stem}_Target{scene_file.suffix or '.txt'}")


def load_scenario(path, check_files=True) -> Scenario:
    """Read and check a scenario file; with ``check_files``, its model files must exist."""
    path = _absolute(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputFileError(path, "scenario file not found") from None
    except IsADirectoryError:
        raise InputFileError(path, "is a folder; expected a scenario file (.toml)") from None
    except UnicodeDecodeError:
        raise InputFileError(path, "not UTF-8 text; expected a scenario file (.toml)") from None
    except OSError as error:
        raise InputFileError(path, f"cannot read the scenario file: {error.strerror or error}") from None
    scenario = scenario_from_toml(text, path)
    if check_files:
        scenario.check_files()
    return scenario


NESTED_TOO_DEEP = "not valid TOML: arrays or tables nested too deep to read"


def scenario_from_toml(text: str, path) -> Scenario:
    """Parse scenario TOML ``text`` as if read from ``path`` (errors name that file)."""
    path = _absolute(path)
    try:
        doc = tomllib.loads(text)
    except RecursionError:
        raise InputFileError(path, NESTED_TOO_DEEP) from None
    except tomllib.TOMLDecodeError as error:
        message = str(error)
        found = re.search(r"\(at line (\d+), column \d+\)", message)
        line = int(found.group(1)) if found else None
        message = re.sub(r"\s*\(at line \d+, column \d+\)", "", message)
        raise InputFileError(path, f"not valid TOML: {message}", line) from None
    return _Reader(path, text).scenario(doc)


# -- reading ------------------------------------------------------------------------


class _Reader:
    """Turns the TOML document into a Scenario; every error names file, line and key."""

    def __init__(self, path: Path, text: str):
        self.path = path
        self.lines = key_lines_from_text(text)

    def line(self, key: str):
        # The exact key, else the nearest enclosing table or array item.
        while key:
            if key in self.lines:
                return self.lines[key]
            key = re.sub(r"(\.[^.\[]+|\[\d+\])$", "", key) if re.search(r"[.\[]", key) else ""
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
                raise self.file_error(where, f"missing key '{where}.{name}'{what}")

    def scenario(self, doc) -> Scenario:
        for name in doc:
            if name not in _SECTIONS:
                raise self.file_error(name, f"unknown section [{name}] (allowed: {', '.join(_SECTIONS)})")
        files = self.table(doc, "files", _SECTIONS["files"], required=("scene",))
        sensor_table = self.table(doc, "sensor", _SECTIONS["sensor"])
        flight = self.table(doc, "flight", _SECTIONS["flight"], required=("segments",))
        sim = self.table(doc, "simulation", _SECTIONS["simulation"])
        detection = None
        if "detection" in doc:
            table = self.table(doc, "detection", _SECTIONS["detection"])
            try:
                detection = detection_from_table(table)
            except FieldError as error:
                key = error.field.rpartition(".")[2]
                raise self.field_error(error.field, table.get(key, error.value), error.expected) from None

        levels = None
        if "levels" in doc:
            table = self.table(doc, "levels", _SECTIONS["levels"])
            try:
                levels = levels_from_table(table)
            except FieldError as error:
                key = error.field.rpartition(".")[2]
                raise self.field_error(error.field, table.get(key, error.value), error.expected) from None
        target_names: tuple = ()
        if "targets" in doc:
            names = self.table(doc, "targets", _SECTIONS["targets"]).get("names", {})
            try:
                target_names = _checked_target_names(names)
            except FieldError as error:
                raise self.field_error("targets.names", error.value, error.expected) from None

        scene = files["scene"]
        if not isinstance(scene, str) or not scene.strip():
            raise self.field_error("files.scene", scene, "the scene model file name (X.txt)")

        if "pixel_pitch_um" in sensor_table:  # checked in the file's unit
            with self.located("sensor.", sensor_table):
                number_field(
                    "pixel_pitch_um",
                    sensor_table["pixel_pitch_um"],
                    0.0,
                    MAX_PIXEL_PITCH * 1e6,
                    low_open=True,
                )
        sensor_args = {}
        for key, (name, scale) in _SENSOR_KEYS.items():
            if key in sensor_table:
                value = sensor_table[key]
                if scale is not None and isinstance(value, (int, float)) and not isinstance(value, bool):
                    value = value / scale  # dividing by 1e6 is exact for 100 -> 1e-4
                sensor_args[name] = value
        rename = {name: key for key, (name, _) in _SENSOR_KEYS.items()}
        with self.located("sensor.", sensor_table, rename):
            sensor = Sensor(**sensor_args)

        plan = self.flight_plan(flight)
        options = {"voxel_size": files.get("voxel_size", 1.0), "speed": flight.get("speed_mps", 30.0)}
        for key in _SECTIONS["simulation"]:
            if key in sim:
                options[key] = sim[key]
        try:
            return Scenario(
                self.path,
                Path(scene),
                sensor=sensor,
                flight=plan,
                detection=detection,
                levels=levels,
                target_names=target_names,
                **options,
            )
        except FieldError as error:
            raw = {"files.voxel_size": files.get("voxel_size"), "flight.speed_mps": flight.get("speed_mps")}
            table, _, key = error.field.rpartition(".")
            value = raw.get(error.field, sim.get(key, error.value) if table == "simulation" else error.value)
            raise self.field_error(error.field, value, error.expected) from None

    def pose(self, table, where) -> ScanPose:
        if not isinstance(table, dict):
            raise self.file_error(where, f"'{where}' must be a table of {', '.join(_POSE_KEYS)}")
        self.keys(table, where, _POSE_KEYS, required=("x", "y", "z"))
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
            _check_flight(plan)
        except FieldError as error:
            raise self.field_error(error.field, error.value, error.expected) from None
        return plan

    def segment(self, item, where):
        if "kind" not in item:
            raise self.file_error(where, f"missing key '{where}.kind' (one of {', '.join(_SEGMENT_KINDS)})")
        kind = item["kind"]
        if not isinstance(kind, str) or kind not in _SEGMENT_KINDS:
            raise self.field_error(
                f"{where}.kind", kind, "one of " + ", ".join(repr(k) for k in _SEGMENT_KINDS)
            )
        cls = _SEGMENT_KINDS[kind]
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
            args["file"] = str(_resolve(self.path.parent, args["file"]))
        with self.located(where + ".", item):
            return cls(**args)


def _checked_target_names(names) -> tuple[tuple[int, str], ...]:
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
        out[int(text)] = value
    return tuple(sorted(out.items()))


def _check_flight(plan: FlightPlan) -> None:
    """Every scan can be built, and there is at least one and at most MAX_SCANS."""
    if not plan.segments:
        raise FieldError("flight.segments", [], "at least one segment")
    try:
        count = sum(len(p) for p in plan.segment_poses())
    except FieldError as error:
        raise FieldError("flight." + error.field, error.value, error.expected) from None
    if count > MAX_SCANS:
        raise FieldError("flight.segments", f"{count} scans", f"at most {MAX_SCANS} scans")


# -- writing ------------------------------------------------------------------------


def _segment_to_dict(segment, folder: Path) -> dict:
    data = {"kind": segment.kind}
    for f in dataclasses.fields(segment):
        value = getattr(segment, f.name)
        if value is None:
            continue
        if f.name == "poses":
            value = [p.to_dict() for p in value]
        elif isinstance(segment, LogSegment) and f.name == "file":
            value = _relative(Path(value), folder)
        elif isinstance(value, tuple):
            value = list(value)
        data[f.name] = value
    return data


def _to_micrometres(metres: float) -> float:
    # Shortest decimal, so 100e-6 m is written as 100.0 and reads back identically.
    micrometres = float(f"{metres * 1e6:.12g}")
    return micrometres if micrometres / 1e6 == metres else metres * 1e6


def _compact_arrays(text: str) -> str:
    """Put short numeric arrays on one line: ``centre = [32.0, 32.0, 1.0]``."""
    number = r"[-+]?(?:\d[\d_]*(?:\.\d+)?(?:[eE][-+]?\d+)?|inf|nan)"

    def join(match):
        items = re.findall(number, match.group(1))
        return "[" + ", ".join(items) + "]"

    return re.sub(r"\[\n((?:[ \t]+" + number + r",\n)+)[ \t]*\]", join, text)


def _absolute(path) -> Path:
    return Path(os.path.normpath(Path(path).expanduser().absolute()))


def _resolve(folder: Path, file) -> Path:
    file = Path(file).expanduser()
    return Path(os.path.normpath(file if file.is_absolute() else folder / file))


def _relative(file: Path, folder: Path) -> str:
    """``file`` relative to ``folder`` unless they share nothing but the root."""
    try:
        common = os.path.commonpath([file, folder])
    except ValueError:  # different drives
        return str(file)
    if common == file.anchor:
        return str(file)
    return os.path.relpath(file, folder)


__all__ = ["Scenario", "load_scenario", "scenario_from_toml", "target_file_for"]


def _segment_scans(segment) -> int:
    if hasattr(segment, "poses"):
        return len(segment.poses)
    if hasattr(segment, "standoffs"):
        return len(segment.standoffs)
    if hasattr(segment, "scans"):
        return segment.scans
    return len(segment.build(None))  # a recorded log: its scans come from the file


def _check_work(scenario):
    """Refuse a scenario whose rays (two runs of every scan) exceed the work limit."""
    from ladartui.resources import check_rays

    sensor, scans = scenario.sensor, scenario.scan_count()
    check_rays(
        2 * sensor.rays_per_scan * scans,
        f"{scenario.path.name}: sensor.grid = {sensor.grid}, sensor.ray_grid = "
        f"{sensor.ray_grid}, {scans:,} scans",
    )
