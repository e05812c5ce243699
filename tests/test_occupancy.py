"""Occupancy: the sparse hierarchy answers membership exactly and grows with content only."""

import numpy as np
import pytest

from ladartui.errors import FieldError
from ladartui.scene.occupancy import Occupancy


def _random_scene(rng, shape, n):
    return np.unique(rng.integers(0, shape, size=(n, 3)), axis=0)


def test_listed_voxels_are_occupied_and_others_are_not():
    rng = np.random.default_rng(3)
    shape = (700, 600, 90)  # spans several 512-voxel root cells
    vox = _random_scene(rng, shape, 20_000)
    occ = Occupancy.build(vox, shape)
    assert occ.count == len(vox)
    assert occ.contains(vox).all()
    probes = rng.integers(0, shape, size=(50_000, 3))
    listed = set(map(tuple, vox.tolist()))
    expected = np.array([tuple(p) in listed for p in probes.tolist()])
    assert np.array_equal(occ.contains(probes), expected)


def test_duplicates_counted_once_and_bounds():
    vox = np.array([[5, 6, 7], [5, 6, 7], [1, 2, 3], [9, 0, 4]])
    occ = Occupancy.build(vox, (10, 10, 10))
    assert occ.count == 3
    assert occ.bbox_lo.tolist() == [1, 0, 3]
    assert occ.bbox_hi.tolist() == [10, 7, 8]
    assert occ.zmax == 7
    # Neighbours of listed voxels, outside the scene and negative indices are empty.
    assert not occ.contains([[5, 6, 8], [4, 6, 7], [-1, 0, 0], [100, 0, 0]]).any()


def test_empty_scene():
    occ = Occupancy.build(np.zeros((0, 3), int), (8, 8, 8))
    assert occ.count == 0 and occ.zmax == -1 and occ.nbytes == 0
    assert not occ.contains([[0, 0, 0]]).any()


def test_default_shape_from_voxels():
    occ = Occupancy.build(np.array([[3, 4, 5]]))
    assert occ.shape == (4, 5, 6)


def test_node_counts_match_distinct_cells():
    rng = np.random.default_rng(5)
    vox = _random_scene(rng, (300, 300, 100), 5_000)
    occ = Occupancy.build(vox, (300, 300, 100))
    assert occ.n_bricks == len(np.unique(vox >> 3, axis=0))
    assert occ.n_tiles == len(np.unique(vox >> 6, axis=0))
    assert occ.n_regions == len(np.unique(vox >> 9, axis=0))
    assert len(occ.bricks) == 16 * occ.n_bricks
    for array in (occ.root, occ.regions, occ.tiles, occ.bricks):
        assert array.dtype == np.uint32


def test_same_content_in_a_larger_extent_costs_no_more_memory():
    rng = np.random.default_rng(7)
    vox = _random_scene(rng, (400, 400, 120), 40_000) + [300, 200, 0]
    small = Occupancy.build(vox, (800, 700, 200))
    large = Occupancy.build(vox, (8000, 7000, 2000))
    assert large.nbytes <= 1.2 * small.nbytes
    # Moved far into the large extent, the content still costs about the same.
    far = Occupancy.build(vox + [5000, 6000, 0], (8000, 7000, 2000))
    assert far.nbytes <= 1.2 * small.nbytes
    assert far.contains(vox + [5000, 6000, 0]).all()


@pytest.mark.parametrize(
    "bad, shape",
    [
        (np.zeros((4, 2), int), (5, 5, 5)),
        (np.zeros((4, 3), float), (5, 5, 5)),
        (np.array([[0, 0, 5]]), (5, 5, 5)),
        (np.array([[-1, 0, 0]]), (5, 5, 5)),
    ],
)
def test_bad_voxel_lists_are_field_errors(bad, shape):
    with pytest.raises(FieldError):
        Occupancy.build(bad, shape)


def test_column_tops_give_the_highest_brick_of_each_brick_column():
    rng = np.random.default_rng(17)
    shape = (600, 300, 700)
    vox = _random_scene(rng, shape, 3_000)
    occ = Occupancy.build(vox, shape)
    q = (vox - occ.root_origin) >> 3
    width = 64 * int(occ.root_dims[0])
    expected = np.zeros(len(occ.columns), np.int64)
    for qx, qy, qz in q.tolist():
        expected[qx + width * qy] = max(expected[qx + width * qy], qz + 1)
    assert np.array_equal(occ.columns, expected)


