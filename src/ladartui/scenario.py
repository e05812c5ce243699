"""Scenarios: the files, sensor, flight plan and run options, stored as TOML.

A scenario ``S.toml`` names a scene model ``X.txt``; the target model is
``X_Target.txt`` beside it, and a run writes ``S_Scene.txt``, ``S_Target.txt``
and ``S.cmf`` beside the scenario (report section 4.1 and table 2).

The file format, every key and the reader that checks it: ``ladartui.scenario_file``.
"""

from __future__ import annotations

import dataclasses
import os
import shlex
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

from ladartui import defaults
from ladartui.atomic import write_errors_named, write_text_atomic
from ladartui.checks import choice_field, number_field, switch_field
from ladartui.detection.settings import DetectionSettings
from ladartui.errors import FieldError, InputFileError, LadarError, OutputFileError
from ladartui.fileprobe import (
    OTHER_FILE_KINDS,
    absolute_path,
    file_problem,
    no_such_file,
    other_code_points,
    other_file_kind,
    path_field,
    read_utf8,
    require_file,
)
from ladartui.flight import (
    FlightPlan,
    ScanPose,
)
from ladartui.levels import LEVELS, LevelThresholds, percent_text
from ladartui.number_text import fixed, plural
from ladartui.scenario_file import (
    RECORD_SUFFIX,
    ScenarioReader,
    check_flight,
    checked_target_names,
    declared_scans,
    is_record,
    parse_document,
    record_owner,
    resolve_path,
)
from ladartui.scenario_style import restyle
from ladartui.scenario_writer import scenario_document, toml_text
from ladartui.sensor import Sensor
from ladartui.textsafe import one_line, single_line
from ladartui.toml_lines import key_lines
from ladartui.tracing.backend import METHODS, PRECISIONS
from ladartui.tracing.config import MIN_STEP

BUILTIN_BACKENDS = ("numba", "wgpu")
MAX_VOXEL_SIZE = 100.0
MIN_VOXEL_SIZE = 0.001  # a millimetre: finer than any LADAR resolves; 1e-300 m passed
MAX_SPEED = 1000.0
MAX_STEP = 10.0

RUN_ONLY_FIELDS = ("path", "backend", "fast_mode")  # change no output (``same_outputs``)

