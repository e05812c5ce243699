"""Run a study: trace every scan with every setting, time it and score it.

For each ray grid m (smallest first) and each scan, the rays are made once;
exact float64 numba traces them first (the per-ray reference), then every
other setting. The first scan of each setting is preceded by ``warmup``
untimed calls on a slice of its rays (compilation, uploads), and a timed call
during which numba compiled is run again (``timed_without_compiling``); a setting's
timings are one per scan plus repeats of the first scan up to ``runs`` (fewer
once a setting has spent ``REPEAT_BUDGET_S``), and the figure quoted is their
median. Only the trace call is timed, not ray generation or scoring.
Coverage is the obscured target coverage of the fused returns (after the
depth-resolution rule) of all traced scans, scored by ``compute_measures``;
its error is taken against exact float64 numba at the largest ray grid.
"""

from __future__ import annotations

import datetime
import os
import platform
import threading
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from ladartui.errors import BackendUnavailable, Cancelled, LadarError, check_cancelled
from ladartui.number_text import plural
from ladartui.study.inputs import StudyInputs, with_ray_grid
from ladartui.study.misses import summarise, voxel_geometry
from ladartui.study.results import FAILED, SKIPPED, StudyResult, StudyRow
from ladartui.study.settings import Setting, reference_setting
from ladartui.study.timing import timed_without_compiling
from ladartui.tracing.backend import VOXEL

# Rays per trace call: the cancel event is checked between calls.
CHUNK_RAYS = 1 << 18
# A march's warm-up calls trace this many rays: enough to compile and upload everything.
WARMUP_RAYS = 4096
# Repeats of the first scan (to reach ``runs`` timings) stop once a setting has
# spent this long: a slow setting is timed once per scan instead.
REPEAT_BUDGET_S = 3.0


@dataclass(frozen=True)
class StudyProgress:
    """Progress in trace calls: ``done`` of ``total``; ``label`` is the setting now traced."""

    done: int
    total: int
    label: str
    scan: int
    scans: int

    @property
    def fraction(self) -> float:
        return self.done / self.total if self.total else 1.0


def backend_reasons(names) -> dict[str, str | None]:
    """For each backend name, None when usable here, else why not."""
    from ladartui.tracing.backend import get_backend

    reasons: dict[str, str | None] = {}
    for name in sorted(set(names)):
        try:
            get_backend(name)
            reasons[name] = None
        except BackendUnavailable as error:
            reasons[name] = str(error)
        except LadarError as error:
            reasons[name] = str(error)
    return reasons


