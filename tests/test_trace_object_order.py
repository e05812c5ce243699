"""Object-order tracing of scans (tracing/object_order.py): the same answers as ray order,
bit for bit, wherever it is used, and ray order wherever it cannot be."""

import math

import numpy as np
import pytest

from ladartui.flight import ScanPose, aim_at
from ladartui.scene.occupancy import Occupancy
from ladartui.sensor import Sensor
from ladartui.tracing import trace
from ladartui.tracing.backend import GROUND, MISS, VOXEL
from ladartui.tracing.config import SCAN_BLOCK
from ladartui.tracing.numba_backend import NumbaBackend
from ladartui.tracing.prepare import one_origin
from ladartui.tracing.reference import reference_trace_cells
from ladartui.tracing.scan_rays import cone_frame, ray_bounds
from ladartui.tracing.tile_tests import trace_scan
from scans import assert_same, forest_scene, numpy_with_junk_empty, one_scan, pinhole_scan_cells, random_scan


@pytest.fixture(scope="module")
def forest():
    return forest_scene()


def block_bounds(origins, directions):
    """What rays_to_cells finds per SCAN_BLOCK rays, for rays already in cell space."""
    rows = []
    for a in range(0, len(origins), SCAN_BLOCK):
        rows.append(np.concatenate(ray_bounds(origins[a : a + SCAN_BLOCK], directions[a : a + SCAN_BLOCK])))
    return np.array(rows)


def both_orders(backend, occ, origins, directions):
    """Ray order, and object order (which must agree with and without the block bounds
    that tell it when every ray starts at one point)."""
    ray = backend.trace_cells(occ, origins, directions, order="ray")
    obj = backend.trace_cells(occ, origins, directions, order="object")
    bounds = block_bounds(origins, directions)
    assert_same(obj, backend.trace_cells(occ, origins, directions, order="object", block_bounds=bounds))
    return ray, obj


@pytest.mark.parametrize("depression", [1.5, 10.0, 45.0, 89.9, 90.0])
@pytest.mark.parametrize("slant", [150.0, 600.0])
def test_scans_match_ray_order_bit_for_bit(forest, numba_backend, depression, slant):
    _, occ = forest
    rng = np.random.default_rng(int(depression * 10 + slant))
    for _ in range(3):
        aim = [rng.uniform(60, 180), rng.uniform(60, 180), rng.uniform(0, 40)]
        origins, directions = one_scan(aim, depression, rng.uniform(0, 2 * math.pi), slant)
        ray, obj = both_orders(numba_backend, occ, origins, directions)
        # Low looks put the aircraft among the tree tops, where ray order takes over;
        # well above them it is always object order.
        above = origins[0, 2] > occ.zmax + 40
        assert obj.info["order"] == "object" or not above
        assert ray.info["order"] == "ray"
        assert_same(ray, obj)
        assert (obj.kind == VOXEL).sum() > len(obj.kind) // 10  # the scans do see the forest


def test_scan_matches_the_reference(forest, numba_backend):
    voxels, occ = forest
    # A wide view: voxels, the ground through gaps, and misses past the scene's edge.
    origins, directions = one_scan(
        [120, 120, 20], 45.0, 0.3, 200.0, sensor=Sensor(grid=16, ray_grid=4, fov=40.0)
    )
    obj = numba_backend.trace_cells(occ, origins, directions, order="object")
    assert obj.info["order"] == "object"
    pick = np.random.default_rng(0).choice(len(origins), 800, replace=False)
    ref = reference_trace_cells(voxels, occ.shape, origins[pick], directions[pick])
    assert np.array_equal(obj.kind[pick], ref.kind)
    assert np.array_equal(obj.index[pick], ref.index)
    assert np.array_equal(obj.t[pick], ref.t)
    assert {MISS, VOXEL, GROUND} <= set(np.unique(ref.kind).tolist())


def test_origins_spread_over_the_focal_plane_are_covered(forest, numba_backend):
    # Origins spread almost a cell each way: rays from the edges meet voxels that rays
    # from the centre, with the same directions, pass by. Without growing each voxel
    # by the spread, object order would miss those hits.
    _, occ = forest
    rng = np.random.default_rng(5)
    for _ in range(4):
        aim = [rng.uniform(60, 180), rng.uniform(60, 180), rng.uniform(0, 40)]
        origins, directions = one_scan(aim, rng.uniform(30, 90), rng.uniform(0, 6.3), 150.0)
        origins = origins + rng.uniform(-0.9, 0.9, size=origins.shape)
        ray, obj = both_orders(numba_backend, occ, origins, directions)
        assert obj.info["order"] == "object"
        assert_same(ray, obj)


