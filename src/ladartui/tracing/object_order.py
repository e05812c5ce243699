"""Exact tracing of one scan in object order: voxel by voxel instead of ray by ray.

A scan's rays leave one aircraft (origins within a focal plane's width of
each other) inside a narrow cone. Instead of walking every ray through the
grid, this visits the occupied voxels that the cone can reach, nearest
first, and tests each against the rays whose directions can pass through it.
The answers are those of the ray-order kernel bit for bit: each test is the
slab test with the kernels' boundary formula ``(b - o) * inv``, and the
per-axis parameters of one ray split its line into the same cells as the
DDA's (docs/architecture.md, "Object order").

Why a candidate list is never short. Rays are binned by their gnomonic
coordinates ``(d.u / d.a, d.v / d.a)`` about the cone's axis ``a``. A ray
from ``o_r = o_c + delta`` meets voxel V only if the parallel ray from the
centre ``o_c`` meets ``V - delta``, which lies inside V grown by the origins'
half-spread on each axis; that grown cube, seen from ``o_c``, projects inside
the rectangle of its eight projected corners (all in front of ``o_c``). So
every ray that can meet V is in the bins of that rectangle, widened by
``EPS`` against rounding. Nodes wholly behind ``o_c``'s plane (normal
``a``) cannot be met, nor can nodes across it farther from ``o_c`` than
``reach`` (``box_bins``); a brick across it within reach cannot be
projected and sends the scan back to ray order.

Why nearest first may stop early. Every point of a grown cube has depth
``(x - o_c).a >= near`` (its smallest corner depth), and a ray meeting V
there has ``t >= (x - o_r).a`` (unit directions, ``d.a <= 1``), so its entry
is at least ``near``. Voxels come brick by brick in order of the bricks'
``near``, so once every ray of a tile of bins has a bound (a hit, or its exit
from the occupied box) no further than the least ``near`` still to come,
nothing later can change that tile.

This module finds a scan's voxels in view, each with its rectangle of bins,
and has them listed per tile of bins (tracing/tile_lists.py); its frame and
its rays' bins come from tracing/scan_rays.py. numba's tests are in tracing/tile_tests.py,
the wgpu backend's in shaders/object_order.wgsl; which order is faster depends
on the scene (tracing/order_choice.py). All numba functions here release the
GIL; the passes over rays and voxels run under ``prange``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ladartui.tracing.config import EPS, INF, MIN_COS, NEAR_MARGIN, PARTS
from ladartui.tracing.llvm_ops import trailing_zeros
from ladartui.tracing.passes import timed
from ladartui.tracing.scan_rays import bin_scales
from ladartui.tracing.tile_lists import tile_lists


@njit(nogil=True, cache=True, inline="always")
def box_bins(x0, y0, z0, size, centre, grow, axis, u, v, grid, nb):
    """Bins covered by the cube [x0, x0 + size)^3 grown by ``grow``, seen from ``centre``.

    Returns (i0, i1, j0, j1, state, near): state 1 projected (i0 > i1 when it
    covers no bin), 0 out of every ray's way (wholly behind the centre's plane,
    or across it but too far from the centre), -1 across the plane near the centre.
    """
    pl, ph, ql, qh, near = INF, -INF, INF, -INF, INF
    behind = 0
    # Corner k is the low corner plus the edges picked by k's bits: its depth and
    # projections are the low corner's plus those of the edges (rounding far below EPS).
    lx, ly, lz = x0 - grow[0] - centre[0], y0 - grow[1] - centre[1], z0 - grow[2] - centre[2]
    ex, ey, ez = size + 2.0 * grow[0], size + 2.0 * grow[1], size + 2.0 * grow[2]
    w0 = lx * axis[0] + ly * axis[1] + lz * axis[2]
    p0 = lx * u[0] + ly * u[1] + lz * u[2]
    q0 = lx * v[0] + ly * v[1] + lz * v[2]
    for k in range(8):
        w, pn, qn = w0, p0, q0
        if k & 1:
            w, pn, qn = w + ex * axis[0], pn + ex * u[0], qn + ex * v[0]
        if k & 2:
            w, pn, qn = w + ey * axis[1], pn + ey * u[1], qn + ey * v[1]
        if k & 4:
            w, pn, qn = w + ez * axis[2], pn + ez * u[2], qn + ez * v[2]
        if not w > 0.0:
            behind += 1
            continue
        inv_w = 1.0 / w  # one division, not two: EPS covers the extra rounding
        pp, qq = pn * inv_w, qn * inv_w
        pl, ph, ql, qh, near = min(pl, pp), max(ph, pp), min(ql, qq), max(qh, qq), min(near, w)
    if behind == 8:
        return 0, -1, 0, -1, 0, 0.0
    if behind > 0:
        # A ray meets a box straddling the plane only within ``reach`` of the centre:
        # there its depth, at least t cos(60 deg) - |grow|, is below the box's diameter.
        spread = math.sqrt(grow[0] ** 2 + grow[1] ** 2 + grow[2] ** 2)
        reach = spread + (math.sqrt(3.0) * size + 3.0 * spread) / MIN_COS
        gap = 0.0
        for a, low in enumerate((x0, y0, z0)):
            c = centre[a]
            gap += max(0.0, low - grow[a] - c, c - (low + size + grow[a])) ** 2
        return 0, -1, 0, -1, (0 if gap > reach * reach else -1), 0.0
    return _rectangle_bins(pl, ph, ql, qh, near, grid, nb)


@njit(nogil=True, cache=True, inline="always")
def voxel_bins(x0, y0, z0, centre, grow, axis, u, v, grid, nb):
    """``box_bins`` of the unit voxel at (x0, y0, z0) from two divisions, not eight.

    A point ``x = c + delta`` of the grown cube (centre c, half-sizes ``h = 1/2 +
    grow``) has depth ``w(x) = w_c + delta.a >= w_low = w_c - sum(h |a|)`` and, with
    ``p_c`` the centre's projection, ``p(x) - p_c = delta.(u - p_c a) / w(x)``, whose
    size is at most ``sum(h |u - p_c a|) / w_low`` (the numerator's exact bound). So
    the rectangle ``p_c`` plus or minus that bound, and the same in q, holds every
    projected point: within a thousandth of the corners' rectangle at the peer
    script's ranges, and ``w_low`` is its corners' least depth. A cube reaching the
    centre's plane (``w_low <= 0``) goes to ``box_bins``. 1.30-1.35x emit_voxels,
    with the bit walk there (peer rays)."""
    hx, hy, hz = 0.5 + grow[0], 0.5 + grow[1], 0.5 + grow[2]
    cx, cy, cz = x0 + 0.5 - centre[0], y0 + 0.5 - centre[1], z0 + 0.5 - centre[2]
    w_centre = cx * axis[0] + cy * axis[1] + cz * axis[2]
    w_low = w_centre - (hx * abs(axis[0]) + hy * abs(axis[1]) + hz * abs(axis[2]))
    if not w_low > 0.0:
        return box_bins(x0, y0, z0, 1, centre, grow, axis, u, v, grid, nb)
    # Reciprocals, two divisions for four (EPS covers the extra rounding).
    inv_centre, inv_low = 1.0 / w_centre, 1.0 / w_low
    pc = (cx * u[0] + cy * u[1] + cz * u[2]) * inv_centre
    qc = (cx * v[0] + cy * v[1] + cz * v[2]) * inv_centre
    hp = (
        hx * abs(u[0] - pc * axis[0]) + hy * abs(u[1] - pc * axis[1]) + hz * abs(u[2] - pc * axis[2])
    ) * inv_low
    hq = (
        hx * abs(v[0] - qc * axis[0]) + hy * abs(v[1] - qc * axis[1]) + hz * abs(v[2] - qc * axis[2])
    ) * inv_low
    return _rectangle_bins(pc - hp, pc + hp, qc - hq, qc + hq, w_low, grid, nb)


@njit(nogil=True, cache=True, inline="always")
def _rectangle_bins(pl, ph, ql, qh, depth, grid, nb):
    """``box_bins``' answer for a box projected in front of the centre onto [pl, ph] x
    [ql, qh] with least depth ``depth``: its bins (the rectangle widened by EPS), state
    1, and its ``near``, the depth lowered by NEAR_MARGIN (a bound, so rounding may
    only lower it)."""
    near = depth - NEAR_MARGIN * (1.0 + depth)
    # Bin numbers clamped as floats first: with a tiny bin step they overflow int64.
    _, p_scale, _, q_scale = bin_scales(grid)  # by the rays' rule
    i0 = _first_bin(pl - EPS, grid[0], p_scale, grid[4], nb)
    i1 = _last_bin(ph + EPS, grid[0], p_scale, grid[4], nb)
    j0 = _first_bin(ql - EPS, grid[2], q_scale, grid[5], nb)
    j1 = _last_bin(qh + EPS, grid[2], q_scale, grid[5], nb)
    if i1 < 0 or j1 < 0 or i0 >= nb or j0 >= nb:
        return 0, -1, 0, -1, 1, near
    return max(i0, 0), min(i1, nb - 1), max(j0, 0), min(j1, nb - 1), 1, near


@njit(nogil=True, cache=True, inline="always")
def _first_bin(x, x0, scale, slack, nb):
    """The first bin whose ray can lie at or above x (its middle within ``slack`` of
    the ray; ``scale`` bins a unit of x), limited to -1 .. nb."""
    return np.int64(math.ceil(min(max((x - x0) * scale - 0.5 - slack, -1.0), float(nb))))


@njit(nogil=True, cache=True, inline="always")
def _last_bin(x, x0, scale, slack, nb):
    """The last bin whose ray can lie at or below x, limited to -1 .. nb."""
    return np.int64(math.floor(min(max((x - x0) * scale - 0.5 + slack, -1.0), float(nb))))


@njit(nogil=True, cache=True, inline="always")
def _out_of_view(x0, y0, z0, size, centre, grow, axis, u, v, grid, nb):
    """Whether no ray can meet the node: it covers no bin, or lies out of every ray's way
    (a node across the plane near the centre is opened, its bricks decide)."""
    i0, i1, _, _, state, _ = box_bins(x0, y0, z0, size, centre, grow, axis, u, v, grid, nb)
    return state == 0 or (state == 1 and i0 > i1)


@njit(nogil=True, cache=True)
def spread_stride(count):
    """A step through ``count`` items that is prime to their number and near the golden
    section of it: ``(k * stride) % count`` then visits every item once, and any run of
    k (one thread's share of a prange) takes items from all over, so threads get equal
    work when the costly items lie together (the far side of a scan at 45 degrees,
    the regions in view)."""
    stride = max(1, round(count * 0.6180339887))
    while math.gcd(stride, count) != 1:
        stride += 1
    return stride


@njit(parallel=True, nogil=True, cache=True)
def bricks_in_view(centre, grow, axis, u, v, grid, nb, root, regions, tiles, rorg, rdims):
    """Non-empty bricks whose grown cube covers a bin, nearest first.

    Returns ((m, 4) corner x, y, z and brick number, (m,) near, ok); ok is
    False when a brick crosses the centre's plane near the centre (trace in ray order).

    The regions (64-cubes) of the root cells in view are walked in parallel: a
    first pass marks each region's bricks in view, a second writes them in the
    serial walk's order (root cell, region, brick), so the sort by ``near`` sees
    the same list whatever the number of threads.
    """
    cells = rdims[0] * rdims[1] * rdims[2]
    live = np.empty(cells, np.int64)  # root cells in view, in walk order
    lives = 0
    for r in range(cells):
        if root[r] == 0:
            continue
        x0, y0, z0 = _root_corner(r, rorg, rdims)
        if not _out_of_view(x0, y0, z0, 512, centre, grow, axis, u, v, grid, nb):
            live[lives] = r
            lives += 1
    items = lives * 512  # (root cell in view, region)
    marks = np.zeros((items, 8), np.int64)  # bit s2 & 63 of word s2 >> 6: brick s2 in view
    counts = np.zeros(items + 1, np.int64)
    crossing = np.zeros(items, np.bool_)
    stride = spread_stride(items)  # the regions in view lie together
    for step in prange(items):
        item = (step * stride) % items
        x0, y0, z0, tl = _region(item, live, root, regions, rorg, rdims)
        if tl == 0 or _out_of_view(x0, y0, z0, 64, centre, grow, axis, u, v, grid, nb):
            continue
        c = 0
        for s2 in range(512):
            if tiles[(np.int64(tl) - 1) * 512 + s2] == 0:
                continue
            bx, by, bz = _child_corner(x0, y0, z0, s2, 3)
            i0, i1, _, _, state, _ = box_bins(bx, by, bz, 8, centre, grow, axis, u, v, grid, nb)
            if state == -1:
                crossing[item] = True
                break
            if state == 0 or i0 > i1:
                continue
            marks[item, s2 >> 6] |= np.int64(1) << (s2 & 63)
            c += 1
        counts[item + 1] = c
    if np.any(crossing):
        return np.empty((0, 4), np.int64), np.empty(0), False
    for item in range(items):
        counts[item + 1] += counts[item]
    found = np.empty((counts[items], 4), np.int64)
    nears = np.empty(counts[items])
    for step in prange(items):
        item = (step * stride) % items
        k = counts[item]
        if counts[item + 1] == k:
            continue
        x0, y0, z0, tl = _region(item, live, root, regions, rorg, rdims)
        for s2 in range(512):
            if (marks[item, s2 >> 6] >> (s2 & 63)) & 1 == 0:
                continue
            bx, by, bz = _child_corner(x0, y0, z0, s2, 3)
            # near again: the few bricks in view cost less than keeping one per slot
            near = box_bins(bx, by, bz, 8, centre, grow, axis, u, v, grid, nb)[5]
            found[k, 0], found[k, 1], found[k, 2] = bx, by, bz
            found[k, 3] = tiles[(np.int64(tl) - 1) * 512 + s2]
            nears[k] = near
            k += 1
    by_near = np.argsort(nears)
    return found[by_near], nears[by_near], True


@njit(nogil=True, cache=True, inline="always")
def _region(item, live, root, regions, rorg, rdims):
    """Corner and tile number (0: empty) of region ``item % 512`` of root cell
    ``live[item // 512]``."""
    r, s1 = live[item >> 9], item & 511
    rx0, ry0, rz0 = _root_corner(r, rorg, rdims)
    x0, y0, z0 = _child_corner(rx0, ry0, rz0, s1, 6)
    return x0, y0, z0, regions[(np.int64(root[r]) - 1) * 512 + s1]


@njit(nogil=True, cache=True, inline="always")
def _root_corner(r, rorg, rdims):
    """Low corner of root cell ``r`` (x fastest, then y, then z; 512 cells a side)."""
    rx, ry, rz = r % rdims[0], (r // rdims[0]) % rdims[1], r // (rdims[0] * rdims[1])
    return rorg[0] + (rx << 9), rorg[1] + (ry << 9), rorg[2] + (rz << 9)


@njit(nogil=True, cache=True, inline="always")
def _child_corner(x0, y0, z0, slot, shift):
    """Low corner of child ``slot`` (x in bits 0-2, y 3-5, z 6-8) of the node at
    (x0, y0, z0) whose children are ``1 << shift`` cells a side."""
    return x0 + ((slot & 7) << shift), y0 + (((slot >> 3) & 7) << shift), z0 + ((slot >> 6) << shift)


@njit(nogil=True, cache=True, inline="always")
def _popcount(x):
    x = x - ((x >> np.uint32(1)) & np.uint32(0x55555555))
    x = (x & np.uint32(0x33333333)) + ((x >> np.uint32(2)) & np.uint32(0x33333333))
    x = (x + (x >> np.uint32(4))) & np.uint32(0x0F0F0F0F)
    return np.int64(((x * np.uint32(0x01010101)) >> np.uint32(24)) & np.uint32(0xFF))


@njit(parallel=True, nogil=True, cache=True)
def voxel_starts(bricks_found, bricks):
    """Where each found brick's voxels begin in the voxel list (brick e holds
    ``first[e] .. first[e + 1]``); ``first[-1]`` is the number of voxels in view."""
    count = bricks_found.shape[0]
    first = np.zeros(count + 1, np.int64)
    for e in prange(count):
        base = (bricks_found[e, 3] - 1) * 16
        c = 0
        for w in range(16):
            c += _popcount(bricks[base + w])
        first[e + 1] = c
    for e in range(count):
        first[e + 1] += first[e]
    return first


@njit(parallel=True, nogil=True, cache=True)
def emit_voxels(bricks_found, brick_near, first, bricks, centre, grow, axis, u, v, grid, nb):
    """Every voxel of the found bricks, in their order (``first`` from ``voxel_starts``):
    (m, 7) i, j, k, i0, i1, j0, j1 (i0 > i1: covers no bin) and (m, 2) its near and its
    brick's near.

    Within a brick, front first: layers, rows and cells in the order the axis
    crosses them. A ray's cells only move with its direction's signs, so for rays
    with the axis's signs a voxel listed later is never met before one listed
    earlier; their first hit then comes first and their later candidates fail the
    cheap ``near`` check instead of taking slab tests.
    """
    count = bricks_found.shape[0]
    vox = np.empty((first[count], 7), np.int64)
    nears = np.empty((first[count], 2))
    # Runs of bricks holding about equal numbers of voxels: the near bricks of a scan
    # hold more, and halves by bricks left one thread 70 % more voxels than the other.
    runs = max(1, min(count, PARTS))
    cuts = np.searchsorted(first, np.arange(runs + 1) * (first[count] / runs))
    cuts[0], cuts[runs] = 0, count
    for run in prange(runs):
        for e in range(cuts[run], cuts[run + 1]):
            _emit_brick(
                e, bricks_found, brick_near, first, bricks, centre, grow, axis, u, v, grid, nb, vox, nears
            )
    return vox, nears


# Each byte value with its bits in reverse order: a brick's rows and cells walked
# from the high bit down, where the axis runs against x or y.
REVERSED_BYTE = np.array([int(f"{b:08b}"[::-1], 2) for b in range(256)], np.int64)


@njit(nogil=True, cache=True, inline="always")
def _nonzero_bytes(word):
    """Bit k set when byte k of the 64-bit word is non-zero."""
    folded = word | (word >> 4)
    folded |= folded >> 2
    folded |= folded >> 1
    folded &= 0x0101010101010101  # bit 0 of each byte: its byte's bits OR'ed
    return np.int64((np.uint64(folded) * np.uint64(0x0102040810204080)) >> np.uint64(56))


@njit(nogil=True, cache=True, inline="always")
def _emit_brick(e, bricks_found, brick_near, first, bricks, centre, grow, axis, u, v, grid, nb, vox, nears):
    """Brick e's voxels into vox/nears from ``first[e]`` on (``emit_voxels``): its
    layers, then the set bits of each layer's non-empty rows, then of each row
    (cttz; a test of each of 512 bits was a mispredicted branch per cell), each
    in the order the axis crosses them."""
    flip_x, flip_y, flip_z = 7 if axis[0] < 0.0 else 0, 7 if axis[1] < 0.0 else 0, 7 if axis[2] < 0.0 else 0
    bx, by, bz = bricks_found[e, 0], bricks_found[e, 1], bricks_found[e, 2]
    base = (bricks_found[e, 3] - 1) * 16
    k = first[e]
    for zi in range(8):
        dz = zi ^ flip_z
        layer = np.int64(bricks[base + 2 * dz]) | (np.int64(bricks[base + 2 * dz + 1]) << 32)
        if layer == 0:
            continue
        rows = _nonzero_bytes(layer)
        rows = REVERSED_BYTE[rows] if flip_y else rows
        while rows != 0:
            dy = trailing_zeros(rows) ^ flip_y
            rows &= rows - 1
            row = (layer >> (8 * dy)) & 0xFF
            row = REVERSED_BYTE[row] if flip_x else row
            while row != 0:
                dx = trailing_zeros(row) ^ flip_x
                row &= row - 1
                x, y, z = bx + dx, by + dy, bz + dz
                i0, i1, j0, j1, _, near = voxel_bins(x, y, z, centre, grow, axis, u, v, grid, nb)
                vox[k, 0], vox[k, 1], vox[k, 2] = x, y, z
                vox[k, 3], vox[k, 4], vox[k, 5], vox[k, 6] = i0, i1, j0, j1
                nears[k, 0], nears[k, 1] = near, brick_near[e]
                k += 1


def scan_voxels(occ, frame, grid, nb, max_voxels, tile_shift):
    """(vox, nears, tile_starts, listed): the voxels in view of a scan whose rays are
    binned by ``grid`` (``voxels_in_view``), listed per tile of ``1 << tile_shift`` bins
    a side (``voxels_per_tile``); None when ``voxels_in_view`` finds none to give."""
    found = voxels_in_view(occ, frame, grid, nb, max_voxels)
    if found is None:
        return None
    vox, nears = found
    with timed("tile lists"):
        tile_starts, listed = tile_lists(vox, nb, tile_shift, np.arange(len(vox), dtype=np.int64))
    return vox, nears, tile_starts, listed


@timed("voxels in view")
def voxels_in_view(occ, frame, grid, nb, max_voxels):
    """(vox, nears) of ``emit_voxels`` for the voxels in view of a scan whose rays are
    binned by ``grid``; None when a brick straddles the aircraft's plane near it, or
    when more than ``max_voxels`` are in view."""
    centre, grow, axis, u, v = frame
    found, brick_near, ok = bricks_in_view(
        centre,
        grow,
        axis,
        u,
        v,
        grid,
        nb,
        occ.root,
        occ.regions,
        occ.tiles,
        occ.root_origin.astype(np.int64),
        occ.root_dims.astype(np.int64),
    )
    if not ok:
        return None
    first = voxel_starts(found, occ.bricks)
    if first[-1] > max_voxels:
        return None
    return emit_voxels(found, brick_near, first, occ.bricks, centre, grow, axis, u, v, grid, nb)
