"""Rays in metres to cell-space rays, in one parallel pass that releases the GIL.

It computes exactly what the numpy expressions in its docstrings compute (same
operations in the same order, so the same bits), without their temporaries:
on a 262,144-ray scan the numpy passes cost a fifth of a nadir trace. A ray
costs a square root and three divisions, so the pass runs on every core (about
1.0 ms on two for the peer comparison's rays), and a ray from the same origin
as the one before reuses its cell (a scan's rays often share one); when all
do, the cells are one row broadcast. A serial pass then finds the first bad
ray, if any, for the message. ``scale_in_place`` takes the ranges back to
metres.
"""

import threading
from collections.abc import Iterator
from contextlib import contextmanager

import numba
import numpy as np
from numba import prange

from ladartui.errors import FieldError
from ladartui.tracing.config import INF, PARTS, SCAN_BLOCK

# Outside (NORM_LOW, inf) the squares under- or overflow: such directions are
# scaled by their largest component first (1e160 along x is still along x).
NORM_LOW = 1e-150
# Rays a work item turns into unit directions at a time (``_unit_chunk``).
UNIT_CHUNK = 64


@numba.njit(nogil=True, cache=True, inline="always")
def _scaled(dx, dy, dz):
    """(dx, dy, dz, norm) with unit direction d / norm: d itself (so the bits of
    d / sqrt(d.d)) unless d.d under- or overflows, then d over its largest
    component; norm 0: no direction."""
    norm = np.sqrt(dx * dx + dy * dy + dz * dz)
    if NORM_LOW < norm < np.inf:
        return dx, dy, dz, norm
    m = max(abs(dx), abs(dy), abs(dz))
    if not 0.0 < m < np.inf:
        return dx, dy, dz, norm
    dx, dy, dz = dx / m, dy / m, dz / m
    return dx, dy, dz, np.sqrt(dx * dx + dy * dy + dz * dz)


@numba.njit(nogil=True, cache=True)
def _first_bad_ray(origins, directions):
    """The first ray with a non-finite value (-1 - i for an origin, i for a
    direction) or with a zero-length direction (n + 1 + i); n when all are good."""
    n = origins.shape[0]
    for i in range(n):
        for a in range(3):
            if not np.isfinite(origins[i, a]):
                return -1 - i
            if not np.isfinite(directions[i, a]):
                return i
        if not _scaled(directions[i, 0], directions[i, 1], directions[i, 2])[3] > 0:
            return n + 1 + i
    return n


@numba.njit(nogil=True, cache=True, inline="always")
def _item_rays(item, n, block):
    """The rays of work item ``item``: PARTS items share each ``block`` rays."""
    first = item // PARTS * block
    m = min(n, first + block) - first
    k = item % PARTS
    return first + k * m // PARTS, first + (k + 1) * m // PARTS


@numba.njit(nogil=True, cache=True, inline="always")
def _unit_chunk(directions, first, m, tiny, dx, dy, dz, norm):
    """Unit directions of rays ``first .. first + m`` into dx, dy, dz (``_scaled``, then
    ``d / norm``, components under ``tiny`` set to 0); False when one is bad (its norm
    zero or not finite). Loads, square roots and divisions in loops of their own: the
    last two then run as vector code (1.15-1.3x this pass)."""
    good = True
    for k in range(m):
        dx[k], dy[k], dz[k] = directions[first + k, 0], directions[first + k, 1], directions[first + k, 2]
    for k in range(m):
        norm[k] = np.sqrt(dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k])
    for k in range(m):
        if not NORM_LOW < norm[k] < np.inf:  # rare: scale first (or a bad direction)
            dx[k], dy[k], dz[k], norm[k] = _scaled(dx[k], dy[k], dz[k])
            good &= 0.0 < norm[k] < np.inf
    for k in range(m):
        ux, uy, uz = dx[k] / norm[k], dy[k] / norm[k], dz[k] / norm[k]
        dx[k] = 0.0 if abs(ux) < tiny else ux
        dy[k] = 0.0 if abs(uy) < tiny else uy
        dz[k] = 0.0 if abs(uz) < tiny else uz
    return good


