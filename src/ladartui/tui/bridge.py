"""The UI's one door into the core: scenario edits, checks and file handling.

Every check is the core's own (``Scenario``, ``Sensor``, ``ScanPose`` and the
flight segments raise ``FieldError``); this module only maps form fields to
those constructors, so limits are never repeated in the interface.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from ladartui.checks import compass_field, number_field
from ladartui.defaults import to_millimetres
from ladartui.errors import FieldError, InputFileError, LadarError
from ladartui.fileprobe import file_problem
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
    aim_at,
    altitude_field,
)
from ladartui.flight.plan import refuse_two_pointings
from ladartui.scenario import Scenario, load_scenario, other_model_kind, target_file_for
from ladartui.scenario_file import is_record
from ladartui.sensor import Sensor


@dataclass(frozen=True)
class Param:
    """A numeric parameter shown in a panel: where it lives and how it is typed."""

    key: str  # "sensor.grid", "scenario.speed", "start.x"
    label: str
    unit: str = ""  # the unit typed in the field (after ``scale``)
    integer: bool = False
    scale: float = 1.0  # field units -> stored units

    @property
    def group(self) -> str:
        return self.key.split(".", 1)[0]

    @property
    def name(self) -> str:
        return self.key.split(".", 1)[1]


SENSOR_PARAMS = [
    Param("sensor.grid", "Sensor grid n", integer=True),
    Param("sensor.ray_grid", "Ray grid m", integer=True),
    Param("sensor.fov", "Field of view", "deg"),
    Param("sensor.depth_resolution", "Depth res.", "m"),
    Param("sensor.pixel_pitch", "Pixel pitch", "um", scale=1e-6),
]
START_PARAMS = [
    Param("start.x", "Start x", "m"),
    Param("start.y", "Start y", "m"),
    Param("start.z", "Altitude", "m"),
    Param("start.heading", "Heading", "deg"),
    Param("start.azimuth", "Sensor az", "deg"),
    Param("start.depression", "Depression", "deg"),
]
FLIGHT_PARAMS = [Param("scenario.speed", "Speed", "m/s")]
RUN_PARAMS = [
    Param("scenario.voxel_size", "Voxel size", "m"),
    Param("scenario.step", "March step", "vox"),
]
ALL_PARAMS = {p.key: p for p in SENSOR_PARAMS + START_PARAMS + FLIGHT_PARAMS + RUN_PARAMS}

_POSE_FIELDS = ("x", "y", "z", "heading", "azimuth", "depression")


def _dataclass_default(cls, name):
    for f in dataclasses.fields(cls):
        if f.name == name and f.default is not dataclasses.MISSING:
            return f.default
    return None


def start_pose(scenario: Scenario) -> ScanPose:
    """The plan's start pose, or the first scan when the plan has none."""
    if scenario.flight.start is not None:
        return scenario.flight.start
    poses = scenario.poses()
    return as_written(poses[0]) if poses else ScanPose(0.0, 0.0, 100.0)


def as_written(pose: ScanPose) -> ScanPose:
    """A computed pose as a person would write it: to the millimetre and the millionth
    of a degree (3.3 and 44.554438, not 3.3000000000000074 and 44.55443822900466)."""
    x, y, z = to_millimetres(pose.position)
    angles = (round(a, 6) for a in (pose.heading, pose.azimuth, pose.depression))
    return ScanPose(x, y, z, *angles)


def param_value(scenario: Scenario, key: str):
    group, name = key.split(".", 1)
    if group == "sensor":
        return getattr(scenario.sensor, name)
    if group == "start":
        return getattr(start_pose(scenario), name)
    return getattr(scenario, name)


def param_default(key: str, fallback=None):
    """The parameter's default: the constructor's own default, else ``fallback``."""
    group, name = key.split(".", 1)
    cls = {"sensor": Sensor, "start": ScanPose, "scenario": Scenario}[group]
    value = _dataclass_default(cls, name)
    return fallback if value is None else value


