"""The one-pass ray preparation gives the numpy expressions' exact bits."""

import numpy as np
import pytest

from ladartui.errors import FieldError
from ladartui.tracing import TINY
from ladartui.tracing.config import SCAN_BLOCK
from ladartui.tracing.prepare import SCALE_IN_PARTS, Scratch, one_origin, rays_to_cells, scale_in_place
from ladartui.tracing.scan_rays import ray_bounds


def test_cells_and_unit_directions_match_numpy_bit_for_bit():
    rng = np.random.default_rng(7)
    origins = rng.uniform(-1e4, 1e4, (5000, 3))
    origins[2000:] = np.repeat(origins[2000:2600], 5, axis=0)  # runs of one origin reuse its cell
    origins[4000:4002] = [[0.0, -0.0, 1.0], [-0.0, 0.0, 1.0]]
    directions = rng.normal(size=(5000, 3)) * rng.uniform(1e-3, 1e3, (5000, 1))
    directions[:10, 0] = 1e-250  # below TINY once normalised: becomes exactly 0
    cells, unit, _ = rays_to_cells(origins, directions, 0.1, TINY)
    expected_unit = directions / np.linalg.norm(directions, axis=1)[:, None]
    expected_unit[np.abs(expected_unit) < TINY] = 0.0
    assert np.array_equal(cells, origins / 0.1 + 0.5)
    assert np.array_equal(unit, expected_unit)
    assert np.all(unit[:10, 0] == 0.0)


