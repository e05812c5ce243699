"""Object order on the wgpu backend (shaders/object_order.wgsl): in f64 the same
answers as numba, bit for bit, on scans; ray order wherever it cannot run."""

import math

import numpy as np
import pytest

from ladartui.scene.occupancy import Occupancy
from ladartui.sensor import Sensor
from ladartui.tracing.backend import GROUND, MISS, VOXEL
from ladartui.tracing.object_order import shader_voxels
from ladartui.tracing.reference import reference_trace_cells
from scans import assert_same, forest_scene, one_scan, random_scan

# The wgpu_backend and numba_backend fixtures come from tests/conftest.py.


@pytest.fixture(scope="module")
def forest():
    return forest_scene()


@pytest.fixture(scope="module")
def f64_backend(wgpu_backend):
    if "f64" not in wgpu_backend.describe()["precisions"]:
        pytest.skip("the adapter has no shader-f64: object order runs in f64 only")
    return wgpu_backend


def gpu_object_order(backend, occ, origins, directions):
    hits = backend.trace_cells(occ, origins, directions, order="object")
    assert hits.info["order"] == "object"
    return hits


@pytest.mark.parametrize("depression", [10.0, 45.0, 90.0])
def test_scans_match_numba_bit_for_bit(forest, f64_backend, numba_backend, depression):
    _, occ = forest
    rng = np.random.default_rng(int(depression))
    for slant in (150.0, 600.0):
        aim = [rng.uniform(60, 180), rng.uniform(60, 180), rng.uniform(0, 40)]
        origins, directions = one_scan(aim, depression, rng.uniform(0, 2 * math.pi), slant)
        gpu = gpu_object_order(f64_backend, occ, origins, directions)
        assert_same(numba_backend.trace_cells(occ, origins, directions, order="ray"), gpu)
        assert (gpu.kind == VOXEL).sum() > len(gpu.kind) // 10


def test_a_wide_view_matches_the_reference(forest, f64_backend):
    voxels, occ = forest
    origins, directions = one_scan(
        [120, 120, 20], 45.0, 0.3, 200.0, sensor=Sensor(grid=16, ray_grid=4, fov=40.0)
    )
    gpu = gpu_object_order(f64_backend, occ, origins, directions)
    pick = np.random.default_rng(1).choice(len(origins), 800, replace=False)
    ref = reference_trace_cells(voxels, occ.shape, origins[pick], directions[pick])
    assert_same(ref, type(ref)(gpu.kind[pick], gpu.index[pick], gpu.t[pick], {}))
    assert {MISS, VOXEL, GROUND} <= set(np.unique(ref.kind).tolist())


def test_random_scenes_spread_origins_and_grid_planes(f64_backend, numba_backend):
    rng = np.random.default_rng(23)
    for trial in range(8):
        _, _, occ, origins, directions = random_scan(rng, 0.9)
        if trial % 2 == 0:
            origins = np.round(origins)  # on grid planes, edges and corners
        gpu = gpu_object_order(f64_backend, occ, origins, directions)
        assert_same(numba_backend.trace_cells(occ, origins, directions, order="ray"), gpu)


def test_rays_in_cell_faces_and_zero_components(f64_backend, numba_backend):
    shape = (16, 16, 12)
    grid = np.stack(np.meshgrid(np.arange(16), np.arange(16), np.arange(3, 6), indexing="ij"), -1).reshape(
        -1, 3
    )
    occ = Occupancy.build(grid[(grid[:, 0] * 7 + grid[:, 1] * 3 + grid[:, 2]) % 5 != 0], shape)
    steps = np.arange(-4, 5) * 0.03
    fan = np.array([[a, b, -1.0] for a in steps for b in steps])
    fan /= np.linalg.norm(fan, axis=1, keepdims=True)
    corners = np.array([[x, y, 40.0] for x in (7.5, 7.75, 8.0, 8.25, 8.5) for y in (7.5, 8.0)])
    origins = np.repeat(corners, len(fan), axis=0)
    directions = np.tile(fan, (len(corners), 1))
    gpu = gpu_object_order(f64_backend, occ, origins, directions)
    assert_same(numba_backend.trace_cells(occ, origins, directions, order="ray"), gpu)
    assert ((directions[:, 0] == 0) & (origins[:, 0] % 1 == 0)).any()


