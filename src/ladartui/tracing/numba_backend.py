"""The numba backend: exact hierarchical traversal, and the report's fixed-step
march (its kernel in tracing/march.py).

Both kernels follow docs/architecture.md ("Exact traversal", "March") step by
step, so the WGSL shader can mirror them. Rays run in chunks under ``prange``
in the order given (detector order is coherent: neighbouring rays touch the
same nodes, so the working set stays in cache).
"""

from __future__ import annotations

import math
import threading
import time
import weakref
from typing import Any

import numba
import numpy as np
from numba import njit, prange

from ladartui.errors import check_cancelled
from ladartui.scene.occupancy import block_masks
from ladartui.tracing.answers import ray_answer
from ladartui.tracing.axis import boundary_t, cell_at, clamp, node_slot, slab
from ladartui.tracing.backend import CellHits, TraceOrder, check_order, check_step, register_backend
from ladartui.tracing.bundle import bundle_start, halo_arrays
from ladartui.tracing.config import BLOCK, BUNDLE, INF, SCAN_BLOCK
from ladartui.tracing.march import march_kernel
from ladartui.tracing.order_choice import RAY_SAMPLE, OrderChoice, trace_in_blocks
from ladartui.tracing.passes import timed
from ladartui.tracing.prepare import float_rows, one_origin, origin_rows
from ladartui.tracing.scan_rays import cone_frame
from ladartui.tracing.tile_tests import trace_scan


@njit(nogil=True, cache=True, inline="always")
def _exit_boundary(c, s, positive):
    if positive:
        return ((c >> s) + 1) << s
    return (c >> s) << s


@njit(nogil=True, cache=True, inline="always")
def _node_skip(c, s, positive, moving, o, inv):
    """Exit boundary and its parameter of the node ``c >> s`` on one axis."""
    b = _exit_boundary(c, s, positive)
    return b, (boundary_t(np.float64(b), o, inv) if moving else INF)


@njit(nogil=True, cache=True, inline="always")
def _enter(c, b, stepped, positive, s, o, d, inv, t):
    """Cell on one axis after crossing into a new node at ``t``: the boundary cell
    for an axis that stepped, else ``cell_at(t)`` kept inside the node of ``c``."""
    if stepped:
        return b if positive else b - 1
    lo = (c >> s) << s
    return clamp(cell_at(o, d, inv, t), lo, lo + (1 << s) - 1)


@njit(nogil=True, cache=True, inline="always")
def _brick_entry(b, stepped, positive, o, d, inv, t):
    """Cell on one axis on entering brick ``b`` at ``t`` after a brick step."""
    return _enter(b << 3, (b << 3) if positive else ((b + 1) << 3), stepped, positive, 3, o, d, inv, t)