def test_random_scenes_and_jittered_origins(numba_backend):
    rng = np.random.default_rng(11)
    for trial in range(12):
        vox, shape, occ, origins, directions = random_scan(rng, 0.4)
        if trial % 3 == 0:
            origins = np.round(origins)  # on grid planes, edges and corners
        ray, obj = both_orders(numba_backend, occ, origins, directions)
        assert_same(ray, obj)
        if obj.info["order"] == "object":
            pick = rng.choice(len(origins), 200, replace=False)
            ref = reference_trace_cells(vox, shape, origins[pick], directions[pick])
            assert np.array_equal(obj.t[pick], ref.t) and np.array_equal(obj.index[pick], ref.index)


def test_axis_aligned_rays_and_rays_in_cell_faces(numba_backend):
    # Rays with zero components from origins on cell corners, edges and centres over a
    # slab with holes: rays lying in a plane of cell faces enter no voxel.
    shape = (16, 16, 12)
    grid = np.stack(np.meshgrid(np.arange(16), np.arange(16), np.arange(3, 6), indexing="ij"), -1).reshape(
        -1, 3
    )
    keep = (grid[:, 0] * 7 + grid[:, 1] * 3 + grid[:, 2]) % 5 != 0
    occ = Occupancy.build(grid[keep], shape)
    steps = np.arange(-4, 5) * 0.03
    fan = np.array([[a, b, -1.0] for a in steps for b in steps])
    fan /= np.linalg.norm(fan, axis=1, keepdims=True)
    corners = np.array([[x, y, 40.0] for x in (7.5, 7.75, 8.0, 8.25, 8.5) for y in (7.5, 8.0, 8.5)])
    origins = np.repeat(corners, len(fan), axis=0)
    directions = np.tile(fan, (len(corners), 1))
    ray, obj = both_orders(numba_backend, occ, origins, directions)
    assert obj.info["order"] == "object"
    assert_same(ray, obj)
    ref = reference_trace_cells(grid[keep], shape, origins, directions)
    assert np.array_equal(obj.kind, ref.kind) and np.array_equal(obj.t, ref.t)
    in_face = ((origins[:, 0] % 1 == 0) & (directions[:, 0] == 0)) | (
        (origins[:, 1] % 1 == 0) & (directions[:, 1] == 0)
    )
    assert in_face.sum() > 20 and (obj.kind[in_face] != VOXEL).all()
    assert (obj.kind[~in_face] == VOXEL).sum() > 100


def test_far_aircraft(forest, numba_backend):
    # 10 km away (40,000 cells): projected rectangles and depth bounds stay conservative.
    _, occ = forest
    origins, directions = one_scan(
        [120, 120, 10], 30.0, 1.0, 40000.0, sensor=Sensor(grid=16, ray_grid=4, fov=0.05)
    )
    ray, obj = both_orders(numba_backend, occ, origins, directions)
    assert obj.info["order"] == "object"
    assert_same(ray, obj)
    assert (obj.kind == VOXEL).any()


def test_ray_order_where_object_order_cannot_or_should_not(forest, numba_backend):
    _, occ = forest
    rng = np.random.default_rng(2)
    # Origins scattered over the scene: no scan.
    origins = rng.uniform([0, 0, 80], [240, 240, 120], size=(5000, 3))
    directions = np.tile([0.0, 0.6, -0.8], (5000, 1))
    assert cone_frame(origins, directions) is None
    assert numba_backend.trace_cells(occ, origins, directions).info["order"] == "ray"
    # Directions over a wide cone (beyond 60 degrees of their mean).
    wide = rng.normal(size=(5000, 3))
    wide[:, 2] = -np.abs(wide[:, 2])
    wide /= np.linalg.norm(wide, axis=1, keepdims=True)
    same_origin = np.tile([120.0, 120.0, 150.0], (5000, 1))
    result = numba_backend.trace_cells(occ, same_origin, wide, order="object")
    assert result.info["order"] == "ray"
    # The aircraft among the trees: bricks on both sides of its plane.
    inside = np.tile([120.0, 120.0, 30.0], (5000, 1))
    fan = np.tile([0.0, 0.0, -1.0], (5000, 1)) + rng.normal(size=(5000, 3)) * 0.05
    fan /= np.linalg.norm(fan, axis=1, keepdims=True)
    ray, obj = both_orders(numba_backend, occ, inside, fan)
    assert obj.info["order"] == "ray"
    assert_same(ray, obj)
    # Far away with a wide view, most of the forest in view: ray order is the cheaper
    # (auto), while forcing object order still gives the same answers.
    origins, directions = one_scan(
        [120, 120, 10], 60.0, 0.0, 2000.0, sensor=Sensor(grid=64, ray_grid=1, fov=8.0)
    )
    auto = numba_backend.trace_cells(occ, origins, directions)
    assert auto.info["order"] == "ray"
    assert_same(auto, numba_backend.trace_cells(occ, origins, directions, order="object"))


