"""The host's half of the wgpu backend's object order: a scan made ready for
shaders/object_order.wgsl, and the shader's hits made answers.

The steps are numba's (tracing/tile_tests.py's ``trace_scan``): the rays in bin
order (``scan_rays.bin_order``, no copies: the shader reads each ray through
the order), the voxels in view (``object_order.voxels_in_view``) listed per
tile (``tile_lists.voxels_per_tile``). What differs is the shape of the
lists. The shader runs one invocation per ray and lavapipe loads storage lane
by lane, so each word an invocation reads costs: a tile's entry is two u32
(``voxel_words``, listed as they are, then ``tile_rests``), the least voxel
``near`` from it to the end of its list (the tile stop numba takes per tile,
here per ray) and the voxel's cell packed into one word relative to the
voxels' least corner (``cell_packing``). The shader writes back the packed cell of each ray's
hit; ``entry_answers`` unpacks it and recomputes ``t`` with the slab test both
tracers share (``answers.voxel_entry``), reading nothing but the rays.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange

from ladartui.tracing.answers import ray_answer, voxel_entry
from ladartui.tracing.config import INF, NO_CELL, PARTS
from ladartui.tracing.object_order import voxels_in_view
from ladartui.tracing.passes import timed
from ladartui.tracing.scan_rays import bin_order, scan_grid
from ladartui.tracing.tile_lists import tile_lists

PACKED_BITS = 32  # a packed cell is one u32


@njit(nogil=True, cache=True, inline="always")
def _f32_below(x):
    """The float32 nearest ``x`` from below (a depth bound must not rise)."""
    f = np.float32(x)
    if np.float64(f) > x:
        f = np.nextafter(f, np.float32(-np.inf))
    return f


class ShaderScan(NamedTuple):
    """A scan made ready for the shader (``prepare_shader_scan``).

    Sorted position ``s`` is ray ``order[s]``, in tile ``ray_tiles[s]`` (empty when
    every bin holds one ray: the tile is then ``s >> 2 * tile_shift``). Tile ``k``'s
    entries are ``tile_starts[k] .. tile_starts[k + 1]`` of ``entries`` (rest as
    float32 bits, packed cell). ``packing`` is (offset, shifts, masks) of the cells
    (``cell_packing``).
    """

    order: np.ndarray
    ray_tiles: np.ndarray
    tile_starts: np.ndarray
    entries: np.ndarray
    packing: tuple
    tile_shift: int


def cell_packing(vox):
    """(offset, shifts, masks) that pack cell ``vox[e, :3]`` into one u32 as
    ``sum((cell[a] - offset[a]) << shifts[a])``, each axis with the bits its span
    of the voxels needs; None when they need more than 32 bits together or one
    axis needs 32 (the shader unpacks an axis as i32), or when the greatest cell
    packs to NO_CELL, the shader's word for no hit (32 bits, every span all
    ones). An axis with one value takes no bits (shift and mask 0)."""
    offset, top = _cell_box(vox)
    bits = [int(span).bit_length() for span in top - offset]
    if sum(bits) > PACKED_BITS or max(bits) >= PACKED_BITS:
        return None
    shifts = np.array([0, bits[0], bits[0] + bits[1]], np.int64) * (np.array(bits) > 0)
    masks = np.array([(1 << b) - 1 for b in bits], np.int64)
    if sum(int(top[a] - offset[a]) << int(shifts[a]) for a in range(3)) == NO_CELL:
        return None
    return offset, shifts, masks


@njit(parallel=True, nogil=True, cache=True)
def _cell_box(vox):
    """(least, greatest) cell of the voxels per axis; zeros when there are none."""
    m = vox.shape[0]
    lo, hi = np.zeros(3, np.int64), np.zeros(3, np.int64)
    if m == 0:
        return lo, hi
    spans = min(PARTS, m)  # every span holds a voxel
    span_lo, span_hi = np.empty((spans, 3), np.int64), np.empty((spans, 3), np.int64)
    for span in prange(spans):
        first, end = span * m // spans, (span + 1) * m // spans
        for a in range(3):
            least = greatest = vox[first, a]
            for q in range(first + 1, end):
                least, greatest = min(least, vox[q, a]), max(greatest, vox[q, a])
            span_lo[span, a], span_hi[span, a] = least, greatest
    for a in range(3):
        lo[a], hi[a] = span_lo[:, a].min(), span_hi[:, a].max()
    return lo, hi


@njit(parallel=True, nogil=True, cache=True)
def voxel_words(vox, nears, offset, shifts):
    """(m, 2) u32 per voxel: its ``near`` as float32 rounded down (still a lower
    bound), and its packed cell."""
    words = np.empty((vox.shape[0], 2), np.uint32)
    as_float = words.view(np.float32)
    for q in prange(vox.shape[0]):
        as_float[q, 0] = _f32_below(nears[q, 0])
        packed = 0
        for a in range(3):
            packed |= (vox[q, a] - offset[a]) << shifts[a]
        words[q, 1] = np.uint32(packed)
    return words


@njit(parallel=True, nogil=True, cache=True)
def tile_rests(tile_starts, entries):
    """In place: each tile's entries (rows ``tile_starts[k] .. tile_starts[k + 1]`` of
    (E, 2) u32, ``voxel_words``' words as listed) get in their first word the least
    float32 near from that entry to the end of the list (rounding down commutes with
    the minimum)."""
    near = entries.view(np.float32)
    for tile in prange(tile_starts.shape[0] - 1):
        first, end = tile_starts[tile], tile_starts[tile + 1]
        rest = np.float32(np.inf)
        for k in range(end - first):  # last entry first (a reversed range ran slower)
            e = end - 1 - k
            rest = min(rest, near[e, 0])
            near[e, 0] = rest


@njit(parallel=True, nogil=True, cache=True)
def ray_tiles_of(bin_starts, shift):
    """Tile of every sorted position, from the bins' starts (bin key ``b`` holds
    positions ``bin_starts[b] .. bin_starts[b + 1]``; a tile's bins are contiguous)."""
    per_tile = 1 << (2 * shift)
    tiles = (bin_starts.shape[0] - 1) // per_tile
    out = np.empty(bin_starts[-1], np.uint32)
    for tile in prange(tiles):
        for s in range(bin_starts[tile * per_tile], bin_starts[(tile + 1) * per_tile]):
            out[s] = tile
    return out