# A run traces every scan twice: against the scene, and against the target alone.
RUNS_TRACED = 2


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
        path = _scenario_path(self.path)
        set_(self, "path", path)
        scene_file = path_field("files.scene", self.scene_file, "a scene model's path")
        set_(self, "scene_file", resolve_path(path.parent, scene_file))
        set_(
            self,
            "voxel_size",
            number_field("files.voxel_size", self.voxel_size, MIN_VOXEL_SIZE, MAX_VOXEL_SIZE),
        )
        if not isinstance(self.sensor, Sensor):
            raise FieldError("sensor", self.sensor, "a Sensor")
        if not isinstance(self.flight, FlightPlan):
            raise FieldError("flight", self.flight, "a FlightPlan")
        set_(self, "speed", number_field("flight.speed_mps", self.speed, 0.0, MAX_SPEED, low_open=True))
        set_(self, "backend", choice_field("simulation.backend", self.backend, _backend_choices()))
        set_(self, "method", choice_field("simulation.method", self.method, METHODS))
        set_(self, "step", number_field("simulation.step", self.step, MIN_STEP, MAX_STEP))
        set_(self, "precision", choice_field("simulation.precision", self.precision, PRECISIONS))
        fast_mode = switch_field("simulation.fast_mode", self.fast_mode, "true or false")
        set_(self, "fast_mode", fast_mode)
        check_flight(self.flight)
        set_(self, "target_names", checked_target_names(self.target_names))
        if self.detection is not None:
            if not isinstance(self.detection, DetectionSettings):
                raise FieldError("detection", self.detection, "a DetectionSettings")
            if self.detection.geiger:
                self.detection.bin_width(self.sensor.depth_resolution)
        if self.levels is not None and not isinstance(self.levels, LevelThresholds):
            raise FieldError("levels", self.levels, "a LevelThresholds")

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

    def traced_rays(self) -> int:
        """Rays a run traces, the ray limit's count: every scan's, in both runs."""
        return RUNS_TRACED * self.sensor.rays_per_scan * self.scan_count()

    def scan_count(self) -> int:
        """Scans of the flight plan, counted without building the poses where it can be."""
        return sum(declared_scans(seg) for seg in self.flight.segments)

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

    @property
    def run_record(self) -> Path:
        """The settings a run went with, written with its outputs (ladartui.run_record)."""
        return self.path.with_name(f"{self.path.stem}{RECORD_SUFFIX}")

    # -- use --

    def poses(self) -> list[ScanPose]:
        """Every scan of the flight plan, in flying order."""
        return self.flight.poses()

    def path_length(self) -> float:
        return self.flight.path_length()

    def flight_time(self) -> float:
        return self.flight.flight_time(self.speed)

    def _clock_text(self) -> str:
        """How the flight time is reckoned: at the speed, or by a flight log's own clock."""
        from ladartui.flight.plan import keeps_own_clock

        if not any(map(keeps_own_clock, self.flight.segments)):
            return f"at {self.speed:g} m/s"
        if self.flight.one_log:
            return "by the flight log's clock"
        return f"by the flight logs' clock, other legs at {self.speed:g} m/s"

    def load_scene(self):
        """The scene model and its target model as a ``ladartui.scene.model.Scene``."""
        from ladartui.scene.model import Scene

        return Scene.load(self.scene_file, self.voxel_size)

    def check_files(self) -> None:
        """InputFileError naming the first referenced model file that does not exist, or a
        scene model of another kind (a point cloud, a mesh)."""
        missing = None
        if problem := file_problem(self.scene_file):
            missing = f"scene model file {self.scene_file} {problem} (files.scene)"
            if problem == "not found":
                missing += other_code_points(self.scene_file)
        # another kind of file: else its target, 'X_Target.las', was asked for
        elif other := other_model_kind(self.scene_file, self.voxel_size):
            kind, hint = other
            missing = (
                f"scene model file {self.scene_file} is {kind} ({self.scene_file.suffix}) "
                f"(files.scene): expected a voxel list (.txt){hint}"
            )
        elif (problem := file_problem(self.target_file)) and self.scene_file.stem.endswith("_Target"):
            scene = self.scene_file.with_stem(self.scene_file.stem.removesuffix("_Target"))
            missing = (
                f"scene model file {self.scene_file} is a target model (files.scene): "
                f"expected the scene model {scene}, whose target model it is"
            )
        elif problem:
            missing = (
                f"target model file {self.target_file} {problem} (the target model of "
                f"{self.scene_file.name} must sit beside it, named "
                f"{self.target_file.name})"
            )
            if problem == "not found":
                missing += other_code_points(self.target_file)
        if missing:
            raise InputFileError(self.path, missing, self.key_line("files.scene"))

    def key_line(self, key: str) -> int | None:
        """The line of ``key`` ("files.scene") in the scenario's file; None when the file
        is not there (not saved yet) or does not hold the key."""
        return key_lines(self.path).get(key) if self.path.is_file() else None

    def with_changes(self, **fields) -> Scenario:
        """A copy with ``fields`` replaced (checked like a new scenario)."""
        names = [f.name for f in dataclasses.fields(self) if f.init]
        for name, value in fields.items():
            if name not in names:
                raise FieldError(name, value, f"a Scenario field: {', '.join(names)}")
        return dataclasses.replace(self, **fields)

    def same_outputs(self, other: Scenario) -> bool:
        """Whether a run of ``other`` writes what a run of this scenario writes: every
        field equal but those ``no_output_fields`` names."""
        ignored = self.no_output_fields(other)
        return all(
            getattr(self, f.name) == getattr(other, f.name)
            for f in dataclasses.fields(self)
            if f.name not in ignored
        )

    def no_output_fields(self, other: Scenario) -> tuple[str, ...]:
        """The fields in which this scenario and ``other`` may differ and still write the
        same: the file's name, what only changes how a run goes (the backend, whose
        answers are the same, and fast mode, which draws less), and the march's step
        unless both march (methods that differ differ already)."""
        return RUN_ONLY_FIELDS + (() if self.method == other.method == "march" else ("step",))

    def outputs_alike(self, other: Scenario) -> Scenario:
        """``other`` with this scenario's values in ``no_output_fields``: where it still
        differs from this one, a run of it writes something else."""
        return dataclasses.replace(
            other, **{name: getattr(self, name) for name in self.no_output_fields(other)}
        )

    @classmethod
    def new(cls, path, scene_file, voxel_size=1.0, *, sensor=None, flight=None, **options) -> Scenario:
        """A new scenario for ``scene_file``; without ``flight``, an orbit around its target.

        The default orbit (see ``ladartui.defaults.default_flight``) reads the
        target model to find the target centre; ``sensor`` defaults likewise.
        """
        path = _scenario_path(path)
        scene_file = resolve_path(path.parent, path_field("files.scene", scene_file, "a scene model's path"))
        # before the default orbit reads it: a bad size is the field's error, not the sums'
        voxel_size = number_field("files.voxel_size", voxel_size, MIN_VOXEL_SIZE, MAX_VOXEL_SIZE)
        # another kind of file: else its default orbit asks for 'X_Target.las'
        if other := other_model_kind(scene_file, voxel_size):
            kind, hint = other
            raise FieldError(
                "files.scene", str(scene_file), f"a voxel list (.txt), not {kind} ({scene_file.suffix}){hint}"
            )
        if sensor is None:
            sensor = defaults.DEFAULT_SENSOR
        if flight is None:
            # the orbit reads the target model beside the scene's: a missing scene is named first
            require_file(scene_file, "expected a scene model (voxel list)")
            target_file = target_file_for(scene_file)
            if not target_file.is_file():
                raise InputFileError(
                    target_file,
                    "target model not found (a new scenario's "
                    "default orbit circles the target this file holds)",
                )
            from ladartui.scene.target_model import load_target

            target = load_target(target_file)[0]
            if len(target) == 0:  # a scene made without one ('generate --no-target')
                raise InputFileError(
                    target_file,
                    "target model holds no voxels; expected a target to circle (a new "
                    "scenario's default orbit circles the target this file holds)",
                )
            flight = defaults.default_flight(target, voxel_size)
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
            f"flight     {plural(len(poses), 'scan')}: {kinds}",
            f"           altitude {min(altitudes):g}..{max(altitudes):g} m, depression "
            f"{min(depressions):.3g}..{max(depressions):.3g} deg",
            f"           path {fixed(length, 1)} m, {fixed(self.flight_time(), 1)} s {self._clock_text()}",
            # the ray limit counts what is traced: both runs
            f"rays       {s.rays_per_scan:,} per scan, {s.rays_per_scan * len(poses):,} in all; "
            f"{self.traced_rays():,} traced with the target-alone run",
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
            f"{self.measures_file.name}, {self.run_record.name} in {self.path.parent}",
        ]
        return "\n".join(single_line(line) for line in lines)  # a path's line break kept in its line

    # -- TOML --

    def to_dict(self) -> dict:
        """The TOML document as plain data (paths relative to the scenario's folder)."""
        return scenario_document(self)

    def to_toml(self) -> str:
        return self.header() + self.toml_body()

    def header(self, quoted: bool = True) -> str:
        """The comment a new file starts with: how to check it, what a run writes
        (``quoted=False``: as written before its command quoted the file's name)."""
        # names in comments escaped: a control character there is not TOML
        name, scene, target = (one_line(p.name) for p in (self.path, self.scene_output, self.target_output))
        measures, record = one_line(self.measures_file.name), one_line(self.run_record.name)
        command = f"ladartui validate {shlex.quote(name) if quoted else name}"  # runs as written
        return (
            f"# ladartui scenario. Check it with: {command}\n"
            f"# A run writes {scene}, {target}, {measures} and {record} beside this file.\n\n"
        )

    def toml_body(self) -> str:
        """The TOML document without the header comments."""
        return toml_text(self.to_dict())

    def save(self, path=None) -> Scenario:
        """Write the scenario atomically to ``path`` (default: its own path), making
        its folder if there is none.

        Returns the scenario as saved (with ``path`` as its path, so its
        outputs sit beside the new file).
        """
        if path is not None:
            path = path_field("path", path, "a scenario file's path, or None for its own")
        scenario = self if path is None else self.with_changes(path=path)
        if refused := record_refusal(scenario.path) or input_refusal(scenario):
            raise OutputFileError(scenario.path, refused)
        text = None
        # keep the analyst's comments, key order and layout (not a record's header)
        if self.path.is_file() and not is_record(self.path):
            # its line ends as the file has them (restyle keeps CRLF); no byte order mark
            text = restyle(
                self.path.read_bytes().decode("utf-8-sig"), scenario.to_dict(), _saved_data(self.path)
            )
        if text is not None:  # the program's header: its names follow the file's
            newline = "\r\n" if "\r\n" in text else "\n"
            for old in (self.header(), self.header(quoted=False)):
                old = old.replace("\n", newline)
                if text.startswith(old):
                    text = scenario.header().replace("\n", newline) + text[len(old) :]
                    break
        with write_errors_named(scenario.path):
            write_text_atomic(scenario.path, text if text is not None else scenario.to_toml())
        return scenario


