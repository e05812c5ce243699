"""Bundle starts: where a chunk of nearly parallel rays from one point may all begin.

A flash LADAR scan is a few hundred thousand rays from one origin, and each
run of 64 consecutive rays (a few neighbouring detectors) stays within a
voxel or two of its centre ray for hundreds of metres. One walk of that centre
ray over ``Occupancy.halo`` (bricks that are, or touch, a non-empty brick)
therefore tells every ray of the chunk how far it crosses empty space; the
exact traversal then starts each ray there instead of at the occupied box.

Why it is exact: while the centre ray ``Q(t) = o_c + t d_c`` is in an unset
halo cell, that brick and its 26 neighbours are empty. A ray of the chunk is
at ``P(t) = o + t d`` with ``|P(t) - Q(t)| <= |o - o_c| + t |d - d_c|``; while
that bound is at most ``BUNDLE_REACH`` (7 voxels, less than a brick), ``P(t)``
lies in one of those empty bricks. So no ray of the chunk meets a voxel before
the centre ray enters a set cell (or before the bound passes 7 voxels). The
start returned is one voxel of centre-ray length before that, so every ray
starts in an empty cell and the cells it visits afterwards, and their
parameters, are those of a traversal from its box entry.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

BUNDLE_REACH = 7.0  # voxels: under one brick (8), one voxel of slack for rounding
INF = np.inf


@njit(nogil=True, cache=True)
def bundle_start(orig, dirs, first, end, halo, halo_origin, halo_dims):
    """Parameter ``t`` before which no ray ``first..end-1`` meets an occupied voxel (>= 0)."""
    if halo.shape[0] == 0 or end <= first:
        return 0.0
    ox, oy, oz = orig[first, 0], orig[first, 1], orig[first, 2]
    dx, dy, dz = 0.0, 0.0, 0.0
    for r in range(first, end):
        dx += dirs[r, 0]
        dy += dirs[r, 1]
        dz += dirs[r, 2]
    scale = 1.0 / (end - first)
    dx, dy, dz = dx * scale, dy * scale, dz * scale
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    offset, spread = 0.0, 0.0
    for r in range(first, end):
        ax, ay, az = orig[r, 0] - ox, orig[r, 1] - oy, orig[r, 2] - oz
        offset = max(offset, math.sqrt(ax * ax + ay * ay + az * az))
        ax, ay, az = dirs[r, 0] - dx, dirs[r, 1] - dy, dirs[r, 2] - dz
        spread = max(spread, math.sqrt(ax * ax + ay * ay + az * az))
    reach = BUNDLE_REACH - offset
    if reach <= 0.0 or length == 0.0:
        return 0.0
    limit = reach / spread if spread > 0.0 else INF
    # The centre ray over the halo box (brick cells), one brick at a time.
    ix = 1.0 / dx if dx != 0.0 else INF
    iy = 1.0 / dy if dy != 0.0 else INF
    iz = 1.0 / dz if dz != 0.0 else INF
    t0, t1 = 0.0, limit
    for axis in range(3):
        o = ox if axis == 0 else (oy if axis == 1 else oz)
        d = dx if axis == 0 else (dy if axis == 1 else dz)
        inv = ix if axis == 0 else (iy if axis == 1 else iz)
        lo = 8.0 * halo_origin[axis]
        hi = 8.0 * (halo_origin[axis] + halo_dims[axis])
        if d == 0.0:
            if not lo < o < hi:
                t1 = -INF
        else:
            a, b = (lo - o) * inv, (hi - o) * inv
            t0 = max(t0, min(a, b))
            t1 = min(t1, max(a, b))
    stop = limit
    if t0 < t1:
        bx = _cell(ox + t0 * dx, halo_origin[0], halo_dims[0])
        by = _cell(oy + t0 * dy, halo_origin[1], halo_dims[1])
        bz = _cell(oz + t0 * dz, halo_origin[2], halo_dims[2])
        sx = 1 if dx > 0.0 else -1
        sy = 1 if dy > 0.0 else -1
        sz = 1 if dz > 0.0 else -1
        t = t0
        while True:
            lin = (bx - halo_origin[0]) + halo_dims[0] * ((by - halo_origin[1])
                                                          + halo_dims[1] * (bz - halo_origin[2]))
            if (halo[lin >> 5] >> (lin & 31)) & 1:
                stop = t
                break
            tx = (8.0 * (bx + 1 if dx > 0.0 else bx) - ox) * ix if dx != 0.0 else INF
            ty = (8.0 * (by + 1 if dy > 0.0 else by) - oy) * iy if dy != 0.0 else INF
            tz = (8.0 * (bz + 1 if dz > 0.0 else bz) - oz) * iz if dz != 0.0 else INF
            t = min(tx, min(ty, tz))
            if t >= t1:
                break  # left the halo box (or the reach) without meeting a set cell
            if tx == t:
                bx += sx
            if ty == t:
                by += sy
            if tz == t:
                bz += sz
    return max(0.0, stop - 1.0 / length)


@njit(nogil=True, cache=True)
def _cell(c, origin, dims):
    b = np.int64(math.floor(c * 0.125))
    return min(max(b, origin), origin + dims - 1)


@njit(parallel=True, nogil=True, cache=True)
def bundle_starts(orig, dirs, chunk, halo, halo_origin, halo_dims, out):
    """``bundle_start`` of every ``chunk`` consecutive rays, into ``out``."""
    n = orig.shape[0]
    for c in prange((n + chunk - 1) // chunk):
        out[c] = bundle_start(orig, dirs, c * chunk, min(n, (c + 1) * chunk), halo, halo_origin,
                              halo_dims)


def halo_arrays(occupancy):
    """(halo, origin, dims): the occupancy's halo, or an empty one (no bundle starts)."""
    halo = getattr(occupancy, "halo", None)
    if halo is None or getattr(occupancy, "halo_dims", None) is None or len(halo) == 0:
        return np.zeros(0, np.uint32), np.zeros(3, np.int64), np.zeros(3, np.int64)
    return (halo, np.asarray(occupancy.halo_origin, np.int64),
            np.asarray(occupancy.halo_dims, np.int64))
