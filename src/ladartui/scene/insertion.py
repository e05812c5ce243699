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
from ladartui.scene.ground import Resting, rest_on_ground
from ladartui.scene.model import target_path_for
from ladartui.scene.model_files import write_model_pair
from ladartui.scene.voxelize import merge_voxels


@dataclass(frozen=True)
class Insertion:
    """A scene model and its target model with a vehicle added."""

    scene: np.ndarray  # (N, 3) int32, sorted
    target: np.ndarray  # (M, 3) int32, sorted
    added: int  # vehicle voxels new to the scene
    occupied: int  # vehicle voxels the scene already held (ground, plants, another vehicle)
    new_target: bool  # the scene had no target model file: one is started
    resting: Resting  # where it was set: on the ground found, or on the floor
    # One id per target voxel when the target model names targets (x,y,z,id lines), else None
    # (the report's x,y,z layout: one target, which the vehicle joins).
    target_ids: np.ndarray | None = None
    vehicle_id: int | None = None  # the vehicle's target id, when the model names targets


def scene_model_paths(out) -> tuple[Path, Path]:
    """``dir/X`` or ``dir/X.txt`` -> (``dir/X.txt``, ``dir/X_Target.txt``)."""
    scene = Path(out)
    if scene.suffix.lower() != ".txt":
        scene = scene.with_name(scene.name + ".txt")
    return scene, target_path_for(scene)


def load_scene_model(scene_path) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """The scene's voxels, its target's and their target ids (empty when ``X_Target.txt`` is
    absent; 1 on every line of a three-column target model), and whether it was there."""
    from ladartui.scene.target_model import load_target
    from ladartui.scene.voxels import load_voxels

    scene_path = Path(scene_path)
    voxels = load_voxels(scene_path)
    if len(voxels) == 0:
        raise InputFileError(scene_path, "the scene model is empty; expected the voxels of a scene")
    target_path = target_path_for(scene_path)
    if not target_path.exists():
        return voxels, np.zeros((0, 3), dtype=np.int32), np.zeros(0, dtype=np.int32), False
    target, ids = load_target(target_path)
    return voxels, target, ids, True


def insert_vehicle(
    scene: np.ndarray,
    target: np.ndarray,
    vehicle: np.ndarray,
    voxel_size: float,
    had_target: bool = True,
    source: object = "scene",
    target_ids: np.ndarray | None = None,
    vehicle_id: int | None = None,
) -> Insertion:
    """Add ``vehicle`` voxels to ``scene`` and ``target``.

    ``vehicle`` is placed on the floor (the plane at the bottom of voxel
    layer 0, as ``Placement`` puts it); it is first raised
    whole layers to rest on the scene's ground under its footprint
    (:func:`ladartui.scene.ground.rest_on_ground`: unchanged where none is
    found, as in a generated flat scene), and ``Insertion.resting`` says how.

    Refused (``LadarError`` naming ``source``, the scene file) when the
    vehicle reaches past the scene's x-y extent: the scene's ground ends there.

    Target ids: with ``vehicle_id`` the vehicle becomes that target and the
    existing targets keep their ids (``target_ids``; a three-column model is
    target 1); an id already in use, or a vehicle voxel already in another
    target, is refused (``FieldError`` on ``id``, ``LadarError``). Without it,
    a model of one target takes the vehicle into that target (the report's
    three-column layout, written as before) and a model of several gives it
    the next free id.
    """
    extent = scene[:, :2].max(axis=0).astype(np.int64) + 1
    reach = vehicle[:, :2].max(axis=0) if len(vehicle) else np.zeros(2, dtype=np.int64)
    for axis, name in ((0, "x"), (1, "y")):
        if reach[axis] >= extent[axis]:
            edge = (extent[axis] - 0.5) * voxel_size
            raise LadarError(
                f"{source}: the vehicle would reach {name} = {(reach[axis] + 0.5) * voxel_size:.3f} m, "
                f"past the scene's edge at {name} = {edge:g} m; place it inside the scene"
            )
    vehicle, resting = rest_on_ground(scene, vehicle, voxel_size)
    merged = merge_voxels(scene, vehicle)
    added = len(merged) - len(scene)
    ids = np.ones(len(target), dtype=np.int32) if target_ids is None else np.asarray(target_ids, np.int32)
    several = bool(len(ids)) and bool(np.any(ids != ids[0]))
    if vehicle_id is None and not several:
        return Insertion(
            scene=merged,
            target=merge_voxels(target, vehicle),
            added=added,
            occupied=len(vehicle) - added,
            new_target=not had_target,
            resting=resting,
        )
    if vehicle_id is None:
        vehicle_id = int(ids.max()) + 1
    labelled_target, labelled_ids = _add_target(target, ids, vehicle, vehicle_id, source)
    return Insertion(
        scene=merged,
        target=labelled_target,
        added=added,
        occupied=len(vehicle) - added,
        new_target=not had_target,
        target_ids=labelled_ids,
        vehicle_id=vehicle_id,
        resting=resting,
    )


def _add_target(
    target: np.ndarray, ids: np.ndarray, vehicle: np.ndarray, vehicle_id: int, source: object
) -> tuple[np.ndarray, np.ndarray]:
    """Target voxels and ids with the vehicle added as target ``vehicle_id``, sorted by voxel."""
    from ladartui.errors import FieldError
    from ladartui.scene.keys import voxel_keys
    from ladartui.scene.voxels import MAX_TARGET_ID

    if not 1 <= vehicle_id <= MAX_TARGET_ID:
        raise FieldError("id", vehicle_id, f"a target id from 1 to {MAX_TARGET_ID}")
    used = sorted({int(i) for i in ids})
    if vehicle_id in used:
        raise FieldError(
            "id",
            vehicle_id,
            f"a target id not yet in {target_path_for(Path(str(source))).name} "
            f"(it has {', '.join(map(str, used))})",
        )
    vehicle = merge_voxels(vehicle)  # sorted, unique
    target_keys, vehicle_keys = voxel_keys(target), voxel_keys(vehicle)
    clash = np.isin(vehicle_keys, target_keys)
    if np.any(clash):
        first = vehicle[int(np.argmax(clash))]
        owner = int(ids[int(np.flatnonzero(target_keys == voxel_keys(first[None, :])[0])[0])])
        x, y, z = (int(c) for c in first)
        raise LadarError(
            f"{target_path_for(Path(str(source)))}: {int(clash.sum()):,} of the vehicle's voxels are "
            "already target voxels "
            f"(voxel {x},{y},{z} is target {owner}); expected the vehicle apart from the other "
            "targets (move it with --at)"
        )
    voxels = np.concatenate([np.asarray(target, np.int32).reshape(-1, 3), vehicle])
    labels = np.concatenate([ids, np.full(len(vehicle), vehicle_id, dtype=np.int32)])
    order = np.argsort(np.concatenate([target_keys, vehicle_keys]), kind="stable")
    return voxels[order], labels[order]


def write_scene_model(
    out,
    insertion: Insertion,
    cancel: threading.Event | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> tuple[Path, Path]:
    """Write ``X.txt`` and ``X_Target.txt`` as one set (both or neither); returns their paths."""
    scene_path, target_path = scene_model_paths(out)
    model = (insertion.scene, insertion.target, insertion.target_ids)
    write_model_pair(scene_path, target_path, *model, cancel, progress)
    return scene_path, target_path
