"""Voxel scenes: voxel-list files, LAS/LAZ point clouds, the Scene model and
the synthetic forest generator. Submodules load on first use."""

from ladartui.lazy import lazy_getattr

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


__getattr__ = lazy_getattr("ladartui.scene", _EXPORTS, globals())
