"""A ray's answer, shared by both backends: the voxel it hit, else the ground rule.

``ray_answer`` is compiled into the numba kernels (the exact kernel and the
object-order tile tests); ``put_answer`` writes numba's object-order hits with
it (the tile tests), tracing/shader_scan.py's ``entry_answers`` the wgpu
shader's, ``box_offset_answers`` the hits of the wgpu backend's exact ray
order, and ``ground_answers`` the ground rule for the rays in which its
``trace_rays`` (f32, or a box too large for offsets) found no voxel. No shader
applies the ground rule: a GPU may fuse its multiply and add (an f32 ray onto
a corner of the extent then missed), and on the host it is numba's, bit for bit.
"""

import math

import numpy as np
from numba import njit, prange

from ladartui.tracing.axis import cube_start
from ladartui.tracing.config import CUT_WORD, GROUND, INF, MISS, VOXEL


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


@njit(nogil=True, cache=True, inline="always")
def voxel_entry(ox, oy, oz, dx, dy, dz, i, j, k):
    """Where the ray enters voxel (i, j, k): the slab test both tracers share
    (``axis.cube_start``), for a voxel the ray is known to hit."""
    inv_x = 1.0 / dx if dx != 0.0 else INF
    inv_y = 1.0 / dy if dy != 0.0 else INF
    inv_z = 1.0 / dz if dz != 0.0 else INF
    return cube_start(
        ox, oy, oz, dx, dy, dz, inv_x, inv_y, inv_z, np.float64(i), np.float64(j), np.float64(k)
    )[0]


@njit(parallel=True, nogil=True, cache=True)
def box_offset_answers(found, lo, sx, sy, orig, shared_origin, dirs, nx, ny, kind, index, tout):
    """Every ray's answer from shaders/trace.wgsl's ``first_hits`` words: the voxel at
    box offset ``found[r]`` (``(i - lo[0]) + sx * ((j - lo[1]) + sy * (k - lo[2]))``),
    entered where ``voxel_entry`` says; for NO_VOXEL the ground rule. Returns how
    many rays say CUT_WORD (left as misses). ``shared_origin``: every ray starts at
    ``orig[0]``, which is then read for all. Offsets are decoded in u32 (they fit
    an i32, ``wgpu_hits.box_sides``): 1.38-1.42x this pass on two cores, against
    i64 divisions."""
    cut = 0
    row_length, plane_rows = np.uint32(sx), np.uint32(sy)
    for r in prange(found.shape[0]):
        o = np.int64(0) if shared_origin else np.int64(r)  # (prange's r is unsigned)
        ox, oy, oz = orig[o, 0], orig[o, 1], orig[o, 2]
        dx, dy, dz = dirs[r, 0], dirs[r, 1], dirs[r, 2]
        word = np.int64(found[r])
        i, j, k, t = np.int64(-1), np.int64(-1), np.int64(-1), INF
        if word == CUT_WORD:
            cut += 1
        elif word >= 0:
            offset = np.uint32(word)
            row = offset // row_length
            plane = row // plane_rows
            i = lo[0] + np.int64(offset - row * row_length)
            j = lo[1] + np.int64(row - plane * plane_rows)
            k = lo[2] + np.int64(plane)
            t = voxel_entry(ox, oy, oz, dx, dy, dz, i, j, k)
        kind[r], index[r, 0], index[r, 1], index[r, 2], tout[r] = ray_answer(
            word >= 0, i, j, k, t, ox, oy, oz, dx, dy, dz, nx, ny
        )
    return cut


@njit(parallel=True, nogil=True, cache=True)
def ground_answers(rows, orig, shared_origin, dirs, nx, ny, kind, index, tout):
    """The ground rule (``ray_answer`` with no voxel) for rays ``rows``, in float64
    on the rays as given: the wgpu backend's answer where ``trace_rays`` found none.
    ``shared_origin``: every ray starts at ``orig[0]``."""
    for n in prange(rows.shape[0]):
        r = rows[n]
        o = np.int64(0) if shared_origin else r
        kind[r], index[r, 0], index[r, 1], index[r, 2], tout[r] = ray_answer(
            False,
            np.int64(-1),
            np.int64(-1),
            np.int64(-1),
            INF,
            orig[o, 0],
            orig[o, 1],
            orig[o, 2],
            dirs[r, 0],
            dirs[r, 1],
            dirs[r, 2],
            nx,
            ny,
        )
