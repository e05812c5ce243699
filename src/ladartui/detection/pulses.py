"""Coverage and false alarms against pulses per look (Geiger-mode, one scenario).

Each scan is traced once (scene and target alone); the ideal model's obscured
coverage comes from the depth rule as in ``simulate``; the Geiger model's from
declared points only, so noise never counts as coverage: a voxel counts when
its ray survives the depth rule (as in the ideal model) and its range bin is
declared, so with certain detection the Geiger coverage equals the ideal one. See docs/detection.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ladartui.detection.geiger import noise_per_bin
from ladartui.detection.look import geiger_look, incidence_cosines
from ladartui.errors import FieldError
from ladartui.measures import voxel_keys
from ladartui.simulation import kept_returns

GROUND = 2


@dataclass(frozen=True)
class GeigerSettings:
    n_ref: float = 5.0              # mean photoelectrons, full-footprint return at range_ref
    range_ref: float = 85.0         # metres
    reflectance_ref: float = 0.5
    reflectance_foliage: float = 0.5
    reflectance_ground: float = 0.2
    reflectance_target: float = 0.3
    dark_rate_hz: float = 1e4
    solar_rate_hz: float = 1e6
    dead_time_m: float = math.inf   # range equivalent; inf: one fire per pulse
    threshold_share: float = 0.1    # declare at k = max(1, ceil(share * pulses)) fires
    seed: int = 0

    def __post_init__(self):
        for name in ("n_ref", "range_ref", "reflectance_ref", "dead_time_m"):
            if not getattr(self, name) > 0:
                raise FieldError(f"detection.{name}", getattr(self, name), "a number > 0")
        for name in ("reflectance_foliage", "reflectance_ground", "reflectance_target"):
            if not 0 <= getattr(self, name) <= 1:
                raise FieldError(f"detection.{name}", getattr(self, name), "a number in 0..1")
        for name in ("dark_rate_hz", "solar_rate_hz"):
            if not getattr(self, name) >= 0:
                raise FieldError(f"detection.{name}", getattr(self, name), "a number >= 0")
        if not 0 < self.threshold_share <= 1:
            raise FieldError("detection.threshold_share", self.threshold_share, "a number in (0, 1]")

    def threshold(self, pulses: int) -> int:
        return max(1, math.ceil(self.threshold_share * pulses - 1e-12))


@dataclass(frozen=True)
class PulseRow:
    pulses: int
    threshold: int
    obscured_coverage: float
    declared_points: int
    false_alarms: int
    target_detection: float  # declared target hits / ideal target hits (per ray)


def pulse_study(scenario, pulses_list, settings: GeigerSettings | None = None, scene=None,
                backend=None) -> tuple[float, list[PulseRow]]:
    """Ideal obscured coverage and one ``PulseRow`` per pulse count."""
    from ladartui.tracing import trace

    settings = settings or GeigerSettings()
    if scene is None:
        scene = scenario.load_scene()
    sensor = scenario.sensor
    target_keys = np.unique(voxel_keys(scene.target))
    total = target_keys.size
    rays_per_detector = sensor.ray_grid ** 2
    bin_width = sensor.depth_resolution
    dead_bins = int(min(1e6, math.ceil(min(1e6, settings.dead_time_m / bin_width))))
    noise = noise_per_bin(settings.dark_rate_hz + settings.solar_rate_hz, bin_width)
    looks = []
    ideal = []
    for pose in scenario.poses():
        origins, directions, detector = sensor.rays(pose)
        hits = trace(scene.occupancy, origins, directions, voxel_size=scene.voxel_size,
                     backend=backend or scenario.backend, method=scenario.method)
        kept = kept_returns(detector, hits.kind, hits.range, sensor.depth_resolution)
        ideal.append(voxel_keys(hits.index[kept]))
        is_target = (hits.kind == 1) & np.isin(voxel_keys(np.maximum(hits.index, 0)), target_keys)
        refl = np.where(hits.kind == GROUND, settings.reflectance_ground,
                        np.where(is_target, settings.reflectance_target, settings.reflectance_foliage))
        cos = incidence_cosines(origins, directions, hits.kind, hits.index, hits.range,
                                scene.voxel_size)
        kept_mask = np.zeros(detector.size, dtype=bool)
        kept_mask[kept] = True
        looks.append((detector, hits, refl, cos, is_target, kept_mask))
    ideal_cov = np.isin(target_keys, np.concatenate(ideal)).sum() / total if total else 0.0
    rows = []
    for pulses in pulses_list:
        k = settings.threshold(pulses)
        declared_keys, points, false_alarms, hit_t, seen_t = [], 0, 0, 0, 0
        for scan, (detector, hits, refl, cos, is_target, kept_mask) in enumerate(looks):
            look = geiger_look(detector, hits.kind, hits.range, refl, cos,
                               rays_per_detector=rays_per_detector, n_ref=settings.n_ref,
                               range_ref=settings.range_ref,
                               reflectance_ref=settings.reflectance_ref, noise=noise,
                               bin_width=bin_width, pulses=pulses, threshold=k,
                               dead_bins=dead_bins, seed=settings.seed, scan=scan)
            points += int(look.declared.sum())
            false_alarms += look.false_alarms
            declared_keys.append(voxel_keys(hits.index[look.ray_declared & kept_mask]))
            hit_t += int((look.ray_declared & is_target).sum())
            seen_t += int(is_target.sum())
        covered = np.isin(target_keys, np.concatenate(declared_keys)).sum() if total else 0
        rows.append(PulseRow(pulses, k, covered / total if total else 0.0, points, false_alarms,
                             hit_t / seen_t if seen_t else 0.0))
    return float(ideal_cov), rows