def run_study(
    inputs: StudyInputs,
    settings: list[Setting],
    runs: int = 5,
    warmup: int = 1,
    progress: Callable[[StudyProgress], None] | None = None,
    cancel: threading.Event | None = None,
) -> StudyResult:
    """Measure every setting on ``inputs``; see the module docstring for what is measured."""
    if runs < 1:
        raise LadarError("runs must be at least 1")
    if not inputs.poses:
        raise LadarError(f"{inputs.name}: the flight has no scans to trace")
    grids = sorted({s.ray_grid for s in settings})
    # The per-ray reference is traced at every ray grid, listed or not.
    ordered = []
    for m in grids:
        ordered.append(reference_setting(m))
        ordered += [s for s in settings if s.ray_grid == m and not s.is_reference]
    listed = set(settings)
    rows = {s: StudyRow(s) for s in ordered}
    reasons = backend_reasons(s.backend for s in ordered)
    if reasons.get("numba"):
        raise BackendUnavailable(f"the reference tracer is unavailable: {reasons['numba']}")
    for s, row in rows.items():
        if reasons.get(s.backend):
            row.status, row.reason = SKIPPED, reasons[s.backend]

    scene = inputs.scene
    poses = inputs.poses
    extra = max(0, runs - len(poses))
    active = [s for s in ordered if rows[s].status != SKIPPED]
    _check_rays(inputs, active, warmup, extra)
    total = sum(len(poses) + warmup + extra for _ in active)
    done = 0
    returns: dict[Setting, list[np.ndarray]] = {s: [] for s in ordered}
    notes: dict[Setting, str] = {}

    for m in grids:
        sensor = with_ray_grid(inputs.sensor, m)
        grid_settings = [s for s in active if s.ray_grid == m]
        for scan, pose in enumerate(poses):
            check_cancelled(cancel, "study cancelled")
            origins, directions, detector = sensor.rays(pose, attitude=inputs.attitude(scan))
            cells = origins / scene.voxel_size + 0.5
            exact = None
            exact_classes = None
            for s in grid_settings:
                row = rows[s]
                if row.status != "ok":
                    continue
                calls = 1 + (warmup + extra if scan == 0 else 0)
                done_before = done  # a failure counts this scan's calls as done
                try:
                    if scan == 0:
                        # Warm-up: compile and upload. An exact setting traces the whole
                        # scan: a slice misses what a scan compiles (object order; 30 s
                        # timed on a cold cache). A march, slow, traces a slice.
                        rays = len(origins) if s.method == "exact" else WARMUP_RAYS
                        for _ in range(warmup):
                            check_cancelled(cancel, "study cancelled")
                            _trace(scene, origins[:rays], directions[:rays], s, cancel)
                            done += 1
                    repeats = 1 + (extra if scan == 0 else 0)
                    for call in range(repeats):
                        check_cancelled(cancel, "study cancelled")
                        if progress is not None:
                            progress(StudyProgress(done, total, s.label, scan + 1, len(poses)))
                        hits, seconds = timed_without_compiling(
                            partial(_trace, scene, origins, directions, s, cancel)
                        )
                        done += 1
                        row.timing.add(seconds)
                        if sum(row.timing.seconds) > REPEAT_BUDGET_S:
                            # Slow settings: every scan is a timed run already.
                            done += repeats - call - 1
                            break
                except Cancelled:
                    raise
                except (LadarError, RuntimeError, ValueError, MemoryError) as error:
                    if s.is_reference:
                        raise
                    row.status, row.reason = FAILED, f"{type(error).__name__}: {error}"
                    # its later scans (a call each) are not traced: done too, so the count keeps up
                    done = done_before + calls + len(poses) - scan - 1
                    continue
                note = hits.info.get("precision_note")
                if note:
                    notes[s] = note
                row.rays_per_scan = len(hits.kind)
                row.scans += 1
                answer = (hits.kind, hits.index, hits.range)
                if s.is_reference:
                    exact = answer
                    voxel = hits.kind == VOXEL
                    exact_classes = voxel_geometry(
                        cells[voxel], directions[voxel], hits.index[voxel], scene.occupancy
                    )
                row.misses.add(summarise(cells, directions, exact, answer, scene.occupancy, exact_classes))
                returns[s].append(_scan_returns(hits, detector, sensor.depth_resolution))
    if progress is not None:
        progress(StudyProgress(total, total, "scoring", len(poses), len(poses)))

    coverage = {s: _coverage(scene, returns[s]) for s in ordered if rows[s].status == "ok"}
    for s, value in coverage.items():
        rows[s].coverage = value
        if s in notes:
            rows[s].reason = notes[s]
    top = reference_setting(grids[-1])
    result = StudyResult(
        [rows[s] for s in ordered if s in listed or s.is_reference],
        context=_context(inputs, runs, warmup, reasons),
        reference_label=top.label,
        reference_coverage=coverage.get(top),
    )
    result.notes += inputs.notes
    if grids[-1] < 8:
        result.notes.append(
            f"The converged reference is exact float64 numba at m={grids[-1]}, "
            f"the largest ray grid measured (8 in the full study)."
        )
    if result.reference_coverage is None:
        result.notes.append(
            "Coverage is undefined (the reference saw no target voxel), so coverage errors are not shown."
        )
    result.finish()
    return result


def _check_rays(inputs: StudyInputs, active: list[Setting], warmup: int, extra: int) -> None:
    """Refuse, before the first trace, a study whose calls would trace more rays than the
    work limit: every scan and repeat of each setting, and its warm-up calls."""
    from ladartui.resources import RAISE_BY_ENV, check_rays

    rays = 0
    for s in active:
        scan = with_ray_grid(inputs.sensor, s.ray_grid).rays_per_scan
        warm = scan if s.method == "exact" else min(scan, WARMUP_RAYS)
        rays += (len(inputs.poses) + extra) * scan + warmup * warm
    settings = plural(len(active), "setting")
    check_rays(
        rays,
        f"{inputs.name}: a study of {settings} on {plural(len(inputs.poses), 'scan')}",
        raise_with=RAISE_BY_ENV,
    )