# error_model="numpy": a bad direction's division gives inf or nan (its ray is
# reported), and without the check the divisions run as vector code.
@numba.njit(parallel=True, nogil=True, cache=True, error_model="numpy")
def _rays_to_cells(origins, directions, voxel_size, tiny, block, cells, unit, bounds, repeats):
    """cells = o / voxel_size + 0.5; unit = d / sqrt(dx*dx + dy*dy + dz*dz), |u| < tiny -> 0
    (d scaled first where its squares would under- or overflow). True when no ray is
    bad (a non-finite value or a zero-length direction): read off the values the
    pass makes, the direction's norm (not finite or zero for such a direction) and
    each new origin's cell, not six tests a ray (1.17-1.2x this pass). A finite
    origin whose cell overflows says False too; ``_first_bad_ray`` then finds none.

    A ray from the same origin as the ray before it gets no cell written (a scan's
    rays often share one): ``repeats[item]`` says that some ray of the work item
    (``_item_rays``) was one, and ``_fill_repeats`` completes the cells when they
    are not all one point.

    ``bounds[b]`` gets the least and greatest cell of the origins and the sum of the
    unit directions of rays ``b * block ..`` (``scan_rays.ray_bounds``, summed in
    the same runs), so a scan's frame costs no pass of its own."""
    n = origins.shape[0]
    items = bounds.shape[0] * PARTS
    bad = np.zeros(items, np.bool_)
    part = np.empty((items, 9))
    for item in prange(items):
        lo = np.full(3, INF)
        hi = np.full(3, -INF)
        total = np.zeros(3)
        last = np.full(3, np.nan)  # the previous origin and its cell
        last_cell = np.empty(3)
        repeated = False
        chunk = np.empty((4, UNIT_CHUNK))  # a chunk's directions (unit when done) and norms
        dx, dy, dz, norm = chunk[0], chunk[1], chunk[2], chunk[3]
        first, end = _item_rays(item, n, block)
        for c0 in range(first, end, UNIT_CHUNK):
            m = min(end - c0, UNIT_CHUNK)
            if not _unit_chunk(directions, c0, m, tiny, dx, dy, dz, norm):
                bad[item] = True
            for k in range(m):
                i = c0 + k
                same = origins[i, 0] == last[0] and origins[i, 1] == last[1] and origins[i, 2] == last[2]
                repeated |= same
                if not same:  # (equal inputs, equal bits: the division is the pass's cost)
                    for a in range(3):
                        last[a] = origins[i, a]
                        last_cell[a] = origins[i, a] / voxel_size + 0.5
                        cells[i, a] = last_cell[a]
                        if not np.isfinite(last_cell[a]):  # (once per origin, not per ray)
                            bad[item] = True
                        lo[a], hi[a] = min(lo[a], last_cell[a]), max(hi[a], last_cell[a])
                unit[i, 0], unit[i, 1], unit[i, 2] = dx[k], dy[k], dz[k]
                total[0] += dx[k]
                total[1] += dy[k]
                total[2] += dz[k]
        part[item, :3], part[item, 3:6], part[item, 6:] = lo, hi, total
        repeats[item] = repeated  # (once: the items' flags share a cache line)
    for b in range(bounds.shape[0]):
        bounds[b] = part[b * PARTS]
        for k in range(1, PARTS):
            for a in range(3):
                bounds[b, a] = min(bounds[b, a], part[b * PARTS + k, a])
                bounds[b, 3 + a] = max(bounds[b, 3 + a], part[b * PARTS + k, 3 + a])
                bounds[b, 6 + a] += part[b * PARTS + k, 6 + a]
    return not bad.any()


@numba.njit(parallel=True, nogil=True, cache=True)
def _fill_repeats(origins, block, cells, repeats):
    """The cells ``_rays_to_cells`` left unwritten: a ray from the same origin as the
    ray before it has that ray's cell (each item's first ray has its own)."""
    n = origins.shape[0]
    for item in prange(repeats.shape[0]):
        if not repeats[item]:
            continue
        first, end = _item_rays(item, n, block)
        for i in range(first + 1, end):
            if origins[i, 0] == origins[i - 1, 0] and origins[i, 1] == origins[i - 1, 1]:
                if origins[i, 2] == origins[i - 1, 2]:
                    cells[i, 0], cells[i, 1], cells[i, 2] = cells[i - 1, 0], cells[i - 1, 1], cells[i - 1, 2]