@pytest.mark.parametrize("n", [1, 63, 5000, 2 * SCAN_BLOCK + 777])
def test_block_bounds_are_the_scan_frames_bounds_bit_for_bit(n):
    # What a scan's frame would compute in a pass of its own, per block of SCAN_BLOCK rays.
    rng = np.random.default_rng(n)
    origins = rng.uniform(-50.0, 50.0, (n, 3))
    directions = rng.normal(size=(n, 3))
    cells, unit, bounds = rays_to_cells(origins, directions, 0.25, TINY)
    assert bounds.shape == (-(-n // SCAN_BLOCK), 9)
    for b, row in enumerate(bounds):
        block = slice(b * SCAN_BLOCK, (b + 1) * SCAN_BLOCK)
        lo, hi, total = ray_bounds(cells[block], unit[block])
        assert np.array_equal(row, np.concatenate([lo, hi, total]))
    assert np.array_equal(bounds[0, :3], cells[:SCAN_BLOCK].min(axis=0))


def _bad_ray(origins, directions, voxel_size=1.0):
    with pytest.raises(FieldError) as error:
        rays_to_cells(origins, directions, voxel_size, TINY)
    return error.value.field, error.value.expected


def test_first_bad_ray_is_named():
    origins = np.zeros((4, 3))
    directions = np.tile([0.0, 0.0, -1.0], (4, 1))
    directions[2] = 0.0
    assert _bad_ray(origins, directions) == ("directions[2]", "a non-zero vector")
    origins[1, 2] = np.nan
    assert _bad_ray(origins, directions) == ("origins[1]", "finite numbers")
    origins[1, 2] = 0.0
    directions[0, 1] = np.inf
    assert _bad_ray(origins, directions) == ("directions[0]", "finite numbers")


def test_a_bad_ray_anywhere_in_a_large_batch_is_found():
    # The parallel pass runs in 64 parts: a bad ray in any one of them is noticed.
    rng = np.random.default_rng(3)
    origins = rng.uniform(-100, 100, (100_000, 3))
    directions = rng.normal(size=(100_000, 3))
    for bad in (0, 77_777, 99_999):
        broken = directions.copy()
        broken[bad] = 0.0
        assert _bad_ray(origins, broken, 0.5) == (f"directions[{bad}]", "a non-zero vector")
        broken = origins.copy()
        broken[bad, 1] = -np.inf
        assert _bad_ray(broken, directions, 0.5) == (f"origins[{bad}]", "finite numbers")


def test_bad_values_are_found_through_the_norm_and_the_cell():
    """The pass reads badness off what it computes: a direction's norm (NaN or inf
    for any bad component, also beside a huge one) and each new origin's cell (a
    bad origin repeated is still named). A finite origin whose cell overflows is
    no error: the serial pass finds no bad ray and the rays go on."""
    origins = np.tile([1.0, 2.0, 3.0], (6, 1))
    directions = np.tile([0.0, 0.0, -1.0], (6, 1))
    for bad in ([np.nan, 0.0, -1.0], [1e300, np.inf, 0.0], [-np.inf, 0.0, 0.0], [1e200, np.nan, 1e200]):
        broken = directions.copy()
        broken[3] = bad
        assert _bad_ray(origins, broken) == ("directions[3]", "finite numbers"), bad
    broken = origins.copy()
    broken[2:5] = [1.0, np.inf, 3.0]  # one bad origin, shared by three rays
    assert _bad_ray(broken, directions) == ("origins[2]", "finite numbers")
    huge = np.tile([1e308, 0.0, 10.0], (2, 1))
    cells, _, _ = rays_to_cells(huge, directions[:2], 1e-3, TINY)
    assert np.isinf(cells[0, 0]) and cells[0, 2] == 10.0 / 1e-3 + 0.5


def test_huge_and_tiny_directions_keep_their_direction():
    # Their squares over- or underflow: scaled by the largest component first, they
    # give the unit vector of the same direction (here bit for bit).
    plain = np.array([[1.0, 1.0, -1.0], [3.0, 0.0, -4.0]])
    for factor in (1e160, 1e300, 1e-170, 1e-300):
        _, unit, _ = rays_to_cells(np.zeros((2, 3)), plain * factor, 1.0, TINY)
        assert np.array_equal(unit, plain / np.linalg.norm(plain, axis=1)[:, None]), factor
    _, unit, _ = rays_to_cells(np.zeros((1, 3)), np.array([[0.0, 0.0, -5e-324]]), 1.0, TINY)
    assert unit.tolist() == [[0.0, 0.0, -1.0]]  # the smallest float is still a direction


def test_a_huge_direction_is_traced_where_it_points():
    from ladartui.scene.occupancy import Occupancy
    from ladartui.tracing import trace

    occ = Occupancy.build(np.array([[5, 5, 2]]), (16, 16, 8))
    down = trace(occ, [[5.0, 5.0, 7.0]], [[0.0, 0.0, -1e200]], backend="numba")  # cell centre
    assert down.kind[0] == 1 and down.index[0].tolist() == [5, 5, 2]


def test_one_origin_is_read_from_the_block_bounds():
    """rays_to_cells' bounds say when every ray of a range starts at one point."""
    directions = np.random.default_rng(3).normal(size=(4096, 3))
    origins = np.tile([32.25, 32.25, 40.0], (len(directions), 1))
    _, _, bounds = rays_to_cells(origins, directions, 1.0, TINY)
    assert one_origin(bounds, 0, len(origins))
    assert not one_origin(None, 0, len(origins)) and not one_origin(bounds, 5, 5)
    moved = origins.copy()
    moved[1000, 2] = np.nextafter(moved[1000, 2], np.inf)  # one ray, one ulp higher
    assert not one_origin(rays_to_cells(moved, directions, 1.0, TINY)[2], 0, len(origins))
    # Blocks of SCAN_BLOCK rays: only those a range touches count, and they must agree.
    row = bounds[0]
    other = row.copy()
    other[[2, 5]] += 1.0  # another scan, one cell higher
    two = np.array([row, other])
    assert not one_origin(two, 0, 2 * SCAN_BLOCK)
    assert one_origin(two, 0, SCAN_BLOCK) and one_origin(two, SCAN_BLOCK + 7, 2 * SCAN_BLOCK)
    assert one_origin(np.array([row, row]), 3, SCAN_BLOCK + 3)


@pytest.mark.parametrize("n", [4096, SCAN_BLOCK + 5])
def test_one_origin_for_every_ray_is_one_row_broadcast(n):
    """A pinhole scan's origins are one cell broadcast to every ray (no rows written);
    two scans' blocks, each from its own point, get every row, as do runs of origins."""
    rng = np.random.default_rng(n)
    directions = rng.normal(size=(n, 3))
    origins = np.tile([12.3, -4.5, 150.0], (n, 1))
    cells, unit, bounds = rays_to_cells(origins, directions, 0.1, TINY)
    assert cells.shape == (n, 3) and cells.strides[0] == 0 and not cells.flags.writeable
    assert np.array_equal(cells, origins / 0.1 + 0.5)
    assert np.array_equal(unit, rays_to_cells(origins + np.arange(n)[:, None], directions, 0.1, TINY)[1])
    moved = origins.copy()
    moved[n // 2 :] += [0.0, 0.0, 1e-3]  # a second point halfway (two scans, or two blocks)
    cells, _, _ = rays_to_cells(moved, directions, 0.1, TINY)
    assert cells.strides[0] == 24 and np.array_equal(cells, moved / 0.1 + 0.5)


@pytest.mark.parametrize("n", [SCALE_IN_PARTS - 1, SCALE_IN_PARTS, 3 * SCALE_IN_PARTS + 5])
def test_scaling_in_place_is_numpys_product_bit_for_bit(n):
    """Short rows on one thread, long ones in parts: every value as numpy's own
    product, inf, nan, -0.0 and subnormals too; strided views scaled where they are."""
    rng = np.random.default_rng(n)
    values = rng.uniform(0, 3000, n) * 10.0 ** rng.integers(-310, 300, n)
    values[:6] = [np.inf, -np.inf, np.nan, -0.0, 5e-324, 1.7e308]
    for factor in (0.1, 0.25, 3.0e-9):
        scaled = values.copy()
        scale_in_place(scaled, factor)
        assert np.array_equal(scaled.view(np.int64), (values * factor).view(np.int64))
    grid = values[: n // 2 * 2].reshape(-1, 2).copy()
    column = grid[:, 1]  # not contiguous: scaled by numpy, in place
    scale_in_place(column, 0.1)
    assert np.array_equal(grid[:, 1].view(np.int64), (values[1 : n // 2 * 2 : 2] * 0.1).view(np.int64))
    assert np.array_equal(grid[:, 0].view(np.int64), values[0 : n // 2 * 2 : 2].view(np.int64))


def test_a_long_traces_ranges_are_its_cell_ranges_times_the_voxel_size():
    """trace() scales a long call's ranges in parts: each is the backend's cell
    range times the voxel size, bit for bit."""
    from ladartui.scene.occupancy import Occupancy
    from ladartui.tracing import trace
    from ladartui.tracing.numba_backend import NumbaBackend

    rng = np.random.default_rng(5)
    occupancy = Occupancy.build(rng.integers(0, 40, (3000, 3)).astype(np.int32), (40, 40, 40))
    n = SCALE_IN_PARTS + 1000
    origins = rng.uniform(-5, 45, (n, 3)) * 0.3
    directions = rng.normal(size=(n, 3))
    got = trace(occupancy, origins, directions, backend="numba", voxel_size=0.3)
    cells, unit, bounds = rays_to_cells(origins, directions, 0.3, TINY)
    hits = NumbaBackend().trace_cells(occupancy, cells, unit, block_bounds=bounds)
    assert (got.kind == 1).sum() > 1000
    assert np.array_equal(got.range.view(np.int64), (hits.t * 0.3).view(np.int64))


def test_kept_arrays_hold_any_earlier_values_and_give_the_same_answers():
    """Rays written into arrays that held another call's rays (a scan from one origin,
    whose rows ``rays_to_cells`` mostly leaves unwritten, then rays of many
    origins, then the scan again): the same cells and directions as new arrays."""
    rng = np.random.default_rng(9)
    many = rng.uniform(-50, 50, (3000, 3)), rng.normal(size=(3000, 3))
    scan = np.tile([1.0, 2.0, 30.0], (3000, 1)), rng.normal(size=(3000, 3))
    scratch = Scratch(most=4096)
    for origins, directions in (scan, many, scan, (many[0][:100], many[1][:100])):
        fresh = rays_to_cells(origins, directions, 0.1, TINY)
        with scratch.arrays(len(origins)) as into:
            assert into is not None and into[0].flags.c_contiguous and into[1].shape == (len(origins), 3)
            kept = rays_to_cells(origins, directions, 0.1, TINY, into)
            for a, b in zip(fresh, kept):
                assert np.array_equal(a, b)
    with scratch.arrays(3000) as first:
        assert first is not None
        with scratch.arrays(3000) as second:  # another thread's trace meanwhile
            assert second is None
    with scratch.arrays(5000) as over:
        assert over is None
    with scratch.arrays(4000) as grown:
        assert grown is not None and len(grown[0]) == 4000
    with scratch.arrays(10) as again:
        assert again is not None and np.shares_memory(again[0], grown[0])


def test_a_traces_results_are_its_own_after_the_next_call():
    """trace() keeps its cell-space arrays between calls; the answers it returned
    do not share them, so a later call leaves them as they were."""
    from ladartui.scene.occupancy import Occupancy
    from ladartui.tracing import trace

    rng = np.random.default_rng(11)
    occupancy = Occupancy.build(rng.integers(0, 40, (3000, 3)), shape=(40, 40, 40))
    first_rays = rng.uniform(0, 40, (2000, 3)) + [0, 0, 50], rng.normal(size=(2000, 3)) - [0, 0, 2]
    other_rays = rng.uniform(0, 40, (2000, 3)) + [0, 0, 50], rng.normal(size=(2000, 3)) - [0, 0, 2]
    first = trace(occupancy, *first_rays, backend="numba")
    kept = [first.kind.copy(), first.index.copy(), first.range.copy()]
    trace(occupancy, *other_rays, backend="numba")
    assert all(np.array_equal(a, b) for a, b in zip(kept, (first.kind, first.index, first.range)))
    assert (first.kind == 1).sum() > 100
