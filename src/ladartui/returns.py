"""Hits to returns: the depth-resolution rule per detector, and fusing scans.

Each scan's hits pass the detector's depth-resolution rule (report section
7.4); the returned voxels of all scans are fused into one sorted voxel list.
Used by the run (``simulation``) and by the detection models, which sit below it.
"""

from __future__ import annotations

import numba
import numpy as np

from ladartui.scene.keys import keys_to_voxels, sorted_unique, voxel_keys
from ladartui.tracing.backend import MISS

# Detectors with more rays than this are sorted up front, not by insertion.
_INSERTION_LIMIT = 64


# --------------------------------------------------------------------------- depth rule


@numba.njit(nogil=True, cache=True)
def _depth_rule_kernel(order, grouped, detector, kind, ranges, depth_resolution, kept):
    """Write the indices of the kept returns into ``kept``; return how many.

    Rays are visited in ``order`` (or 0..n-1 when ``grouped``), which lists
    each detector's rays together (already sorted by range when groups are
    large). Within a detector the returns are sorted by range (stably, so equal
    ranges keep ray order); the first is kept and every later one closer than
    ``depth_resolution`` to the last kept return is dropped.
    """
    n = detector.size
    group_rays = np.empty(n, dtype=np.int64)
    group_ranges = np.empty(n, dtype=np.float64)
    return _rule_over(
        0, n, order, grouped, detector, kind, ranges, depth_resolution, kept, group_rays, group_ranges
    )


@numba.njit(nogil=True, cache=True)
def _rule_over(start, stop, order, grouped, detector, kind, ranges, depth_resolution, kept, rays, values):
    """The rule over positions ``start:stop`` (whole detector groups), writing the kept
    rays from ``kept[start]`` on; returns how many. ``rays``/``values``: scratch for a group."""
    count_kept = 0
    first = start
    while first < stop:
        group = detector[first if grouped else order[first]]
        end = first
        while end < stop and detector[end if grouped else order[end]] == group:
            end += 1
        count = 0
        for position in range(first, end):
            ray = position if grouped else order[position]
            value = ranges[ray]
            if kind[ray] == MISS or not np.isfinite(value):
                continue
            # Insertion sort, stable; linear when the order is sorted already.
            j = count - 1
            while j >= 0 and values[j] > value:
                values[j + 1] = values[j]
                rays[j + 1] = rays[j]
                j -= 1
            values[j + 1] = value
            rays[j + 1] = ray
            count += 1
        last = 0.0
        for i in range(count):
            if i == 0 or values[i] - last >= depth_resolution:
                kept[start + count_kept] = rays[i]
                count_kept += 1
                last = values[i]
        first = end
    return count_kept


@numba.njit(nogil=True, cache=True, parallel=True)
def _grouped_rule_in_parts(bounds, detector, kind, ranges, depth_resolution, kept, counts):
    # Each part is whole detector groups and writes inside its own rays' span of
    # ``kept``, so the parts run at once and, joined in order, equal one pass.
    for part in numba.prange(bounds.size - 1):
        start, stop = bounds[part], bounds[part + 1]
        group_rays = np.empty(_INSERTION_LIMIT, dtype=np.int64)
        group_ranges = np.empty(_INSERTION_LIMIT, dtype=np.float64)
        counts[part] = _rule_over(
            start,
            stop,
            bounds[:0],
            True,
            detector,
            kind,
            ranges,
            depth_resolution,
            kept,
            group_rays,
            group_ranges,
        )


# Parts a grouped scan's depth rule is split into (whole detectors each), run in parallel.
_RULE_PARTS = 32
_PARALLEL_RULE_RAYS = 1 << 14  # fewer rays than this: one pass beats starting threads


def kept_returns(detector, kind, ranges, depth_resolution) -> np.ndarray:
    """Indices of the rays whose hits survive the detector's depth resolution.

    Rays are grouped by ``detector`` id and sorted by ``ranges`` (metres); the
    nearest return of each detector is kept, and each later one is kept only if
    it lies at least ``depth_resolution`` metres beyond the last kept return.
    Misses (``kind == MISS``) never return; ground returns are returns.
    """
    detector = np.ascontiguousarray(detector)
    kind = np.ascontiguousarray(kind, dtype=np.uint8)
    ranges = np.ascontiguousarray(ranges, dtype=np.float64)
    n = detector.shape[0]
    if not (kind.shape[0] == ranges.shape[0] == n):
        raise ValueError("detector, kind and ranges must have the same length")
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    # Sensor rays come grouped by detector in increasing order, a few per
    # detector: sort each group in place. Otherwise sort everything first.
    grouped = bool(np.all(detector[1:] >= detector[:-1])) and _largest_group(detector) <= _INSERTION_LIMIT
    kept = np.empty(n, dtype=np.int64)
    if grouped and n >= _PARALLEL_RULE_RAYS:
        # part bounds at the start of the group holding every n/_RULE_PARTS-th ray
        cuts = detector[np.arange(1, _RULE_PARTS) * n // _RULE_PARTS]
        bounds = np.unique(np.concatenate(([0], np.searchsorted(detector, cuts), [n])))
        counts = np.zeros(bounds.size - 1, dtype=np.int64)
        _grouped_rule_in_parts(bounds, detector, kind, ranges, float(depth_resolution), kept, counts)
        return np.concatenate([kept[bounds[i] : bounds[i] + counts[i]] for i in range(counts.size)])
    order = np.zeros(0, dtype=np.int64) if grouped else np.lexsort((ranges, detector))
    count = _depth_rule_kernel(
        order.astype(np.int64), grouped, detector, kind, ranges, float(depth_resolution), kept
    )
    return kept[:count]


def _largest_group(sorted_ids) -> int:
    starts = np.flatnonzero(sorted_ids[1:] != sorted_ids[:-1]) + 1
    bounds = np.concatenate(([0], starts, [sorted_ids.size]))
    return int(np.diff(bounds).max())


def apply_depth_resolution(detector, kind, ranges, depth_resolution) -> np.ndarray:
    """Boolean mask over the rays: True where the hit survives the depth resolution."""
    mask = np.zeros(np.shape(detector)[0], dtype=bool)
    mask[kept_returns(detector, kind, ranges, depth_resolution)] = True
    return mask


def scan_returns(trace_result, detector, depth_resolution) -> np.ndarray:
    """The voxels one scan returns: hits after the depth rule, unique, (K, 3) int32."""
    kept = kept_returns(detector, trace_result.kind, trace_result.range, depth_resolution)
    return unique_voxels(trace_result.index[kept])


def unique_voxels(voxels) -> np.ndarray:
    """The distinct voxels of a (K, 3) list, sorted by (i, j, k), as int32."""
    voxels = np.asarray(voxels).reshape(-1, 3)
    if voxels.shape[0] == 0:
        return np.zeros((0, 3), dtype=np.int32)
    return keys_to_voxels(sorted_unique(voxel_keys(voxels)))


def fuse_scans(per_scan) -> np.ndarray:
    """The fused output of several scans: the union of their returned voxels."""
    per_scan = [np.asarray(v).reshape(-1, 3) for v in per_scan]
    if not per_scan:
        return np.zeros((0, 3), dtype=np.int32)
    keys = [voxel_keys(v) for v in per_scan]
    # Scans' outputs come sorted (unique_voxels): merging them beats sorting anew.
    sorted_runs = len(keys) > 1 and all(bool(np.all(k[1:] >= k[:-1])) for k in keys)
    return keys_to_voxels(sorted_unique(np.concatenate(keys), sorted_runs=sorted_runs))