def record_refusal(path) -> str | None:
    """Why no scenario is saved at ``path``: it is a run record (it would say that settings
    which never ran made outputs); None where one may be."""
    if not is_record(path):
        return None
    return (
        f"is a run record (the settings that made {record_owner(path)}'s outputs, "
        "written by its runs): save under another name"
    )


def input_files(scenario) -> list[tuple[Path, str, str]]:
    """The files ``scenario`` reads, each as (path, the key that names it, what it is):
    its scene and target models, then each flight log with its segment's index."""
    return [
        (Path(scenario.scene_file), "files.scene", "the scene model (files.scene)"),
        (Path(scenario.target_file), "files.scene", f"the target model of {scenario.scene_file.name}"),
        *(
            (
                Path(segment.file),
                f"flight.segments[{index}].file",
                f"the flight log of flight.segments[{index}]",
            )
            for index, segment in enumerate(scenario.flight.segments)
            if segment.kind == "log"
        ),
    ]


def input_refusal(scenario) -> str | None:
    """Why ``scenario`` is not saved at its path: that is a file it reads, its scene or
    target model or a flight log (paths compared resolved: a link is the file it names),
    whose contents the TOML would replace; None where it may be."""
    where = os.path.realpath(scenario.path)
    for path, _key, what in input_files(scenario):
        if os.path.realpath(path) == where:
            return f"is {what} this scenario reads: save it under another name"
    return None


