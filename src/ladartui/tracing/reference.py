"""A slow, obviously correct float64 tracer for tests: slab tests against every voxel.

Written apart from the kernels on purpose. For each ray and each occupied
voxel cube [i, i+1) x [j, j+1) x [k, k+1) (cell space) it intersects the ray's
parameter interval with the cube's open interior; the voxel is hit when the
overlap after the origin has positive length, and the answer is the hit with
the smallest entry parameter. Boundary parameters use the same formula as the
kernels, ``(b - o) * (1 / d)``, so exact ties (edges, corners) agree.
Vectorised with numpy over blocks of rays x voxels: fine for thousands of rays
against thousands of voxels.
"""

from __future__ import annotations

import numpy as np

from ladartui.tracing.backend import GROUND, MISS, VOXEL, CellHits


def reference_trace_cells(voxels, shape, origins, directions, block=1 << 22) -> CellHits:
    """Exact first hits of cell-space rays against the voxel list, with the ground rule."""
    vox = np.asarray(voxels, dtype=np.int64).reshape(-1, 3)
    vox = np.unique(vox, axis=0)
    o = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    n = len(o)
    best_t = np.full(n, np.inf)
    best_v = np.full(n, -1, np.int64)
    rays_per_block = max(1, block // max(1, len(vox)))
    for a in range(0, n if len(vox) else 0, rays_per_block):
        b = min(n, a + rays_per_block)
        enter, leave = _cube_intervals(o[a:b], d[a:b], vox)
        start = np.maximum(enter, 0.0)
        hit = start < leave
        t = np.where(hit, start, np.inf)
        j = np.argmin(t, axis=1)
        tj = t[np.arange(b - a), j]
        found = np.isfinite(tj)
        best_t[a:b] = tj
        best_v[a:b] = np.where(found, j, -1)

    kind = np.full(n, MISS, np.uint8)
    index = np.full((n, 3), -1, np.int32)
    t_out = np.full(n, np.inf)
    found = best_v >= 0
    kind[found] = VOXEL
    index[found] = vox[best_v[found]]
    t_out[found] = best_t[found]

    nx, ny = shape[0], shape[1]
    down = ~found & (d[:, 2] < 0) & (o[:, 2] > 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        tg = (0.0 - o[:, 2]) * (1.0 / d[:, 2])
        gx = o[:, 0] + tg * d[:, 0]
        gy = o[:, 1] + tg * d[:, 1]
    on_ground = down & (gx >= 0) & (gx < nx) & (gy >= 0) & (gy < ny)
    kind[on_ground] = GROUND
    index[on_ground, 0] = np.floor(gx[on_ground])
    index[on_ground, 1] = np.floor(gy[on_ground])
    index[on_ground, 2] = 0
    t_out[on_ground] = tg[on_ground]
    return CellHits(kind, index, t_out, {"backend": "reference"})


def _cube_intervals(o, d, vox):
    """(rays, voxels) entry and exit parameters of each ray in each cube's open interior."""
    enter = np.full((len(o), len(vox)), -np.inf)
    leave = np.full((len(o), len(vox)), np.inf)
    for axis in range(3):
        oa = o[:, axis, None]
        da = d[:, axis, None]
        lo = vox[None, :, axis].astype(np.float64)
        hi = lo + 1.0
        moving = da != 0
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            inv = 1.0 / da
            t_lo = (lo - oa) * inv
            t_hi = (hi - oa) * inv
        a_enter = np.where(moving, np.minimum(t_lo, t_hi), np.where((lo < oa) & (oa < hi), -np.inf, np.inf))
        a_leave = np.where(moving, np.maximum(t_lo, t_hi), np.where((lo < oa) & (oa < hi), np.inf, -np.inf))
        np.maximum(enter, a_enter, out=enter)
        np.minimum(leave, a_leave, out=leave)
    return enter, leave
