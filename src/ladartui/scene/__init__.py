"""Voxel scenes: voxel-list files, LAS/LAZ point clouds, the Scene model and
the synthetic forest generator. Submodules load on first use."""

import importlib

_EXPORTS = {
    "load_voxels": "ladartui.scene.voxels",
    "save_voxels": "ladartui.scene.voxels",
    "import_las": "ladartui.scene.las",
    "export_las": "ladartui.scene.las",
    "Scene": "ladartui.scene.model",
    "target_path_for": "ladartui.scene.model",
    "generate_scene": "ladartui.scene.generate",
    "GeneratedScene": "ladartui.scene.generate",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'ladartui.scene' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value