def with_param(scenario: Scenario, key: str, value) -> Scenario:
    """A new scenario with one parameter changed; FieldError (naming it) if not allowed."""
    group, name = key.split(".", 1)
    if group == "sensor":
        try:
            sensor = dataclasses.replace(scenario.sensor, **{name: value})
        except FieldError as error:
            raise FieldError(
                f"sensor.{error.field}", error.value, error.expected, limits=error.limits
            ) from None
        return scenario.with_changes(sensor=sensor)
    if group == "start":
        if name == "heading":
            value = compass_field("heading", value)
        elif name == "z":
            value = altitude_field("z", value)
        try:
            start = dataclasses.replace(start_pose(scenario), **{name: value})
        except FieldError as error:
            raise FieldError(
                f"start.{error.field}", error.value, error.expected, limits=error.limits
            ) from None
        return scenario.with_changes(flight=FlightPlan(start, scenario.flight.segments))
    return scenario.with_changes(**{name: value})


def check_param(scenario: Scenario, key: str, value) -> None:
    with_param(scenario, key, value)


# -- flight segments -----------------------------------------------------------------

SEGMENT_LABELS = {
    "manual": "Manual poses",
    "straight": "Straight",
    "turn": "Turn",
    "orbit": "Orbit",
    "flypast": "Fly-past",
    "standoff": "Standoff",
    "log": "Flight log",
}
# segments the sidebar shows but cannot edit in a form (their data is a file)
FILE_SEGMENTS = {"log"}
FIELD_LABELS = {
    "distance": "Distance m",
    "scans": "Scans",
    "azimuth": "Sensor az deg",
    "depression": "Depression deg",
    "aim_at": "Aim at x,y,z m",
    "radius": "Radius m",
    "arc": "Arc deg",
    "direction": "Direction",
    "centre": "Centre x,y,z m",
    "altitude": "Altitude m",
    "start_bearing": "Start bearing deg",
    "target": "Target x,y,z m",
    "standoff": "Standoff m",
    "length": "Length m",
    "heading": "Heading deg",
    "side": "Target side",
    "standoffs": "Standoffs m",
    "bearing": "Bearing deg",
}
CHOICES = {"direction": ("right", "left"), "side": ("right", "left")}
POINT_FIELDS = {"centre", "target", "aim_at"}


def default_segment(kind: str, target_xyz, current: ScanPose | None):
    """A sensible new segment of ``kind`` around the target (metres)."""
    tx, ty, tz = (float(v) for v in target_xyz)
    altitude = current.z if current is not None else 100.0
    centre = (round(tx, 2), round(ty, 2), round(tz, 2))
    if kind == "straight":
        return Straight(distance=100.0, scans=5)
    if kind == "turn":
        return Turn(radius=100.0, arc=90.0, direction="right", scans=4)
    if kind == "orbit":
        return Orbit(centre=centre, radius=100.0, altitude=altitude, scans=12)
    if kind == "flypast":
        return FlyPast(target=centre, standoff=100.0, altitude=altitude, length=200.0, scans=5)
    if kind == "standoff":
        return Standoff(target=centre, standoffs=(50.0, 100.0, 150.0), altitude=altitude)
    raise FieldError("kind", kind, "a segment kind")


def segment_spec(segment, defaults=None):
    """Form rows (name, label, kind, value, default) for a segment's fields."""
    defaults = defaults or segment
    rows = []
    for f in dataclasses.fields(segment):
        name = f.name
        value = getattr(segment, name)
        default = getattr(defaults, name)
        kind: str | tuple[str, ...]  # a tuple: the choices of a select
        if name in CHOICES:
            kind = CHOICES[name]
        elif name in POINT_FIELDS:
            kind = "point"
        elif name == "standoffs":
            kind = "points"
        elif name == "scans":
            kind = "int"
        elif f.default is None:
            kind = "optional"
        else:
            kind = "float"
        rows.append((name, FIELD_LABELS.get(name, name), kind, value, default))
    return rows