def _layout_by_sorting(vox, lo, hi):
    """The layout docs/architecture.md gives, built the plain way: every voxel's key
    (root cell, region slot, tile slot, brick bit) made, sorted and counted."""
    root_origin = (lo >> 9) << 9
    root_dims = ((hi - 1) >> 9) - (lo >> 9) + 1
    rel = vox.astype(np.int64) - root_origin
    key = (rel[:, 0] >> 9) + root_dims[0] * ((rel[:, 1] >> 9) + root_dims[1] * (rel[:, 2] >> 9))
    for shift in (6, 3, 0):
        local = (
            ((rel[:, 0] >> shift) & 7) | (((rel[:, 1] >> shift) & 7) << 3) | (((rel[:, 2] >> shift) & 7) << 6)
        )
        key = (key << 9) | local
    key = np.unique(key)
    nodes = {}
    child_keys, child_of = np.unique(key >> 9, return_inverse=True)
    bit = key & 511
    bricks = np.zeros(len(child_keys) * 16, np.uint32)
    np.bitwise_or.at(bricks, child_of * 16 + (bit >> 5), np.uint32(1) << (bit & 31).astype(np.uint32))
    for level in ("tiles", "regions"):
        parent_keys, parent_of = np.unique(child_keys >> 9, return_inverse=True)
        slots = np.zeros(len(parent_keys) * 512, np.uint32)
        slots[parent_of * 512 + (child_keys & 511)] = np.arange(1, len(child_keys) + 1)
        nodes[level], child_keys = slots, parent_keys
    root = np.zeros(int(np.prod(root_dims)), np.uint32)
    root[child_keys] = np.arange(1, len(child_keys) + 1)
    return {"root": root, "regions": nodes["regions"], "tiles": nodes["tiles"], "bricks": bricks}, len(key)


@pytest.mark.parametrize("kind", ["dense", "scattered", "across root cells"])
def test_the_hierarchy_is_the_documented_layout_of_the_sorted_voxel_keys(kind):
    """The build sets each voxel's bit through its brick cell's number rather than
    sorting every voxel's key: the arrays must be those the sorted keys give."""
    rng = np.random.default_rng(21)
    if kind == "dense":
        vox = rng.integers(0, (90, 70, 40), size=(30_000, 3))
    elif kind == "scattered":
        vox = rng.integers(0, 40, size=(3_000, 3)) * np.array([37, 29, 11]) + 5
    else:
        vox = rng.integers(0, (1300, 1100, 600), size=(20_000, 3))
    vox = np.concatenate([vox, vox[:700]])  # with duplicates
    occ = Occupancy.build(vox.astype(np.int32))
    lo, hi = vox.min(axis=0), vox.max(axis=0) + 1
    expected, count = _layout_by_sorting(vox, lo, hi)
    assert occ.count == count
    for field, array in expected.items():
        assert np.array_equal(getattr(occ, field), array), field
    # a brick cell's empty-cube side is 0 exactly where a brick holds a voxel
    cells = np.unique((vox >> 3) - occ.cube_origin, axis=0)
    dims = occ.cube_dims
    sides = occ.cubes.reshape(int(dims[2]), int(dims[1]), int(dims[0]), 4)
    full = np.zeros(sides.shape[:3], bool)
    full[cells[:, 2], cells[:, 1], cells[:, 0]] = True
    assert np.array_equal((sides == 0).all(axis=3), full)


@pytest.mark.parametrize("dtype", [np.int32, np.int64, np.uint16, np.int16])
def test_the_same_voxels_in_any_integer_type_and_order_build_the_same_occupancy(dtype):
    rng = np.random.default_rng(8)
    vox = _random_scene(rng, (600, 200, 60), 4_000)
    shuffled = np.concatenate([vox, vox[:500]])[rng.permutation(len(vox) + 500)]  # repeats too
    reference = Occupancy.build(vox.astype(np.int64), (600, 200, 60))
    built = Occupancy.build(shuffled.astype(dtype), (600, 200, 60))
    assert built.count == len(vox)
    for field in ("root", "regions", "tiles", "bricks", "columns", "blocks", "cubes", "halo", "halo4"):
        assert np.array_equal(getattr(built, field), getattr(reference, field)), field
    # and the bricks are exactly the listed voxels
    assert built.contains(vox).all()
    assert int(sum(int(w).bit_count() for w in built.bricks)) == len(vox)