def _levels_text(thresholds: LevelThresholds, default: bool) -> str:
    shares = ", ".join(
        f"{level} {percent_text(thresholds.voxel_share(level))}% / "
        f"{percent_text(thresholds.footprint_share(level))}%"
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
    """Read and check a scenario file; with ``check_files``, its model files must exist.
    A flight log is read either way: its records are the flight's poses, which the
    scenario's checks (scan count, work limit) need."""
    path = absolute_path(path_field("path", path, "a scenario file's path"))
    try:
        try:
            text = read_utf8(path, "expected a scenario file (.toml)")
        except InputFileError as error:  # no UTF-8 text (a point cloud, say), on its line
            if error.line is not None:  # not a folder or a pipe, whatever its suffix
                _refuse_other_kind(path, None)
            raise
        _refuse_other_kind(path, text)
    except FileNotFoundError:
        raise InputFileError(path, f"{no_such_file(path)}; expected a scenario file (.toml)") from None
    except OSError as error:
        raise InputFileError(path, f"cannot read the scenario file: {error.strerror or error}") from None
    scenario = scenario_from_toml(text, path)
    if switch_field("check_files", check_files):
        scenario.check_files()
    return scenario


# What a file of another kind given as a scenario is, by its suffix.
_NOT_SCENARIOS = {".txt": "a voxel list", ".npy": "a NumPy array", **OTHER_FILE_KINDS}
_NOT_SCENARIOS.pop(".toml")


def _refuse_other_kind(path: Path, text: str | None) -> None:
    """A voxel list, mesh or point cloud given as a scenario fails on its first line as
    TOML (or as text): say what it is. ``text``: None where it was no UTF-8 text."""
    kind = _NOT_SCENARIOS.get(path.suffix.lower())
    if kind is None:
        return
    if text is not None:
        try:
            tomllib.loads(text)
            return  # TOML after all: its keys are checked as a scenario's
        except tomllib.TOMLDecodeError:
            pass
        except RecursionError:
            return
    raise InputFileError(path, f"{kind} ({path.suffix}), not a scenario; expected a scenario file (.toml)")


def scenario_from_toml(text: str, path) -> Scenario:
    """Parse scenario TOML ``text`` as if read from ``path`` (errors name that file)."""
    path = absolute_path(path)
    doc = parse_document(text, path)
    reader = ScenarioReader(path, text)
    arguments = reader.arguments(doc)
    with reader.constructed(doc):
        return Scenario(path, **arguments)


# -- writing ------------------------------------------------------------------------


def _scenario_path(path) -> Path:
    """A scenario's path, absolute; FieldError for a folder (a run would write its
    outputs beside the folder, named after it)."""
    path = absolute_path(path_field("path", path, "a scenario file's path"))
    if path.is_dir():
        raise FieldError("path", str(path), "a scenario file's path (S.toml), not a folder")
    return path


__all__ = ["Scenario", "load_scenario", "scenario_from_toml", "target_file_for"]


def check_work(scenario, raise_with=None):
    """Refuse a run of ``scenario`` whose rays (two runs of every scan) exceed the work
    limit (``RayLimitError``; ``raise_with`` says how its user raises the limit). Checked
    where work starts, not as a scenario is read: one over the limit can still be opened,
    shown and cut down."""
    from ladartui.resources import RAISE_RAYS, check_rays

    sensor, scans = scenario.sensor, scenario.scan_count()
    check_rays(
        scenario.traced_rays(),
        f"{scenario.path}: sensor.grid = {sensor.grid}, sensor.ray_grid = "
        f"{sensor.ray_grid}, {plural(scans, 'scan')} x {RUNS_TRACED} runs "
        "(the scene run and the target-alone run)",
        raise_with=raise_with or RAISE_RAYS,
    )


def other_model_kind(path: Path, voxel_size: float) -> tuple[str, str] | None:
    """A model file of another kind than a voxel list, by its suffix (a point cloud, a
    mesh): what it is, and the hint that makes a scene model of it (``voxelize_hint``);
    None for a voxel list."""
    kind = other_file_kind(path)
    return (kind, voxelize_hint(path, kind, voxel_size)) if kind else None


def voxelize_hint(cloud: Path, kind: str, voxel_size: float) -> str:
    """For a point cloud named as the scene: the command that makes a scene model of it."""
    if kind != "a LAS point cloud":
        return ""
    return (
        f": make one from it with 'ladartui voxelize {shlex.quote(str(cloud))} "
        f"{shlex.quote(str(cloud.with_suffix('')))} --voxel-size {voxel_size:g}'"
    )
