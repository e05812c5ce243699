"""The numba backend's object-order tests: each tile of bins against its voxels.

``trace_scan`` runs a whole scan: the rays are binned (``scan_rays.bin_order``,
an order and no copies), the voxels in view listed per tile
(``object_order.scan_voxels``), and ``test_tiles`` then takes each tile on its
own: it copies the tile's rays next to each other, tests them against the
tile's voxels nearest first (eight rays at a time, tracing/slab_lanes.py), and
writes their answers in ray order. One pass over the rays does the copying,
the testing and the answers, so a scan's rays are read from memory about once
(docs/architecture.md, "Object order").
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ladartui.tracing.answers import put_answer
from ladartui.tracing.config import INF, MAX_TILE_SHIFT
from ladartui.tracing.llvm_ops import prefetch_row, prefetch_row_for_write, trailing_zeros
from ladartui.tracing.object_order import scan_voxels, spread_stride
from ladartui.tracing.passes import timed
from ladartui.tracing.scan_rays import bin_order, scan_grid
from ladartui.tracing.slab_lanes import LANES, slab_lanes, slab_lanes_from

# Prefetch distances, in tile rays and in list entries. Prefetching the rays' loads and
# answers made the tile tests 1.11-1.19x faster, and the entries' voxels 2 % more
# (peer rays, 2 threads, 32 against 64 rays ahead within noise).
AHEAD = 32
ENTRIES_AHEAD = 8


@njit(nogil=True, cache=True, inline="always")
def _load_ray(r, shared_origin, orig, dirs, ray, s):
    """Ray r into tile column s: its direction, and its origin unless all rays
    share ``orig[0]`` (``1 / d`` follows in a pass of its own)."""
    for a in range(3):
        ray[3 + a, s] = dirs[r, a]
        if not shared_origin:
            ray[a, s] = orig[r, a]


@njit(nogil=True, cache=True, inline="always")
def _tile_ray(starts, single, b):
    """The first tile ray of the tile's bin b: ``starts[b]``, or b itself when every bin
    holds one ray (not loaded: the load sat in each row's chain of dependent steps,
    and skipping it made the tile tests 0.90-0.96x on the peer rays)."""
    return b if single else starts[b]


def tile_shift_for(nb):
    """Tiles of ``1 << shift`` bins a side for an nb x nb grid of bins: the largest up
    to MAX_TILE_SHIFT that divides nb (a whole scan's rays then go to their bins by
    the parallel scatter) and leaves at least 4 x 4 tiles for the threads; else
    about a quarter of nb (the counting sort places the rays)."""
    for shift in range(MAX_TILE_SHIFT, 1, -1):
        if nb % (1 << shift) == 0 and nb >> shift >= 4:
            return shift
    return max(2, min(MAX_TILE_SHIFT, (nb // 4).bit_length() - 1))


# error_model="numpy": a division by zero gives inf, as the guarded divisions here never
# meet; without the check, the pass of inverses runs as vector code.
@njit(parallel=True, nogil=True, cache=True, error_model="numpy")
def test_tiles(
    vox,
    nears,
    tile_starts,
    listed,
    nt,
    shift,
    stride,
    bin_starts,
    order,
    nb,
    orig,
    shared_origin,
    dirs,
    nx,
    ny,
    kind,
    index,
    tout,
):
    """Nearest hit of each ray among the voxels of its tile (tiles of ``1 << shift`` bins a side), and
    its answer (``ray_answer``) into kind/index/tout at the ray's own place.

    ``shared_origin``: every ray starts at ``orig[0]``, which is then read for all (half
    the bytes a tile's rays load: at 45 degrees a tenth of the tests' time), and the
    lanes take it as one point (``slab_lanes_from``: 1.05-1.09x the tile tests).
    Sorted position s is ray ``order[s]``; bin key b holds positions
    ``bin_starts[b] .. bin_starts[b + 1]``, or position b alone when ``bin_starts``
    is empty (one ray per bin, whole tiles). A tile's rays start with no voxel
    and an infinite bound (a bound at the ray's exit from the occupied box, as
    the wgpu backend starts, cost 4 % here and stopped no tile: a tile of 64 x 64
    rays nearly always holds one that reaches the ground). A tile stops when no later voxel
    can come nearer than every ray's bound (a voxel's ``near`` is below every
    entry into it). Per row of the tile a mask of live bins: a bin is cleared when
    met with every one of its rays bound at or before the least ``near`` of the
    voxels after this one, which then cannot change it; its rays take no more tests
    (most candidates of a scan are such rays, behind their hit). A voxel tests a
    row's rays from its first live bin on, eight at a time (``slab_lanes``, vector
    code: 1.16x faster tile tests on the peer rays than a test per live bin), each
    run of eight starting at the next live bin.
    shaders/object_order.wgsl runs the same tests ray by ray.
    """
    tiles = nt * nt
    tile_side = 1 << shift
    ox, oy, oz = (orig[0, 0], orig[0, 1], orig[0, 2]) if shared_origin else (0.0, 0.0, 0.0)
    single = bin_starts.shape[0] == 0
    # One ray per bin: every (whole) tile's bin starts and ray columns are the same.
    whole_starts = np.arange(tile_side * tile_side + 1) if single else np.empty(0, np.int64)
    whole_cols = (np.arange(tile_side * tile_side + LANES) & (tile_side - 1)) if single else whole_starts
    for step in prange(tiles):
        tile = (step * stride) % tiles
        bi0 = (tile % nt) * tile_side
        bi1 = min(nb, bi0 + tile_side) - 1
        bj0 = (tile // nt) * tile_side
        bj1 = min(nb, bj0 + tile_side) - 1
        base = tile * tile_side * tile_side  # bin_key of the tile's first bin; rows of tile_side follow
        s0 = base if single else bin_starts[base]
        m = tile_side * tile_side if single else bin_starts[base + tile_side * tile_side] - s0
        if m == 0:
            continue
        # bin b of the tile: tile rays starts[b] .. starts[b + 1]; cols[s]: tile ray s's column
        live = np.zeros(tile_side, np.int64)  # per row: bit c set while bin (bi0 + c) may still change
        if single:  # every bin of the (whole) tile holds one ray
            starts, cols = whole_starts, whole_cols
            width = bi1 - bi0 + 1
            full = np.int64(-1) if width >= 64 else (np.int64(1) << width) - 1
            for r in range(bj1 - bj0 + 1):
                live[r] = full
        else:
            starts = np.empty(tile_side * tile_side + 1, np.int64)
            cols = np.zeros(m + LANES, np.int64)
            for b in range(tile_side * tile_side + 1):
                starts[b] = bin_starts[base + b] - s0
            for r in range(bj1 - bj0 + 1):
                for c in range(bi1 - bi0 + 1):
                    b = r * tile_side + c
                    if starts[b + 1] > starts[b]:
                        live[r] |= np.int64(1) << c
                    for s in range(starts[b], starts[b + 1]):
                        cols[s] = c
        # By rows: origin (unless shared), direction, 1 / d; padded by LANES (8 rays a call).
        ray = np.empty((9, m + LANES))
        ray[:, m:] = 0.0
        best_t = np.full(m + LANES, INF)
        best_v = np.full(m + LANES, -1, np.int64)
        for s in range(m):
            if s + AHEAD < m:  # the permutation hides the next rays from the hardware's prefetchers
                prefetch_row(dirs, order[s0 + s + AHEAD])
                if not shared_origin:
                    prefetch_row(orig, order[s0 + s + AHEAD])
            r = order[s0 + s]
            _load_ray(r, shared_origin, orig, dirs, ray, s)
        for a in range(3):  # (a pass of its own: vector divisions)
            for s in range(m):
                d = ray[3 + a, s]
                ray[6 + a, s] = 1.0 / d if d != 0.0 else INF
        far = INF  # no bound of the tile is beyond (infinite while some ray has no hit)
        unhit = m
        # rest[k]: the least near of the tile's entries from k on. No later voxel can
        # bring a ray nearer than that, so a ray whose bound is there is done.
        e0, e1 = tile_starts[tile], tile_starts[tile + 1]
        rest = np.empty(e1 - e0 + 1)
        rest[e1 - e0] = INF
        for e in range(e1 - 1, e0 - 1, -1):
            rest[e - e0] = min(nears[listed[e], 0], rest[e - e0 + 1])
        stale = False  # far may be lowered (bounds moved nearer since it was taken)
        for e in range(e0, e1):
            if unhit == 0 and far == INF:  # every ray has a hit: the bounds are finite
                far = 0.0
                for s in range(m):
                    far = max(far, best_t[s])
                stale = False
            if rest[e - e0] >= far:
                if stale:
                    far = 0.0
                    for s in range(m):
                        far = max(far, best_t[s])
                    stale = False
                if rest[e - e0] >= far:
                    break
            if e + ENTRIES_AHEAD < e1:
                prefetch_row(vox, listed[e + ENTRIES_AHEAD])
                prefetch_row(nears, listed[e + ENTRIES_AHEAD])
            q = listed[e]
            near = nears[q, 0]
            if near >= far:
                continue
            after = rest[e - e0 + 1]
            x, y, z = np.float64(vox[q, 0]), np.float64(vox[q, 1]), np.float64(vox[q, 2])
            c0, c1 = max(vox[q, 3], bi0) - bi0, min(vox[q, 4], bi1) - bi0
            span = ((np.int64(2) << c1) - 1) ^ ((np.int64(1) << c0) - 1)
            for r in range(max(vox[q, 5], bj0) - bj0, min(vox[q, 6], bj1) - bj0 + 1):
                todo = live[r] & span
                if todo == 0:
                    continue
                row = r * tile_side
                s, s_end = (
                    _tile_ray(starts, single, row + trailing_zeros(todo)),
                    _tile_ray(starts, single, row + c1 + 1),
                )
                alive = np.int64(0)
                while True:  # the row's rays from its first live bin on, 8 at a time
                    if shared_origin:
                        bins, hit, first_hits = slab_lanes_from(
                            ray, s, ox, oy, oz, x, y, z, near, after, q, todo, cols, s_end, best_t, best_v
                        )
                    else:
                        bins, hit, first_hits = slab_lanes(
                            ray, s, x, y, z, near, after, q, todo, cols, s_end, best_t, best_v
                        )
                    alive |= bins
                    unhit -= first_hits
                    stale = stale or hit != 0
                    s += LANES
                    if s >= s_end:
                        break
                    todo &= -(np.int64(1) << cols[s])  # bins before ray s are done
                    if todo == 0:
                        break
                    s = max(s, _tile_ray(starts, single, row + trailing_zeros(todo)))
                live[r] &= ~span | alive
        for s in range(m):
            if s + AHEAD < m:
                prefetch_row_for_write(index, order[s0 + s + AHEAD])
                prefetch_row_for_write(tout, order[s0 + s + AHEAD])
            put_answer(
                order[s0 + s],
                best_v[s],
                best_t[s],
                vox,
                ox if shared_origin else ray[0, s],
                oy if shared_origin else ray[1, s],
                oz if shared_origin else ray[2, s],
                ray[3, s],
                ray[4, s],
                ray[5, s],
                nx,
                ny,
                kind,
                index,
                tout,
            )


def trace_scan(occ, orig, dirs, frame, max_voxels, nx, ny, kind, index, t, shared_origin=False):
    """One scan's exact answers in object order into kind/index/t; False (nothing
    written) when it is no scan for it: its rays cannot be binned (``scan_grid``), or
    ``scan_voxels`` finds a brick it cannot project or more than ``max_voxels`` in view.
    ``shared_origin``: every ray starts at ``orig[0]`` (``prepare.one_origin``)."""
    binned = scan_grid(dirs, frame)
    if binned is None:
        return False
    nb, p, q, grid = binned
    shift = tile_shift_for(nb)
    order, bin_starts, grid = bin_order(p, q, grid, nb, shift)
    voxels = scan_voxels(occ, frame, grid, nb, max_voxels, shift)
    if voxels is None:
        return False
    vox, nears, tile_starts, listed = voxels
    nt = -(-nb >> shift)
    with timed("tile tests"):
        test_tiles(
            vox,
            nears,
            tile_starts,
            listed,
            nt,
            shift,
            spread_stride(nt * nt),
            bin_starts,
            order,
            nb,
            orig,
            shared_origin,
            dirs,
            nx,
            ny,
            kind,
            index,
            t,
        )
    return True