def rays_to_cells(origins, directions, voxel_size, tiny, into=None):
    """(cells, unit, bounds) for (N, 3) float64 arrays; FieldError naming the first bad
    ray: ``origins[i]`` or ``directions[i]`` with a non-finite value,
    ``directions[i]`` of zero length. ``bounds`` is (blocks, 9): per SCAN_BLOCK rays,
    the origins' least and greatest cells and the directions' sum (the backends'
    ``block_bounds``).

    When every ray starts at one point, ``cells`` is that one cell broadcast to
    (N, 3) (read-only, no rows of its own: a pinhole scan's 262,144 origins are not
    written out); the backends read one row then, or make rows where they need them
    (``float_rows``). ``into``: two C-contiguous (N, 3) float64 arrays to write the
    cells and directions in (``Scratch``), else new ones.
    """
    n = len(origins)
    cells, unit = (np.empty((n, 3)), np.empty((n, 3))) if into is None else into
    bounds = np.empty((-(-n // SCAN_BLOCK), 9))
    repeats = np.zeros(len(bounds) * PARTS, np.bool_)
    # Strided views (columns of one (N, 6) array) are read in place: a copy costs as much as the pass.
    ok = _rays_to_cells(
        origins, directions, float(voxel_size), float(tiny), SCAN_BLOCK, cells, unit, bounds, repeats
    )
    first = n if ok else _first_bad_ray(origins, directions)
    if first == n:
        if not repeats.any():
            return cells, unit, bounds
        if one_origin(bounds, 0, n):
            return np.broadcast_to(cells[0].copy(), (n, 3)), unit, bounds
        _fill_repeats(origins, SCAN_BLOCK, cells, repeats)
        return cells, unit, bounds
    if first < 0:
        raise FieldError(f"origins[{-1 - first}]", origins[-1 - first].tolist(), "finite numbers")
    if first < n:
        raise FieldError(f"directions[{first}]", directions[first].tolist(), "finite numbers")
    zero = first - n - 1
    raise FieldError(f"directions[{zero}]", directions[zero].tolist(), "a non-zero vector")


class Scratch:
    """The two (N, 3) arrays ``rays_to_cells`` writes, kept from one trace() to the next.

    Freed, a scan's 12.6 MB of them went back to the system, and the next call's
    new arrays faulted their pages in again: 2.5 ms where writing the same bytes
    into kept arrays took 0.2 ms (two 262,144-ray arrays, two cores). One set,
    for calls of up to ``most`` rays; a call that finds it in use (another
    thread's trace) makes new arrays."""

    def __init__(self, most: int):
        self.most = most
        self._lock = threading.Lock()
        self._arrays: tuple[np.ndarray, np.ndarray] | None = None

    @contextmanager
    def arrays(self, n: int) -> Iterator[tuple[np.ndarray, np.ndarray] | None]:
        """The first ``n`` rows of both arrays while the block runs; None when ``n``
        is over ``most`` or another thread holds them."""
        if n > self.most or not self._lock.acquire(blocking=False):
            yield None
            return
        try:
            if self._arrays is None or len(self._arrays[0]) < n:
                self._arrays = (np.empty((n, 3)), np.empty((n, 3)))
            yield self._arrays[0][:n], self._arrays[1][:n]
        finally:
            self._lock.release()


# Ranges below this many go to metres by numpy: starting a parallel region costs
# about as much as their multiply (4 us against 1-4 us for 4,096-32,768 on two cores).
SCALE_IN_PARTS = 1 << 15


@numba.njit(parallel=True, nogil=True, cache=True)
def _scale_in_parts(values, factor):
    n = values.shape[0]
    for part in prange(PARTS):
        for i in range(part * n // PARTS, (part + 1) * n // PARTS):
            values[i] *= factor


def scale_in_place(values, factor: float) -> None:
    """``values *= factor`` (trace()'s ranges to metres), on numba's threads for a
    long contiguous 1-D float64 array: the same product, so the same bits. On an
    H200 machine's 16-core host a 262,144-ray scan's ranges took 0.135 ms on one
    thread and 0.035 ms in parts (a wgpu trace 1.016-1.018x, calls alternating);
    on two cores, 0.074 ms and 0.076 ms."""
    long_row = values.ndim == 1 and values.dtype == np.float64 and values.flags.c_contiguous
    if not long_row or len(values) < SCALE_IN_PARTS:
        values *= factor
    else:
        _scale_in_parts(values, float(factor))


def float_rows(origins):
    """``origins`` for the backends: ``rays_to_cells``' one cell broadcast to every ray
    as it is (``origin_rows`` gives a kernel the rows it reads), any other array as
    C-contiguous float64."""
    if origins.ndim == 2 and origins.dtype == np.float64 and origins.strides[0] == 0:
        return origins
    return np.ascontiguousarray(origins, dtype=np.float64)


def origin_rows(origins, shared=False):
    """The origin rows a kernel reads: the first alone when every ray starts there
    (``shared``), else a C-contiguous row per ray (made here from a broadcast one)."""
    return origins[:1] if shared else np.ascontiguousarray(origins)


def one_origin(block_bounds, first: int, end: int) -> bool:
    """True when rays ``first..end`` all start at one point, by ``block_bounds``
    (``rays_to_cells``' third answer: the least and greatest origin of
    each SCAN_BLOCK rays). Equal least and greatest means equal values, and a
    cell there is never -0.0, so equal bits."""
    if block_bounds is None or end <= first:
        return False
    rows = np.asarray(block_bounds)[first // SCAN_BLOCK : -(-end // SCAN_BLOCK)]
    return bool(len(rows)) and bool((rows[:, :6] == np.tile(rows[:1, :3], 2)).all())