@pytest.mark.parametrize("kind", ["dense", "scattered", "one column"])
def test_the_memory_estimate_bounds_what_the_build_takes(kind):
    import tracemalloc

    from ladartui.resources import occupancy_bytes

    rng = np.random.default_rng(2)
    if kind == "dense":  # a forest-like slab
        vox = _random_scene(rng, (400, 400, 60), 300_000)
    elif kind == "scattered":  # every voxel in its own tile
        vox = rng.integers(0, 16, size=(2_000, 3)) * 64
    else:
        vox = np.column_stack([np.zeros(5000, int), np.zeros(5000, int), np.arange(5000)])
    Occupancy.build(np.array([[0, 0, 0], [9, 9, 9]]))  # kernels loaded before measuring
    tracemalloc.start()
    Occupancy.build(vox)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    estimate = occupancy_bytes(vox.min(axis=0), vox.max(axis=0) + 1, len(vox))
    assert peak <= estimate, (peak, estimate)


def test_build_holds_few_bytes_per_voxel_beyond_its_result():
    """The build's temporaries are a few bytes a brick cell of the box, none a voxel; a
    build holding a dozen per-voxel arrays took 125 bytes a voxel."""
    import tracemalloc

    rng = np.random.default_rng(11)
    shape = (600, 600, 60)
    vox = rng.integers(0, shape, size=(400_000, 3)).astype(np.int32)
    Occupancy.build(vox[:100], shape)  # kernels loaded first
    tracemalloc.start()
    try:
        occ = Occupancy.build(vox, shape)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    beyond_result = peak - occ.nbytes
    assert beyond_result < 16 * len(vox), f"{beyond_result / len(vox):.1f} bytes a voxel"


@pytest.mark.parametrize(
    "shape", ["abc", 5, (None, 1, 2), (20.7, 20, 20), (20, 20), (True, 20, 20), (-1, 20, 20)]
)
def test_a_shape_that_is_not_three_whole_numbers_is_named(shape):
    """'abc' raised ValueError from int(), 5 a TypeError, and 20.7 was cut to 20 without a word."""
    voxels = np.array([[1, 1, 1]], np.int32)
    with pytest.raises(FieldError, match=r"^shape = .*: expected three non-negative integers \(nx, ny, nz\)"):
        Occupancy.build(voxels, shape=shape)


def test_a_shape_of_whole_numbers_in_any_form_is_taken():
    voxels = np.array([[1, 1, 1]], np.int32)
    for shape in ((4, 4, 4), [4.0, 4, 4], np.array([4, 4, 4]), (np.int64(4), 4, 4)):
        assert Occupancy.build(voxels, shape=shape).shape == (4, 4, 4)


@pytest.mark.parametrize("ijk", ["abc", [[1, 2]], [1.5, 1, 1]])
def test_contains_names_what_is_no_voxel_index(ijk):
    occupancy = Occupancy.build(np.array([[1, 1, 1]], np.int32), shape=(4, 4, 4))
    with pytest.raises(FieldError, match=r"^ijk = .*: expected voxel indices \(\.\., 3\) of integers"):
        occupancy.contains(ijk)


def test_a_negative_index_is_named_as_such_not_against_a_shape_it_made():
    """Occupancy.build([[-1, 0, 0]]) said 'expected indices inside the scene shape
    [0, 1, 1]': a shape taken from the bad data itself."""
    with pytest.raises(FieldError) as caught:
        Occupancy.build(np.array([[3, 1, 2], [-1, 0, 0]]))
    assert str(caught.value) == "voxels[1] = (-1, 0, 0): expected non-negative voxel indices"
    with pytest.raises(FieldError) as caught:
        Occupancy.build(np.array([[0, 0, 5]]), (5, 5, 5))
    assert (
        str(caught.value) == "voxels[0] = (0, 0, 5): expected voxel indices inside the scene shape (5, 5, 5)"
    )


def test_a_few_voxels_over_a_huge_box_take_memory_for_what_they_hold(tmp_path, capsys):
    """116 voxels spread over 10 km x 10 km x 1 km at 0.25 m were refused: 'need about 420
    GiB for the tracing structures', the empty cubes and halos of the whole box; they are
    left out where the content is this small for its box."""
    from ladartui.cli import main
    from ladartui.resources import occupancy_bytes

    rng = np.random.default_rng(5)
    far = np.array([40000, 40000, 4000])
    vox = np.concatenate([[[0, 0, 0], far - 1], rng.integers(0, far, size=(114, 3))])
    estimate = occupancy_bytes(vox.min(axis=0), vox.max(axis=0) + 1, len(vox))
    import tracemalloc

    Occupancy.build(vox[:3])  # kernels loaded before measuring
    tracemalloc.start()
    occ = Occupancy.build(vox)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert occ.nbytes <= peak <= estimate < 150 * 2**20  # the column tops (4 bytes a brick column) and nodes
    assert occ.cubes is None and occ.halo is None and occ.halo4 is None
    assert occ.contains(vox).all() and occ.count == len(vox)
    path = tmp_path / "far.txt"
    path.write_text("".join(f"{x},{y},{z}\n" for x, y, z in vox))
    assert main(["info", str(path)]) == 0
    assert "occupancy" in capsys.readouterr().out


