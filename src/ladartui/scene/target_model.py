"""Target-model files: voxel lines ``x,y,z`` (one target) or ``x,y,z,id`` (several).

The lines are read as scene voxel lists are (scene.voxels: the same parser, the
same errors naming file and line); this module adds what a target model needs:
the ids, each voxel in one target, repeated lines dropped.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from ladartui.errors import InputFileError
from ladartui.fileprobe import path_field
from ladartui.fingerprint import Digest
from ladartui.scene.unique_rows import row_keys
from ladartui.scene.voxels import (
    _BOM,
    EXPECTED_TARGET,
    MAX_TARGET_ID,
    _first_line_columns,
    _read_bytes,
    _read_rows,
    load_voxels_counted,
)

log = logging.getLogger(__name__)


def load_target(path, digest: Digest | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read a target model: ``((N, 3) int32 unique voxels, (N,) int32 target ids)``.

    Lines are ``x,y,z`` (one target, id 1: the report's layout) or
    ``x,y,z,id`` with ``id`` in 1..``MAX_TARGET_ID``; every line has the
    same number of values. A repeated voxel line is dropped; the same voxel
    given two different ids is an error naming the later line. ``digest`` is fed
    the file's bytes as they are read.
    """
    path = path_field("path", path, "a target model file's path")
    head = _read_bytes(path, limit=4096)
    start = len(_BOM) if head[: len(_BOM)].tobytes() == _BOM else 0
    if _first_line_columns(head, start) == 3:  # the report's layout: the scene parser as it is
        voxels, _ = load_voxels_counted(path, _target=True, digest=digest)
        return voxels, np.ones(len(voxels), dtype=np.int32)
    rows = _read_rows(path, 4, target=True, digest=digest)
    ids = rows[:, 3]
    bad = np.flatnonzero((ids < 1) | (ids > MAX_TARGET_ID))
    if len(bad):  # blank lines come only at the end: row r is line r + 1
        raise InputFileError(
            path,
            f"id = {int(ids[bad[0]])} is not a target id; {EXPECTED_TARGET}",
            line=int(bad[0]) + 1,
        )
    return _unique_labelled(path, np.ascontiguousarray(rows[:, :3]), np.ascontiguousarray(ids))


def _unique_labelled(path: Path, voxels: np.ndarray, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Drop repeated voxels (first kept); refuse a voxel given two different ids."""
    if len(voxels) < 2:
        return voxels, ids
    keys = row_keys(voxels)
    if keys is not None and bool(np.all(keys[1:] > keys[:-1])):  # sorted (ours are): no repeats
        return voxels, ids
    rows = voxels if keys is None else keys  # one int64 a voxel sorts faster than rows
    _, first, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    conflict = np.flatnonzero(ids != ids[first[inverse]])
    if len(conflict):
        row = int(conflict[0])
        earlier = int(first[inverse[row]])
        x, y, z = (int(c) for c in voxels[row])
        raise InputFileError(
            path,
            f"voxel {x},{y},{z} is target {int(ids[row])} here but target {int(ids[earlier])} "
            f"on line {earlier + 1}; expected each voxel in one target",
            line=row + 1,
        )
    if len(first) == len(voxels):
        return voxels, ids
    keep = np.sort(first)
    log.info("%s: dropped %d duplicate voxel lines", path, len(voxels) - len(keep))
    return voxels[keep], ids[keep]