@njit(parallel=True, nogil=True, cache=True)
def _exact_kernel(
    orig,
    dirs,
    root,
    regions,
    tiles,
    bricks,
    blocks,
    columns,
    cubes,
    corg,
    cdims,
    halo,
    horg,
    hdims,
    halo4,
    h4org,
    h4dims,
    lo,
    hi,
    rorg,
    rdims,
    nx,
    ny,
    kind,
    index,
    tout,
):
    """The exact traversal of docs/architecture.md for every ray, chunks under prange.

    The per-ray code is written out here rather than called: passing the
    arrays to a per-ray function costs reference counting on every ray.
    Each chunk of rays first gets its bundle start (tracing.bundle), so rays
    from one aircraft begin near the first brick any of them can meet.
    Empty root cells and regions are skipped as nodes; a DDA over 8-voxel
    bricks skips empty bricks (and, for descending rays, whole empty brick
    columns; not where ``columns`` is empty, the occupancy having none), jumps
    across the empty cube of bricks ahead of the ray (``Occupancy.cubes``) and
    walks on past tile faces while bricks are known empty; inside a brick a
    voxel DDA skips empty 4- and 2-voxel blocks (one mask word per brick),
    tests bits and goes on into neighbouring non-empty bricks of the tile.
    Every cell boundary parameter comes from the one formula ``(b - o) * inv``,
    so the cells visited are those of a plain voxel DDA.
    """
    n = orig.shape[0]
    chunks = (n + BUNDLE - 1) // BUNDLE
    has_columns = columns.shape[0] > 0
    for ch in prange(chunks):
        # Step 0: where the chunk's rays may all start (tracing.bundle; 0 when they diverge).
        start = bundle_start(
            orig, dirs, ch * BUNDLE, min(n, (ch + 1) * BUNDLE), halo, horg, hdims, halo4, h4org, h4dims
        )
        for r in range(ch * BUNDLE, min(n, (ch + 1) * BUNDLE)):
            ox, oy, oz = orig[r, 0], orig[r, 1], orig[r, 2]
            dx, dy, dz = dirs[r, 0], dirs[r, 1], dirs[r, 2]
            found = False
            done = False
            cx, cy, cz, t = np.int64(-1), np.int64(-1), np.int64(-1), INF
            for _once in range(1):  # a block to break out of: no hit, or a hit
                if root.shape[0] == 0:
                    done = True
                    break
                # Step 1: a ray inside a plane of cell faces enters no interior.
                if (
                    (dx == 0.0 and ox == math.floor(ox))
                    or (dy == 0.0 and oy == math.floor(oy))
                    or (dz == 0.0 and oz == math.floor(oz))
                ):
                    done = True
                    break
                ix = 1.0 / dx if dx != 0.0 else INF
                iy = 1.0 / dy if dy != 0.0 else INF
                iz = 1.0 / dz if dz != 0.0 else INF
                mx, my, mz = dx != 0.0, dy != 0.0, dz != 0.0
                # Step 2: clip to the occupied box, from the bundle start on.
                ex, xx = slab(ox, dx, ix, lo[0], hi[0])
                ey, xy = slab(oy, dy, iy, lo[1], hi[1])
                ez, xz = slab(oz, dz, iz, lo[2], hi[2])
                t0 = max(start, max(ex, max(ey, ez)))
                t1 = min(xx, min(xy, xz))
                if not t0 < t1:
                    done = True
                    break
                # Step 3: the start cell.
                cx = clamp(cell_at(ox, dx, ix, t0), lo[0], hi[0] - 1)
                cy = clamp(cell_at(oy, dy, iy, t0), lo[1], hi[1] - 1)
                cz = clamp(cell_at(oz, dz, iz, t0), lo[2], hi[2] - 1)
                px, py, pz = dx > 0.0, dy > 0.0, dz > 0.0
                sx = 1 if px else -1
                sy = 1 if py else -1
                sz = 1 if pz else -1
                # Offset from a cell to its exit boundary, for the voxel DDA. A still axis
                # (inv = +inf, origin off the boundaries) gets +1 so its parameter is +inf.
                fx = 0.0 if dx < 0.0 else 1.0
                fy = 0.0 if dy < 0.0 else 1.0
                fz = 0.0 if dz < 0.0 else 1.0
                ax, ay, az = np.int64(fx), np.int64(fy), np.int64(fz)
                t = t0
                rx0, ry0, rz0 = rorg[0], rorg[1], rorg[2]
                rdx, rdy = rdims[0], rdims[1]
                # Brick columns (see Occupancy.columns), relative to the root grid.
                qx0, qy0, qz0 = rx0 >> 3, ry0 >> 3, rz0 >> 3
                qnx = rdx * 64
                # Empty-cube sides (see Occupancy.cubes) for this ray's octant.
                dox, doy, doz = corg[0], corg[1], corg[2]
                ddx, ddy, ddz = cdims[0], cdims[1], cdims[2]
                octant = (0 if px else 1) | (0 if py else 2)
                if pz:  # cubes are kept for rays that do not climb only
                    ddx = 0
                descending = dz < 0.0 and has_columns  # the column skip's one gate
                cap = 4 * (hi[0] - lo[0] + hi[1] - lo[1] + hi[2] - lo[2]) + 64
                steps = 0
                while steps < cap:
                    steps += 1
                    if cx < lo[0] or cy < lo[1] or cz < lo[2] or cx >= hi[0] or cy >= hi[1] or cz >= hi[2]:
                        done = True
                        break
                    s = 9
                    g = root[((cx - rx0) >> 9) + rdx * (((cy - ry0) >> 9) + rdy * ((cz - rz0) >> 9))]
                    if g != 0:
                        s = 6
                        tl = regions[(np.int64(g) - 1) * 512 + node_slot(cx, cy, cz, 6)]
                        if tl != 0:
                            # Inside a tile: DDA over its 8 x 8 x 8 brick slots.
                            tile = (np.int64(tl) - 1) * 512
                            gx, gy, gz = cx >> 6, cy >> 6, cz >> 6
                            bx, by, bz = cx >> 3, cy >> 3, cz >> 3
                            fresh = True  # (cx, cy, cz) is the cell at t
                            stx, sty, stz = False, False, False  # axes stepped by the last brick step
                            while steps < cap:
                                # The empty cubes tell empty bricks without the tile; only a
                                # brick it cannot vouch for needs the tile, so only then does
                                # leaving the tile end this walk.
                                ux, uy, uz = bx - dox, by - doy, bz - doz
                                far = np.int64(-1)
                                if 0 <= ux < ddx and 0 <= uy < ddy and 0 <= uz < ddz:
                                    far = np.int64(cubes[((ux + ddx * (uy + ddy * uz)) << 2) | octant])
                                br = 0
                                if far <= 0:
                                    if (bx >> 3) != gx or (by >> 3) != gy or (bz >> 3) != gz:
                                        break
                                    br = tiles[tile + ((bx & 7) | ((by & 7) << 3) | ((bz & 7) << 6))]
                                if br != 0:
                                    if not fresh:
                                        cx = _brick_entry(bx, stx, px, ox, dx, ix, t)
                                        cy = _brick_entry(by, sty, py, oy, dy, iy, t)
                                        cz = _brick_entry(bz, stz, pz, oz, dz, iz, t)
                                    # Voxel DDA inside the brick, skipping empty 4- and 2-voxel
                                    # blocks; t of each axis's next voxel boundary is recomputed
                                    # from that boundary whenever the axis steps.
                                    base = (np.int64(br) - 1) * 16
                                    mask = blocks[np.int64(br) - 1]  # its 64 2x2x2 blocks, one load
                                    tx = (cx + fx - ox) * ix
                                    ty = (cy + fy - oy) * iy
                                    tz = (cz + fz - oz) * iz
                                    while True:
                                        lx, ly, lz = cx & 7, cy & 7, cz & 7
                                        bit = lx | ((ly & 3) << 3)
                                        if (bricks[base + (ly >> 2) + (lz << 1)] >> bit) & 1:
                                            found = True
                                            done = True
                                            break
                                        # Leave the largest empty aligned block holding the cell:
                                        # 4 or 2 voxels a side, else the voxel (sh = 2, 1, 0).
                                        at4 = ((lx >> 2) << 1) | ((ly >> 2) << 3) | ((lz >> 2) << 5)
                                        at2 = (lx >> 1) | ((ly >> 1) << 2) | ((lz >> 1) << 4)
                                        sh = (
                                            2
                                            if (mask >> np.uint64(at4)) & np.uint64(0x330033) == 0
                                            else (1 if (mask >> np.uint64(at2)) & np.uint64(1) == 0 else 0)
                                        )
                                        tn = min(
                                            (np.float64(((cx >> sh) + ax) << sh) - ox) * ix,
                                            min(
                                                (np.float64(((cy >> sh) + ay) << sh) - oy) * iy,
                                                (np.float64(((cz >> sh) + az) << sh) - oz) * iz,
                                            ),
                                        )
                                        if tn >= t1:
                                            done = True
                                            break
                                        steps += 1
                                        # Every axis passes the voxel boundaries up to tn; tied
                                        # axes step together (touching an edge is no visit).
                                        while tx <= tn:
                                            cx += sx
                                            tx = (cx + fx - ox) * ix
                                        while ty <= tn:
                                            cy += sy
                                            ty = (cy + fy - oy) * iy
                                        while tz <= tn:
                                            cz += sz
                                            tz = (cz + fz - oz) * iz
                                        t = tn
                                        if (cx >> 3) != bx or (cy >> 3) != by or (cz >> 3) != bz:
                                            # Into the next brick: stay in this loop while it is a
                                            # non-empty brick of the same tile.
                                            bx, by, bz = cx >> 3, cy >> 3, cz >> 3
                                            if (bx >> 3) != gx or (by >> 3) != gy or (bz >> 3) != gz:
                                                break
                                            br = tiles[tile + ((bx & 7) | ((by & 7) << 3) | ((bz & 7) << 6))]
                                            if br == 0:
                                                break
                                            base = (np.int64(br) - 1) * 16
                                            mask = blocks[np.int64(br) - 1]
                                        if steps >= cap:
                                            break
                                    if done:
                                        break
                                    bx, by, bz = cx >> 3, cy >> 3, cz >> 3
                                    fresh = True
                                else:
                                    # Skip empty bricks: the cube of ``far`` empty bricks ahead
                                    # (Occupancy.cubes; one brick without it), or for a
                                    # descending ray above the highest brick of its brick column
                                    # that whole column part, whichever reaches further.
                                    k = far if far >= 2 else 1
                                    near = k - 1
                                    tbx = (
                                        (np.float64((bx + k) << 3 if px else (bx - near) << 3) - ox) * ix
                                        if mx
                                        else INF
                                    )
                                    tby = (
                                        (np.float64((by + k) << 3 if py else (by - near) << 3) - oy) * iy
                                        if my
                                        else INF
                                    )
                                    tbz = (
                                        (np.float64((bz + k) << 3 if pz else (bz - near) << 3) - oz) * iz
                                        if mz
                                        else INF
                                    )
                                    tn = min(tbx, min(tby, tbz))
                                    top = (
                                        columns[(bx - qx0) + qnx * (by - qy0)] + qz0 if descending else bz + 1
                                    )
                                    above = bz >= top
                                    if above:
                                        tcx = (
                                            (np.float64((bx + 1) << 3 if px else bx << 3) - ox) * ix
                                            if mx
                                            else INF
                                        )
                                        tcy = (
                                            (np.float64((by + 1) << 3 if py else by << 3) - oy) * iy
                                            if my
                                            else INF
                                        )
                                        tcz = (np.float64(top << 3) - oz) * iz
                                        tc = min(tcx, min(tcy, tcz))
                                        above = tc > tn or k == 1
                                        if above:
                                            k, near = 1, 0
                                            tbx, tby, tbz, tn = tcx, tcy, tcz, tc
                                    if tn >= t1:
                                        done = True
                                        break
                                    steps += 1
                                    stx, sty, stz = tbx == tn, tby == tn, tbz == tn
                                    if stx:
                                        bx += sx * k
                                    elif near > 0:
                                        bx = clamp(
                                            cell_at(ox, dx, ix, tn) >> 3,
                                            bx - (0 if px else near),
                                            bx + (near if px else 0),
                                        )
                                    if sty:
                                        by += sy * k
                                    elif near > 0:
                                        by = clamp(
                                            cell_at(oy, dy, iy, tn) >> 3,
                                            by - (0 if py else near),
                                            by + (near if py else 0),
                                        )
                                    if stz:
                                        bz = top - 1 if above else bz + sz * k
                                    elif above or near > 0:
                                        zlo, zhi = (
                                            (top, bz)
                                            if above
                                            else (bz - (0 if pz else near), bz + (near if pz else 0))
                                        )
                                        bz = clamp(cell_at(oz, dz, iz, tn) >> 3, zlo, zhi)
                                    t = tn
                                    fresh = False
                            if done:
                                break
                            if not fresh:
                                # Left the tile through an empty brick: the cell at t for the node lookup.
                                cx = _brick_entry(bx, stx, px, ox, dx, ix, t)
                                cy = _brick_entry(by, sty, py, oy, dy, iy, t)
                                cz = _brick_entry(bz, stz, pz, oz, dz, iz, t)
                            continue
                    # Skip the empty root cell or region c >> s.
                    bxn, tx = _node_skip(cx, s, px, mx, ox, ix)
                    byn, ty = _node_skip(cy, s, py, my, oy, iy)
                    bzn, tz = _node_skip(cz, s, pz, mz, oz, iz)
                    tn = min(tx, min(ty, tz))
                    if tn >= t1:
                        done = True
                        break
                    cx = _enter(cx, bxn, tx == tn, px, s, ox, dx, ix, tn)
                    cy = _enter(cy, byn, ty == tn, py, s, oy, dy, iy, tn)
                    cz = _enter(cz, bzn, tz == tn, pz, s, oz, dz, iz, tn)
                    t = tn
            kind[r], index[r, 0], index[r, 1], index[r, 2], tout[r] = ray_answer(
                found, cx, cy, cz, t, ox, oy, oz, dx, dy, dz, nx, ny
            )


