"""Object order on the wgpu backend (shaders/object_order.wgsl): in f64 the same
answers as numba, bit for bit, on scans; ray order wherever it cannot run."""

import math

import numpy as np
import pytest

from ladartui.scene.occupancy import Occupancy
from ladartui.sensor import Sensor
from ladartui.tracing.backend import GROUND, MISS, VOXEL
from ladartui.tracing.config import NO_CELL
from ladartui.tracing.reference import reference_trace_cells
from ladartui.tracing.shader_scan import cell_packing, ray_tiles_of, tile_rests, voxel_words
from scans import assert_same, forest_scene, numpy_with_junk_empty, one_scan, pinhole_scan_cells, random_scan

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


def test_still_axes_inside_on_faces_and_outside_the_voxels_span(f64_backend, numba_backend):
    """A ray with d = 0 on an axis is inside a cell's slab there only when its origin
    is strictly inside that cell: on a face, or beside every voxel (below or beyond
    the packing's span on that axis), it never enters. Rays run level through
    layers of voxels, in their faces, above and below them, some with x still as
    well; z packs into no bits (one layer) and into one (two layers)."""
    rng = np.random.default_rng(5)
    steps = np.arange(-6, 7) * 0.04
    fan = np.array([[a, 1.0, b] for a in steps for b in (0.0, 0.0, 0.01, -0.02)])
    fan /= np.linalg.norm(fan, axis=1, keepdims=True)
    level = fan[:, 2] == 0
    for layers, heights in (([4], (3.75, 4.0, 4.5, 4.75, 5.0, 5.25)), ([4, 5], (4.5, 5.0, 5.5, 5.75, 6.25))):
        grid = np.meshgrid(np.arange(3, 15), np.arange(3, 15), layers, indexing="ij")
        cells = np.stack(grid, -1).reshape(-1, 3)
        occ = Occupancy.build(cells[rng.random(len(cells)) < 0.3], (24, 24, 8))
        starts = np.array([[x, -6.0, z] for x in (8.5, 9.0, 9.5) for z in heights])
        origins = np.repeat(starts, len(fan), axis=0)
        directions = np.tile(fan, (len(starts), 1))
        gpu = gpu_object_order(f64_backend, occ, origins, directions)
        expected = numba_backend.trace_cells(occ, origins, directions, order="ray")
        assert_same(expected, gpu)
        z = origins[:, 2]
        in_layer = (z % 1 > 0) & (z > min(layers)) & (z < max(layers) + 1)
        still = np.tile(level, len(starts))
        x_still = still & (directions[:, 0] == 0)
        assert (expected.kind[still & in_layer] == VOXEL).any()
        assert not (expected.kind[still & ~in_layer] == VOXEL).any()
        assert (expected.kind[x_still & in_layer & (origins[:, 0] % 1 > 0)] == VOXEL).any()
        assert not (expected.kind[x_still & (origins[:, 0] % 1 == 0)] == VOXEL).any()


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


def test_arrays_through_the_queue_give_the_same_answers(forest, f64_backend, numba_backend):
    # On lavapipe the scan's buffers are mapped by the host; a GPU's way, copies
    # through the queue, runs here too and answers the same, scan after scan.
    from ladartui.tracing.wgpu_backend import WgpuBackend

    _, occ = forest
    queued = WgpuBackend(map_storage=False)
    queued.trace_cells(occ, *one_scan([100, 140, 20], 60.0, 2.0, 180.0), order="object")
    assert not queued.describe()["maps_storage"] and not queued._scans.uniform_tile_bounds
    if f64_backend.describe()["adapter_type"] == "CPU":
        assert f64_backend.describe()["maps_storage"]  # lavapipe: the mapped way
    for depression in (45.0, 80.0):
        origins, directions = one_scan([120, 110, 15], depression, 0.7, 200.0)
        expected = numba_backend.trace_cells(occ, origins, directions, order="ray")
        for backend in (queued, f64_backend):
            assert_same(expected, gpu_object_order(backend, occ, origins, directions))


def test_ray_order_where_object_order_cannot_run(forest, f64_backend, numba_backend, monkeypatch):
    from ladartui.tracing import shader_scan
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
    # Voxels in view whose cells do not pack into the shader's word.
    monkeypatch.setattr(shader_scan, "PACKED_BITS", 8)
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


