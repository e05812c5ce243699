"""The top height of each occupied x-y column, kept as the views can afford it.

A dense map (``model.top_height_map``) has one entry a column of the voxels' x-y
box: cheap where the voxels fill the box, but a few hundred voxels spread over
40,000 x 40,000 columns would take 12 GB. Past a size, the views keep the occupied
columns only (``SparseTops``: their keys, sorted, and their tops) and pool the
columns of the window drawn, so memory follows what the scene holds and each
picture costs the columns in its window, not the box. Plain numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# A dense map takes 8 bytes a column as it is made (the int32 map and a temporary).
MAP_BYTES_PER_COLUMN = 8
# Kept dense up to this many columns whatever the scene holds (64 MiB) ...
DENSE_COLUMNS = 8 * 2**20
# ... or while the box has at most this many columns a voxel (then it costs what the
# scene holds too; the voxels bound the occupied columns from above).
DENSE_COLUMNS_PER_VOXEL = 4
# Making the sparse columns: keys (int64), their order, the sorted keys and tops
# (32 bytes a voxel measured), with room to spare.
SPARSE_BYTES_PER_VOXEL = 40


def map_layout(nx: int, ny: int, voxels: int) -> tuple[bool, int]:
    """Whether the views keep an ``nx`` x ``ny`` column box of ``voxels`` voxels as a
    dense map, and about the bytes that layout takes as it is made."""
    columns = int(nx) * int(ny)
    if columns <= max(DENSE_COLUMNS, DENSE_COLUMNS_PER_VOXEL * int(voxels)):
        return True, MAP_BYTES_PER_COLUMN * columns
    return False, SPARSE_BYTES_PER_VOXEL * int(voxels)


@dataclass(frozen=True)
class SparseTops:
    """The occupied columns of an (nx, ny) box: ``keys`` x * ny + y (from the box's
    corner), sorted, and the highest occupied z of each in ``tops``. Stands in for a
    dense map's ``shape``, ``size`` and ``max()``."""

    shape: tuple[int, int]
    keys: np.ndarray  # (K,) int64, sorted, distinct
    tops: np.ndarray  # (K,) int32

    @classmethod
    def of_voxels(cls, voxels, nx: int, ny: int, origin=(0, 0)) -> SparseTops:
        """The columns of ``voxels`` ((N, 3), every one inside the box from ``origin``)."""
        voxels = np.asarray(voxels).reshape(-1, 3)
        keys = (voxels[:, 0].astype(np.int64) - origin[0]) * int(ny) + (voxels[:, 1] - origin[1])
        order = np.lexsort((voxels[:, 2], keys))  # by column, then height
        keys = keys[order]
        tops = voxels[order, 2].astype(np.int32)
        del order
        last = np.ones(len(keys), bool)  # the highest voxel of each column
        last[:-1] = keys[1:] != keys[:-1]
        return cls((int(nx), int(ny)), keys[last], tops[last])

    @property
    def size(self) -> int:
        return self.shape[0] * self.shape[1]

    @property
    def nbytes(self) -> int:
        return int(self.keys.nbytes + self.tops.nbytes)

    def max(self) -> int:
        """The highest top, -1 when no column is occupied (a dense map's ``max()``)."""
        return int(self.tops.max()) if len(self.tops) else -1

    def columns(self, index=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """x, y (from the box's corner) and top of the columns ``index`` (None: all)."""
        keys = self.keys if index is None else self.keys[index]
        tops = self.tops if index is None else self.tops[index]
        x, y = np.divmod(keys, self.shape[1])
        return x, y, tops

    def window(self, x0: int, x1: int, y0: int, y1: int) -> np.ndarray:
        """Indices of the columns in [x0, x1) x [y0, y1): the keys of x0..x1 are one run;
        where that run holds more columns than the window has x values, each x's own run
        of [y0, y1) is found instead, so the work is the lesser of the two."""
        ny = self.shape[1]
        lo, hi = np.searchsorted(self.keys, [x0 * ny, x1 * ny])
        if hi - lo <= 4 * (x1 - x0):
            index = np.arange(lo, hi)
            y = self.keys[lo:hi] % ny
            return index[(y >= y0) & (y < y1)]
        xs = np.arange(x0, x1, dtype=np.int64) * ny
        starts = np.searchsorted(self.keys, xs + y0)
        counts = np.searchsorted(self.keys, xs + y1) - starts
        return _runs(starts, counts)

    def block_max(self, xa, xb, ya, yb) -> np.ndarray:
        """(rows, cols) int32: the highest top over columns [xa, xb) x [ya, yb) of each
        pixel, -1 where none is occupied. ``xa``, ``xb`` (one a picture column) never
        decrease and ``ya``, ``yb`` (one a picture row, north first) never increase, as
        the top view makes them; every block is within the box and not empty."""
        rows, cols = len(ya), len(xa)
        pooled = np.full((rows, cols), -1, np.int32)
        if not rows or not cols or not len(self.keys):
            return pooled
        index = self.window(int(xa[0]), int(xb[-1]), int(ya[-1]), int(yb[0]))
        x, y, tops = self.columns(index)
        # the picture columns whose blocks hold each x form one run, as do the rows
        c0, c1 = np.searchsorted(xb, x, side="right"), np.searchsorted(xa, x, side="right")
        r0 = rows - np.searchsorted(ya[::-1], y, side="right")
        r1 = rows - np.searchsorted(yb[::-1], y, side="right")
        wide, tall = np.maximum(c1 - c0, 0), np.maximum(r1 - r0, 0)
        count = wide * tall
        held = count > 0
        c0, r0, wide, count, tops = c0[held], r0[held], wide[held], count[held], tops[held]
        one = np.repeat(np.arange(len(count)), count)
        step = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
        r = r0[one] + step // wide[one]
        c = c0[one] + step % wide[one]
        np.maximum.at(pooled, (r, c), tops[one])
        return pooled

    def surface(self, stride: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """x, y and top of the columns on a ``stride`` lattice from the box's corner (a
        dense map's ``[::stride, ::stride]``), in the same order."""
        x, y, tops = self.columns()
        on = (x % stride == 0) & (y % stride == 0)
        return x[on], y[on], tops[on]


def _runs(starts: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """The indices start, start + 1, ... of each run, runs in turn."""
    total = int(counts.sum())
    if not total:
        return np.zeros(0, np.int64)
    offsets = np.repeat(np.cumsum(counts) - counts, counts)
    return np.repeat(starts, counts) + (np.arange(total) - offsets)
