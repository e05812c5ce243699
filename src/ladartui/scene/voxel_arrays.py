"""Voxel arrays and sizes given to the API: checked, or refused with a FieldError naming the argument.

A wrong shape or type would otherwise be reshaped or truncated into other
voxels and give a wrong answer, or fail deep inside numpy with no name.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from ladartui.errors import Described, FieldError, described

MAX_TARGET_ID = 65535  # a LAS point source id is an unsigned 16-bit number


def voxel_list_field(name, value, high=None) -> np.ndarray:
    """``value`` as an (N, 3) integer array of voxel indices from 0 (to ``high``), else FieldError.

    An integer array keeps its type; whole numbers in floats and an empty array
    become int64. A bad row is named by its index (``voxels[4]``).
    """
    array = np.asarray(value)
    if array.size == 0:
        return np.zeros((0, 3), dtype=np.int64)
    if array.ndim != 2 or array.shape[1] != 3:
        raise FieldError(name, described(value), "an (N, 3) array of voxel indices")
    if not np.issubdtype(array.dtype, np.integer):
        # whole numbers in a float array (np.vstack with np.zeros((0, 3))) are indices still
        whole = (
            np.issubdtype(array.dtype, np.floating)
            and bool(np.isfinite(array).all())
            and bool((np.floor(array) == array).all())
            and float(np.abs(array).max()) < 2.0**62
        )
        if not whole:
            raise FieldError(
                name, Described(f"an array of {array.dtype}"), "an (N, 3) array of integer voxel indices"
            )
        array = array.astype(np.int64)
    too_high = high is not None and array.max() > high
    if array.min() < 0 or too_high:
        bad = (array < 0).any(axis=1)
        if too_high:
            bad |= (array > high).any(axis=1)
        row = int(np.argmax(bad))
        limit = f" up to {high}" if high is not None else ""
        raise FieldError(
            f"{name}[{row}]", tuple(int(c) for c in array[row]), f"non-negative voxel indices{limit}"
        )
    return array


def target_ids_field(name, ids, count: int) -> np.ndarray:
    """``ids`` as ``count`` target ids (1..``MAX_TARGET_ID``), one per target voxel, else FieldError."""
    array = np.asarray(ids)
    if array.shape != (count,):
        raise FieldError(name, described(ids), f"{count} target ids, one per target voxel")
    if count and not np.issubdtype(array.dtype, np.integer):
        raise FieldError(name, Described(f"an array of {array.dtype}"), f"{count} integer target ids")
    if count and (array.min() < 1 or array.max() > MAX_TARGET_ID):
        row = int(np.argmax((array < 1) | (array > MAX_TARGET_ID)))
        raise FieldError(f"{name}[{row}]", int(array[row]), f"a target id from 1 to {MAX_TARGET_ID}")
    return array


def voxel_size_field(value, name="voxel_size") -> float:
    """A voxel size in metres: a finite number above 0 (not True, not text), else FieldError."""
    ok = isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
    size = float(value) if ok else math.nan
    if not (size > 0 and math.isfinite(size)):
        raise FieldError(name, value, "a positive number of metres")
    return size
