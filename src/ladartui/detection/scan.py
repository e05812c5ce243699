"""One scan's traced rays through the Geiger-mode model: shared by ``simulate`` and ``pulse_study``.

``prepare_look`` attaches what the model needs to a scan's hits (reflectance
per class, incidence cosines, which rays the depth rule keeps, which hit the
target); ``declare_look`` runs the pulses and says which kept returns are
declared. A voxel counts as a return only when its ray survives the depth
rule, as in the ideal model, *and* its range bin is declared, so noise never
counts as coverage and with certain detection the answer is the ideal one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ladartui.detection.geiger import noise_per_bin
from ladartui.detection.look import geiger_look, incidence_cosines, range_gate
from ladartui.errors import ResourceLimitError
from ladartui.number_text import plural
from ladartui.returns import unique_voxels
from ladartui.scene.keys import voxel_keys

VOXEL = 1
GROUND = 2
# Bytes the model keeps per traced ray until its scan is declared (origins,
# directions, kind, range, voxel, detector, and the model's per-ray inputs).
BYTES_PER_HELD_RAY = 110
# Bytes per (detector, range bin) cell of a look: mean counts, fire probability,
# fire counts, declared and has-return flags.
BYTES_PER_BIN = 22


def check_memory(nbytes: float, what: str, advice: str) -> None:
    """``ResourceLimitError`` up front when ``nbytes`` would exceed the memory available,
    as for the tracing structures (``resources.available_memory``: ``LADARTUI_MAX_MEMORY``
    where set, else the least of the free memory, ``ulimit -v`` and the memory cgroup's room)."""
    from ladartui.resources import available_memory, gib

    limit = available_memory()
    if nbytes > limit:
        raise ResourceLimitError(
            f"the Geiger-mode model would need about {gib(nbytes)} for {what}, more than the "
            f"{gib(limit)} it may use here: {advice}"
        )


@dataclass(frozen=True)
class LookInputs:
    """A scan's rays and hits with the model's per-ray inputs."""

    detector: np.ndarray  # (N,) detector id
    kind: np.ndarray  # (N,) trace kind (0 miss, 1 voxel, 2 ground)
    range: np.ndarray  # (N,) metres
    index: np.ndarray  # (N, 3) voxel hit
    reflectance: np.ndarray  # (N,)
    cos_incidence: np.ndarray
    is_target: np.ndarray  # (N,) bool: the hit is a target-model voxel
    kept: np.ndarray  # (N,) bool: the hit survives the depth rule
    # the detectors with a hit and the range bins of the gate, as the model fires them:
    # each pulse visits every such (detector, bin) cell once
    cells: tuple[int, int]


@dataclass(frozen=True)
class LookOutcome:
    """What one scan declared."""

    declared_voxels: np.ndarray  # (K, 3) voxels of kept returns in declared bins
    declared_points: int  # declared bins (returns and noise)
    false_alarms: int  # declared bins without a return
    noise_bins: int  # bins without a return
    target_ideal: int  # distinct target voxels the ideal model returns
    target_declared: int  # of those, declared


def prepare_look(
    origins, directions, detector, hits, kept_rays, target_keys, settings, voxel_size, bin_width
) -> LookInputs:
    """The model's inputs for one scan; ``kept_rays`` indexes the rays the depth rule keeps;
    ``bin_width``: the range bins' (settings.bin_width of the sensor's depth resolution)."""
    kind = np.asarray(hits.kind)
    index = np.asarray(hits.index)
    is_target = (kind == VOXEL) & np.isin(voxel_keys(np.maximum(index, 0)), target_keys)
    reflectance = np.where(
        kind == GROUND,
        settings.reflectance_ground,
        np.where(is_target, settings.reflectance_target, settings.reflectance_foliage),
    )
    cos = incidence_cosines(origins, directions, kind, index, hits.range, voxel_size)
    kept = np.zeros(kind.shape[0], dtype=bool)
    kept[kept_rays] = True
    detector, ranges = np.asarray(detector), np.asarray(hits.range)
    hit = kind != 0
    cells = (
        (int(np.unique(detector[hit]).size), range_gate(ranges[hit], bin_width)[1]) if hit.any() else (0, 0)
    )
    return LookInputs(detector, kind, ranges, index, reflectance, cos, is_target, kept, cells)


def declare_look(
    look: LookInputs, settings, sensor, pulses: int, threshold: int, scan_key: int, cancel=None
) -> LookOutcome:
    """Fire ``pulses`` pulses at one scan (random stream keyed by ``scan_key``); ``cancel``
    is checked between blocks of pulses."""
    bin_width = settings.bin_width(sensor.depth_resolution)
    detectors, bins = look.cells
    check_memory(
        detectors * bins * BYTES_PER_BIN,
        f"{detectors:,} detectors x {bins:,} range bins in one look",
        "use a wider detection.bin_width_m or a smaller sensor grid",
    )
    result = geiger_look(
        look.detector,
        look.kind,
        look.range,
        look.reflectance,
        look.cos_incidence,
        rays_per_detector=sensor.ray_grid**2,
        n_ref=settings.n_ref,
        range_ref=settings.range_ref_m,
        reflectance_ref=settings.reflectance_ref,
        noise=noise_per_bin(settings.noise_rate_hz, bin_width),
        bin_width=bin_width,
        pulses=pulses,
        threshold=threshold,
        dead_bins=settings.dead_bins(bin_width),
        seed=settings.seed,
        scan=scan_key,
        cancel=cancel,
    )
    declared_rays = result.ray_declared & look.kept
    ideal_target = np.unique(voxel_keys(look.index[look.kept & look.is_target]))
    declared_target = np.unique(voxel_keys(look.index[declared_rays & look.is_target]))
    return LookOutcome(
        look.index[declared_rays],
        int(result.declared.sum()),
        result.false_alarms,
        result.noise_bins,
        int(ideal_target.size),
        int(declared_target.size),
    )


class GeigerRun:
    """The Geiger model inside ``simulate``: collects a scan's traced chunks per run, then
    declares points over the whole scan (so chunking never changes an answer).

    Random streams: the scene run's scan ``s`` (0-based) is keyed ``s``, as in
    ``pulse_study``; the target-alone run's ``s + 2**32``.
    """

    TARGET_RUN_KEY = 1 << 32

    def __init__(self, settings, sensor, scene, cancel=None, scans=1, source="scenario"):
        from ladartui.detection.measures import DetectionTally

        check_memory(
            2 * sensor.rays_per_scan * BYTES_PER_HELD_RAY,
            f"one scan's {sensor.rays_per_scan:,} rays in two runs",
            "use a smaller sensor grid or fewer rays per detector",
        )
        self.settings = settings
        self.sensor = sensor
        self.cancel = cancel  # checked between blocks of pulses
        self.scans, self.source = scans, source  # the firing's work, checked at each look
        self.cells_fired = 0  # detector range bins of the scene looks so far
        self.voxel_size = scene.voxel_size
        self.target_model = scene.target
        self.target_keys = np.unique(voxel_keys(scene.target))
        self.tally = DetectionTally()
        self.ideal: dict[str, list[np.ndarray]] = {"scene": [], "target": []}
        self.chunks: dict[str, list[tuple]] = {"scene": [], "target": []}  # a scan's traced rays

    def add_chunk(self, run, origins, directions, detector, hits, kept_rays) -> None:
        self.chunks[run].append(
            (
                origins,
                directions,
                detector,
                np.asarray(hits.kind),
                np.asarray(hits.range),
                np.asarray(hits.index),
                kept_rays,
            )
        )

    def finish_scan(self, run: str, scan: int) -> np.ndarray:
        """The declared voxels of ``run``'s scan ``scan`` (1-based), unique (K, 3)."""
        from types import SimpleNamespace

        chunks, self.chunks[run] = self.chunks[run], []
        offsets = np.cumsum([0] + [c[2].shape[0] for c in chunks[:-1]])
        join = lambda i: np.concatenate([c[i] for c in chunks])  # noqa: E731
        hits = SimpleNamespace(kind=join(3), range=join(4), index=join(5))
        kept = np.concatenate([c[6] + o for c, o in zip(chunks, offsets)])
        self.ideal[run].append(unique_voxels(hits.index[kept]))
        look = prepare_look(
            join(0),
            join(1),
            join(2),
            hits,
            kept,
            self.target_keys,
            self.settings,
            self.voxel_size,
            self.settings.bin_width(self.sensor.depth_resolution),
        )
        if run == "scene":
            self._check_work(look, scan)
        key = scan - 1 + (self.TARGET_RUN_KEY if run == "target" else 0)
        outcome = declare_look(
            look,
            self.settings,
            self.sensor,
            self.settings.pulses,
            self.settings.coincidence,
            scan_key=key,
            cancel=self.cancel,
        )
        if run == "scene":
            self.tally.add(outcome)
        return unique_voxels(outcome.declared_voxels)

    def _check_work(self, look: LookInputs, scan: int) -> None:
        """Refuse, before a scene look's first pulse, a run whose firing would pass the
        work limit: the looks fired so far, this one, and the looks to come taken as
        this one (the target-alone run's looks, its hits alone, are far smaller). A
        look with no hit fires nothing and the next look is checked."""
        from ladartui.resources import check_bin_visits

        detectors, bins = look.cells
        self.cells_fired += detectors * bins
        pulses = self.settings.pulses
        check_bin_visits(
            (self.cells_fired + detectors * bins * (self.scans - scan)) * pulses,
            self.source,
            f"{plural(pulses, 'pulse')} on each of {plural(self.scans, 'look')}, those to come taken as look "
            f"{scan}'s {detectors:,} detectors x {bins:,} range bins",
        )

    def measures(self):
        from ladartui.detection.measures import coverage

        ideal = {
            run: coverage(self.target_model, np.concatenate(v) if v else np.zeros((0, 3)))
            for run, v in self.ideal.items()
        }
        return self.tally.measures(self.settings, ideal["scene"], ideal["target"])