def test_order_is_learned_per_occupancy(forest, f64_backend, numba_backend, monkeypatch):
    # Left to choose, the backend takes turns between the orders (OrderChoice): each is
    # timed twice, and every call gives the same answers. On a CPU adapter ray order's
    # turns while it does not lead are samples (object order answers), on a GPU whole.
    from ladartui.tracing.order_choice import RAY_SAMPLE
    from ladartui.tracing.wgpu_backend import WgpuBackend

    _, occ = forest
    backend = WgpuBackend()
    origins, directions = one_scan([120, 120, 10], 45.0, 1.0, 200.0)  # few voxels per ray
    expected = numba_backend.trace_cells(occ, origins, directions, order="ray")
    for _ in range(4):
        assert_same(expected, backend.trace_cells(occ, origins, directions))
    choice = backend._orders[occ]
    assert [len(times) for times in choice.samples.values()] == [2, 2]
    cpu = backend.describe()["adapter_type"] == "CPU"
    assert choice.ray_sample == (RAY_SAMPLE if cpu else None)
    monkeypatch.setattr(backend, "_cpu_adapter", not cpu)
    assert backend._order_choice().ray_sample == (None if cpu else RAY_SAMPLE)


def test_cells_pack_into_one_word_and_back():
    rng = np.random.default_rng(8)
    for spans in ([2048, 2048, 1000], [1, 300, 7], [1 << 20, 1, 1 << 12], [5000, 5000, 1]):
        vox = np.zeros((500, 7), np.int64)
        vox[:, :3] = rng.integers(0, spans, (500, 3)) + rng.integers(-(1 << 23), 1 << 23, 3)
        vox[:2, :3] = vox[:, :3].min(axis=0), vox[:, :3].max(axis=0)
        offset, shifts, masks = cell_packing(vox)
        tile_starts = np.array([0, len(vox)])
        listed = rng.permutation(len(vox))
        words = voxel_words(vox, np.zeros((len(vox), 2)), offset, shifts)
        entries = words[listed]
        tile_rests(tile_starts, entries)
        packed = entries[:, 1]
        cells = np.stack([(packed >> np.uint32(shifts[a])) & np.uint32(masks[a]) for a in range(3)], axis=1)
        assert np.array_equal(cells.astype(np.int64) + offset, vox[listed, :3])
    vox[:2, :3] = [0, 0, 0], [1 << 11, 1 << 11, 1 << 10]  # 12 + 12 + 11 bits
    assert cell_packing(vox) is None
    # 11 + 11 + 10 bits, and the greatest corner packs to all ones: the shader's no hit.
    vox[:, :3] = 5
    vox[1, :3] = [5 + 2047, 5 + 2047, 5 + 1023]
    assert cell_packing(vox) is None
    vox[1, 2] -= 1
    assert cell_packing(vox) is not None
    # One axis of 32 bits, the others of none: the shader unpacks an axis as i32.
    vox[:, :3] = 0
    vox[1, 0] = (1 << 31) + 5
    assert cell_packing(vox) is None
    vox[1, 0] = (1 << 31) - 1
    assert cell_packing(vox) is not None


def test_tile_rests_carry_the_least_near_still_to_come_rounded_down():
    rng = np.random.default_rng(9)
    m = 3000
    vox = np.zeros((m, 7), np.int64)
    nears = rng.uniform(-1e-6, 1e5, (m, 2)) * rng.choice([1.0, 1e-6], (m, 2))
    tile_starts = np.array([0, 0, 700, 701, 2900, 4000])
    listed = rng.integers(0, m, tile_starts[-1])
    words = voxel_words(vox, nears, np.zeros(3, np.int64), np.zeros(3, np.int64))
    entries = words[listed]
    tile_rests(tile_starts, entries)
    rests = entries[:, 0].view(np.float32).astype(np.float64)
    exact = np.concatenate(
        [
            np.minimum.accumulate(nears[listed[a:b], 0][::-1])[::-1]
            for a, b in zip(tile_starts[:-1], tile_starts[1:])
        ]
    )
    assert (rests <= exact).all()
    assert (np.nextafter(rests.astype(np.float32), np.float32(np.inf)).astype(np.float64) > exact).all()
    assert (rests < exact).any()  # some did need rounding down


def test_ray_tiles_follow_the_bins_starts():
    rng = np.random.default_rng(4)
    shift = 1
    counts = rng.integers(0, 3, 4 * 25)  # 25 tiles of 2 x 2 bins
    bin_starts = np.concatenate([[0], np.cumsum(counts)])
    per_tile = counts.reshape(25, 4).sum(axis=1)
    assert np.array_equal(ray_tiles_of(bin_starts, shift), np.repeat(np.arange(25), per_tile))


