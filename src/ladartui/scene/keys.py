"""Voxel keys: one int64 per voxel, for sorting, set membership and fusing.

The one home of ``voxel_keys`` and its inverse, and of the target-model
visibility built on them; measures, simulation, the
detection models and the CLI all use these, so keys from any of them compare.
"""

from __future__ import annotations

import numba
import numpy as np

from ladartui.errors import FieldError

# Voxel keys pack (i+1, j+1, k+1) into 22 + 22 + 19 bits of one int64.
_KEY_BITS_XY = 22
_KEY_BITS_Z = 19
_KEY_LIMITS = np.array([1 << _KEY_BITS_XY, 1 << _KEY_BITS_XY, 1 << _KEY_BITS_Z], dtype=np.int64)


def voxel_keys(voxels) -> np.ndarray:
    """One int64 key per voxel ``(i, j, k)``, ordered like the voxels lexicographically.

    Indices may range over -1 .. 2**22 - 2 for i and j and -1 .. 2**19 - 2 for
    k (the -1 lets neighbour lookups step off the grid's low side); others raise
    ``FieldError``.
    """
    v = np.asarray(voxels).reshape(-1, 3)
    if v.dtype not in (np.int32, np.int64):  # the kernel is compiled for these two
        v = v.astype(np.int64)
    keys = np.empty(v.shape[0], dtype=np.int64)
    bad = _pack_keys(np.ascontiguousarray(v), keys)
    if bad >= 0:
        raise FieldError(
            "voxel index",
            tuple(int(c) for c in v[bad]),
            f"0..{_KEY_LIMITS[0] - 2} for x and y, 0..{_KEY_LIMITS[2] - 2} for z",
        )
    return keys


@numba.njit(nogil=True, cache=True)
def _pack_keys(voxels, keys):
    # One pass (numpy took five over the rows); the first row out of range, else -1.
    for i in range(voxels.shape[0]):
        x = np.int64(voxels[i, 0]) + 1
        y = np.int64(voxels[i, 1]) + 1
        z = np.int64(voxels[i, 2]) + 1
        if (
            x < 0
            or y < 0
            or z < 0
            or x >= 1 << _KEY_BITS_XY
            or y >= 1 << _KEY_BITS_XY
            or z >= 1 << _KEY_BITS_Z
        ):
            return i
        keys[i] = (x << (_KEY_BITS_XY + _KEY_BITS_Z)) | (y << _KEY_BITS_Z) | z
    return -1


def keys_to_voxels(keys) -> np.ndarray:
    """The inverse of ``voxel_keys``: (K, 3) int32 voxel indices."""
    keys = np.asarray(keys, dtype=np.int64)
    out = np.empty((keys.size, 3), dtype=np.int32)
    out[:, 0] = (keys >> (_KEY_BITS_XY + _KEY_BITS_Z)) - 1
    out[:, 1] = ((keys >> _KEY_BITS_Z) & (_KEY_LIMITS[1] - 1)) - 1
    out[:, 2] = (keys & (_KEY_LIMITS[2] - 1)) - 1
    return out


def sorted_unique(keys, sorted_runs: bool = False) -> np.ndarray:
    """The distinct values of an int64 array, sorted.

    Sorting and comparing neighbours is several times faster than np.unique
    on these arrays. ``sorted_runs``: the array is a few sorted runs joined
    (fused scans), which a merging sort (numpy's stable one) orders in a few
    passes where quicksort would start from scratch.
    """
    keys = np.sort(np.asarray(keys, dtype=np.int64).ravel(), kind="stable" if sorted_runs else None)
    if keys.size < 2:
        return keys
    distinct = np.empty(keys.size, dtype=bool)
    distinct[0] = True
    np.not_equal(keys[1:], keys[:-1], out=distinct[1:])
    return keys[distinct]


# Faces through which a target voxel can be seen: the ground-facing (-z) face is
# left out, since a sensor above the ground never looks up at it.
VISIBLE_FACE_OFFSETS = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], dtype=np.int64)


def member(keys: np.ndarray, sorted_keys: np.ndarray) -> np.ndarray:
    """Boolean mask: which ``keys`` occur in ``sorted_keys`` (sorted, unique)."""
    if sorted_keys.size == 0:
        return np.zeros(keys.shape, dtype=bool)
    pos = np.searchsorted(sorted_keys, keys)
    pos[pos == sorted_keys.size] = 0
    return sorted_keys[pos] == keys


def visible_mask(target_model) -> np.ndarray:
    """Which target-model voxels have a face open to empty space (the -z face aside).

    Decided with the target model alone: foliage and other scene voxels do not
    close a face, since the maximum coverage is a property of the target.
    """
    target = np.asarray(target_model, dtype=np.int64).reshape(-1, 3)
    keys = sorted_unique(voxel_keys(target))
    visible = np.zeros(len(target), dtype=bool)
    for offset in VISIBLE_FACE_OFFSETS:
        visible |= ~member(voxel_keys(target + offset), keys)
    return visible


def count_inside(target, voxels) -> int:
    """How many of the ``target`` rows are voxels of ``voxels`` (info's and validate's count)."""
    try:
        scene_keys = voxel_keys(voxels)
        target_keys = voxel_keys(target)
    except FieldError:  # indices too large to pack: compare rows
        scene_rows = set(map(tuple, voxels.tolist()))
        return sum(1 for row in map(tuple, target.tolist()) if row in scene_rows)
    # (np.isin's hashed unique of both arrays took seconds on millions of voxels)
    return int(np.count_nonzero(member(target_keys, sorted_unique(scene_keys))))
