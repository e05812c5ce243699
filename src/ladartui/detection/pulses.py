"""Coverage and false alarms against pulses per look (Geiger-mode, one scenario).

Each scan is traced once (scene and target alone); the ideal model's obscured
coverage comes from the depth rule as in ``simulate``; the Geiger model's from
declared points only (``detection.scan``), so noise never counts as coverage
and with certain detection the Geiger coverage equals the ideal one. The
coincidence k for M pulses keeps the scenario's share (``threshold``). Rows
use the same random stream as ``simulate`` (keyed by seed, scan, detector,
pulse and bin), so a row for the scenario's own pulse count matches a run's
obscured coverage. See docs/detection.md.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from ladartui.checks import integer_field, items_or_none
from ladartui.detection.scan import BYTES_PER_HELD_RAY, check_memory, declare_look, prepare_look
from ladartui.detection.settings import MAX_PULSES, DetectionSettings
from ladartui.errors import FieldError, check_cancelled, described
from ladartui.number_text import plural
from ladartui.returns import kept_returns
from ladartui.scene.keys import voxel_keys

# Kept for callers of the first version: the settings are the [detection] section's.
GeigerSettings = DetectionSettings


@dataclass(frozen=True)
class PulseRow:
    pulses: int
    threshold: int
    obscured_coverage: float | None  # None: the target model holds no voxels
    declared_points: int
    false_alarms: int
    # declared / ideal distinct target voxels, summed over looks; None (as in a run's
    # measures) when the ideal model saw no target voxel
    target_detection: float | None

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class PulseProgress:
    """Where a pulse study stands: ``stage`` "trace" (scan i of n) or "pulses" (row i of n)."""

    stage: str
    done: int
    total: int
    # Work units over both stages (a traced scan is 1, a scan's pulses are 1 per pulse
    # per 10), for one overall bar.
    units_done: float
    units_total: float
    # Once every scan is traced: the ideal model's coverage and the rows finished so far
    # (what a study cancelled now has to show).
    ideal: float | None = None
    rows: tuple[PulseRow, ...] = ()


def pulse_study(
    scenario,
    pulses_list,
    settings: DetectionSettings | None = None,
    scene=None,
    backend=None,
    progress: Callable[[PulseProgress], None] | None = None,
    cancel: threading.Event | None = None,
) -> tuple[float | None, list[PulseRow]]:
    """Ideal obscured coverage and one ``PulseRow`` per pulse count; coverages are None
    (undefined, as in a run's measures) when the target model holds no voxels.

    ``settings`` default to the scenario's ``[detection]`` section (or its
    defaults). ``progress`` is called after each traced scan and each scan's
    pulses; ``cancel`` is checked as often and stops with ``Cancelled``.
    """
    from ladartui.attitude import plan_attitudes
    from ladartui.tracing import trace

    pulses_list = pulse_counts_field(pulses_list)
    if not all(hasattr(scenario, name) for name in ("poses", "sensor", "detection", "load_scene")):
        raise FieldError(
            "scenario", described(scenario), "a Scenario (ladartui.load_scenario reads one from a file)"
        )
    if settings is not None and not isinstance(settings, DetectionSettings):
        raise FieldError("settings", described(settings), "a DetectionSettings (or None: the scenario's)")
    settings = settings or scenario.detection or DetectionSettings()
    check_study_rays(scenario)
    poses = scenario.poses()
    # Every scan's rays are kept (traced once, fired at for each pulse count).
    check_memory(
        len(poses) * scenario.sensor.rays_per_scan * BYTES_PER_HELD_RAY,
        f"{len(poses)} scans of {scenario.sensor.rays_per_scan:,} rays",
        "use fewer scans, a smaller sensor grid or fewer rays per detector",
    )
    if scene is None:
        scene = scenario.load_scene()
    sensor = scenario.sensor
    target_keys = np.unique(voxel_keys(scene.target))
    total = target_keys.size
    attitudes = plan_attitudes(scenario.flight, scenario.speed, sensor)
    bin_width = settings.bin_width(sensor.depth_resolution)
    per_scan_units = [max(1.0, p / 10.0) for p in pulses_list]
    units_total = len(poses) * (1.0 + sum(per_scan_units))
    units = 0.0

    rows: list[PulseRow] = []
    ideal_cov: float | None = None

    def report(stage, done, count):
        if progress is not None:
            progress(PulseProgress(stage, done, count, units, units_total, ideal_cov, tuple(rows)))

    looks, ideal = [], []
    for scan, pose in enumerate(poses):
        check_cancelled(cancel, "pulse study cancelled; nothing was written")
        origins, directions, detector = sensor.rays(pose, attitude=attitudes[scan])
        hits = trace(
            scene.occupancy,
            origins,
            directions,
            voxel_size=scene.voxel_size,
            backend=backend or scenario.backend,
            method=scenario.method,
            step=scenario.step,
            precision=scenario.precision,
            cancel=cancel,
        )
        kept = kept_returns(detector, hits.kind, hits.range, sensor.depth_resolution)
        ideal.append(voxel_keys(hits.index[kept]))
        looks.append(
            prepare_look(
                origins, directions, detector, hits, kept, target_keys, settings, scene.voxel_size, bin_width
            )
        )
        units += 1.0
        report("trace", scan + 1, len(poses))
    ideal_cov = float(np.isin(target_keys, np.concatenate(ideal)).sum() / total) if total else None
    _check_work(scenario, looks, pulses_list)
    for row, pulses in enumerate(pulses_list):
        report("pulses", row + 1, len(pulses_list))  # the count now fired, before its first scan
        k = settings.threshold(pulses)
        declared_keys, points, false_alarms, target_ideal, target_declared = [], 0, 0, 0, 0
        for scan, look in enumerate(looks):
            check_cancelled(cancel, "pulse study cancelled; nothing was written")
            outcome = declare_look(look, settings, sensor, pulses, k, scan_key=scan, cancel=cancel)
            points += outcome.declared_points
            false_alarms += outcome.false_alarms
            declared_keys.append(voxel_keys(outcome.declared_voxels))
            target_ideal += outcome.target_ideal
            target_declared += outcome.target_declared
            units += per_scan_units[row]
            report("pulses", row + 1, len(pulses_list))
        covered = np.isin(target_keys, np.concatenate(declared_keys)).sum() if total else 0
        rows.append(
            PulseRow(
                pulses,
                k,
                float(covered / total) if total else None,
                points,
                false_alarms,
                target_declared / target_ideal if target_ideal else None,
            )
        )
    return ideal_cov, rows


def pulse_counts_field(pulses_list) -> list[int]:
    """``pulses_list`` as a list of ints, each a pulse count a scenario may hold
    (1..MAX_PULSES), else ``FieldError`` naming it: a count of 2.5 was fired as 2
    pulses in a row that read 2.5, and a 0 failed deep in the firing."""
    items = items_or_none(pulses_list)
    expected = f"a list of pulse counts, whole numbers from 1 to {MAX_PULSES}"
    if items is None:
        raise FieldError("pulses_list", pulses_list, expected)
    try:
        return [integer_field("pulses_list", p, 1, MAX_PULSES) for p in items]
    except FieldError:
        raise FieldError("pulses_list", pulses_list, expected) from None


def check_study_rays(scenario) -> None:
    """Refuse a pulse study whose tracing (each scan once, against the scene alone)
    would pass the ray limit (``RayLimitError``)."""
    from ladartui.resources import RAISE_BY_ENV, check_rays

    scans, each = scenario.scan_count(), scenario.sensor.rays_per_scan
    check_rays(
        scans * each, f"{scenario.path}: {plural(scans, 'scan')} of {each:,} rays", raise_with=RAISE_BY_ENV
    )


def _check_work(scenario, looks, pulses_list) -> None:
    """Refuse, before the first pulse, firing whose work would pass the limit."""
    from ladartui.resources import check_bin_visits

    cells = sum(detectors * bins for detectors, bins in (look.cells for look in looks))
    fired = sum(pulses_list)
    check_bin_visits(
        cells * fired,
        scenario.path,
        f"{plural(fired, 'pulse')} in all on each of {plural(len(looks), 'look')}, "
        f"{plural(cells, 'detector range bin')} among them",
    )