def test_far_aircraft(forest, f64_backend, numba_backend):
    _, occ = forest
    origins, directions = one_scan(
        [120, 120, 10], 30.0, 1.0, 40000.0, sensor=Sensor(grid=16, ray_grid=4, fov=0.05)
    )
    gpu = gpu_object_order(f64_backend, occ, origins, directions)
    assert_same(numba_backend.trace_cells(occ, origins, directions, order="ray"), gpu)
    assert (gpu.kind == VOXEL).any()


def test_buffers_grow_and_are_reused(forest, f64_backend, numba_backend):
    # Scans of different sizes one after another: buffers made for a small scan grow
    # for a large one, and a small scan after it reads none of the large one's data.
    _, occ = forest
    for grid in (8, 40, 12):
        origins, directions = one_scan(
            [100, 140, 20], 60.0, 2.0, 180.0, sensor=Sensor(grid=grid, ray_grid=4, fov=6.0)
        )
        gpu = gpu_object_order(f64_backend, occ, origins, directions)
        assert_same(numba_backend.trace_cells(occ, origins, directions, order="ray"), gpu)


def test_ray_order_where_object_order_cannot_run(forest, f64_backend, numba_backend, monkeypatch):
    from ladartui.tracing import wgpu_backend as module

    _, occ = forest
    origins, directions = one_scan([120, 120, 10], 45.0, 1.0, 200.0)
    expected = numba_backend.trace_cells(occ, origins, directions, order="ray")
    # f32, or object order turned off: the ray-order shader.
    assert (
        f64_backend.trace_cells(occ, origins, directions, precision="f32", order="object").info["order"]
        == "ray"
    )
    off = f64_backend.trace_cells(occ, origins, directions, order="ray")
    assert off.info["order"] == "ray"
    assert_same(expected, off)
    # A tile list longer than an invocation may walk on lavapipe.
    monkeypatch.setattr(module, "LOOP_BUDGET", 1)
    long_lists = f64_backend.trace_cells(occ, origins, directions, order="object")
    assert long_lists.info["order"] == "ray"
    assert_same(expected, long_lists)
    monkeypatch.undo()
    # A scene too large for float32 voxel coordinates.
    monkeypatch.setattr(module, "F32_EXACT", max(occ.shape))
    large = f64_backend.trace_cells(occ, origins, directions, order="object")
    assert large.info["order"] == "ray"
    assert_same(expected, large)
    monkeypatch.undo()
    # Origins scattered over the scene: no scan.
    rng = np.random.default_rng(3)
    scattered = rng.uniform([0, 0, 80], [240, 240, 120], size=(5000, 3))
    down = np.tile([0.0, 0.6, -0.8], (5000, 1))
    hits = f64_backend.trace_cells(occ, scattered, down, order="object")
    assert hits.info["order"] == "ray"
    assert_same(numba_backend.trace_cells(occ, scattered, down), hits)


def test_order_is_learned_per_occupancy(forest, f64_backend, numba_backend):
    # Left to choose, the backend takes turns between the orders (OrderChoice) and
    # every call gives the same answers.
    from ladartui.tracing.wgpu_backend import WgpuBackend

    _, occ = forest
    backend = WgpuBackend()
    origins, directions = one_scan([120, 120, 10], 45.0, 1.0, 200.0)  # few voxels per ray
    expected = numba_backend.trace_cells(occ, origins, directions, order="ray")
    seen = set()
    for _ in range(4):
        hits = backend.trace_cells(occ, origins, directions)
        seen.add(hits.info["order"])
        assert_same(expected, hits)
    assert seen == {"object", "ray"}


def test_shader_voxels_round_the_brick_nears_down():
    rng = np.random.default_rng(8)
    m = 2000
    vox = np.zeros((m, 7), np.int64)
    vox[:, :3] = rng.integers(-(1 << 24) + 1, 1 << 24, (m, 3))
    nears = rng.uniform(-1e-6, 1e5, (m, 2)) * rng.choice([1.0, 1e-6], (m, 2))
    records = shader_voxels(vox, nears)
    low = records[:, 0].astype(np.float64)
    assert (low <= nears[:, 1]).all()
    assert (np.nextafter(records[:, 0], np.float32(np.inf)).astype(np.float64) >= nears[:, 1]).all()
    assert (low < nears[:, 1]).any()  # some did need rounding down
    assert np.array_equal(records[:, 1:].astype(np.int64), vox[:, :3])
