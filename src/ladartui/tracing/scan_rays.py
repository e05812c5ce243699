"""A scan's rays for object order: their frame, and their bins on its tangent plane.

A scan (origins within a focal plane's width of each other, directions in a
narrow cone) gets a frame: the origins' centre and half-spread and the cone's
axis ``a`` with two directions ``u``, ``v`` across it (``cone_frame``). Its rays
are binned by their gnomonic coordinates ``(d.u / d.a, d.v / d.a)`` in an
nb x nb grid (``ray_grid``) and put in bin order, tile by tile
(``bin_order``). tracing/object_order.py finds the voxels in view of those bins.
All numba functions here release the GIL; the passes over rays run under
``prange``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ladartui.tracing.config import INF, MAX_SPREAD, MIN_COS, PARTS
from ladartui.tracing.passes import timed

# Ray numbers in bin order are u32 (a block holds far fewer rays): half the bytes
# the tile tests read, and the shader's own type. NO_RAY marks a bin left empty.
NO_RAY = np.uint32(0xFFFFFFFF)


@njit(parallel=True, nogil=True, cache=True)
def ray_bounds(orig, dirs):
    """(lo, hi, direction sum) of a batch: origin box and the sum of directions."""
    n = orig.shape[0]
    part_lo = np.empty((PARTS, 3))
    part_hi = np.empty((PARTS, 3))
    part_sum = np.zeros((PARTS, 3))
    for k in prange(PARTS):
        for a in range(3):
            part_lo[k, a], part_hi[k, a] = INF, -INF
        for r in range(k * n // PARTS, (k + 1) * n // PARTS):
            for a in range(3):
                part_lo[k, a] = min(part_lo[k, a], orig[r, a])
                part_hi[k, a] = max(part_hi[k, a], orig[r, a])
                part_sum[k, a] += dirs[r, a]
    lo, hi, total = part_lo[0].copy(), part_hi[0].copy(), part_sum[0].copy()
    for k in range(1, PARTS):
        for a in range(3):
            lo[a], hi[a] = min(lo[a], part_lo[k, a]), max(hi[a], part_hi[k, a])
            total[a] += part_sum[k, a]
    return lo, hi, total


def cone_frame(orig, dirs, bounds=None):
    """(centre, half_spread, axis, u, v) of a batch of rays, or None when it is no scan.

    A scan here: origins within ``MAX_SPREAD`` cells of their centre on every
    axis (``ray_grid`` then checks every direction is within 60 degrees of
    the mean direction). ``bounds``: the batch's ``ray_bounds`` as nine numbers,
    when known (prepare.rays_to_cells finds them).
    """
    if len(orig) == 0:
        return None
    if bounds is None:
        lo, hi, total = ray_bounds(orig, dirs)
        bounds = np.concatenate((lo, hi, total))
    frame = np.empty((5, 3))
    if not _frame(np.asarray(bounds, np.float64), dirs[0], dirs[min(1, len(dirs) - 1)], frame):
        return None
    return frame[0], frame[1], frame[2], frame[3], frame[4]


@njit(nogil=True, cache=True, inline="always")
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(nogil=True, cache=True)
def _frame(bounds, first, second, frame):
    """cone_frame's rows (centre, half spread, axis, u, v) from the nine numbers of
    ``ray_bounds`` and the first two directions; False when it is no scan. (Compiled:
    as numpy calls on 3-vectors it cost 0.2 ms, a fiftieth of a scan.)"""
    lo, hi, total = bounds[0:3], bounds[3:6], bounds[6:9]
    half = 0.5 * (hi - lo)
    norm = math.sqrt(total[0] ** 2 + total[1] ** 2 + total[2] ** 2)
    if not (half.max() <= MAX_SPREAD and norm > 0.0):
        return False
    axis = total / norm
    # u along the first row of rays when there is one (bins then follow the sensor's grid):
    # the step between their points on the plane one unit along the axis, which a
    # row of a pinhole grid keeps to exactly (their own difference leans off it).
    side = second / _dot(second, axis) - first / _dot(first, axis)
    side = side - axis * _dot(side, axis)
    if math.sqrt(_dot(side, side)) < 1e-12:
        side = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        side = side - axis * _dot(side, axis)
    u = side / math.sqrt(_dot(side, side))
    v = np.array(
        [axis[1] * u[2] - axis[2] * u[1], axis[2] * u[0] - axis[0] * u[2], axis[0] * u[1] - axis[1] * u[0]]
    )
    # Grown cubes use the spread, widened by a hair and by a few units in the last place
    # of the coordinates (far from the origin the centre itself is rounded).
    largest = max(np.abs(lo).max(), np.abs(hi).max())
    slack = 1e-12 + 8.0 * (np.nextafter(largest, INF) - largest)
    frame[0], frame[1], frame[2], frame[3], frame[4] = (
        0.5 * (lo + hi),
        half * (1.0 + 1e-9) + slack,
        axis,
        u,
        v,
    )
    return True


@njit(parallel=True, nogil=True, cache=True)
def _gnomonic(dirs, axis, u, v, p, q):
    """p, q = d.u / d.a, d.v / d.a per ray; returns (p min, p max, q min, q max, all unit
    and within 60 degrees of the axis)."""
    n = dirs.shape[0]
    part = np.empty((PARTS, 4))
    off_axis = np.zeros(PARTS, np.bool_)
    for k in prange(PARTS):
        pmin, pmax, qmin, qmax = INF, -INF, INF, -INF
        for r in range(k * n // PARTS, (k + 1) * n // PARTS):
            d0, d1, d2 = dirs[r, 0], dirs[r, 1], dirs[r, 2]
            w = d0 * axis[0] + d1 * axis[1] + d2 * axis[2]
            # The depth bounds need unit directions (trace() gives them; a caller of
            # trace_cells might not): anything else goes in ray order.
            if not (w >= MIN_COS and abs(d0 * d0 + d1 * d1 + d2 * d2 - 1.0) <= 1e-9):
                off_axis[k] = True
                w = 1.0
            pp = (d0 * u[0] + d1 * u[1] + d2 * u[2]) / w
            qq = (d0 * v[0] + d1 * v[1] + d2 * v[2]) / w
            p[r], q[r] = pp, qq
            pmin, pmax, qmin, qmax = min(pmin, pp), max(pmax, pp), min(qmin, qq), max(qmax, qq)
        part[k, 0], part[k, 1], part[k, 2], part[k, 3] = pmin, pmax, qmin, qmax
    return (part[:, 0].min(), part[:, 1].max(), part[:, 2].min(), part[:, 3].max(), not off_axis.any())


@njit(nogil=True, cache=True, inline="always")
def bin_key(i, j, tiles_per_side, shift):
    """Sort key of bin (i, j) with tiles of ``1 << shift`` bins a side: bins are
    numbered tile by tile, rows within a tile, so a tile's rays are contiguous and
    so is each of its rows. (Shifts, not divisions: several times faster here.)"""
    mask = (1 << shift) - 1
    return ((((j >> shift) * tiles_per_side + (i >> shift)) << shift | (j & mask)) << shift) | (i & mask)


@njit(nogil=True, cache=True, inline="always")
def bin_scales(grid):
    """(p0, p_scale, q0, q_scale): a ray's position in bins is ``((p - p0) * p_scale,
    (q - q0) * q_scale)``, its bin the whole part of that (``_bin_at``). By the steps'
    reciprocals (1.1x the scatter): the measured slack comes from the same products,
    and the 1e-6 bins ``bin_order`` adds to it dwarf their rounding."""
    return grid[0], 1.0 / grid[1], grid[2], 1.0 / grid[3]


@njit(nogil=True, cache=True, inline="always")
def _bin_at(position, nb):
    """The bin of a position in bins, clamped into 0 .. nb - 1."""
    return min(nb - 1, max(0, np.int64(position)))


@njit(parallel=True, nogil=True, cache=True)
def _bin_keys(p, q, grid, nb, shift, key_of):
    nt = -(-nb >> shift)
    p0, p_scale, q0, q_scale = bin_scales(grid)
    for r in prange(p.shape[0]):
        i, j = _bin_at((p[r] - p0) * p_scale, nb), _bin_at((q[r] - q0) * q_scale, nb)
        key_of[r] = bin_key(i, j, nt, shift)


@njit(nogil=True, cache=True)
def _sort_into_bins(p, q, grid, nb, shift):
    """(starts, order): counting sort of the rays by ``bin_key``."""
    n = p.shape[0]
    nt = -(-nb >> shift)
    key_of = np.empty(n, np.int64)
    _bin_keys(p, q, grid, nb, shift, key_of)
    starts = np.zeros((nt * nt << 2 * shift) + 1, np.int64)
    for r in range(n):
        starts[key_of[r] + 1] += 1
    for b in range(starts.shape[0] - 1):
        starts[b + 1] += starts[b]
    fill = starts[:-1].copy()
    order = np.empty(n, np.uint32)
    for r in range(n):
        order[fill[key_of[r]]] = r
        fill[key_of[r]] += 1
    return starts, order


@njit(parallel=True, nogil=True, cache=True)
def _scatter_one_per_bin(p, q, grid, nb, shift, order, slack):
    """The sort when every bin holds exactly one ray (a whole scan, whose own ray grid
    the bins then are): each ray's number goes straight to the position of its bin's
    key, in one parallel pass. Needs nb * nb rays and whole tiles (the keys are then
    0 .. n-1). False when some bin got none (so another got two): the caller sorts
    instead. ``slack`` gets the largest distance,
    in bins, of a ray's p and q from its bin's middle."""
    n = p.shape[0]
    nt = nb >> shift
    for k in prange(n):
        order[k] = NO_RAY
    far = np.zeros((PARTS, 2))
    p0, p_scale, q0, q_scale = bin_scales(grid)
    for part in prange(PARTS):
        far_p, far_q = 0.0, 0.0
        for r in range(part * n // PARTS, (part + 1) * n // PARTS):
            x, y = (p[r] - p0) * p_scale, (q[r] - q0) * q_scale
            i, j = _bin_at(x, nb), _bin_at(y, nb)
            order[bin_key(i, j, nt, shift)] = r
            far_p, far_q = max(far_p, abs(x - (i + 0.5))), max(far_q, abs(y - (j + 0.5)))
        far[part, 0], far[part, 1] = far_p, far_q
    slack[0], slack[1] = far[:, 0].max(), far[:, 1].max()
    missing = np.zeros(PARTS, np.bool_)
    for part in prange(PARTS):
        for k in range(part * n // PARTS, (part + 1) * n // PARTS):
            if order[k] == NO_RAY:
                missing[part] = True
                break
    return not missing.any()


def ray_grid(dirs, axis, u, v, nb):
    """(p, q, grid) of a scan: gnomonic coordinates and the nb x nb bins over them,
    ``grid = (p0, p_step, q0, q_step, p_slack, q_slack)``; None when a ray is more than
    60 degrees off the axis or not of unit length.

    The bins are centred on an even spread of nb values from the least to the
    greatest coordinate, so a scan's own ray grid puts each ray near its bin's
    middle (robust to the sensor's small unevenness). A ray of bin i lies within
    ``slack`` bins of i + 1/2 (0.5 here: anywhere in its bin; ``bin_order`` measures
    less for a whole scan, and voxels then cover fewer bins, ``box_bins``).
    """
    n = len(dirs)
    p, q = np.empty(n), np.empty(n)
    pmin, pmax, qmin, qmax, on_axis = _gnomonic(dirs, axis, u, v, p, q)
    if not on_axis:
        return None
    p_step = (pmax - pmin) / (nb - 1) if pmax > pmin and nb > 1 else 1.0
    q_step = (qmax - qmin) / (nb - 1) if qmax > qmin and nb > 1 else 1.0
    return p, q, np.array([pmin - 0.5 * p_step, p_step, qmin - 0.5 * q_step, q_step, 0.5, 0.5])


@timed("bins")
def scan_grid(dirs, frame):
    """(nb, p, q, grid) of a scan with ``frame`` (``cone_frame``): nb = ceil(sqrt(N))
    bins a side over its rays (``ray_grid``); None when a ray is not of unit length
    within 60 degrees of the axis."""
    nb = max(1, int(math.ceil(math.sqrt(len(dirs)))))
    gnomonic = ray_grid(dirs, frame[2], frame[3], frame[4], nb)
    return None if gnomonic is None else (nb, *gnomonic)


@timed("bins")
def bin_order(p, q, grid, nb, shift):
    """(order, starts, grid) of the rays in bin order, without copying them: sorted
    position s is ray ``order[s]`` (u32); the rays of the bin with key ``b`` (``bin_key``)
    are sorted positions ``starts[b] .. starts[b + 1]``, or ``starts`` is empty when
    every bin holds exactly one ray (bin key b is then position b). The
    grid comes back with the slack measured then: how far, in bins, any ray lies from
    its bin's middle (a scan's rays sit near the middles, so voxels cover fewer bins)."""
    n = len(p)
    if n == nb * nb and nb % (1 << shift) == 0:
        order = np.empty(n, np.uint32)
        slack = np.empty(2)
        if _scatter_one_per_bin(p, q, grid, nb, shift, order, slack):
            measured = grid.copy()
            # A hair over the measure: it is rounded as box_bins' own positions are.
            measured[4:] = np.minimum(0.5, slack + 1e-6)
            return order, np.empty(0, np.int64), measured
    starts, order = _sort_into_bins(p, q, grid, nb, shift)
    return order, starts, grid
