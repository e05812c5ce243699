"""The run: scans along the flight path, the depth-resolution rule, fusion, measures.

``simulate`` traces every scan twice, as the report's section 4.4 describes: once
against the full scene model (the *obscured* view) and once against the target
model alone over the same extent (the *unobscured* view, the ideal). Each scan's
hits pass the detector's depth-resolution rule, and the returns of all scans are
fused into one voxel list per run. The outputs are checked for writability and
locked before tracing, and written as one all-or-nothing set after both runs
have finished (``ladartui.outputset``), so a failed, cancelled or killed run
leaves the earlier set as it was.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ladartui.checks import switch_field
from ladartui.errors import Described, FieldError, check_callbacks, check_cancelled, described
from ladartui.measures import Measures, compute_measures
from ladartui.returns import fuse_scans, kept_returns
from ladartui.run_record import as_run, check_record_spare, record_text, run_inputs
from ladartui.scenario import Scenario, check_work, input_files
from ladartui.scene.model import Scene
from ladartui.tracing.config import SCAN_BLOCK

RUNS = ("scene", "target")
NOTHING_WRITTEN = "run cancelled; nothing was written, earlier outputs are unchanged"

# Aim for trace calls of about this long, so a cancel is answered quickly.
_CHUNK_SECONDS = 0.1
_FIRST_CHUNK_RAYS = 32768
_MIN_CHUNK_RAYS = 1024
# Up to one object-order block (tracing.config.SCAN_BLOCK: a 128 x 128 sensor's
# scan with 4 x 4 rays): object order traces a whole scan for little more than a
# strip of it, and strips of 65,536 rays saw too many voxels per ray at some poses
# and went to ray order (the reference orbit ran 1.37x faster with whole scans).
_MAX_CHUNK_RAYS = SCAN_BLOCK

# --------------------------------------------------------------------------- the run


@dataclass(frozen=True)
class RunProgress:
    """Where a run stands; passed to the ``progress`` callback.

    The two runs advance together, scan by scan, over the same rays: ``run``
    is the one just traced, "scene" (obscured) or "target" (unobscured), and
    ``scan`` counts 1..``scans``. ``rays_done`` and ``rays_total`` count rays
    traced over both runs, and ``fraction`` is their ratio. ``returns`` is None
    while a scan is being traced; when a scan is complete, one report per run
    (scene first) holds that run's returned voxels for the scan, (K, 3) int32.
    """

    run: str
    scan: int
    scans: int
    rays_done: int
    rays_total: int
    fraction: float
    returns: np.ndarray | None = None


@dataclass
class SimulationResult:
    """Fused outputs, per-scan returns, measures and how the run went.

    ``timings`` holds seconds spent per stage (``setup``: backend choice and
    scene loading, ``rays``, ``trace``, ``depth_rule``, ``fusion``,
    ``measures``, ``write``, and ``total``);
    ``outputs`` the files written (empty when nothing was written); ``precision`` the
    arithmetic the tracing used ("f64" where a backend lacks the f32 asked for).
    """

    scene_output: np.ndarray
    target_output: np.ndarray
    scene_per_scan: list
    target_per_scan: list
    measures: Measures
    backend: str
    method: str
    rays_per_scan: int
    timings: dict = field(default_factory=dict)
    outputs: dict = field(default_factory=dict)
    precision: str = ""

    @property
    def scans(self) -> int:
        return len(self.scene_per_scan)


def simulate(
    scenario,
    backend=None,
    method=None,
    step=None,
    precision=None,
    progress: Callable[[RunProgress], None] | None = None,
    cancel: threading.Event | None = None,
    write=True,
    las=False,
    scene=None,
) -> SimulationResult:
    """Simulate the scenario's collection and score it.

    ``backend``, ``method``, ``step`` and ``precision`` override the scenario's
    tracing settings. Each scan is traced in chunks of whole detector rows,
    against the scene and then the target alone on the same rays.
    ``progress`` is called from this thread after every traced chunk and once
    per run when a scan is complete; ``cancel`` is checked between chunks and
    stops the run with ``Cancelled`` before anything is written. With
    ``write`` the fused outputs (``S_Scene.txt``, ``S_Target.txt``, and with
    ``las`` also ``.las`` copies), the measures (``S.cmf``) and the settings
    as run (``S_Run.toml``, ladartui.run_record) are written atomically once
    both runs are done. ``scene`` may pass the scenario's
    already loaded ``Scene`` (its occupancy is built once and kept). ``scenario``
    may also be a scenario file's path.
    """
    if isinstance(scenario, (str, os.PathLike)):
        from ladartui.scenario import load_scenario

        scenario = load_scenario(scenario)
    _check_arguments(scenario, progress, cancel, scene)
    ran = _as_run(scenario, backend, method, step, precision)
    check_work(scenario)  # before the output set is locked and before any tracing
    write, las = switch_field("write", write), switch_field("las", las)
    with contextlib.ExitStack() as stack:
        output_set = stack.enter_context(_output_set(scenario, las)) if write else None
        return _simulate(scenario, ran, progress, cancel, output_set, scene)


def _check_arguments(scenario, progress, cancel, scene) -> None:
    """Refuse, naming it, what would otherwise fail deep in the run or score another scene."""
    if not isinstance(scenario, Scenario):
        raise FieldError("scenario", described(scenario), "a Scenario or a scenario file's path")
    check_callbacks(progress, cancel)
    if scene is not None:
        if not isinstance(scene, Scene):
            raise FieldError("scene", described(scene), "the scenario's Scene (scenario.load_scene())")
        if scene.path is not None and scene.path.resolve() != scenario.scene_file.resolve():
            raise FieldError(
                "scene",
                Described(f"the scene of {scene.path}"),
                f"the scenario's Scene, of {scenario.scene_file} (scenario.load_scene())",
            )
        if scene.voxel_size != scenario.voxel_size:
            raise FieldError(
                "scene.voxel_size", scene.voxel_size, f"the scenario's voxel size ({scenario.voxel_size})"
            )


def _as_run(scenario, backend, method, step, precision) -> Scenario | None:
    """The scenario as a run with these overrides goes (``as_run``; None without any),
    the overrides held to what the scenario's own fields take, named as the arguments:
    a march step of 50 voxels ran to nonsense, or traced every scan and then failed to
    write the record of the run, which holds the settings as run."""
    if backend is method is step is precision is None:
        return None
    try:
        return as_run(scenario, backend, method, step, precision)
    except FieldError as error:  # "simulation.step": the file's key, the argument's name
        raise FieldError(error.field.rpartition(".")[2], error.value, error.expected) from None


def _simulate(scenario, ran, progress, cancel, output_set, scene):
    """Run ``scenario`` with the tracing settings of ``ran`` (``_as_run``; None: its own)."""
    started = time.perf_counter()
    timings = dict.fromkeys(("setup", "rays", "trace", "depth_rule", "fusion", "measures", "write"), 0.0)
    settings = _trace_settings(scenario if ran is None else ran)
    if scene is None:
        scene = scenario.load_scene()
    poses = list(scenario.poses())
    from ladartui.attitude import plan_attitudes

    attitudes = plan_attitudes(scenario.flight, scenario.speed, scenario.sensor)
    runner = _ScanRunner(scene, scenario.sensor, settings, len(poses), timings, progress, cancel)
    if getattr(scenario, "geiger", False):
        from ladartui.detection.scan import GeigerRun

        runner.geiger = GeigerRun(
            scenario.detection, scenario.sensor, scene, cancel, scans=len(poses), source=scenario.path
        )
    timings["setup"] = time.perf_counter() - started

    per_scan: dict[str, list[np.ndarray]] = {run: [] for run in RUNS}
    for scan, (pose, attitude) in enumerate(zip(poses, attitudes), start=1):
        for run, returns in runner.scan(scan, pose, attitude).items():
            per_scan[run].append(returns)

    check_cancelled(cancel, NOTHING_WRITTEN)
    tick = time.perf_counter()
    scene_output = fuse_scans(per_scan["scene"])
    target_output = fuse_scans(per_scan["target"])
    timings["fusion"] += time.perf_counter() - tick

    tick = time.perf_counter()
    measures = compute_measures(
        scene.target,
        scene_output,
        target_output,
        scene_per_scan=per_scan["scene"],
        target_per_scan=per_scan["target"],
        path_length_m=scenario.path_length(),
        flight_time_s=scenario.flight_time(),
        voxel_size=scene.voxel_size,
    )
    if runner.geiger is not None:
        measures = dataclasses.replace(measures, detection=runner.geiger.measures())
    measures = dataclasses.replace(measures, levels=run_levels(scenario, scene.target, per_scan["scene"]))
    measures = dataclasses.replace(
        measures, targets=_per_target(scenario, scene, per_scan, scene_output, target_output, measures)
    )
    timings["measures"] = time.perf_counter() - tick

    outputs = {}
    if output_set is not None:
        check_cancelled(cancel, NOTHING_WRITTEN)
        tick = time.perf_counter()
        ran = as_run(scenario) if ran is None else ran
        inputs = run_inputs(scenario, scene)
        outputs = _write_outputs(
            output_set,
            scene_output,
            target_output,
            measures,
            lambda written: record_text(scenario, ran, inputs, written),
            scene,
            cancel,
        )
        timings["write"] = time.perf_counter() - tick
    timings["total"] = time.perf_counter() - started
    return SimulationResult(
        scene_output=scene_output,
        target_output=target_output,
        scene_per_scan=per_scan["scene"],
        target_per_scan=per_scan["target"],
        measures=measures,
        backend=runner.backends_used() or settings["backend"],
        method=settings["method"],
        rays_per_scan=scenario.sensor.rays_per_scan,
        timings=timings,
        outputs=outputs,
        precision="+".join(sorted(runner.precisions)) or settings["precision"],
    )


def run_levels(scenario, target, scene_per_scan):
    """Detect / recognise / identify for the target in the obscured view of a run."""
    from ladartui.levels import target_levels

    return target_levels(
        target,
        scene_per_scan,
        scenario.flight.scan_times(scenario.speed),
        scenario.flight.scan_distances(),
        scenario.level_thresholds,
    )


def _per_target(scenario, scene, per_scan, scene_output, target_output, measures):
    """Every measure for each target of the scene's target model, named by the scenario."""
    from ladartui.target_measures import LevelInputs, PerTarget, TargetMeasures, compute_target_measures

    names = scenario.target_name
    ids = np.unique(scene.target_ids)
    if ids.size == 1:
        # One target: its measures are the overall ones (the same voxels), not computed twice.
        target_id = int(ids[0])
        alone = dataclasses.replace(measures, detection=None, targets=None)
        name = names(target_id) if names is not None else f"target {target_id}"
        return PerTarget((TargetMeasures(target_id, name, alone),))
    flight = scenario.flight
    levels = LevelInputs(
        flight.scan_times(scenario.speed), flight.scan_distances(), scenario.level_thresholds
    )
    return compute_target_measures(
        scene.target,
        scene.target_ids,
        scene_output,
        target_output,
        scene_per_scan=per_scan["scene"],
        target_per_scan=per_scan["target"],
        names=names,
        levels=levels,
        path_length_m=measures.path_length_m,
        flight_time_s=measures.flight_time_s,
        voxel_size=measures.voxel_size,
    )


