"""Occupancy: the sparse bitmask hierarchy that every tracer reads.

The layout is a contract shared with the WGSL shader (see docs/architecture.md,
"Occupancy layout"): the shared arrays are uint32, nodes have fan-out 8 per axis;
blocks, cubes and halo are optional accelerations a tracer may ignore.

    root    dense grid of 512-voxel cells over the occupied box: region number (index + 1), 0 = empty
    regions 512 slots per region (64-voxel cells): tile number, 0 = empty
    tiles   512 slots per tile (8-voxel cells): brick number, 0 = empty
    bricks  16 words per brick: one bit per voxel
    columns (optional) per 8 x 8 column of bricks: 1 + highest non-empty brick z (relative to the root grid)
    blocks  (uint64, optional acceleration) per brick: bit b of its 64 2x2x2 blocks is set
            when block b holds a voxel, b = bx + 4 * by + 16 * bz with (bx, by, bz) = l >> 1
    cubes   (uint8, optional acceleration) per downward ray octant and brick cell of the occupied
            box: the side (bricks) of the largest empty cube with that corner reaching into the octant
    halo    (uint32, optional acceleration) one bit per brick cell of the occupied box grown by
            one brick on every side: set when that brick or any of its 26 neighbours holds a
            voxel (bit l & 31 of word l >> 5, l = x + dims.x * (y + dims.y * z))
    halo4   (uint32, optional acceleration) the same over 4-voxel cells

Inside any node the local position (lx, ly, lz), each 0..7, is linear
``l = lx + 8 * ly + 64 * lz``; a brick's bit ``l`` is bit ``l & 31`` of word ``l >> 5``.
Memory grows with the content: one node per non-empty cell at its level. The root
grid is sized by the box coarsely; column tops, cubes and halos are built only while
affordable for the content (``resources.builds_columns``, ``builds_accelerations``),
else left None.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from ladartui.errors import Described, FieldError, described

BRICK_WORDS = 16
NODE_SLOTS = 512
# log2 of the cell size (voxels) at each level: brick voxel, tile slot, region slot, root cell.
VOXEL_SHIFT, BRICK_SHIFT, TILE_SHIFT, REGION_SHIFT = 0, 3, 6, 9
CUBE_CAP = 255  # largest stored empty-cube side (uint8)


def column_bounds(voxels) -> tuple[np.ndarray, np.ndarray]:
    """The least and greatest index of each axis of a non-empty (N, 3) integer voxel
    list, as int64. Axis by axis: numpy's ``min(axis=0)`` over rows of three ran 13x
    slower (94 ms against 7 for the 3.8 million voxels of the reference scene)."""
    lo = np.array([voxels[:, a].min() for a in range(3)], np.int64)
    hi = np.array([voxels[:, a].max() for a in range(3)], np.int64)
    return lo, hi


SHAPE_EXPECTED = "three non-negative integers (nx, ny, nz)"


def shape_field(shape) -> tuple[int, int, int]:
    """``shape`` as (nx, ny, nz) ints: whole numbers in any form (4, 4.0, numpy's),
    else FieldError naming it (20.7 is not cut to 20, nor a bool taken for 1)."""
    items = None if isinstance(shape, (str, bytes)) else _items(shape)
    if items is None or len(items) != 3:
        raise FieldError("shape", shape, SHAPE_EXPECTED)
    out = []
    for value in items:
        whole = isinstance(value, (int, np.integer, float, np.floating)) and not isinstance(
            value, (bool, np.bool_)
        )
        if not whole or not float(value).is_integer() or value < 0:
            raise FieldError("shape", shape, SHAPE_EXPECTED)
        out.append(int(value))
    return out[0], out[1], out[2]


def _items(value) -> list | None:
    try:
        return list(value)
    except TypeError:
        return None


def _voxel_indices(ijk) -> np.ndarray:
    """``ijk`` as an int64 array of shape (.., 3), else FieldError naming it."""
    expected = "voxel indices (.., 3) of integers"
    try:
        array = np.asarray(ijk)
    except (TypeError, ValueError):
        raise FieldError("ijk", ijk, expected) from None
    whole = array.dtype.kind in "iu" or (array.dtype.kind == "f" and bool(np.all(np.mod(array, 1) == 0)))
    if not whole or array.ndim == 0 or array.shape[-1] != 3:
        raise FieldError("ijk", ijk, expected)
    return array.astype(np.int64)


@dataclass(frozen=True, eq=False)
class Occupancy:
    """Which voxels are occupied, as a sparse hierarchy sized to the content.

    Cell-space coordinates: voxel (i, j, k) spans [i, i+1) x [j, j+1) x [k, k+1).
    ``bbox_lo``/``bbox_hi`` bound the occupied voxels (hi exclusive; equal when empty).
    """

    shape: tuple
    bbox_lo: np.ndarray
    bbox_hi: np.ndarray
    root_origin: np.ndarray
    root_dims: np.ndarray
    root: np.ndarray
    regions: np.ndarray
    tiles: np.ndarray
    bricks: np.ndarray
    count: int
    columns: np.ndarray | None = None
    blocks: np.ndarray | None = None
    cubes: np.ndarray | None = None
    cube_origin: np.ndarray | None = None
    cube_dims: np.ndarray | None = None
    halo: np.ndarray | None = None
    halo_origin: np.ndarray | None = None
    halo_dims: np.ndarray | None = None
    halo4: np.ndarray | None = None
    halo4_origin: np.ndarray | None = None
    halo4_dims: np.ndarray | None = None

    @classmethod
    def build(cls, voxels, shape=None, source="voxels", bounds=None) -> Occupancy:
        """Build from an (N, 3) integer voxel list (duplicates allowed) and the scene shape.

        ``shape`` is (nx, ny, nz); by default the greatest index on each axis + 1. Voxels
        outside ``[0, shape)`` raise FieldError; a build whose extent-sized arrays
        would not fit in memory raises ResourceLimitError naming ``source``.
        ``bounds``: the voxels' ``column_bounds`` where the caller has them (a Scene
        finds them as it is made), so they are not found again.
        """
        vox = np.asarray(voxels)
        if vox.size == 0:
            vox = vox.reshape(0, 3)
        if vox.ndim != 2 or vox.shape[1] != 3:
            raise FieldError("voxels", described(voxels), "an (N, 3) integer array")
        if vox.dtype.kind not in "iu":
            raise FieldError("voxels", Described(f"an array of {vox.dtype}"), "integer voxel indices")
        if vox.dtype not in (np.int32, np.int64):  # the kernels are compiled for these two
            vox = vox.astype(np.int64)
        if not len(vox):
            lo, last = np.zeros(3, np.int64), np.full(3, -1, np.int64)
        else:
            lo, last = column_bounds(vox) if bounds is None else bounds
        hi = last + 1
        shape = tuple(int(v) for v in hi) if shape is None else shape_field(shape)
        if not len(vox):
            return cls._empty(shape)
        if lo.min() < 0 or np.any(hi > np.array(shape)):  # the first bad row, by its index
            negative = lo.min() < 0
            bad = (vox < 0).any(axis=1) if negative else (vox >= np.array(shape)).any(axis=1)
            row = int(np.argmax(bad))
            raise FieldError(
                f"voxels[{row}]",
                tuple(int(c) for c in vox[row]),
                "non-negative voxel indices"
                if negative
                else f"voxel indices inside the scene shape ({', '.join(str(n) for n in shape)})",
            )
        from ladartui.resources import builds_accelerations, builds_columns, check_occupancy

        # Some arrays are sized by extent: refuse before allocating what cannot fit.
        check_occupancy(lo, hi, len(vox), source)
        columns = builds_columns(lo, hi, len(vox))
        if builds_accelerations(lo, hi, len(vox)):
            return cls._from_nonempty(vox, lo, hi, shape, columns)
        return cls._sparse(vox, lo, hi, shape, columns)

    @classmethod
    def _empty(cls, shape):
        zero = np.zeros(3, np.int64)
        empty = np.zeros(0, np.uint32)
        return cls(
            shape,
            zero.copy(),
            zero.copy(),
            zero.copy(),
            zero.copy(),
            empty,
            empty.copy(),
            empty.copy(),
            empty.copy(),
            0,
            empty.copy(),
            np.zeros(0, np.uint64),
            np.zeros(0, np.uint8),
            zero.copy(),
            zero.copy(),
            empty.copy(),
            zero.copy(),
            zero.copy(),
            empty.copy(),
            zero.copy(),
            zero.copy(),
        )

    @classmethod
    def _from_nonempty(cls, vox, lo, hi, shape, columns: bool):
        root_origin, root_dims = _root_box(lo, hi)
        cube_origin = lo >> BRICK_SHIFT
        cube_dims = ((hi - 1) >> BRICK_SHIFT) - cube_origin + 1
        # Bricks without sorting the voxels (a sort of 3.8 million keys was half the
        # reference scene's build): the brick cells holding a voxel are marked, their
        # keys (root cell, region slot, tile slot) sorted, one a brick, and each voxel's
        # bit set through its cell's brick number. Bricks of a tile and tiles of a
        # region end up adjacent in memory. Besides the voxels the build holds 5 bytes
        # a brick cell of the box, as the empty cubes do, not bytes a voxel.
        occupied = np.zeros((int(cube_dims[2]), int(cube_dims[1]), int(cube_dims[0])), np.bool_)
        _mark_cells(vox, BRICK_SHIFT, cube_origin.astype(np.int64), occupied)
        cells = np.flatnonzero(occupied)
        bkeys = _brick_keys(cells, cube_dims, cube_origin - (root_origin >> BRICK_SHIFT), root_dims)
        order = np.argsort(bkeys)
        bkeys = bkeys[order]
        n_bricks = len(bkeys)
        brick_of_cell = np.empty(occupied.size, np.int32)  # read at occupied cells only
        brick_of_cell[cells[order]] = np.arange(n_bricks, dtype=np.int32)
        del cells, order
        bricks = np.zeros(n_bricks * BRICK_WORDS, np.uint32)
        count = _set_voxel_bits(
            vox, cube_origin.astype(np.int64), cube_dims.astype(np.int64), brick_of_cell, bricks
        )
        del brick_of_cell

        brick_cells = _brick_cells(bkeys, root_dims) + (root_origin >> BRICK_SHIFT)
        cubes = _empty_cubes(occupied)
        del occupied
        halo_origin, halo_dims = cube_origin - 1, cube_dims + 2
        halo = _halo_bits(brick_cells - halo_origin, halo_dims)
        halo4_origin = (lo >> 2) - 1
        halo4_dims = ((hi - 1) >> 2) - (lo >> 2) + 3
        halo4 = _halo_bits_of_voxels(vox, 2, halo4_origin, halo4_dims)
        return cls._over_bricks(
            shape,
            (lo, hi, root_origin, root_dims),
            bkeys,
            bricks,
            count,
            columns,
            cubes=cubes,
            cube_origin=cube_origin.astype(np.int64),
            cube_dims=cube_dims.astype(np.int64),
            halo=halo,
            halo_origin=halo_origin.astype(np.int64),
            halo_dims=halo_dims.astype(np.int64),
            halo4=halo4,
            halo4_origin=halo4_origin.astype(np.int64),
            halo4_dims=halo4_dims.astype(np.int64),
        )

    @classmethod
    def _over_bricks(cls, shape, box, bkeys, bricks, count, columns: bool, **accelerations):
        """The occupancy of the sorted brick keys ``bkeys`` and their ``bricks``: the tiles,
        regions and root above them, the column tops (when ``columns``) and block masks;
        ``box`` (lo, hi, root origin, root dims); ``accelerations``: the optional empty
        cubes and halos."""
        lo, hi, root_origin, root_dims = box
        tiles, tkeys = _parents(bkeys, len(bkeys))
        regions, rkeys = _parents(tkeys, len(tkeys))
        root = np.zeros(int(np.prod(root_dims)), np.uint32)
        root[rkeys] = np.arange(1, len(rkeys) + 1, dtype=np.uint32)
        return cls(
            shape,
            lo.astype(np.int64),
            hi.astype(np.int64),
            root_origin.astype(np.int64),
            root_dims.astype(np.int64),
            root,
            regions,
            tiles,
            bricks,
            count,
            _column_tops(bkeys, root_dims) if columns else None,
            block_masks(bricks),
            **accelerations,
        )

    @classmethod
    def _sparse(cls, vox, lo, hi, shape, columns: bool):
        """The hierarchy of voxels few for their box, without the extent-sized empty
        cubes and halos: the bricks come from the voxels' sorted brick keys, not a grid
        of the box's brick cells."""
        root_origin, root_dims = _root_box(lo, hi)
        keys = np.empty(len(vox), np.int64)
        for a in range(0, len(vox), _CHUNK):
            q = (vox[a : a + _CHUNK].astype(np.int64) - root_origin) >> BRICK_SHIFT
            keys[a : a + _CHUNK] = _keys_of_bricks(q[:, 0], q[:, 1], q[:, 2], root_dims)
        bkeys = np.unique(keys)
        n_bricks = len(bkeys)
        bricks = np.zeros(n_bricks * BRICK_WORDS, np.uint32)
        count = 0
        for a in range(0, len(vox), _CHUNK):
            brick_of_voxel = np.searchsorted(bkeys, keys[a : a + _CHUNK]).astype(np.int64)
            count += _set_bits_of_bricks(vox[a : a + _CHUNK], brick_of_voxel, bricks)
        del keys
        return cls._over_bricks(shape, (lo, hi, root_origin, root_dims), bkeys, bricks, count, columns)

    @property
    def nbytes(self) -> int:
        """Bytes held by the hierarchy arrays."""
        optional = (self.columns, self.blocks, self.cubes, self.halo, self.halo4)
        extra = sum(a.nbytes for a in optional if a is not None)
        return int(self.root.nbytes + self.regions.nbytes + self.tiles.nbytes + self.bricks.nbytes + extra)

    @property
    def zmax(self) -> int:
        """Highest occupied layer, -1 when empty."""
        return int(self.bbox_hi[2]) - 1 if self.count else -1

    @property
    def n_bricks(self) -> int:
        return len(self.bricks) // BRICK_WORDS

    @property
    def n_tiles(self) -> int:
        return len(self.tiles) // NODE_SLOTS

    @property
    def n_regions(self) -> int:
        return len(self.regions) // NODE_SLOTS

    def contains(self, ijk) -> np.ndarray:
        """Boolean array: is each (.., 3) voxel index occupied? Outside the scene is False."""
        ijk = _voxel_indices(ijk)
        flat = ijk.reshape(-1, 3)
        out = np.zeros(len(flat), bool)
        if self.count == 0 or len(flat) == 0:
            return out.reshape(ijk.shape[:-1])
        inside = np.all((flat >= self.bbox_lo) & (flat < self.bbox_hi), axis=1)
        rel = flat[inside] - self.root_origin
        r = rel >> REGION_SHIFT
        node = self.root[r[:, 0] + self.root_dims[0] * (r[:, 1] + self.root_dims[1] * r[:, 2])]
        node = node.astype(np.int64)
        for array, shift in ((self.regions, TILE_SHIFT), (self.tiles, BRICK_SHIFT)):
            ok = node > 0
            child = np.zeros_like(node)
            child[ok] = array[(node[ok] - 1) * NODE_SLOTS + _local(rel[ok], shift)]
            node = child
        ok = node > 0
        bit = _local(rel[ok], VOXEL_SHIFT)
        words = self.bricks[(node[ok] - 1) * BRICK_WORDS + (bit >> 5)].astype(np.int64)
        hit = np.zeros(len(rel), bool)
        hit[ok] = (words >> (bit & 31)) & 1 == 1
        out[inside] = hit
        return out.reshape(ijk.shape[:-1])

    def summary(self) -> dict:
        """Node counts and bytes, for reports."""
        return {
            "count": self.count,
            "shape": list(self.shape),
            "bbox_lo": self.bbox_lo.tolist(),
            "bbox_hi": self.bbox_hi.tolist(),
            "root_cells": len(self.root),
            "regions": self.n_regions,
            "tiles": self.n_tiles,
            "bricks": self.n_bricks,
            "nbytes": self.nbytes,
        }


