"""A run's output as layers to render: coloured by what each voxel is, or by height.

Classes (report 3.4-3.5): *target seen*, target voxels returned in the
obscured run (the scene output); *target hidden*, target voxels returned
only when the target was traced without the foliage (in the target output
but not the scene output): what the foliage hid; *scene*, every other
returned voxel. A height threshold keeps voxels up to that height and the
colours then span only the heights that remain.
"""

from __future__ import annotations

import numpy as np

from ladartui import colour
from ladartui.render.raster import Layer

COLOUR_MODES = ("class", "height", "scans")


def _keys(voxels) -> np.ndarray:
    v = np.asarray(voxels, dtype=np.int64).reshape(-1, 3)
    return (v[:, 0] << 42) | (v[:, 1] << 21) | v[:, 2]


def in_set(voxels, others) -> np.ndarray:
    """Boolean mask: which rows of ``voxels`` (N, 3) are also rows of ``others``."""
    if others is None or not len(others) or not len(voxels):
        return np.zeros(len(voxels), bool)
    return np.isin(_keys(voxels), _keys(others))


def target_layers(voxels, target_model, target_ids=None) -> list[Layer]:
    """``voxels`` (target voxels) as layers in the target colour: one colour per target
    (ids in ascending order, ``colour.target_colour``) when ``target_ids`` names several."""
    voxels = np.asarray(voxels).reshape(-1, 3)
    ids = None if target_ids is None else np.asarray(target_ids).reshape(-1)
    if ids is None or len(np.unique(ids)) < 2 or not len(voxels):
        return [Layer(voxels, colour.TARGET_RGB)]
    model = np.asarray(target_model).reshape(-1, 3)
    order = np.argsort(_keys(model))
    sorted_keys = _keys(model)[order]
    wanted = _keys(voxels)
    pos = np.minimum(np.searchsorted(sorted_keys, wanted), len(sorted_keys) - 1)
    found = sorted_keys[pos] == wanted
    of_voxel = np.where(found, ids[order[pos]], 0)
    return [
        Layer(voxels[of_voxel == target_id], colour.target_colour(index))
        for index, target_id in enumerate(np.unique(ids))
    ]


def below(voxels, voxel_size: float, threshold_m: float | None) -> np.ndarray:
    """The rows of ``voxels`` whose centre height is at most ``threshold_m`` (None: all)."""
    voxels = np.asarray(voxels).reshape(-1, 3)
    if threshold_m is None:
        return voxels
    return voxels[voxels[:, 2] * voxel_size <= threshold_m]


def classify(scene_output, target_model, target_output=None):
    """(scene voxels, target seen, target hidden) of a run's outputs.

    ``target_output`` is the run of the target alone: its target voxels not in
    the scene output are the hidden ones (its ground returns are not target).
    """
    scene_output = np.asarray(scene_output).reshape(-1, 3)
    is_target = in_set(scene_output, target_model)
    hidden = np.zeros((0, 3), np.int32)
    if target_output is not None and len(target_output):
        target_output = np.asarray(target_output).reshape(-1, 3)
        # the target-only run also returns the ground around the target: not target
        on_target = target_output[in_set(target_output, target_model)]
        hidden = on_target[~in_set(on_target, scene_output)]
    return scene_output[~is_target], scene_output[is_target], hidden


def scan_counts(voxels, per_scan) -> np.ndarray:
    """How many of the scans' return lists (each (K, 3), unique) hold each voxel."""
    voxels = np.asarray(voxels).reshape(-1, 3)
    counts = np.zeros(len(voxels), np.int32)
    keys = _keys(voxels)
    for returns in per_scan or ():
        if len(returns):
            counts += np.isin(keys, _keys(returns))
    return counts


def output_layers(
    scene_output,
    target_model,
    target_output=None,
    *,
    mode: str = "class",
    voxel_size: float = 1.0,
    threshold_m: float | None = None,
    per_scan=None,
    target_ids=None,
):
    """(layers, height_range) for ``raster.render``: the output after the threshold.

    ``mode`` "class" draws scene voxels in greys by height and the target
    classes in their colours; "height" shades the obscured output by height
    (the target still in its colour); "scans" draws scene voxels in greys and
    colours the target voxels seen by how many scans saw them (1 .. the
    number of scans in ``per_scan``). With ``target_ids`` (one per target model
    voxel) naming several targets, each target has its own colour. The height range runs from the ground
    to the highest voxel that remains, so a threshold spreads the colours over
    what is left.
    """
    if mode not in COLOUR_MODES:
        raise ValueError(f"unknown colour mode {mode!r}; expected one of {COLOUR_MODES}")
    scene, seen, hidden = (
        below(v, voxel_size, threshold_m) for v in classify(scene_output, target_model, target_output)
    )
    if mode == "class":
        layers = [
            Layer(scene, colour_map="scene-grey"),
            Layer(hidden, colour.HIDDEN_RGB),
            *target_layers(seen, target_model, target_ids),
        ]
    elif mode == "scans":
        scans = max(len(per_scan or ()), 1)
        layers = [
            Layer(scene, colour_map="scene-grey"),
            Layer(seen, values=scan_counts(seen, per_scan), value_range=(1, scans + 1)),
        ]
    else:
        layers = [Layer(scene), *target_layers(seen, target_model, target_ids)]
    shown = [layer.voxels for layer in layers if len(layer.voxels)]
    top = max((float(v[:, 2].max()) for v in shown), default=1.0)
    return layers, (0.0, max(top, 1.0))


def scene_layers(scene_points, target_model, target_ids=None):
    """Layers of the 3D scene view: the scene by height, each target in its colour."""
    return [Layer(scene_points), *target_layers(target_model, target_model, target_ids)]