@pytest.mark.parametrize(
    "order, method, precision",
    [
        ("object", "exact", "f64"),
        ("ray", "exact", "f64"),
        ("auto", "exact", "f64"),
        ("auto", "march", "f64"),
        ("ray", "exact", "f32"),
    ],
)
def test_every_ray_gets_an_answer_written(forest, monkeypatch, order, method, precision):
    """The wgpu backend's answer arrays start unfilled: every path must write every
    ray. Junk in the new arrays shows up as a difference from a clean run."""
    import ladartui.tracing.wgpu_backend as wgpu_module
    from ladartui.tracing.wgpu_backend import WgpuBackend

    _, occ = forest
    origins, directions = one_scan([100, 100, 10], 50.0, 1.0, 300.0)
    backend = WgpuBackend()
    if precision == "f64" and "f64" not in backend.describe()["precisions"]:
        pytest.skip("the adapter has no shader-f64")
    calls = {"order": order, "method": method, "precision": precision}
    clean = [backend.trace_cells(occ, origins, directions, **calls) for _ in range(4)]

    monkeypatch.setattr(wgpu_module, "np", numpy_with_junk_empty())
    for expected in clean:  # auto: both orders, as they take turns
        assert_same(expected, backend.trace_cells(occ, origins, directions, **calls))


def test_rays_from_one_origin_send_and_read_that_origin_alone(
    forest, f64_backend, numba_backend, monkeypatch
):
    """trace() tells the shader when every ray of a block starts at one point (the
    block bounds say so): one origin row goes to the device and every ray reads it.
    The shader's hits, and the host's answers from them, are the same as from every
    ray's own row, even when the other rows hold NaN; rays from two origins are not told."""
    from ladartui.tracing import trace, wgpu_scans
    from ladartui.tracing.config import OBJECT_ORDER_TILE_SHIFT
    from ladartui.tracing.scan_rays import cone_frame, ray_bounds
    from ladartui.tracing.shader_scan import entry_answers, prepare_shader_scan

    voxels, occ = forest
    origins, directions = one_scan([120, 120, 20], 45.0, 0.7, 300.0)
    origins[:] = origins[0]  # a pinhole camera
    frame = cone_frame(origins, directions, np.concatenate(ray_bounds(origins, directions)))
    scan = prepare_shader_scan(occ, origins, directions, frame, np.inf, OBJECT_ORDER_TILE_SHIFT)
    f64_backend.trace_cells(occ, origins, directions, order="object")  # opens the device
    dispatcher = f64_backend._scans
    own_rows = dispatcher.test_tiles(origins, directions, scan).copy()
    junk = np.full_like(origins, np.nan)
    junk[0] = origins[0]
    assert np.array_equal(dispatcher.test_tiles(junk, directions, scan, shared_origin=True), own_rows)
    assert (own_rows != NO_CELL).mean() > 0.5  # most rays hit: the comparison has teeth
    # The host's answers read that origin alone too.
    answers = []
    for rows, shared in ((origins, False), (junk, True)):
        out = (np.zeros(len(rows), np.uint8), np.zeros((len(rows), 3), np.int32), np.zeros(len(rows)))
        entry_answers(own_rows, *scan.packing, rows, shared, directions, *map(float, occ.shape[:2]), *out)
        answers.append(out)
    assert all(np.array_equal(a, b) for a, b in zip(*answers))
    assert np.isfinite(answers[1][2][answers[1][0] == VOXEL]).all()

    sent = []
    real_test_tiles = wgpu_scans.ScanDispatcher.test_tiles

    def spy(self, origins, directions, scan, shared_origin=False):
        sent.append(shared_origin)
        return real_test_tiles(self, origins, directions, scan, shared_origin)

    monkeypatch.setattr(wgpu_scans.ScanDispatcher, "test_tiles", spy)
    moved = origins.copy()
    moved[1::2] += [0.5, 0.0, 0.0]  # half the rays from a point half a cell east
    for rays_from, shared in ((origins, True), (moved, False)):
        sent.clear()
        fresh = Occupancy.build(voxels, occ.shape)  # its first scan goes in object order
        result = trace(fresh, rays_from - 0.5, directions, backend="wgpu", voxel_size=1.0)
        expected = numba_backend.trace_cells(occ, rays_from, directions, order="ray")
        assert result.info["order"] == "object" and sent == [shared]
        assert np.array_equal(result.kind, expected.kind) and np.array_equal(result.index, expected.index)


@pytest.mark.parametrize("order", ["object", "ray"])
def test_one_origin_broadcast_to_every_ray_answers_as_rows_do(forest, f64_backend, numba_backend, order):
    """rays_to_cells' one origin row broadcast to every ray: the shader's object order
    sends and reads that row, its ray order gets rows; the answers are numba's."""
    _, occ = forest
    cells, unit, bounds = pinhole_scan_cells()
    gpu = f64_backend.trace_cells(occ, cells, unit, order=order, block_bounds=bounds)
    assert gpu.info["order"] == order
    assert_same(numba_backend.trace_cells(occ, np.array(cells), unit, order="ray"), gpu)
    assert (gpu.kind == VOXEL).mean() > 0.5