def test_numba_takes_object_order_for_a_scan_of_over_a_voxel_in_view_per_ray(forest):
    """A default-size sensor's scan at 45 degrees with 2 x 2 rays a detector (about 1.3
    occupied voxels in view per ray) went to ray order, which took 1.5-2.5x object
    order's time on the generated scenes: numba's limit was 0.6 voxels a ray."""
    _, occ = forest
    sensor = Sensor(grid=128, ray_grid=2, fov=30.0)
    origins, directions = one_scan([120, 120, 4], 45.0, 0.7, 340.0, sensor=sensor)
    fresh = NumbaBackend()  # no order learned yet: object order is tried first where it may run
    result = fresh.trace_cells(occ, origins, directions)
    assert result.info["order"] == "object"
    assert_same(result, fresh.trace_cells(occ, origins, directions, order="ray"))


def test_trace_reports_the_order_and_metres(forest):
    voxels, occ = forest
    from ladartui.scene.model import Scene

    scene = Scene(voxels, voxels[:0], 0.25, shape=occ.shape)
    sensor = Sensor(grid=32, ray_grid=4, fov=5.0)  # 16,384 rays: few voxels in view per ray
    pose = aim_at(ScanPose(30.0, -10.0, 45.0), [30.0, 30.0, 5.0])
    origins, directions, _ = sensor.rays(pose)
    result = trace(scene, origins, directions, backend="numba")
    assert result.info["order"] == "object"
    cells = NumbaBackend().trace_cells(occ, origins / 0.25 + 0.5, directions, order="ray")
    assert np.array_equal(result.kind, cells.kind)
    assert np.allclose(result.range[cells.kind == VOXEL], cells.t[cells.kind == VOXEL] * 0.25)


def test_a_pencil_of_rays_just_above_the_canopy(numba_backend):
    # A field of view of 1e-14 degrees: bins far narrower than any voxel, and voxels
    # beside the aircraft project far out (tiny depth), so rectangles span astronomically
    # many bins. They must be clamped: as int64 they overflowed and voxels went missing.
    # (Scans with bricks across the aircraft's plane close by go to ray order.)
    orders = []
    for seed in range(6):
        rng = np.random.default_rng(seed)
        vox = np.column_stack(
            [rng.integers(0, 64, 3000), rng.integers(0, 64, 3000), rng.integers(40, 64, 3000)]
        )
        occ = Occupancy.build(vox, (64, 64, 80))
        sensor = Sensor(grid=16, ray_grid=4, fov=1e-14)
        for _ in range(5):
            x, y = rng.uniform(10, 54, 2)
            pose = aim_at(
                ScanPose(x, y, 64.0 + rng.uniform(0.05, 3)),
                [x + rng.uniform(-3, 3), y + rng.uniform(-3, 3), 0.0],
            )
            origins, directions, _ = sensor.rays(pose)
            ray, obj = both_orders(numba_backend, occ, origins, directions)
            orders.append(obj.info["order"])
            assert_same(ray, obj)
    assert orders.count("object") >= 20


def test_directions_that_are_not_unit_go_in_ray_order(forest, numba_backend):
    _, occ = forest
    origins, directions = one_scan([120, 120, 10], 45.0, 1.0, 200.0)
    result = numba_backend.trace_cells(occ, origins, 3.0 * directions, order="object")
    assert result.info["order"] == "ray"
    assert_same(result, numba_backend.trace_cells(occ, origins, 3.0 * directions, order="ray"))