def _root_box(lo, hi):
    """The root grid's origin (a region corner) and its size in regions over voxels ``lo..hi - 1``."""
    return (lo >> REGION_SHIFT) << REGION_SHIFT, ((hi - 1) >> REGION_SHIFT) - (lo >> REGION_SHIFT) + 1


def _brick_keys(cells, cube_dims, root_offset, root_dims):
    """The key of each brick cell (``cells``: indices ``x + dims.x * (y + dims.y * z)``
    into a ``cube_dims`` box whose cell 0 is brick ``root_offset`` from the root
    origin): root cell << 18 | region slot << 9 | tile slot, the order of bricks."""
    dx, dy = int(cube_dims[0]), int(cube_dims[1])
    return _keys_of_bricks(
        cells % dx + root_offset[0],
        cells // dx % dy + root_offset[1],
        cells // (dx * dy) + root_offset[2],
        root_dims,
    )


def _keys_of_bricks(qx, qy, qz, root_dims):
    """The key of each brick ``q = (c - root_origin) >> 3``: root cell << 18 | region
    slot << 9 | tile slot."""
    key = (qx >> 6) + root_dims[0] * ((qy >> 6) + root_dims[1] * (qz >> 6))
    for shift in (3, 0):
        key = (key << 9) | ((qx >> shift) & 7) | (((qy >> shift) & 7) << 3) | (((qz >> shift) & 7) << 6)
    return key