def segment_builder(kind: str):
    cls = SEGMENT_KINDS[kind]

    def build(values):
        pointing = {FIELD_LABELS[name]: values.get(name) for name in ("azimuth", "depression")}
        refuse_two_pointings(values.get("aim_at"), pointing)  # in the form's words
        return cls(**values)

    return build


def with_article(noun: str) -> str:
    """The noun with its article: an orbit, a turn."""
    return ("an " if noun[:1] in "aeiou" else "a ") + noun


def segment_summary(segment) -> str:
    """A short description for the segments table."""
    k = segment.kind
    if k == "manual":
        return f"{len(segment.poses)} pose" + ("" if len(segment.poses) == 1 else "s")
    if k == "straight":
        return f"{segment.distance:g} m"
    if k == "turn":
        return f"{segment.direction} {segment.arc:g} deg r {segment.radius:g} m"
    if k == "orbit":
        arc = f"{segment.arc:g} deg " if segment.arc < 360.0 else ""  # the full circle unsaid
        return f"{arc}r {segment.radius:g} m at {segment.altitude:g} m"
    if k == "flypast":
        return f"{segment.length:g} m, {segment.standoff:g} m off at {segment.altitude:g} m"
    if k == "standoff":
        return ", ".join(f"{s:g}" for s in segment.standoffs) + " m"
    if k == "log":
        when = f"{segment.rate:g} Hz" if segment.rate is not None else f"{len(segment.times)} times"
        return f"{Path(segment.file).name}, {when}"
    return ""


def _plan(scenario: Scenario, segments) -> FlightPlan:
    start = scenario.flight.start
    if start is None and segments and segments[0].relative:  # else no segment starts from it
        start = start_pose(scenario)
    return FlightPlan(start, tuple(segments))


def with_segments(scenario: Scenario, segments) -> Scenario:
    """The scenario with a new segment list (checked by the scenario)."""
    return scenario.with_changes(flight=_plan(scenario, segments))


def with_segment_at(scenario: Scenario, segments, position: int) -> Scenario:
    """``with_segments`` for the form of segment ``position``: a path of more scans than
    a path may have is refused naming that segment's field as the form does (its scans,
    a standoff's standoffs), with the room the other segments leave it."""
    try:
        return with_segments(scenario, segments)
    except FieldError as error:
        if error.field != "flight.segments":
            raise
        counts = [len(poses) for poses in _plan(scenario, segments).segment_poses()]
        if sum(counts) <= MAX_SCANS:
            raise
    segment = segments[position]
    others = sum(counts) - counts[position]
    room = MAX_SCANS - others
    name, what = "scans", ""
    value: object = getattr(segment, "scans", counts[position])
    if isinstance(segment, Standoff):
        name, value, what = "standoffs", segment.standoffs, " standoff" if room == 1 else " standoffs"
    why = f"the path's other segments have {others} scan{'' if others == 1 else 's'}"
    if room < 1:
        raise FieldError(name, value, f"none here ({why}, the most a path has)")
    raise FieldError(name, value, f"at most {room}{what} here ({why}; a path has at most {MAX_SCANS})")


def aim_all(scenario: Scenario, target_xyz) -> Scenario:
    """Every segment aimed at the target point: presets and manoeuvres get ``aim_at``,
    manual poses are turned to look at it."""
    target = to_millimetres(target_xyz)
    segments = []
    for segment in scenario.flight.segments:
        if isinstance(segment, Manual):
            segments.append(Manual(tuple(aim_at(p, target) for p in segment.poses)))
        else:
            segments.append(dataclasses.replace(segment, aim_at=target, **_no_pointing(segment)))
    return with_segments(scenario, segments)


