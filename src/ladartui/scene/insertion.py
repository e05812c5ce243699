"""Putting a voxelised vehicle into a scene model and its target model; writing models.

The report keeps the target in the same x-y location in both files (table
2): the vehicle's voxels join the scene model ``X.txt`` and its target model
``X_Target.txt`` at the same indices, and the two files are replaced together
or not at all.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ladartui.errors import InputFileError, LadarError
from ladartui.scene.model import target_path_for
from ladartui.scene.voxelize import merge_voxels


@dataclass(frozen=True)
class Insertion:
    """A scene model and its target model with a vehicle added."""

    scene: np.ndarray  # (N, 3) int32, sorted
    target: np.ndarray  # (M, 3) int32, sorted
    added: int  # vehicle voxels new to the scene
    occupied: int  # vehicle voxels the scene already held (ground, plants, another vehicle)
    new_target: bool  # the scene had no target model file: one is started


def scene_model_paths(out) -> tuple[Path, Path]:
    """``dir/X`` or ``dir/X.txt`` -> (``dir/X.txt``, ``dir/X_Target.txt``)."""
    scene = Path(out)
    if scene.suffix.lower() != ".txt":
        scene = scene.with_name(scene.name + ".txt")
    return scene, target_path_for(scene)


def load_scene_model(scene_path) -> tuple[np.ndarray, np.ndarray, bool]:
    """The scene's voxels and its target's (empty when ``X_Target.txt`` is absent), and whether it was."""
    from ladartui.scene.voxels import load_voxels

    scene_path = Path(scene_path)
    voxels = load_voxels(scene_path)
    if len(voxels) == 0:
        raise InputFileError(scene_path, "the scene model is empty; expected the voxels of a scene")
    target_path = target_path_for(scene_path)
    if not target_path.exists():
        return voxels, np.zeros((0, 3), dtype=np.int32), False
    return voxels, load_voxels(target_path), True


def insert_vehicle(
    scene: np.ndarray,
    target: np.ndarray,
    vehicle: np.ndarray,
    voxel_size: float,
    had_target: bool = True,
    source: object = "scene",
) -> Insertion:
    """Add ``vehicle`` voxels to ``scene`` and ``target``.

    Refused (``LadarError`` naming ``source``, the scene file) when the
    vehicle reaches past the scene's x-y extent: the scene's ground ends there.
    """
    # A target id for this vehicle (a fourth column of the target model) joins here.
    extent = scene[:, :2].max(axis=0).astype(np.int64) + 1
    reach = vehicle[:, :2].max(axis=0) if len(vehicle) else np.zeros(2, dtype=np.int64)
    for axis, name in ((0, "x"), (1, "y")):
        if reach[axis] >= extent[axis]:
            edge = (extent[axis] - 0.5) * voxel_size
            raise LadarError(
                f"{source}: the vehicle would reach {name} = {(reach[axis] + 0.5) * voxel_size:.3f} m, "
                f"past the scene's edge at {name} = {edge:g} m; place it inside the scene"
            )
    merged = merge_voxels(scene, vehicle)
    added = len(merged) - len(scene)
    return Insertion(
        scene=merged,
        target=merge_voxels(target, vehicle),
        added=added,
        occupied=len(vehicle) - added,
        new_target=not had_target,
    )


def write_scene_model(
    out,
    insertion: Insertion,
    cancel: threading.Event | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> tuple[Path, Path]:
    """Write ``X.txt`` and ``X_Target.txt`` as one set (both or neither); returns their paths."""
    from ladartui.outputset import OutputSet

    scene_path, target_path = scene_model_paths(out)
    paths = {"scene": scene_path, "target": target_path}
    lock = scene_path.with_name(f".{scene_path.stem}.model.lock")

    def writer(voxels: np.ndarray) -> Callable[[Path], None]:
        return lambda tmp: write_voxel_lines(tmp, voxels, cancel, progress)

    with OutputSet(paths, lock) as output_set:
        output_set.write({"scene": writer(insertion.scene), "target": writer(insertion.target)}, cancel)
    return scene_path, target_path


def save_model(
    path,
    voxels: np.ndarray,
    cancel: threading.Event | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> None:
    """Write one voxel list atomically; cancelled, it leaves ``path`` as it was."""
    from ladartui.atomic import atomic_path

    with atomic_path(path) as tmp:
        write_voxel_lines(tmp, voxels, cancel, progress)


_WRITE_ROWS = 1_000_000  # rows formatted at a time: cancel is checked between them


def write_voxel_lines(
    path: Path,
    voxels: np.ndarray,
    cancel: threading.Event | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> None:
    """``x,y,z`` lines of (N, 3) non-negative voxels into ``path`` (a temporary the caller swaps in).

    Formatted a million rows at a time, so a large model needs no text
    buffer of its own size and a set ``cancel`` stops it (``Cancelled``).
    """
    from ladartui.errors import Cancelled
    from ladartui.scene.voxelize import CANCELLED
    from ladartui.scene.voxels import format_voxel_lines

    with open(path, "wb") as stream:
        for start in range(0, len(voxels), _WRITE_ROWS):
            if cancel is not None and cancel.is_set():
                raise Cancelled(CANCELLED)
            stop = min(start + _WRITE_ROWS, len(voxels))
            stream.write(format_voxel_lines(voxels[start:stop]))
            if progress is not None:
                progress("writing", stop, len(voxels))
