"""Writing voxel models: one list atomically, or a scene and its target model as one set.

No numba at import (``format_voxel_lines`` compiles its kernel only for large
lists), so ``ladartui generate`` and the bundled scenarios write without it.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from pathlib import Path

import numpy as np

WRITING_CANCELLED = "writing cancelled; the earlier files are as they were"
WRITE_ROWS = 1_000_000  # rows formatted at a time: cancel is checked between them

Progress = Callable[[str, int, int], None]


def write_voxel_lines(
    path: Path,
    voxels: np.ndarray,
    cancel: threading.Event | None = None,
    progress: Progress | None = None,
    ids: np.ndarray | None = None,
) -> None:
    """``x,y,z`` lines of (N, 3) non-negative voxels into ``path`` (a temporary the caller swaps in);
    ``x,y,z,id`` lines with ``ids`` (one target id per voxel).

    Formatted ``WRITE_ROWS`` rows at a time, so a large model needs no text
    buffer of its own size and a set ``cancel`` stops it (``Cancelled``).
    """
    from ladartui.errors import check_cancelled
    from ladartui.scene.voxels import format_voxel_lines

    if ids is not None:
        voxels = np.column_stack([np.asarray(voxels, np.int64), np.asarray(ids, np.int64)])
    with open(path, "wb") as stream:
        for start in range(0, len(voxels), WRITE_ROWS):
            check_cancelled(cancel, WRITING_CANCELLED)
            stop = min(start + WRITE_ROWS, len(voxels))
            stream.write(format_voxel_lines(voxels[start:stop]))
            if progress is not None:
                progress("writing", stop, len(voxels))


def save_model(
    path,
    voxels: np.ndarray,
    cancel: threading.Event | None = None,
    progress: Progress | None = None,
    ids: np.ndarray | None = None,
) -> None:
    """Write one voxel list atomically (``x,y,z,id`` lines with ``ids``); cancelled, it leaves
    ``path`` as it was. A path that cannot be written is an ``OutputFileError`` naming it."""
    from ladartui.atomic import atomic_path, write_errors_named

    with write_errors_named(path), atomic_path(path) as tmp:
        write_voxel_lines(tmp, voxels, cancel, progress, ids)


def write_model_pair(
    scene_path: Path,
    target_path: Path,
    scene: np.ndarray,
    target: np.ndarray,
    target_ids: np.ndarray | None = None,
    cancel: threading.Event | None = None,
    progress: Progress | None = None,
    also: dict[Path, Callable[[Path], None]] | None = None,
) -> None:
    """A scene model and its target model (``x,y,z,id`` lines with ``target_ids``) written
    as one output set: both replaced or neither. ``progress("writing", rows, of)`` per file.
    ``also``: more files of the set (path -> writer of a temporary), e.g. LAS copies."""
    from ladartui.outputset import OutputSet

    paths = {"scene": scene_path, "target": target_path}
    lock = scene_path.with_name(f".{scene_path.stem}.model.lock")

    def writer(voxels: np.ndarray, ids: np.ndarray | None = None) -> Callable[[Path], None]:
        return lambda tmp: write_voxel_lines(tmp, voxels, cancel, progress, ids)

    writers = {"scene": writer(scene), "target": writer(target, target_ids)}
    for number, (path, write) in enumerate((also or {}).items()):
        paths[f"also-{number}"], writers[f"also-{number}"] = Path(path), write
    with OutputSet(paths, lock) as output_set:
        output_set.write(writers, cancel)
