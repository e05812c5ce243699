"""A ray's answer, shared by both backends: the voxel it hit, else the ground rule.

``ray_answer`` is compiled into the numba kernels (the exact kernel and the
object-order tile tests) and written again in WGSL (shaders/trace.wgsl,
``ground``); ``put_answer`` writes an object-order hit with it (numba's tile
tests, and tracing/shader_scan.py for the wgpu backend's shader).
"""

import math

import numpy as np
from numba import njit

from ladartui.tracing.config import GROUND, INF, MISS, VOXEL


@njit(nogil=True, cache=True, inline="always")
def ray_answer(found, i, j, k, t, ox, oy, oz, dx, dy, dz, nx, ny):
    """(kind, i, j, k, t) of a ray: the voxel it hit, else the ground rule."""
    if found:
        return VOXEL, i, j, k, t
    if dz < 0.0 and oz > 0.0:
        tg = (0.0 - oz) * (1.0 / dz)
        gx = ox + tg * dx
        gy = oy + tg * dy
        if 0.0 <= gx < nx and 0.0 <= gy < ny:
            return GROUND, np.int64(math.floor(gx)), np.int64(math.floor(gy)), np.int64(0), tg
    return MISS, np.int64(-1), np.int64(-1), np.int64(-1), INF


@njit(nogil=True, cache=True, inline="always")
def put_answer(r, q, t, vox, ox, oy, oz, dx, dy, dz, nx, ny, kind, index, tout):
    """Ray r's answer into kind/index/tout: voxel ``vox[q, :3]`` at t, or for q < 0
    the ground rule (the object-order tests' way to write what they found)."""
    i, j, k = (vox[q, 0], vox[q, 1], vox[q, 2]) if q >= 0 else (-1, -1, -1)
    kind[r], index[r, 0], index[r, 1], index[r, 2], tout[r] = ray_answer(
        q >= 0, i, j, k, t, ox, oy, oz, dx, dy, dz, nx, ny
    )