@pytest.mark.parametrize("threads", [1, 2, 64])
@pytest.mark.parametrize("shift, tiles", [(4, 6), (1, 300)])
def test_tile_lists_keep_the_nearest_first_order(shift, tiles, threads):
    # 16: the numba tiles (64 runs of voxels); 2: the shader's, many tiles (fewer runs).
    from ladartui.tracing.tile_lists import voxels_per_tile

    rng = np.random.default_rng(4)
    n, tile = 5000, 1 << shift
    vox = np.zeros((n, 7), np.int64)
    low = rng.integers(0, tile * tiles, (n, 2))
    vox[:, 3], vox[:, 5] = low[:, 0], low[:, 1]
    vox[:, 4] = np.minimum(low[:, 0] + rng.integers(-1, 2 * tile, n), tile * tiles - 1)
    vox[:, 6] = np.minimum(low[:, 1] + rng.integers(0, 2 * tile, n), tile * tiles - 1)
    starts, listed = voxels_per_tile(vox, tiles, shift, threads, np.arange(n))
    expected = [[] for _ in range(tiles * tiles)]
    for e in range(n):
        if vox[e, 3] <= vox[e, 4]:
            for tj in range(vox[e, 5] // tile, vox[e, 6] // tile + 1):
                for ti in range(vox[e, 3] // tile, vox[e, 4] // tile + 1):
                    expected[tj * tiles + ti].append(e)
    assert sum(map(len, expected)) == len(listed) > n
    for at, voxels in enumerate(expected):
        assert listed[starts[at] : starts[at + 1]].tolist() == voxels
    # With a payload (the shader's words), each place holds its voxel's payload instead.
    payload = rng.integers(0, 1 << 63, n, dtype=np.uint64) * 2 + 1
    paid_starts, paid = voxels_per_tile(vox, tiles, shift, threads, payload)
    assert paid.dtype == np.uint64 and np.array_equal(paid_starts, starts)
    assert np.array_equal(paid, payload[listed])


def test_bins_are_numbered_tile_by_tile():
    # A tile's rays are contiguous after the sort, and so is each of its rows.
    from ladartui.tracing.scan_rays import bin_key

    nb, shift = 37, 2
    tile = 1 << shift
    tiles = -(-nb // tile)
    keys = np.array([[bin_key(i, j, tiles, shift) for i in range(nb)] for j in range(nb)])
    assert len(np.unique(keys)) == nb * nb and keys.max() < (tiles * tile) ** 2
    for j in range(nb):
        for i0 in range(0, nb, tile):
            row = keys[j, i0 : min(nb, i0 + tile)]
            assert np.array_equal(row, row[0] + np.arange(len(row)))
    tile_of = (np.arange(nb)[None, :] // tile) + tiles * (np.arange(nb)[:, None] // tile)
    assert np.array_equal(keys // (tile * tile), tile_of)


@pytest.mark.parametrize("duplicate", [False, True])
def test_a_whole_scan_sorts_by_scatter_as_the_counting_sort_does(duplicate):
    # One ray per bin (a whole scan over its own ray grid): the parallel scatter; a ray
    # moved into its neighbour's bin leaves a bin empty: the counting sort. Same result.
    from ladartui.tracing import scan_rays as sr

    origins, directions = one_scan(
        [100, 100, 10], 60.0, 0.4, 300.0, sensor=Sensor(grid=16, ray_grid=4, fov=5.0)
    )
    if duplicate:
        directions[5] = directions[6]
    centre, _, axis, u, v = cone_frame(origins, directions)
    nb = 64
    p, q, grid = sr.ray_grid(directions, axis, u, v, nb)
    scattered = np.empty(nb * nb, np.uint32)
    assert sr._scatter_one_per_bin(p, q, grid, nb, 4, scattered, np.empty(2)) == (not duplicate)
    starts, order = sr._sort_into_bins(p, q, grid, nb, 4)
    if not duplicate:
        assert np.array_equal(scattered, order)
    got_order, got_starts, _ = sr.bin_order(p, q, grid, nb, 4)
    assert np.array_equal(got_order, order) and got_order.dtype == order.dtype == np.uint32
    assert len(got_starts) == (len(starts) if duplicate else 0)
    assert np.array_equal(np.diff(starts) == 1, np.ones(nb * nb, bool)) == (not duplicate)


@pytest.mark.parametrize("duplicate", [False, True])
def test_a_scan_traced_by_bin_order_matches_ray_order(duplicate, numba_backend):
    # The tile tests read rays through the bin order: without copies when every bin
    # holds one ray (bin_order's empty starts), through the starts when one holds two.
    from ladartui.tracing import scan_rays as sr

    _, occ = forest_scene()
    origins, directions = one_scan(
        [100, 100, 10], 60.0, 0.4, 300.0, sensor=Sensor(grid=64, ray_grid=4, fov=6.0)
    )
    if duplicate:
        directions[5] = directions[6]
    frame = cone_frame(origins, directions)
    nb = int(math.ceil(math.sqrt(len(origins))))
    p, q, grid = sr.ray_grid(directions, frame[2], frame[3], frame[4], nb)
    order, starts, measured = sr.bin_order(p, q, grid, nb, 4)
    assert (len(starts) == 0) == (not duplicate)
    # Every ray within the measured slack of its bin's middle; a sensor's grid is nearly even.
    i, j = np.floor((p - grid[0]) / grid[1]), np.floor((q - grid[2]) / grid[3])
    assert np.abs((p - grid[0]) / grid[1] - i - 0.5).max() <= measured[4]
    assert np.abs((q - grid[2]) / grid[3] - j - 0.5).max() <= measured[5]
    assert measured[4:].max() < (0.1 if not duplicate else 0.6)
    assert np.array_equal(np.sort(order), np.arange(len(origins)))
    ray, obj = both_orders(numba_backend, occ, origins, directions)
    assert obj.info["order"] == "object"
    assert_same(ray, obj)
    assert (obj.kind == VOXEL).sum() > len(obj.kind) // 10


@pytest.mark.parametrize("axis", [(0.3, 0.4, -0.866), (-0.3, -0.4, 0.866), (0.6, -0.1, -0.79)])
def test_voxels_of_a_brick_come_front_first(axis):
    # Along a ray every cell coordinate moves with its direction's sign, so listing
    # layers, rows and cells in the axis's direction puts each voxel after every voxel
    # a ray with the axis's signs can meet before it.
    from ladartui.tracing import object_order as oo

    rng = np.random.default_rng(7)
    cells = rng.choice(512, 200, replace=False)
    voxels = np.stack([8 + cells % 8, 16 + (cells // 8) % 8, 24 + cells // 64], axis=1)
    occ = Occupancy.build(voxels, (64, 64, 64))
    a = np.array(axis) / np.linalg.norm(axis)
    u = np.cross(a, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    centre = np.array([12.0, 20.0, 28.0]) - 500.0 * a
    found, near, ok = oo.bricks_in_view(
        centre,
        np.zeros(3),
        a,
        u,
        v,
        np.array([-1.0, 0.5, -1.0, 0.5, 0.5, 0.5]),
        4,
        occ.root,
        occ.regions,
        occ.tiles,
        occ.root_origin.astype(np.int64),
        occ.root_dims.astype(np.int64),
    )
    assert ok and len(found) == 1
    first = oo.voxel_starts(found, occ.bricks)
    vox, _ = oo.emit_voxels(
        found,
        near,
        first,
        occ.bricks,
        centre,
        np.zeros(3),
        a,
        u,
        v,
        np.array([-1.0, 0.5, -1.0, 0.5, 0.5, 0.5]),
        4,
    )
    assert sorted(map(tuple, vox[:, :3].tolist())) == sorted(map(tuple, voxels.tolist()))
    ahead = vox[:, :3] * np.where(a < 0, -1, 1)  # coordinates in the order the axis meets them
    keys = [(z, y, x) for x, y, z in ahead.tolist()]
    assert keys == sorted(keys)


@pytest.mark.parametrize("tiles", [1, 2, 64, 1024, 1089, 4096])
def test_spread_stride_visits_every_tile_once_and_spreads_each_thread_share(tiles):
    from ladartui.tracing.object_order import spread_stride

    stride = spread_stride(tiles)
    visit = (np.arange(tiles) * stride) % tiles
    assert np.array_equal(np.sort(visit), np.arange(tiles))
    if tiles >= 64:  # each half of the steps (one of two threads) takes tiles from both halves
        for half in (visit[: tiles // 2], visit[tiles // 2 :]):
            assert 0.3 < (half < tiles // 2).mean() < 0.7


@pytest.mark.parametrize("order, method", [("object", "exact"), ("ray", "exact"), ("auto", "march")])
def test_every_ray_gets_an_answer_written(monkeypatch, order, method):
    # The backend's output arrays start uninitialised: every path must write every
    # ray. Junk in the new arrays shows up as a difference from a clean run.
    import ladartui.tracing.numba_backend as nb_module

    _, occ = forest_scene()
    origins, directions = one_scan([100, 100, 10], 50.0, 1.0, 300.0)
    clean = NumbaBackend().trace_cells(occ, origins, directions, order=order, method=method)

    monkeypatch.setattr(nb_module, "np", numpy_with_junk_empty())
    dirty = NumbaBackend().trace_cells(occ, origins, directions, order=order, method=method)
    assert_same(clean, dirty)
    assert clean.info["order"] == ("object" if order == "object" else "ray")


@pytest.mark.parametrize(
    "nb, shift",
    [(512, 6), (256, 6), (128, 5), (64, 4), (400, 4), (401, 6), (96, 4), (24, 2), (3, 2)],
)
def test_tiles_are_as_big_as_divide_the_bins_into_at_least_four_a_side(nb, shift):
    # 64 x 64 at most (a row is one int64 mask); dividing nb keeps the parallel scatter.
    from ladartui.tracing.tile_tests import tile_shift_for

    assert tile_shift_for(nb) == shift


def test_a_scan_where_every_ray_hits_stops_tiles_early_and_still_matches(numba_backend):
    # A roof of voxels over deep cover: every ray hits, so tiles stop once the voxels
    # still to come lie behind every hit; the answers are ray order's.
    rng = np.random.default_rng(3)
    roof = np.stack(np.meshgrid(np.arange(96), np.arange(96), [40], indexing="ij"), -1).reshape(-1, 3)
    cover = rng.integers([0, 0, 0], [96, 96, 40], (60000, 3))
    occ = Occupancy.build(np.concatenate([roof, cover]), (96, 96, 60))
    origins, directions = one_scan(
        [48, 48, 40], 70.0, 0.3, 400.0, sensor=Sensor(grid=64, ray_grid=4, fov=4.0)
    )
    ray, obj = both_orders(numba_backend, occ, origins, directions)
    assert obj.info["order"] == "object"
    assert (obj.kind == VOXEL).all() and (obj.index[:, 2] == 40).mean() > 0.99
    assert_same(ray, obj)


@pytest.mark.parametrize("depression", [35.0, 90.0])
def test_bricks_in_view_are_every_brick_a_ray_can_meet_nearest_first(depression):
    # The walk over root cells and regions runs in parallel; its list must be every
    # non-empty brick whose own test passes (whatever the threads), nearest first.
    import numba

    from ladartui.tracing import object_order as oo
    from ladartui.tracing.scan_rays import scan_grid

    rng = np.random.default_rng(11)
    shape = (1100, 700, 90)
    voxels = np.unique(rng.integers(0, shape, (20000, 3)), axis=0)
    occ = Occupancy.build(voxels, shape)
    assert len(occ.root_dims) == 3 and int(np.prod(occ.root_dims)) >= 4  # several root cells
    origins, directions = one_scan(
        [550, 350, 40], depression, 0.4, 900.0, sensor=Sensor(grid=16, ray_grid=2, fov=40.0)
    )
    frame = cone_frame(origins, directions)
    nb, _, _, grid = scan_grid(directions, frame)
    args = (*frame, grid, nb, occ.root, occ.regions, occ.tiles)
    args += (occ.root_origin.astype(np.int64), occ.root_dims.astype(np.int64))
    found, near, ok = oo.bricks_in_view(*args)
    assert ok and 50 < len(found)
    assert np.all(np.diff(near) >= 0)
    expected = {}
    for corner in np.unique(voxels // 8, axis=0) * 8:
        i0, i1, _, _, state, brick_near = oo.box_bins(*corner.tolist(), 8, *frame, grid, nb)
        assert state != -1
        if state == 1 and i0 <= i1:
            expected[tuple(corner.tolist())] = brick_near
    assert len(expected) < len(np.unique(voxels // 8, axis=0))  # some are out of view
    assert {tuple(c) for c in found[:, :3].tolist()} == set(expected)
    assert all(expected[tuple(c)] == n for c, n in zip(found[:, :3].tolist(), near))
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        alone = oo.bricks_in_view(*args)
    finally:
        numba.set_num_threads(threads)
    assert np.array_equal(alone[0], found) and np.array_equal(alone[1], near)


def test_trace_tells_the_tile_tests_when_rays_share_one_origin(forest, monkeypatch):
    from ladartui.tracing import numba_backend as nb

    voxels, occ = forest
    origins, directions = one_scan([120, 120, 20], 45.0, 0.7, 300.0)
    told = []

    def spy(*args, shared_origin=False):
        told.append(shared_origin)
        return trace_scan(*args, shared_origin=shared_origin)

    monkeypatch.setattr(nb, "trace_scan", spy)
    pinhole = np.repeat(origins[:1], len(origins), axis=0)
    for rays_from, shared in ((pinhole, True), (origins, False)):
        told.clear()
        fresh = Occupancy.build(voxels, occ.shape)  # its first scan goes in object order
        result = trace(fresh, rays_from, directions, backend="numba")
        assert result.info["order"] == "object" and told == [shared]


def test_rays_from_one_origin_read_that_origin_alone(forest, numba_backend):
    """With a shared origin the tile tests read orig[0] for every ray: answers as from
    the real origins though every other row holds NaN; so do rays from two origins,
    whose bounds do not say shared."""
    _, occ = forest
    origins, directions = one_scan([120, 120, 20], 45.0, 0.7, 300.0)
    origins[:] = origins[0]  # a pinhole camera (the sensor's spread over its focal plane)
    bounds = block_bounds(origins, directions)
    assert one_origin(bounds, 0, len(origins))
    ray = numba_backend.trace_cells(occ, origins, directions, order="ray")
    junk = np.full_like(origins, np.nan)
    junk[0] = origins[0]
    nx, ny = float(occ.shape[0]), float(occ.shape[1])
    n = len(origins)
    answers = (np.empty(n, np.uint8), np.empty((n, 3), np.int32), np.empty(n))
    frame = cone_frame(origins, directions, bounds[0])
    assert trace_scan(occ, junk, directions, frame, np.inf, nx, ny, *answers, shared_origin=True)
    assert_same(ray, type(ray)(*answers, {}))
    moved = origins.copy()
    moved[1::2] += [0.5, 0.0, 0.0]  # half the rays from a point half a cell east
    assert not one_origin(block_bounds(moved, directions), 0, len(moved))
    ray, obj = both_orders(numba_backend, occ, moved, directions)
    assert obj.info["order"] == "object"
    assert_same(ray, obj)


def test_numba_times_ray_order_on_a_sample_of_a_scan(forest, monkeypatch):
    # An occupancy's second scan is ray order's first turn: about a sixteenth of the
    # rays go through the ray-order kernel for its time, object order answers all.
    from ladartui.tracing import numba_backend as nb
    from ladartui.tracing.order_choice import RAY_SAMPLE

    voxels, occ = forest
    origins, directions = one_scan([120, 120, 20], 45.0, 0.7, 300.0)
    kernel_rays = []
    real_kernel = nb._exact_kernel

    def counting(orig, *args):
        kernel_rays.append(len(orig))
        return real_kernel(orig, *args)

    monkeypatch.setattr(nb, "_exact_kernel", counting)
    fresh = Occupancy.build(voxels, occ.shape)
    backend = NumbaBackend()
    first = backend.trace_cells(fresh, origins, directions)
    assert first.info["order"] == "object" and kernel_rays == []
    second = backend.trace_cells(fresh, origins, directions)
    assert second.info["order"] == "object"
    assert sum(kernel_rays) == pytest.approx(RAY_SAMPLE * len(origins), abs=4)
    assert_same(first, second)


@pytest.mark.parametrize("order", ["object", "ray"])
def test_one_origin_broadcast_to_every_ray_answers_as_rows_do(forest, numba_backend, order):
    """rays_to_cells gives a pinhole scan's origins as one row broadcast: both orders read
    it (object order its one row, ray order rows made per block) with the same answers
    as from rows of their own."""
    _, occ = forest
    cells, unit, bounds = pinhole_scan_cells()
    shared = numba_backend.trace_cells(occ, cells, unit, order=order, block_bounds=bounds)
    rows = numba_backend.trace_cells(occ, np.array(cells), unit, order=order, block_bounds=bounds)
    assert shared.info["order"] == rows.info["order"] == order
    assert_same(rows, shared)
    assert (shared.kind == VOXEL).mean() > 0.5
