"""Scans for the object-order tests: a generated forest and one sensor scan of it."""

import math

import numpy as np

from ladartui.flight import ScanPose, aim_at
from ladartui.scene.occupancy import Occupancy
from ladartui.sensor import Sensor


def forest_scene():
    """(voxels, occupancy) of the generated "small" forest (240 x 240 x 73 cells)."""
    from ladartui.scene.generate import generate_scene

    generated = generate_scene("small")
    return generated.voxels, Occupancy.build(generated.voxels, generated.shape)


def one_scan(aim, depression_deg, azimuth_rad, slant_cells, sensor=None):
    """Cell-space rays of one sensor scan from ``slant_cells`` away, aimed at ``aim``."""
    sensor = sensor or Sensor(grid=32, ray_grid=4, fov=5.0)
    e = math.radians(depression_deg)
    at = np.asarray(aim, float) + slant_cells * np.array(
        [math.cos(azimuth_rad) * math.cos(e), math.sin(azimuth_rad) * math.cos(e), math.sin(e)]
    )
    origins, directions, _ = sensor.rays(aim_at(ScanPose(*at.tolist()), list(aim)))
    return origins, directions


def pinhole_scan_cells():
    """(cells, unit, bounds) of ``rays_to_cells`` for one scan whose rays all start at
    one point: the cells are that one row broadcast (checked here)."""
    from ladartui.tracing import TINY
    from ladartui.tracing.prepare import rays_to_cells

    origins, directions = one_scan([120, 120, 20], 45.0, 0.7, 300.0)
    origins[:] = origins[0]
    cells, unit, bounds = rays_to_cells(origins, directions, 1.0, TINY)
    assert cells.strides[0] == 0
    return cells, unit, bounds


def assert_same(a, b):
    """Two CellHits agree bit for bit: kind, voxel index and range of every ray."""
    assert np.array_equal(a.kind, b.kind), np.flatnonzero(a.kind != b.kind)[:5]
    assert np.array_equal(a.index, b.index), np.flatnonzero((a.index != b.index).any(axis=1))[:5]
    assert np.array_equal(a.t, b.t), np.flatnonzero(a.t != b.t)[:5]


def random_scan(rng, jitter, n=3000):
    """A random scene and a fan of ``n`` rays within 20 degrees of a downward axis from
    60-400 cells away, origins jittered by up to ``jitter`` cell: (voxels, shape,
    occupancy, origins, directions)."""
    shape = tuple(int(v) for v in rng.integers(20, 70, size=3))
    voxels = rng.integers(0, shape, size=(int(rng.integers(1, 4000)), 3))
    axis = rng.normal(size=3)
    axis[2] = -abs(axis[2]) - 0.2
    axis /= np.linalg.norm(axis)
    start = rng.uniform(0, 1, 3) * shape - axis * rng.uniform(60, 400)
    spread = rng.normal(size=(n, 3)) * math.tan(math.radians(rng.uniform(1, 20)))
    directions = axis + spread - np.outer(spread @ axis, axis)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    origins = start + rng.uniform(-jitter, jitter, size=(n, 3))
    return voxels, shape, Occupancy.build(voxels, shape), origins, directions


def numpy_with_junk_empty():
    """numpy, except that ``empty`` fills its arrays with the byte 0x5A: set as a
    backend module's ``np``, any answer a path leaves unwritten differs from a
    clean run's."""
    import types

    def junk(shape, dtype=float):
        out = np.empty(shape, dtype)
        out.view(np.uint8)[...] = 0x5A
        return out

    return types.SimpleNamespace(**{**vars(np), "empty": junk})