def prepare_shader_scan(occ, orig, dirs, frame, max_voxels, tile_shift):
    """A scan's rays in bin order and its voxels in view as tile entries for the
    shader (tiles of ``1 << tile_shift`` bins a side); None when it cannot be
    projected, has more than ``max_voxels`` voxels in view, or its voxels' cells do
    not pack into 32 bits (ray order then)."""
    binned = scan_grid(dirs, frame)
    if binned is None:
        return None
    nb, p, q, grid = binned
    order, bin_starts, grid = bin_order(p, q, grid, nb, tile_shift)
    voxels = voxels_in_view(occ, frame, grid, nb, max_voxels)
    if voxels is None:
        return None
    vox, nears = voxels
    packing = cell_packing(vox)
    if packing is None:
        return None
    offset, shifts, _ = packing
    with timed("tile lists"):
        # The lists hold the shader's words themselves (two u32 as one u64 each).
        words = voxel_words(vox, nears, offset, shifts).view(np.uint64).reshape(-1)
        tile_starts, listed = tile_lists(vox, nb, tile_shift, words)
        entries = listed.view(np.uint32).reshape(-1, 2)
        tile_rests(tile_starts, entries)
        ray_tiles = ray_tiles_of(bin_starts, tile_shift) if len(bin_starts) else np.empty(0, np.uint32)
    return ShaderScan(order, ray_tiles, tile_starts.astype(np.uint32), entries, packing, tile_shift)


@njit(parallel=True, nogil=True, cache=True)
def entry_answers(found, offset, shifts, masks, orig, shared_origin, dirs, nx, ny, kind, index, tout):
    """Every ray's answer from the shader's ``found`` (per ray, the packed cell of its
    hit, NO_CELL none; ``cell_packing``'s offset, shifts and masks unpack it): that
    voxel at the start of its slab test, else the ground rule. ``shared_origin``:
    every ray starts at ``orig[0]``, which is then read for all."""
    for r in prange(found.shape[0]):
        o = np.int64(0) if shared_origin else np.int64(r)  # (prange's r is unsigned)
        ox, oy, oz = orig[o, 0], orig[o, 1], orig[o, 2]
        dx, dy, dz = dirs[r, 0], dirs[r, 1], dirs[r, 2]
        word = np.int64(found[r])
        i, j, k, t = np.int64(-1), np.int64(-1), np.int64(-1), INF
        if word != NO_CELL:
            i = offset[0] + ((word >> shifts[0]) & masks[0])
            j = offset[1] + ((word >> shifts[1]) & masks[1])
            k = offset[2] + ((word >> shifts[2]) & masks[2])
            t = voxel_entry(ox, oy, oz, dx, dy, dz, i, j, k)
        kind[r], index[r, 0], index[r, 1], index[r, 2], tout[r] = ray_answer(
            word != NO_CELL, i, j, k, t, ox, oy, oz, dx, dy, dz, nx, ny
        )
