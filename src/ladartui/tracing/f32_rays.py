"""Rays made float32 for the wgpu backend's f32 shader without losing their cells.

In f32 each ray starts where it enters the scene's box (``f32_start_offsets``:
moved there on the host in float64, the offset added back to ``t``), so an
aircraft kilometres away loses no precision. The moved origins are then given
from the root grid's corner (``f32_shift``, subtracted in float64 and added
back to the cells found), so voxels at large indices (a scene in map indices:
UTM at 0.25 m is ~2e6 cells) are traced with small coordinates too.
``floor_preserving_f32`` keeps every moved origin in the cell its float64
value is in.
"""

from __future__ import annotations

import numpy as np


def f32_start_offsets(origins, directions, shape, top, method, at_least=None):
    """Per-ray float64 ``t`` to move each origin by before it is made float32.

    Exact: where the ray enters the box ``[0, nx] x [0, ny] x [0, top]`` (the
    scene's extent up to the top of its highest occupied layer), or 0 when it
    starts inside or never enters. March: the march's own start, where a
    descending ray crosses ``c_z = top`` (same formula as the kernels), else 0.
    The shader then sees coordinates no larger than the scene, and the host
    adds ``t`` back in float64. ``at_least`` (exact only): per-ray bundle starts
    (tracing.bundle) to move at least as far as.
    """
    o = np.asarray(origins, dtype=np.float64)
    d = np.asarray(directions, dtype=np.float64)
    if method == "march":
        start = np.zeros(len(o))
        above = (o[:, 2] > top) & (d[:, 2] < 0.0)
        start[above] = (top - o[above, 2]) * (1.0 / d[above, 2])
        return start
    hi = np.array([float(shape[0]), float(shape[1]), max(float(top), 1.0)])
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t_lo = -o * inv
        t_hi = (hi - o) * inv
        # With d == 0 (inv = inf) the pair is (-inf, +inf) inside the slab,
        # one-signed outside it, NaN on its faces (fmin/fmax skip NaN: no shift).
        near = np.fmin(t_lo, t_hi)
        far = np.fmax(t_lo, t_hi)
        enter = np.fmax(np.fmax(near[:, 0], near[:, 1]), near[:, 2])
        leave = np.fmin(np.fmin(far[:, 0], far[:, 1]), far[:, 2])
        if at_least is not None:
            # A start past the box's far side means no voxel: keep the box entry then.
            moved = np.fmax(enter, at_least)
            enter = np.where(moved <= leave, moved, enter)
    # The ground rule needs no care here: the host applies it to the rays as given.
    return np.where((enter > 0.0) & (enter <= leave), enter, 0.0)


def f32_shift(occupancy) -> np.ndarray:
    """The (x, y, 0) cell the f32 rays' cell space starts at: the corner of the
    occupancy's root grid, a multiple of 2**REGION_SHIFT (512) cells at or below its lowest voxel
    (so every node keeps its slots, ``wgpu_occupancy.pack_params``); (0, 0, 0)
    for an empty scene. A float32 holds a coordinate near 2^k to 2^(k-23) cells:
    with voxels 2^16 cells from the rays' zero, 0.5 % of the rays into them
    changed their answer (90 % at 2^24)."""
    if occupancy.count == 0:
        return np.zeros(3, dtype=np.int64)
    root = np.asarray(occupancy.root_origin, dtype=np.int64)
    return np.array([root[0], root[1], 0], dtype=np.int64)


def floor_preserving_f32(values):
    """float32 of float64 ``values``, each in the same unit cell as its float64 value.

    Plain rounding can carry 72.99999999 up to 73.0, which changes the cell a
    ray starts in (the march's first sample sits on the top face exactly in
    real numbers, so its cell is decided by the last bit). Such values step
    down to the float32 just below the integer.
    """
    v32 = np.asarray(values, dtype=np.float64).astype(np.float32)
    crossed = np.floor(v32) > np.floor(values)
    v32[crossed] = np.nextafter(v32[crossed], np.float32(-np.inf))
    return v32