@pytest.mark.parametrize("rays", ["scan", "fan"])
def test_every_pipeline_finds_the_same_hits(forest, f64_backend, numba_backend, rays, monkeypatch):
    """The object-order pipelines differ in where a tile's bounds come from (a uniform
    buffer, or storage: always past UNIFORM_TILES tiles) and in two constants, one ray
    per bin and one origin. On a pinhole scan (one ray per bin) and on a fan of rays
    from one point (several a bin) every pipeline finds the same hits, which answer as
    numba's ray order does."""
    from ladartui.tracing import wgpu_scans
    from ladartui.tracing.config import OBJECT_ORDER_TILE_SHIFT
    from ladartui.tracing.scan_rays import cone_frame, ray_bounds
    from ladartui.tracing.shader_scan import entry_answers, prepare_shader_scan

    _, occ = forest
    if rays == "scan":
        origins, directions = one_scan([120, 120, 20], 45.0, 0.7, 300.0)
    else:
        _, _, _, origins, directions = random_scan(np.random.default_rng(3), 0.0, n=4000)
        origins += [90.0, 90.0, 0.0]  # over the forest
    origins[:] = origins[0]
    frame = cone_frame(origins, directions, np.concatenate(ray_bounds(origins, directions)))
    scan = prepare_shader_scan(occ, origins, directions, frame, np.inf, OBJECT_ORDER_TILE_SHIFT)
    assert (len(scan.ray_tiles) == 0) == (rays == "scan")
    f64_backend.trace_cells(occ, origins, directions, order="object")  # opens the device
    dispatcher = f64_backend._scans
    # lavapipe's way by default; a GPU's way keeps storage
    assert dispatcher.uniform_tile_bounds == (f64_backend.describe()["adapter_type"] == "CPU")
    used = []
    real_pipeline = wgpu_scans.ScanDispatcher._pipeline

    def spy(self, *key):
        used.append(key)
        return real_pipeline(self, *key)

    monkeypatch.setattr(wgpu_scans.ScanDispatcher, "_pipeline", spy)
    monkeypatch.setattr(dispatcher, "uniform_tile_bounds", True)
    found = [dispatcher.test_tiles(origins, directions, scan, shared).copy() for shared in (True, False)]
    monkeypatch.setattr(dispatcher, "uniform_tile_bounds", False)
    found += [dispatcher.test_tiles(origins, directions, scan, shared).copy() for shared in (True, False)]
    monkeypatch.setattr(dispatcher, "uniform_tile_bounds", True)
    monkeypatch.setattr(wgpu_scans, "UNIFORM_TILES", len(scan.tile_starts) - 2)  # one tile too many
    found.append(dispatcher.test_tiles(origins, directions, scan, True).copy())
    one_per_bin = rays == "scan"
    assert used == [
        (True, one_per_bin, True),
        (True, one_per_bin, False),
        (False, one_per_bin, True),
        (False, one_per_bin, False),
        (False, one_per_bin, True),
    ]
    assert all(np.array_equal(found[0], other) for other in found[1:])
    assert (found[0] != NO_CELL).mean() > 0.3  # the comparison has teeth
    expected = numba_backend.trace_cells(occ, origins, directions, order="ray")
    n = len(origins)
    answers = (np.zeros(n, np.uint8), np.zeros((n, 3), np.int32), np.zeros(n))
    entry_answers(found[0], *scan.packing, origins, False, directions, *map(float, occ.shape[:2]), *answers)
    assert_same(expected, type(expected)(*answers, {}))


def test_a_storage_cap_under_64_kib_leaves_the_tile_ends_whole(forest, f64_backend, numba_backend):
    """Tests cap storage bindings (here at 32 KiB, which a small scan's arrays fit);
    the uniform buffer of tile ends is still bound whole, at the 64 KiB its shader
    declares, and the scan runs in object order with numba's answers."""
    from ladartui.tracing.wgpu_backend import WgpuBackend

    _, occ = forest
    capped = WgpuBackend(max_binding_bytes=32 * 1024)
    origins, directions = one_scan(
        [120, 120, 20], 45.0, 0.7, 300.0, sensor=Sensor(grid=8, ray_grid=4, fov=2.0)
    )
    gpu = gpu_object_order(capped, occ, origins, directions)
    assert capped._scans.uniform_tile_bounds == (capped.describe()["adapter_type"] == "CPU")
    assert_same(numba_backend.trace_cells(occ, origins, directions, order="ray"), gpu)
    assert (gpu.kind == VOXEL).any()