def _trace(scene, origins, directions, setting: Setting, cancel):
    """One scan traced with ``setting``, in chunks so a cancel is answered quickly."""
    from ladartui.tracing import trace

    parts = []
    for start in range(0, len(origins), CHUNK_RAYS):
        check_cancelled(cancel, "study cancelled")
        stop = start + CHUNK_RAYS
        parts.append(
            trace(
                scene.occupancy,
                origins[start:stop],
                directions[start:stop],
                backend=setting.backend,
                method=setting.method,
                step=setting.step,
                precision=setting.precision,
                voxel_size=scene.voxel_size,
                cancel=cancel,
            )
        )
    if len(parts) == 1:
        return parts[0]
    first = parts[0]
    first.kind = np.concatenate([p.kind for p in parts])
    first.index = np.concatenate([p.index for p in parts])
    first.range = np.concatenate([p.range for p in parts])
    return first


def _scan_returns(hits, detector, depth_resolution) -> np.ndarray:
    from ladartui.returns import scan_returns

    return scan_returns(hits, detector, depth_resolution)


def _coverage(scene, per_scan) -> float | None:
    from ladartui.measures import compute_measures
    from ladartui.returns import fuse_scans

    fused = fuse_scans(per_scan)
    return compute_measures(scene.target, fused, None).obscured_coverage


def _context(inputs: StudyInputs, runs, warmup, reasons) -> dict:
    return {
        "inputs": inputs.describe(),
        "runs": runs,
        "warmup": warmup,
        "created_utc": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "machine": {
            "cpus": os.cpu_count(),
            "platform": platform.platform(),
            "python": platform.python_version(),
        },
        "backends": reasons,
    }


def output_paths(out_dir, chart_stem="speed-accuracy", stem="study") -> dict[str, Path]:
    """The files ``write_outputs`` writes into ``out_dir``, by kind."""
    out_dir = Path(out_dir)
    names = {"csv": f"{stem}.csv", "json": f"{stem}.json", "txt": f"{chart_stem}.txt"}
    return {
        kind: out_dir / names.get(kind, f"{chart_stem}.{kind}")
        for kind in ("csv", "json", "svg", "png", "txt")
    }


def check_outputs(out_dir) -> None:
    """``OutputFileError`` naming a file of ``write_outputs`` that could not be written
    (a folder, pipe or device there, say): asked before a study, not after it."""
    from ladartui.outputset import check_lock, check_writable

    check_writable(*output_paths(out_dir).values())
    check_lock(_lock_path(out_dir))


def _lock_path(out_dir, stem="study") -> Path:
    return Path(out_dir) / f".{stem}.outputs.lock"


def write_outputs(
    result: StudyResult, out_dir, chart_stem="speed-accuracy", stem="study", width=100, height=30
) -> dict[str, Path]:
    """Write the CSV, JSON, plotted chart (SVG, PNG) and plain-text chart into ``out_dir``
    as one output set: all five replaced, or none (a Ctrl-C while they are written
    leaves the earlier study whole; one that comes once they are all in place is
    ``Cancelled`` saying they were written)."""
    from ladartui.charts import figure_bytes
    from ladartui.outputset import OutputSet
    from ladartui.study.chart import chart_text
    from ladartui.study.figure import speed_accuracy_figure

    out_dir = Path(out_dir)
    figure = speed_accuracy_figure(result)
    contents = {
        "csv": result.to_csv().encode("utf-8"),
        "json": result.to_json().encode("utf-8"),
        "svg": figure_bytes(figure, "svg"),
        "png": figure_bytes(figure, "png"),
        "txt": (chart_text(result, width, height, color=False) + "\n\n" + result.verdict() + "\n").encode(),
    }
    paths = output_paths(out_dir, chart_stem, stem)
    output_set = OutputSet(paths, _lock_path(out_dir, stem))
    try:
        with output_set:
            output_set.write_contents(contents)
    except KeyboardInterrupt:
        if not output_set.committed:  # rolled back, or never begun: the earlier set stands
            raise
        raise Cancelled(interrupted_after_writing(paths)) from None
    return paths


def interrupted_after_writing(paths: dict[str, Path]) -> str:
    """What a Ctrl-C (or SIGTERM) that came once a study's files were in place says."""
    return "interrupted after the study was written; it wrote " + ", ".join(str(p) for p in paths.values())
