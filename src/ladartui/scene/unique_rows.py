"""Repeated rows of a voxel list dropped, the first of each kept in its place.

Sorted lists (the ones we write) cannot repeat a voxel and are checked and kept
as they are; others are keyed one int64 a row over their own extent and the
repeats found with a radix sort. Small lists stay in numpy (numba is not loaded
for them, ``lazy_kernels``).
"""

from __future__ import annotations

import numpy as np

from ladartui.scene.lazy_kernels import NUMPY_BYTES, LazyKernels

_kernel = LazyKernels(globals())


def unique_voxels(voxels: np.ndarray) -> tuple[np.ndarray, int]:
    """Drop repeated rows, keeping first occurrences in order; returns (voxels, dropped)."""
    voxels = np.ascontiguousarray(voxels, dtype=np.int32)
    if len(voxels) < 2:
        return voxels, 0
    # Sorted files (ours are) cannot repeat a voxel: checked in place for large lists
    # (no key array); small ones (start-up files) stay in numpy, without loading numba.
    if voxels.nbytes > NUMPY_BYTES and _rows_increasing(voxels):
        return voxels, 0
    keys = row_keys(voxels)
    if keys is None:  # indices too large to pack into one int64
        _, first = np.unique(voxels, axis=0, return_index=True)
        first.sort()
        return voxels[first], len(voxels) - len(first)
    if bool(np.all(keys[1:] > keys[:-1])):  # sorted files (ours are) cannot repeat a voxel
        return voxels, 0
    keep = _first_occurrences(keys, int(keys.max()).bit_length())
    kept = int(np.count_nonzero(keep))
    if kept == len(voxels):
        return voxels, 0
    return _select_rows(voxels, keep, kept), len(voxels) - kept


@_kernel
def _rows_increasing(voxels):
    # Strictly increasing rows in (x, y, z) order, checked in place (no key array).
    for i in range(1, voxels.shape[0]):
        for axis in range(3):
            a, b = voxels[i - 1, axis], voxels[i, axis]
            if a < b:
                break
            if a > b or axis == 2:
                return False
    return True


@_kernel
def _select_rows(voxels, keep, kept):
    # voxels[keep] in one pass; numpy's boolean row indexing is several times slower here.
    out = np.empty((kept, 3), dtype=voxels.dtype)
    row = 0
    for i in range(voxels.shape[0]):
        if keep[i]:
            out[row, 0] = voxels[i, 0]
            out[row, 1] = voxels[i, 1]
            out[row, 2] = voxels[i, 2]
            row += 1
    return out


_RADIX_BITS = 11


@_kernel
def _first_occurrences(keys, bits):
    """Mask of the rows whose key has not appeared earlier.

    A stable LSD radix sort (11-bit digits) groups equal keys with their
    earliest row first; it costs a few passes over the data whatever the
    scene's extent, several times faster than a comparison sort here.
    """
    n = keys.shape[0]
    order = np.arange(n)
    sorted_keys = keys.copy()
    order_scratch = np.empty(n, dtype=np.int64)
    keys_scratch = np.empty(n, dtype=np.int64)
    passes = max(1, (bits + _RADIX_BITS - 1) // _RADIX_BITS)
    digit_bits = max(1, (bits + passes - 1) // passes)  # equal-width digits
    buckets = 1 << digit_bits
    mask = buckets - 1
    for p in range(passes):
        shift = p * digit_bits
        counts = np.zeros(buckets + 1, dtype=np.int64)
        for i in range(n):
            counts[((sorted_keys[i] >> shift) & mask) + 1] += 1
        for b in range(buckets):
            counts[b + 1] += counts[b]
        for i in range(n):
            key = sorted_keys[i]
            digit = (key >> shift) & mask
            slot = counts[digit]
            keys_scratch[slot] = key
            order_scratch[slot] = order[i]
            counts[digit] = slot + 1
        order, order_scratch = order_scratch, order
        sorted_keys, keys_scratch = keys_scratch, sorted_keys
    keep = np.ones(n, dtype=np.bool_)
    for i in range(1, n):
        if sorted_keys[i] == sorted_keys[i - 1]:
            keep[order[i]] = False
    return keep


def row_keys(voxels: np.ndarray) -> np.ndarray | None:
    """One int64 per row, ``(x * ny + y) * nz + z`` over the rows' own extent; None past 63 bits.

    Spans every index a file may hold (``scene.keys`` covers those of a scene in memory).
    """
    nx, ny, nz = (int(s) for s in _column_max(voxels) + 1)
    if nx * ny * nz >= 2**63:
        return None
    return (voxels[:, 0].astype(np.int64) * ny + voxels[:, 1]) * nz + voxels[:, 2]


def _column_max(voxels: np.ndarray) -> np.ndarray:
    return np.array([voxels[:, axis].max() for axis in range(3)], dtype=np.int64)