@pytest.mark.parametrize("seed", range(3))
def test_an_occupancy_without_the_box_sized_accelerations_traces_the_same(monkeypatch, seed):
    from ladartui import resources
    from ladartui.tracing.backend import get_backend

    rng = np.random.default_rng(seed)
    shape = (300, 260, 90)
    vox = _random_scene(rng, shape, 20_000)
    dense = Occupancy.build(vox, shape)
    monkeypatch.setattr(resources, "ACCELERATION_FLOOR", 0)
    monkeypatch.setattr(resources, "ACCELERATION_SHARE", 0)
    sparse = Occupancy.build(vox, shape)
    assert dense.cubes is not None and sparse.cubes is None
    assert dense.columns is not None and sparse.columns is None  # on the same terms
    for field in ("root", "regions", "tiles", "bricks", "blocks"):
        assert np.array_equal(getattr(sparse, field), getattr(dense, field)), field
    o = np.column_stack(
        [rng.uniform(-50, 350, 20_000), rng.uniform(-50, 310, 20_000), rng.uniform(60, 200, 20_000)]
    )
    d = rng.normal(size=(20_000, 3))
    d[:, 2] = -np.abs(d[:, 2]) - 0.3
    d /= np.linalg.norm(d, axis=1)[:, None]
    backend = get_backend("numba")
    a = backend.trace_cells(dense, o, d, method="exact")
    b = backend.trace_cells(sparse, o, d, method="exact")
    assert (a.kind == 1).sum() > 1000
    assert np.array_equal(a.kind, b.kind) and np.array_equal(a.index, b.index) and np.array_equal(a.t, b.t)


@pytest.mark.parametrize("backend_name", ["numba", "wgpu"])
def test_two_voxels_a_million_apart_take_memory_for_what_they_hold(backend_name):
    """Two voxels 10^6 cells apart on x and y (100 km at 0.1 m) needed about 58 GiB, the
    column tops (4 bytes an 8 x 8 voxel column) of the whole box: refused, and past the
    limit numpy's allocation failed. Unaffordable column tops are left out (the column
    skip only passes empty cells), and both backends trace the reference's answers."""
    import tracemalloc

    from ladartui.resources import occupancy_bytes
    from ladartui.tracing.backend import BackendUnavailable, get_backend
    from ladartui.tracing.reference import reference_trace_cells

    try:
        backend = get_backend(backend_name)
    except BackendUnavailable:
        pytest.skip(f"{backend_name} unavailable here")
    vox = np.array([[3, 5, 0], [1_000_000, 1_000_003, 2], [1_000_001, 1_000_003, 0]])
    shape = (1_000_010, 1_000_010, 16)
    estimate = occupancy_bytes(vox.min(axis=0), vox.max(axis=0) + 1, len(vox))
    Occupancy.build(vox[:1], shape)  # kernels loaded before measuring
    tracemalloc.start()
    occ = Occupancy.build(vox, shape)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert occ.nbytes <= peak <= estimate < 64 * 2**20
    assert occ.columns is None and occ.contains(vox).all()
    rng = np.random.default_rng(3)
    aim = vox[rng.integers(0, len(vox), 600)] + rng.uniform(0, 1, size=(600, 3))
    o = aim + rng.uniform(-30, 30, size=(600, 3))
    o[:, 2] = rng.uniform(5, 40, 600)  # above: descending rays, where the column skip was
    o[:300] = [500_000.5, 500_002.5, 30.0]  # and across the empty half of the box
    d = aim - o
    d /= np.linalg.norm(d, axis=1)[:, None]
    got = backend.trace_cells(occ, o, d, method="exact")
    ref = reference_trace_cells(vox, shape, o, d)
    assert np.array_equal(got.kind, ref.kind) and np.array_equal(got.index, ref.index)
    assert (got.kind == 1).sum() > 500