# voxels a step of a sparse build works on: its int64 temporaries stay tens of megabytes
_CHUNK = 1 << 20


@njit(nogil=True, cache=True)
def _set_bits_of_bricks(vox, brick_of_voxel, bricks):
    # Each voxel's bit in its brick (brick_of_voxel[i]); returns the number newly set.
    count = 0
    for i in range(vox.shape[0]):
        x, y, z = vox[i, 0], vox[i, 1], vox[i, 2]
        bit = (x & 7) | ((y & 7) << 3) | ((z & 7) << 6)
        word = brick_of_voxel[i] * BRICK_WORDS + (bit >> 5)
        mask = np.uint32(1) << np.uint32(bit & 31)
        if not bricks[word] & mask:
            bricks[word] |= mask
            count += 1
    return count


@njit(nogil=True, cache=True)
def _set_voxel_bits(vox, cube_origin, cube_dims, brick_of_cell, bricks):
    # Each voxel's bit (l = lx + 8 ly + 64 lz) in the brick of its cell; returns the
    # number of distinct voxels (a bit already set is a duplicate).
    count = 0
    for i in range(vox.shape[0]):
        x, y, z = vox[i, 0], vox[i, 1], vox[i, 2]
        cell = ((x >> 3) - cube_origin[0]) + cube_dims[0] * (
            ((y >> 3) - cube_origin[1]) + cube_dims[1] * ((z >> 3) - cube_origin[2])
        )
        bit = (x & 7) | ((y & 7) << 3) | ((z & 7) << 6)
        word = np.int64(brick_of_cell[cell]) * BRICK_WORDS + (bit >> 5)
        mask = np.uint32(1) << np.uint32(bit & 31)
        if not bricks[word] & mask:
            bricks[word] |= mask
            count += 1
    return count