def _no_pointing(segment) -> dict:
    """A sensor pointing (a manoeuvre's, a flight log's) cleared: an aim point sets it,
    and one given beside it is refused; presets have none."""
    return {"azimuth": None, "depression": None} if hasattr(segment, "depression") else {}


def make_pose(values: dict) -> ScanPose:
    """A pose typed in the poses dialog: its z is an altitude asked for, so at most
    MAX_FLIGHT_ALTITUDE, as the start field's is (ScanPose alone allows the wide bound
    of computed poses)."""
    pose = {k: values[k] for k in _POSE_FIELDS}
    pose["z"] = altitude_field("z", pose["z"])
    return ScanPose(**pose)


# -- files -----------------------------------------------------------------------------


def derived_names(scenario_path: Path | None, scene_path: Path | None) -> list[tuple[str, str]]:
    """The names a new scenario derives (report table 2), for the setup dialog: any
    path typed so far, so a folder ("/", "dir/") derives nothing yet."""
    scene_path = scene_path if scene_path is not None and scene_path.name else None
    scenario_path = scenario_path if scenario_path is not None and scenario_path.name else None
    target = target_file_for(scene_path).name if scene_path else "(from the scene model)"
    if scenario_path is None:
        outputs = ("(from the scenario file)",) * 4
    else:
        probe = _probe_scenario(scenario_path, scene_path)
        outputs = (
            probe.scene_output.name,
            probe.target_output.name,
            probe.measures_file.name,
            probe.run_record.name,
        )
    return [
        ("3D target model", target),
        ("Scene simulation output", outputs[0]),
        ("Target simulation output", outputs[1]),
        ("Comparison measures", outputs[2]),
        ("Run record (its settings)", outputs[3]),
    ]


def _probe_scenario(scenario_path, scene_path, voxel_size=1.0) -> Scenario:
    # a throw-away scenario: the names and checks come from Scenario itself
    return Scenario(
        scenario_path,
        scene_path or Path("scene.txt"),
        voxel_size,
        Sensor(),
        FlightPlan(None, (Manual((ScanPose(0.0, 0.0, 1.0),)),)),
    )


def check_voxel_size(value) -> None:
    """FieldError unless ``value`` is an allowed voxel size (the scenario's own check)."""
    _probe_scenario(Path("probe.toml"), None, value)


def new_scenario(scenario_path: Path, scene_path: Path, voxel_size: float = 1.0) -> Scenario:
    """A new scenario for a scene model (its target model must exist), not yet saved:
    the app writes it once its scene has been read (``loading``), so a scene model that
    cannot be read leaves no file behind."""
    scenario_path = Path(scenario_path)
    if scenario_path.suffix != ".toml":
        scenario_path = scenario_path.with_name(scenario_path.name + ".toml")
    if is_record(scenario_path):
        raise FieldError("scenario file", str(scenario_path), "a new file name (this one is a run record)")
    if scenario_path.exists():
        raise FieldError(
            "scenario file", str(scenario_path), "a new file name (this one exists: load it instead)"
        )
    for path, what in ((scene_path, "scene model"), (target_file_for(scene_path), "target model")):
        if problem := file_problem(Path(path)):  # (a pipe exists: it is not 'not found')
            raise InputFileError(path, f"{what} file {problem}")
        # another kind of file, by its suffix: else 'S_Target.las: ... not a voxel list' or
        # 'S_Target.toml: ... not found', of a file no one named
        if other := other_model_kind(Path(path), voxel_size):
            kind, hint = other
            kind = "a scenario file" if Path(path).suffix.lower() == ".toml" else kind
            raise InputFileError(
                path, f"{what} file is {kind} ({Path(path).suffix}); expected a {what} (.txt){hint}"
            )
    return Scenario.new(scenario_path, scene_path, voxel_size)