class _ScanRunner:
    """Traces scans for both runs, sizing chunks and reporting progress."""

    def __init__(self, scene, sensor, settings, scans, timings, progress, cancel):
        from ladartui.tracing import trace

        self._trace = trace
        self.voxel_size = scene.voxel_size
        # Built once per scene (the Scene caches them) and used for every scan.
        self.occupancies = {"scene": scene.occupancy, "target": scene.target_occupancy}
        self.sensor = sensor
        self.settings = settings
        self.scans = scans
        self.timings = timings
        self.progress = progress
        self.cancel = cancel
        self.rays_per_row = sensor.grid * sensor.ray_grid**2
        self.rays_total = 2 * sensor.rays_per_scan * scans
        self.done = 0
        self.chunk = _FIRST_CHUNK_RAYS
        self.rays_by_backend: dict[str, int] = {}  # auto may trace some calls on each
        self.precisions: set[str] = set()  # as traced: numba has no f32 kernels
        self.geiger = None  # a detection.scan.GeigerRun when the Geiger model is on

    def backends_used(self) -> str:
        """The backends that traced the run, most rays first ("numba+wgpu")."""
        return "+".join(sorted(self.rays_by_backend, key=lambda name: -self.rays_by_backend[name]))

    def scan(self, scan, pose, attitude=None) -> dict[str, np.ndarray]:
        """Trace one scan for both runs; each run's returned voxels, (K, 3) int32."""
        sensor, timings = self.sensor, self.timings
        kept: dict[str, list[np.ndarray]] = {run: [] for run in RUNS}
        row = 0
        while row < sensor.grid:
            check_cancelled(self.cancel, NOTHING_WRITTEN)
            # Whole detector rows, so that the depth rule can run on each chunk.
            stop = min(sensor.grid, row + max(1, self.chunk // self.rays_per_row))
            tick = time.perf_counter()
            origins, directions, detector = sensor.rays(pose, rows=slice(row, stop), attitude=attitude)
            timings["rays"] += time.perf_counter() - tick
            slowest = 0.0
            for run in RUNS:
                check_cancelled(self.cancel, NOTHING_WRITTEN)
                tick = time.perf_counter()
                hits = self._trace(
                    self.occupancies[run],
                    origins,
                    directions,
                    voxel_size=self.voxel_size,
                    cancel=self.cancel,
                    **self.settings,
                )
                elapsed = time.perf_counter() - tick
                timings["trace"] += elapsed
                slowest = max(slowest, elapsed)
                self.rays_by_backend[hits.backend] = self.rays_by_backend.get(hits.backend, 0) + len(hits)
                self.precisions.add(hits.info.get("precision", self.settings["precision"]))
                tick = time.perf_counter()
                rays = kept_returns(detector, hits.kind, hits.range, sensor.depth_resolution)
                kept[run].append(hits.index[rays])
                if self.geiger is not None:
                    self.geiger.add_chunk(run, origins, directions, detector, hits, rays)
                timings["depth_rule"] += time.perf_counter() - tick
                self.done += origins.shape[0]
                if not (stop == sensor.grid and run == RUNS[-1]):
                    self._report(run, scan)
            self.chunk = _next_chunk(self.chunk, origins.shape[0], slowest)
            row = stop
        returns = {}
        for run in RUNS:
            tick = time.perf_counter()
            if self.geiger is not None:  # declared points only (detection.scan)
                returns[run] = self.geiger.finish_scan(run, scan)
            else:
                returns[run] = fuse_scans(kept[run])
            timings["fusion"] += time.perf_counter() - tick
            self._report(run, scan, returns[run])
        return returns

    def _report(self, run, scan, returns=None):
        if self.progress is not None:
            self.progress(
                RunProgress(
                    run, scan, self.scans, self.done, self.rays_total, self.done / self.rays_total, returns
                )
            )


def _trace_settings(ran) -> dict:
    """The tracing settings of ``ran`` (the scenario with the caller's overrides); "auto"
    resolved once, unless its calls are left to trace()'s learned choice (a GPU is there)."""
    from ladartui.tracing import choose_backend
    from ladartui.tracing.backend_choice import learns

    settings = {"backend": ran.backend, "method": ran.method, "step": ran.step, "precision": ran.precision}
    if settings["backend"] == "auto":
        best = choose_backend()
        if not learns(best, settings["method"], settings["precision"]):
            settings["backend"] = best
    return settings


def _next_chunk(chunk, traced, elapsed) -> int:
    """Size the next trace call to take about ``_CHUNK_SECONDS``."""
    if 2 * traced < chunk or elapsed <= 0.0:
        return chunk  # a short tail chunk says little about speed
    goal = int(traced * _CHUNK_SECONDS / elapsed)
    # Change gradually: one slow call (a shader compile, a busy machine) must not
    # shrink every later call to a crawl.
    return max(_MIN_CHUNK_RAYS, min(goal, 4 * chunk, _MAX_CHUNK_RAYS), chunk // 4)


def output_paths(scenario, las=False) -> dict[str, Path]:
    """The files a run of ``scenario`` writes, by name."""
    paths = {
        "scene": Path(scenario.scene_output),
        "target": Path(scenario.target_output),
        "measures": Path(scenario.measures_file),
        "record": scenario.run_record,
    }
    if las:
        paths["scene_las"] = paths["scene"].with_suffix(".las")
        paths["target_las"] = paths["target"].with_suffix(".las")
    return paths


def check_output_names(scenario, las=False) -> None:
    """Refuse output names too long for the file system, before anything looks for them:
    a name too long fails every call on it."""
    from ladartui.outputset import LOCK_EXTRA, SET_MEMBER_EXTRA, check_names

    shorter = "; use a shorter scenario name"
    paths = output_paths(scenario, las).values()
    check_names(*paths, extra=SET_MEMBER_EXTRA, advice=shorter)
    check_names(output_lock(scenario), extra=LOCK_EXTRA, advice=shorter)
    _check_names_are_text(paths)


def _check_names_are_text(paths) -> None:
    """Refuse outputs whose names hold a byte that is not UTF-8 (a scenario named on a
    Latin-1 system): the run record, a UTF-8 file, names them, and could not be written
    once the run had traced. Their folder's name is not in the record."""
    from ladartui.errors import OutputFileError

    for path in paths:
        name = os.fsencode(Path(path).name)
        try:
            name.decode("utf-8")
        except UnicodeDecodeError as error:
            byte = name[error.start]
            raise OutputFileError(
                path,
                f"its name is not UTF-8 text (the byte 0x{byte:02x}), and the run record, a UTF-8 "
                "file, names each output; rename the scenario",
            ) from None


def check_outputs_spare_inputs(scenario, las=False) -> None:
    """Refuse a run whose outputs would overwrite its own model files or flight logs
    (paths compared resolved: a link to an output's name is that output).

    A scenario ``S.toml`` writes ``S_Target.txt``: with the scene model named
    ``S.txt`` beside it, that is the target model itself. Nor may a run replace
    a file of its record's name that is not a run record (``run_record``).
    """
    from ladartui.outputset import check_lock

    check_output_names(scenario, las)
    check_lock(output_lock(scenario))
    check_outputs_named_apart(scenario, las)


def check_outputs_named_apart(scenario, las=False) -> None:
    """Refuse outputs named as the scenario's own model files or flight logs, or as a file
    of its record's name that is not a record: its name alone, no lock asked about (Save
    As says so before it writes a file that could never run)."""
    from ladartui.errors import FieldError

    # resolved: a model or log reached through a link is the file the link names
    inputs = [(os.path.realpath(file), key) for file, key, _what in input_files(scenario)]
    for name, path in output_paths(scenario, las).items():
        where = os.path.realpath(path)
        key = next((key for file, key in inputs if file == where), None)
        if key is None:
            continue
        if key == "files.scene":
            found = Path(scenario.scene_file).name
            expected = (
                f"a scene model not named after the scenario: the run's {name} output "
                f"{path.name} would overwrite a model file"
            )
        else:
            found = path.name
            expected = (
                f"a flight log not named as a run output: the run's {name} output would "
                "overwrite the flight log"
            )
        line = scenario.key_line(key)
        raise FieldError(
            key, found, expected, source=f"{scenario.path}:{line}" if line else str(scenario.path)
        )
    check_record_spare(scenario)


def _output_set(scenario, las):
    from ladartui.outputset import OutputSet

    check_outputs_spare_inputs(scenario, las)
    return OutputSet(output_paths(scenario, las), output_lock(scenario))


def output_lock(scenario) -> Path:
    """The lock file of ``scenario``'s output set (a second run is refused while held)."""
    path = Path(scenario.path)
    return path.with_name(f".{path.stem}.outputs.lock")


def swap_interrupted(scenario) -> bool:
    """Whether a run was stopped while it replaced ``scenario``'s outputs (its journal is
    on disk): the files there now are part new, part aside, and not to be read; the
    next run puts the earlier set back first (``outputset.recover``)."""
    from ladartui.outputset import journal_path

    return journal_path(output_lock(scenario)).exists()


def _write_outputs(output_set, scene_output, target_output, measures, record, scene, cancel) -> dict:
    """Write every output of the set to a temporary file, then swap them all in together.

    ``record(outputs)`` is the run record's text, given the fingerprints of the bytes the
    scene and target outputs and the measures are written as. LAS outputs carry each
    voxel's target id as its point source id (0: not a target voxel).
    """
    from ladartui.fingerprint import fingerprint_of
    from ladartui.run_record import OUTPUT_ROLES, InputFile
    from ladartui.scene.voxels import voxel_file_bytes

    contents = {
        "scene": voxel_file_bytes(scene_output),
        "target": voxel_file_bytes(target_output),
        "measures": measures.to_cmf().encode("utf-8"),
    }
    written = [
        InputFile(role, output_set.paths[name], fingerprint_of(contents[name]))
        for name, role in OUTPUT_ROLES.items()
    ]

    def put(data):
        return lambda tmp: tmp.write_bytes(data)

    writers = {name: put(data) for name, data in contents.items()}
    writers["record"] = put(record(written).encode("utf-8"))
    if "scene_las" in output_set.paths:
        from ladartui.scene.las import las_writer

        for name, voxels in (("scene_las", scene_output), ("target_las", target_output)):
            writers[name] = las_writer(output_set.paths[name], voxels, scene.voxel_size, scene)
    return output_set.write(writers, cancel)
