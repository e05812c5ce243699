"""One look's Geiger-mode answer from traced rays (after tracing, no backend change).

Signal per ray (its share of the detector's footprint is 1 / rays per
detector), summed into the range bin of the ray's first hit:

    N_s = N_ref * (1 / rays_per_detector) * (rho / rho_ref) * (R_ref / R)^2 * cos(theta)

``N_ref`` is the mean photoelectrons of a full-footprint Lambertian return of
reflectance ``rho_ref`` at range ``R_ref`` (a scenario number: the full link
budget is not exposed). Bins are ``bin_width`` metres (the depth resolution)
over a gate from the nearest to the farthest return of the look, and every
bin also holds ``noise`` mean counts. Declared bins with no ray in them are
false alarms.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ladartui.detection.geiger import declare_points, fire_counts

MISS = 0


@dataclass(frozen=True)
class GeigerLook:
    detectors: np.ndarray  # (D,) detector ids that have at least one return
    gate_start: float  # metres, start of bin 0
    mean_counts: np.ndarray  # (D, B) signal + noise
    counts: np.ndarray  # (D, B) fires over the pulses
    declared: np.ndarray  # (D, B) bool
    ray_declared: np.ndarray  # (N,) bool: the ray's hit lies in a declared bin
    false_alarms: int  # declared bins without a return
    noise_bins: int = 0  # bins without a return (where only noise can fire)


def incidence_cosines(origins, directions, kind, index, ranges, voxel_size) -> np.ndarray:
    """cos of the angle between each ray and the face it enters (1 for misses)."""
    d = np.asarray(directions, dtype=np.float64)
    cos = np.ones(d.shape[0])
    hit = np.asarray(kind) != MISS
    ground = np.asarray(kind) == 2
    cos[ground] = np.abs(d[ground, 2])
    voxel = hit & ~ground
    if voxel.any():
        along = (np.asarray(ranges)[voxel] / voxel_size)[:, None]
        p = np.asarray(origins)[voxel] / voxel_size + 0.5 + d[voxel] * along
        c = np.asarray(index)[voxel].astype(np.float64)
        # The entry face: of the three the ray can enter by (the low side of an axis it
        # goes up, the high side of one it goes down), the one whose plane the hit point
        # lies closest to; never a face it leaves by, which a range rounded long (float32)
        # put nearest a hit close to an edge.
        dv = d[voxel]
        gap = np.where(dv == 0.0, np.inf, np.abs(p - c - (dv < 0.0)))
        axis = np.argmin(gap, axis=1)
        cos[voxel] = np.abs(dv[np.arange(axis.size), axis])
    return cos


def range_gate(hit_ranges, bin_width: float) -> tuple[float, int]:
    """A look's range gate over its (non-empty) hit ranges: its start, on a whole
    number of bins, and how many bins of ``bin_width`` it holds."""
    r = np.asarray(hit_ranges, dtype=np.float64)
    gate_start = float(np.floor(r.min() / bin_width) * bin_width)
    return gate_start, int(np.floor((r.max() - gate_start) / bin_width)) + 1


def geiger_look(
    detector,
    kind,
    ranges,
    reflectance,
    cos_incidence,
    *,
    rays_per_detector: int,
    n_ref: float,
    range_ref: float,
    reflectance_ref: float,
    noise: float,
    bin_width: float,
    pulses: int,
    threshold: int,
    dead_bins: int,
    seed: int,
    scan: int,
    cancel=None,
) -> GeigerLook:
    detector = np.asarray(detector, dtype=np.int64)
    ranges = np.asarray(ranges, dtype=np.float64)
    hit = np.asarray(kind) != MISS
    ray_declared = np.zeros(detector.size, dtype=bool)
    if not hit.any():
        empty = np.zeros((0, 0))
        return GeigerLook(
            np.zeros(0, np.int64), 0.0, empty, empty.astype(np.int32), empty.astype(bool), ray_declared, 0, 0
        )
    ids, row = np.unique(detector[hit], return_inverse=True)
    r = ranges[hit]
    gate_start, bins = range_gate(r, bin_width)
    b = np.minimum(((r - gate_start) / bin_width).astype(np.int64), bins - 1)
    signal = (
        (n_ref / rays_per_detector)
        * (np.asarray(reflectance)[hit] / reflectance_ref)
        * (range_ref / np.maximum(r, 1e-9)) ** 2
        * np.asarray(cos_incidence)[hit]
    )
    mean = np.full((ids.size, bins), float(noise))
    np.add.at(mean, (row, b), signal)
    has_return = np.zeros((ids.size, bins), dtype=bool)
    has_return[row, b] = True
    counts = fire_counts(mean, pulses, dead_bins, seed, scan, detectors=ids, cancel=cancel)
    declared = declare_points(counts, threshold)
    ray_declared[np.flatnonzero(hit)] = declared[row, b]
    return GeigerLook(
        ids,
        gate_start,
        mean,
        counts,
        declared,
        ray_declared,
        int(np.count_nonzero(declared & ~has_return)),
        int(np.count_nonzero(~has_return)),
    )