def load_checked(path: Path) -> Scenario:
    """Load a scenario after checking that the model files it names exist.

    Missing outputs do not stop it (``run_record.missing_outputs`` lists them; a run
    writes them); a missing scene or target model does, with the file named.
    """
    return load_scenario(path)


def run_refusal(scenario: Scenario) -> str | None:
    """Why a run of ``scenario`` would be refused before tracing (more rays than the work
    limit, its outputs would replace a model file, or a file of its record's name that
    is not one); None if not."""
    from ladartui.resources import RAISE_IN_TUI
    from ladartui.scenario import check_work
    from ladartui.simulation import check_outputs_spare_inputs

    try:
        check_work(scenario, raise_with=RAISE_IN_TUI)
        check_outputs_spare_inputs(scenario)
    except LadarError as error:
        return str(error)
    return None


def save_as_refusal(scenario: Scenario, path: Path) -> str | None:
    """Why ``scenario`` saved as ``path`` could never run (its outputs there would replace
    its own model files or flight logs, or be named past the file system's limit), said
    in the Save As dialog where the name can still be changed; None if it could."""
    from ladartui.simulation import check_output_names, check_outputs_named_apart

    moved = scenario.with_changes(path=Path(path))
    try:
        check_output_names(moved)
        check_outputs_named_apart(moved)
    except LadarError as error:
        return str(error)
    return None


def view_angles(values: dict) -> tuple[float, float]:
    azimuth = number_field("azimuth", values["azimuth"])
    elevation = number_field("elevation", values["elevation"], -90.0, 90.0)
    return azimuth, elevation


def image_size(values: dict) -> tuple[int, int]:
    """A PNG's width and height in pixels, checked as the renderer checks them."""
    from ladartui.render.png import check_size

    return check_size(values["width"], values["height"])


def threshold_value(values: dict) -> float | None:
    value = values["threshold"]
    if value is None:
        return None
    return number_field("threshold", value, 0.0, None)


def backend_choices() -> list[tuple[str, str, bool]]:
    """(name, one-line description, available) for "auto" and each registered backend."""
    from ladartui.tracing import auto_summary
    from ladartui.tracing.backend import backend_status, get_backend

    rows = []
    status = backend_status()
    for name, reason in status.items():
        if reason is None:
            backend = get_backend(name)
            rows.append((name, f"{getattr(backend, 'summary', name)}", True))
        else:
            rows.append((name, reason, False))
    available = any(ok for _, _, ok in rows)
    auto = auto_summary() if available else "no backend is available"
    return [("auto", auto, available), *rows]


def export_outputs_las(scenario: Scenario, suffix: str = ".las", scene=None) -> list[Path]:
    """The scenario's outputs on disk (scene and target) as LAS (or LAZ) point clouds beside
    them, ``S_Scene.las`` and ``S_Target.las``, as ``run --las`` names them; the paths.
    With the loaded ``scene``, each point carries its target id (0: not a target), as
    ``run --las`` writes them.

    The two are one output set under the scenario's run lock: both replaced or neither,
    and never while a run swaps the outputs in. Both outputs are read first, so a missing
    output writes nothing.
    """
    from ladartui.outputset import OutputSet
    from ladartui.scene.las import las_writer
    from ladartui.scene.voxels import load_voxels
    from ladartui.simulation import output_lock

    outputs = {"scene": scenario.scene_output, "target": scenario.target_output}
    for path in outputs.values():
        if (problem := file_problem(path)) == "not found":
            raise InputFileError(path, "output not found: run the scenario first")
        if problem:
            raise InputFileError(path, f"output {problem}")
    paths = {name: path.with_suffix(suffix) for name, path in outputs.items()}
    with OutputSet(paths, output_lock(scenario)) as output_set:
        clouds = {name: load_voxels(path) for name, path in outputs.items()}
        output_set.write(
            {name: las_writer(paths[name], clouds[name], scenario.voxel_size, scene) for name in paths}
        )
    return list(paths.values())