class NumbaBackend:
    """CPU threads through numba: exact hierarchical traversal and the report's march."""

    name = "numba"
    summary = "CPU threads (numba), float64"

    def __init__(self):
        self._orders: weakref.WeakKeyDictionary[Any, Any] = weakref.WeakKeyDictionary()  # -> OrderChoice

    def probe(self):
        return None

    def describe(self):
        return {
            "device": "cpu",
            "threads": numba.get_num_threads(),
            "threading_layer": _threading_layer(),
            "precision": "f64",
        }

    def trace_cells(
        self,
        occupancy,
        origins,
        directions,
        *,
        method="exact",
        step=0.5,
        precision="f64",
        cancel: threading.Event | None = None,
        bundles: bool = True,
        order: TraceOrder = "auto",
        block_bounds=None,
    ) -> CellHits:
        """See ``Backend`` (``order`` there). For tests: ``bundles=False`` starts every
        ray at its box entry."""
        check_order(order)
        if method == "march":
            check_step(step)
        n = len(origins)
        orig = float_rows(origins)  # one row broadcast stays so: ray order makes rows per block
        dirs = np.ascontiguousarray(directions, dtype=np.float64)
        # Every path below writes every ray's answer (both kernels and the tile tests).
        kind = np.empty(n, np.uint8)
        index = np.empty((n, 3), np.int32)
        t = np.empty(n)
        occ = occupancy
        nx, ny = float(occ.shape[0]), float(occ.shape[1])
        lo, hi = occ.bbox_lo.astype(np.int64), occ.bbox_hi.astype(np.int64)
        rorg, rdims = occ.root_origin.astype(np.int64), occ.root_dims.astype(np.int64)
        cubes, corg, cdims = _cube_arrays(occ)
        halo = halo_arrays(occ) if bundles else halo_arrays(None)
        blocks = occ.blocks if getattr(occ, "blocks", None) is not None else block_masks(occ.bricks)
        columns = occ.columns if occ.columns is not None else np.zeros(0, np.uint32)
        started = time.perf_counter()

        tree = (occ.root, occ.regions, occ.tiles, occ.bricks)
        extent = (lo, hi, rorg, rdims, nx, ny)

        def ray_order(a, b):
            with timed("ray order" if method == "exact" else "march"):
                for c in range(a, b, BLOCK):
                    check_cancelled(cancel, "trace cancelled")
                    d = min(b, c + BLOCK)
                    rays = (origin_rows(orig[c:d]), dirs[c:d])
                    answers = (kind[c:d], index[c:d], t[c:d])
                    if method == "exact":
                        _exact_kernel(
                            *rays, *tree, blocks, columns, cubes, corg, cdims, *halo, *extent, *answers
                        )
                    else:
                        march_kernel(*rays, float(step), float(occ.zmax), *tree, *extent, *answers)

        def object_order_block(a, b, max_voxels):
            bounds = None if block_bounds is None else block_bounds[a // SCAN_BLOCK]
            shared = one_origin(block_bounds, a, b)
            rows = origin_rows(orig[a:b], shared)
            return self._object_order(
                occ, rows, dirs[a:b], bounds, shared, max_voxels, nx, ny, kind[a:b], index[a:b], t[a:b]
            )

        if method == "exact" and order != "ray" and occ.count > 0:
            # Learned on CPU time: both orders run on this process's threads only.
            orders = trace_in_blocks(
                n,
                order,
                self._orders.setdefault(occ, OrderChoice(ray_sample=RAY_SAMPLE)),
                object_order_block,
                ray_order,
                cancel,
                clock=time.process_time,
            )
        else:
            ray_order(0, n)
            orders = {"ray"}
        info = {
            "seconds": time.perf_counter() - started,
            "precision": "f64",
            "threads": numba.get_num_threads(),
            "order": "+".join(sorted(orders)) or "ray",
        }
        return CellHits(kind, index, t, info)

    @staticmethod
    def _object_order(occ, orig, dirs, bounds, shared_origin, max_voxels, nx, ny, kind, index, t):
        """Trace one scan in object order into kind/index/t; False when it is no scan for it.
        ``shared_origin``: every ray starts at ``orig[0]`` (then the only row given)."""
        frame = cone_frame(orig, dirs, bounds)
        return frame is not None and trace_scan(
            occ, orig, dirs, frame, max_voxels, nx, ny, kind, index, t, shared_origin=shared_origin
        )


def _cube_arrays(occ):
    """The optional empty-cube sides; an empty box (no jumps) when the occupancy has none."""
    cubes = getattr(occ, "cubes", None)
    if cubes is None or occ.cube_dims is None or len(cubes) == 0:
        return np.zeros(1, np.uint8), np.zeros(3, np.int64), np.zeros(3, np.int64)
    return cubes, occ.cube_origin.astype(np.int64), occ.cube_dims.astype(np.int64)


def _threading_layer():
    try:
        return numba.threading_layer()
    except ValueError:  # no parallel kernel has run yet
        return "not yet chosen"


register_backend("numba", NumbaBackend)
