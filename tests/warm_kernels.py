"""Fill numba's on-disk cache with the tracing kernels before the suite runs.

On a fresh clone the suite compiles its numba kernels one at a time as tests
first call them, about two and a half minutes of a run on two cores. ``make
test`` instead runs this script twice in the background while the style and
type checks run, one process per half of the kernels:

    python tests/warm_kernels.py object   # object order (numba's and wgpu's)
    python tests/warm_kernels.py ray      # rays to cells, ray order, the march

(cold, one after the other on two cores: 50 s for numba's object order, 62 s for
its ray order, 7 s rays to cells, 4 s the march). Failing here fails nothing:
a test compiles what it needs again.
"""

from __future__ import annotations

import sys

import numpy as np


def scan_of_small_scene():
    """A generated small scene's occupancy, voxel size and a 64 x 64 scan at its target."""
    from ladartui.flight import ScanPose, aim_at
    from ladartui.scene.generate import generate_scene
    from ladartui.scene.model import Scene
    from ladartui.sensor import Sensor

    generated = generate_scene("small", seed=11, width=16.0, depth=16.0, trees=5)
    scene = Scene(generated.voxels, generated.target, generated.voxel_size, shape=generated.shape)
    centre = np.asarray(generated.target_centre, dtype=np.float64)
    pose = aim_at(ScanPose(centre[0], centre[1] - 40.0, 60.0, 0.0, 0.0, 90.0), centre.tolist())
    origins, directions, _ = Sensor(grid=64, ray_grid=1).rays(pose)
    return scene.occupancy, scene.voxel_size, origins, directions


def warm_object_order(occupancy, voxel_size, origins, directions) -> None:
    # Cell space by numpy here: rays_to_cells is the other process's to compile.
    cells = origins / voxel_size + 0.5
    unit = directions / np.linalg.norm(directions, axis=1)[:, None]
    for name in ("numba", "wgpu"):
        backend = backend_or_none(name)
        if backend is not None:
            backend.trace_cells(occupancy, cells, unit, order="object")


def warm_ray_order(occupancy, voxel_size, origins, directions) -> None:
    from ladartui.tracing import TINY
    from ladartui.tracing.prepare import rays_to_cells

    cells, unit, bounds = rays_to_cells(origins, directions, voxel_size, TINY)
    for name in ("numba", "wgpu"):
        backend = backend_or_none(name)
        if backend is not None:
            backend.trace_cells(occupancy, cells, unit, order="ray", block_bounds=bounds)
            backend.trace_cells(occupancy, cells, unit, method="march")


def backend_or_none(name):
    from ladartui.errors import BackendUnavailable
    from ladartui.tracing.backend import get_backend

    try:
        return get_backend(name)
    except BackendUnavailable:
        return None


if __name__ == "__main__":
    half = sys.argv[1]
    warm = {"object": warm_object_order, "ray": warm_ray_order}[half]
    warm(*scan_of_small_scene())