@njit(nogil=True, cache=True)
def _mark_cells(vox, shift, origin, near):
    for i in range(vox.shape[0]):
        x = (vox[i, 0] >> shift) - origin[0]
        y = (vox[i, 1] >> shift) - origin[1]
        z = (vox[i, 2] >> shift) - origin[2]
        near[z, y, x] = True


def _local(rel, shift):
    """Linear slot ``lx + 8 ly + 64 lz`` of each cell inside its parent node at level ``shift``."""
    c = (rel >> shift) & 7
    return c[:, 0] | (c[:, 1] << 3) | (c[:, 2] << 6)


def _starts(sorted_keys):
    """True where a run of equal sorted keys begins."""
    start = np.empty(len(sorted_keys), bool)
    if len(sorted_keys):
        start[0] = True
        np.not_equal(sorted_keys[1:], sorted_keys[:-1], out=start[1:])
    return start


def _brick_cells(brick_keys, root_dims):
    """(N, 3) brick coordinates ``(c - root_origin) >> 3`` of each brick key."""
    root_lin = brick_keys >> 18
    rx = root_lin % root_dims[0]
    ry = (root_lin // root_dims[0]) % root_dims[1]
    rz = root_lin // (root_dims[0] * root_dims[1])
    tile_slot = (brick_keys >> 9) & 511
    brick_slot = brick_keys & 511
    qx = rx * 64 + (tile_slot & 7) * 8 + (brick_slot & 7)
    qy = ry * 64 + ((tile_slot >> 3) & 7) * 8 + ((brick_slot >> 3) & 7)
    qz = rz * 64 + (tile_slot >> 6) * 8 + (brick_slot >> 6)
    return np.column_stack([qx, qy, qz])


def block_masks(bricks):
    """Per brick a uint64 with bit ``bx + 4 by + 16 bz`` set when its 2x2x2 block holds a voxel."""
    words = bricks.reshape(-1, BRICK_WORDS)
    masks = np.zeros(len(words), np.uint64)
    for bz in range(4):
        for half in range(2):  # word 2 lz + half holds rows ly = 4 half .. 4 half + 3
            pair = words[:, 4 * bz + half] | words[:, 4 * bz + 2 + half]  # lz = 2 bz, 2 bz + 1
            pair = pair | (pair >> 8)  # row pairs (ly & 3 = 0, 1) and (2, 3) on rows 0 and 2
            pair = pair | (pair >> 1)  # column pairs on even bits
            for row in range(2):
                by = 2 * half + row
                for bx in range(4):
                    bit = (pair >> np.uint32(16 * row + 2 * bx)) & np.uint32(1)
                    masks |= bit.astype(np.uint64) << np.uint64(bx + 4 * by + 16 * bz)
    return masks


def _empty_cubes(full):
    """Per downward octant and brick cell of the box ``full`` covers ((z, y, x), true
    at bricks holding a voxel), the side of the largest cube of empty bricks having
    that cell as the corner facing away from the octant, capped at CUBE_CAP.

    uint8, octant ``o = (d_x <= 0) + 2 (d_y <= 0)`` for rays with ``d_z <= 0`` (sensor rays
    look down; climbing rays get no jumps, which halves the memory), indexed
    ``4 * (x + dims.x * (y + dims.y * z)) + o`` (the octants of a cell share a cache line);
    0 at non-empty bricks. A ray of octant ``o`` in a brick of value ``k`` crosses only
    empty bricks until it leaves the ``k``-brick cube starting at that brick and reaching
    along its direction.
    """
    out = np.zeros((*full.shape, 4), np.uint8)
    _fill_empty_cubes(full.view(np.uint8), CUBE_CAP, out)
    return out.reshape(-1)


def _halo_bits(cells, dims):
    """Bits over a ``dims`` box of cells: set where the cell or a neighbour holds a voxel.

    A bundle of rays that stays within one cell less a voxel of its centre ray
    (7 voxels over bricks, 3 over 4-voxel cells) meets no voxel before that ray
    enters a set cell (see tracing.bundle), so the bundle's rays may all start
    there.
    """
    dx, dy, dz = (int(v) for v in dims)
    near = np.zeros((dz, dy, dx), bool)
    near[cells[:, 2], cells[:, 1], cells[:, 0]] = True
    return _grown_bits(near)


def _halo_bits_of_voxels(vox, shift, origin, dims):
    """``_halo_bits`` over cells of ``2**shift`` voxels, marked straight from the voxels."""
    dx, dy, dz = (int(v) for v in dims)
    near = np.zeros((dz, dy, dx), bool)
    _mark_cells(vox, shift, np.asarray(origin, np.int64), near)
    return _grown_bits(near)


def _grown_bits(near):
    """``near`` grown to each cell's 3 x 3 x 3 neighbourhood, packed into uint32 words."""
    for axis in range(3):  # grow by one cell along each axis in turn: the 3 x 3 x 3 neighbourhood
        grown = near.copy()
        lower = [slice(None)] * 3
        upper = [slice(None)] * 3
        lower[axis], upper[axis] = slice(None, -1), slice(1, None)
        grown[tuple(lower)] |= near[tuple(upper)]
        grown[tuple(upper)] |= near[tuple(lower)]
        near = grown
    packed = np.packbits(near.reshape(-1), bitorder="little")
    words = np.zeros(-(-len(packed) // 4) * 4, np.uint8)
    words[: len(packed)] = packed
    return words.view("<u4").astype(np.uint32)


@njit(nogil=True, cache=True)
def _fill_empty_cubes(full, cap, out):
    # side(q) = 1 + min(side of the 7 neighbours q + s * delta), the 3-D largest-square rule;
    # outside the box every brick is empty (side cap).
    nz, ny, nx = full.shape
    for o in range(4):
        sx = -1 if o & 1 else 1
        sy = -1 if o & 2 else 1
        sz = -1
        for kz in range(nz):
            z = nz - 1 - kz if sz > 0 else kz
            for ky in range(ny):
                y = ny - 1 - ky if sy > 0 else ky
                for kx in range(nx):
                    x = nx - 1 - kx if sx > 0 else kx
                    if full[z, y, x]:
                        out[z, y, x, o] = 0
                        continue
                    m = cap
                    for delta in range(1, 8):
                        x2 = x + sx * (delta & 1)
                        y2 = y + sy * ((delta >> 1) & 1)
                        z2 = z + sz * (delta >> 2)
                        if 0 <= x2 < nx and 0 <= y2 < ny and 0 <= z2 < nz:
                            v = out[z2, y2, x2, o]
                            if v < m:
                                m = v
                    out[z, y, x, o] = min(cap, m + 1)


def _column_tops(brick_keys, root_dims):
    """Per 8 x 8 brick column over the root grid: 1 + its highest non-empty brick's z, 0 if none.

    Indexed ``qx + 64 * root_dims.x * qy`` with ``q = (c - root_origin) >> 3``.
    """
    q = _brick_cells(brick_keys, root_dims)
    qx, qy, qz = q[:, 0], q[:, 1], q[:, 2]
    tops = np.zeros(int(root_dims[0] * 64 * root_dims[1] * 64), np.uint32)
    np.maximum.at(tops, qx + root_dims[0] * 64 * qy, (qz + 1).astype(np.uint32))
    return tops


def _parents(child_keys, n_children):
    """Nodes one level up: their 512-slot arrays and their own keys (child key >> 9)."""
    parent_key = child_keys >> 9
    start = _starts(parent_key)
    parent_of_child = np.cumsum(start) - 1
    n_parents = int(parent_of_child[-1]) + 1
    slots = np.zeros(n_parents * NODE_SLOTS, np.uint32)
    slots[parent_of_child * NODE_SLOTS + (child_keys & 511)] = np.arange(1, n_children + 1, dtype=np.uint32)
    return slots, parent_key[start]
