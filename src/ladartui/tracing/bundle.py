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
the centre ray enters a set cell (or before the bound passes 7 voxels). From
there the centre ray goes on in the same way over ``Occupancy.halo4`` (4-voxel
cells, reach 3 voxels) while the bundle is that tight. The start returned is
one voxel of centre-ray length before the last stop, so every ray
starts in an empty cell and the cells it visits afterwards, and their
parameters, are those of a traversal from its box entry.

The numba exact kernel compiles ``bundle_start`` (and tracing.axis) into
itself; numba's on-disk cache only notices edits to the kernel's own file, so
``ladartui.kernel_cache`` clears the cached kernels once this one or axis.py
changed.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ladartui.tracing.axis import slab
from ladartui.tracing.config import BUNDLE, BUNDLE_REACH, FAR, FINE_REACH, INF


@njit(nogil=True, cache=True)
def bundle_start(orig, dirs, first, end, halo, halo_origin, halo_dims, fine, fine_origin, fine_dims):
    """Parameter ``t`` before which no ray ``first..end-1`` meets an occupied voxel (>= 0)."""
    if halo.shape[0] == 0 or end <= first:
        return 0.0
    ox, oy, oz = orig[first, 0], orig[first, 1], orig[first, 2]
    if abs(ox) + abs(oy) + abs(oz) > FAR:
        return 0.0
    dx, dy, dz = 0.0, 0.0, 0.0
    for r in range(first, end):
        dx += dirs[r, 0]
        dy += dirs[r, 1]
        dz += dirs[r, 2]
    scale = 1.0 / (end - first)
    dx, dy, dz = dx * scale, dy * scale, dz * scale
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    offset2, spread2 = 0.0, 0.0  # squared: one square root each, not one per ray
    for r in range(first, end):
        ax, ay, az = orig[r, 0] - ox, orig[r, 1] - oy, orig[r, 2] - oz
        offset2 = max(offset2, ax * ax + ay * ay + az * az)
        ax, ay, az = dirs[r, 0] - dx, dirs[r, 1] - dy, dirs[r, 2] - dz
        spread2 = max(spread2, ax * ax + ay * ay + az * az)
    offset, spread = math.sqrt(offset2), math.sqrt(spread2)
    reach = BUNDLE_REACH - offset
    if reach <= 0.0 or length == 0.0:
        return 0.0
    limit = reach / spread if spread > 0.0 else INF
    stop = _walk(ox, oy, oz, dx, dy, dz, 0.0, limit, halo, halo_origin, halo_dims, 8.0)
    fine_reach = FINE_REACH - offset
    if stop < limit and fine.shape[0] != 0 and fine_reach > 0.0:
        # Near the first brick the centre ray can meet, go on over the 4-voxel halo.
        fine_limit = fine_reach / spread if spread > 0.0 else INF
        stop = max(stop, _walk(ox, oy, oz, dx, dy, dz, stop, fine_limit, fine, fine_origin, fine_dims, 4.0))
    return max(0.0, stop - 1.0 / length)


@njit(nogil=True, cache=True)
def _walk(ox, oy, oz, dx, dy, dz, start, limit, bits, origin, dims, size):
    """Where the ray, from ``start`` on, enters a set cell of the ``bits`` grid of
    ``size``-voxel cells (box ``origin .. origin + dims`` in cells); ``limit`` when it
    leaves the box, or reaches ``limit``, first."""
    ix = 1.0 / dx if dx != 0.0 else INF
    iy = 1.0 / dy if dy != 0.0 else INF
    iz = 1.0 / dz if dz != 0.0 else INF
    ex, xx = slab(ox, dx, ix, size * origin[0], size * (origin[0] + dims[0]))
    ey, xy = slab(oy, dy, iy, size * origin[1], size * (origin[1] + dims[1]))
    ez, xz = slab(oz, dz, iz, size * origin[2], size * (origin[2] + dims[2]))
    t0 = max(start, max(ex, max(ey, ez)))
    t1 = min(limit, min(xx, min(xy, xz)))
    if not t0 < t1:
        return limit
    scale = 1.0 / size
    bx = _cell(ox + t0 * dx, scale, origin[0], dims[0])
    by = _cell(oy + t0 * dy, scale, origin[1], dims[1])
    bz = _cell(oz + t0 * dz, scale, origin[2], dims[2])
    sx = 1 if dx > 0.0 else -1
    sy = 1 if dy > 0.0 else -1
    sz = 1 if dz > 0.0 else -1
    t = t0
    while True:
        lin = (bx - origin[0]) + dims[0] * ((by - origin[1]) + dims[1] * (bz - origin[2]))
        if (bits[lin >> 5] >> (lin & 31)) & 1:
            return t
        tx = (size * (bx + 1 if dx > 0.0 else bx) - ox) * ix if dx != 0.0 else INF
        ty = (size * (by + 1 if dy > 0.0 else by) - oy) * iy if dy != 0.0 else INF
        tz = (size * (bz + 1 if dz > 0.0 else bz) - oz) * iz if dz != 0.0 else INF
        t = min(tx, min(ty, tz))
        if t >= t1:
            return limit  # left the box (or the reach) without meeting a set cell
        if tx == t:
            bx += sx
        if ty == t:
            by += sy
        if tz == t:
            bz += sz


@njit(nogil=True, cache=True)
def _cell(c, scale, origin, dims):
    b = np.int64(math.floor(c * scale))
    return min(max(b, origin), origin + dims - 1)


@njit(parallel=True, nogil=True, cache=True)
def bundle_starts(orig, dirs, chunk, halo, halo_origin, halo_dims, fine, fine_origin, fine_dims, out):
    """``bundle_start`` of every ``chunk`` consecutive rays, into ``out``."""
    n = orig.shape[0]
    for c in prange((n + chunk - 1) // chunk):
        out[c] = bundle_start(
            orig,
            dirs,
            c * chunk,
            min(n, (c + 1) * chunk),
            halo,
            halo_origin,
            halo_dims,
            fine,
            fine_origin,
            fine_dims,
        )


Halos = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def halo_arrays(occupancy) -> Halos:
    """(halo, origin, dims, halo4, origin4, dims4): the occupancy's halos, empty ones
    (no bundle starts, or no fine step) where it has none."""
    return _bits(occupancy, "halo") + _bits(occupancy, "halo4")


def _bits(occupancy, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    bits = getattr(occupancy, name, None)
    if bits is None or getattr(occupancy, name + "_dims", None) is None or len(bits) == 0:
        return np.zeros(0, np.uint32), np.zeros(3, np.int64), np.zeros(3, np.int64)
    return (
        bits,
        np.asarray(getattr(occupancy, name + "_origin"), np.int64),
        np.asarray(getattr(occupancy, name + "_dims"), np.int64),
    )


def bundle_start_array(origins, directions, halo: Halos):
    """float64 bundle start (tracing.bundle) of each ``BUNDLE`` consecutive rays."""
    out = np.zeros(max(1, -(-len(origins) // BUNDLE)))
    bundle_starts(
        np.ascontiguousarray(origins, dtype=np.float64),
        np.ascontiguousarray(directions, dtype=np.float64),
        BUNDLE,
        *halo,
        out,
    )
    return out
