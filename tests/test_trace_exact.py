"""The exact numba tracer against the slab-test reference and hand-worked cases (cell space)."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ladartui.scene.occupancy import Occupancy
from ladartui.tracing.backend import GROUND, MISS, VOXEL, get_backend
from ladartui.tracing.reference import reference_trace_cells


def exact(occ, origins, directions):
    o = np.asarray(origins, float).reshape(-1, 3)
    d = np.asarray(directions, float).reshape(-1, 3)
    return get_backend("numba").trace_cells(occ, o, d, method="exact")


def unit(d):
    d = np.asarray(d, float).reshape(-1, 3)
    return d / np.linalg.norm(d, axis=1)[:, None]


def assert_matches_reference(vox, shape, origins, directions):
    occ = Occupancy.build(vox, shape)
    got = exact(occ, origins, directions)
    ref = reference_trace_cells(vox, shape, origins, directions)
    wrong = np.flatnonzero(
        (got.kind != ref.kind)
        | np.any(got.index != ref.index, axis=1)
        | ~((got.t == ref.t) | np.isclose(got.t, ref.t, rtol=0, atol=1e-9))
    )
    if len(wrong):
        i = wrong[0]
        pytest.fail(
            f"{len(wrong)} of {len(got.kind)} rays differ; first: o={origins[i].tolist()} "
            f"d={directions[i].tolist()} got {got.kind[i]} {got.index[i]} {got.t[i]} "
            f"reference {ref.kind[i]} {ref.index[i]} {ref.t[i]}"
        )
    return got


def random_rays(rng, n, lo, hi, snap=None):
    o = rng.uniform(lo, hi, size=(n, 3))
    if snap:
        o = np.round(o * snap) / snap
    return o, unit(rng.normal(size=(n, 3)))


@pytest.mark.parametrize("seed", range(6))
def test_random_rays_in_small_random_scenes(seed):
    rng = np.random.default_rng(seed)
    shape = (24, 20, 16)
    vox = rng.integers(0, shape, size=(int(rng.integers(1, 400)), 3))
    o, d = random_rays(rng, 1500, -6, 30, snap=4 if seed % 2 else None)
    got = assert_matches_reference(vox, shape, o, d)
    assert (got.kind == VOXEL).sum() > 100  # the comparison covers real hits


def test_rays_aimed_across_regions_and_tiles():
    # Sparse voxels spread over several 512-voxel root cells exercise every skip level.
    rng = np.random.default_rng(11)
    shape = (1100, 700, 120)
    vox = rng.integers(0, shape, size=(300, 3))
    targets = vox[rng.integers(0, len(vox), 1200)] + rng.uniform(0, 1, size=(1200, 3))
    o = rng.uniform([-50, -50, 0], [1150, 750, 400], size=(1200, 3))
    d = unit(targets - o)
    got = assert_matches_reference(vox, shape, o, d)
    assert (got.kind == VOXEL).mean() > 0.5


def test_axis_aligned_rays():
    rng = np.random.default_rng(2)
    shape = (16, 16, 16)
    vox = rng.integers(0, shape, size=(300, 3))
    axes = np.vstack([np.eye(3), -np.eye(3)])
    d = axes[rng.integers(0, 6, 3000)]
    o = rng.uniform(-3, 19, size=(3000, 3))
    o[::3] = np.round(o[::3])  # some on cell faces
    assert_matches_reference(vox, shape, o, d)


def test_rays_running_along_faces_hit_nothing():
    shape = (10, 10, 10)
    vox = np.array(
        [[i, j, k] for i in range(10) for j in range(10) for k in range(10) if (i + j + k) % 2 == 0]
    )
    occ = Occupancy.build(vox, shape)
    # In the plane x = 4 (a face plane): touches voxels on both sides, enters none.
    o = np.array([[4.0, 0.3, 12.0], [4.0, -2.0, 5.5], [3.0, 5.0, 5.0]])
    d = unit([[0, 0.6, -0.8], [0, 1, 0], [0, 0, -1]])
    got = exact(occ, o, d)
    assert np.all(got.kind != VOXEL)
    assert_matches_reference(vox, shape, o, d)


def test_diagonal_ray_through_edges_is_not_a_hit():
    # The ray y = x (z = 0.5) passes through cells (k, k, 0) and touches the
    # edges of (k + 1, k, 0) and (k, k + 1, 0): only the former count.
    shape = (12, 12, 4)
    side = [[k + 1, k, 0] for k in range(11)] + [[k, k + 1, 0] for k in range(11)]
    s = 1 / math.sqrt(2)
    o, d = np.array([[0.0, 0.0, 0.5]]), np.array([[s, s, 0.0]])
    assert exact(Occupancy.build(np.array(side), shape), o, d).kind[0] == MISS
    got = exact(Occupancy.build(np.array(side + [[5, 5, 0]]), shape), o, d)
    assert got.kind[0] == VOXEL and got.index[0].tolist() == [5, 5, 0]
    assert got.t[0] == pytest.approx(5 * math.sqrt(2))
    assert_matches_reference(np.array(side + [[5, 5, 0]]), shape, o, d)


def test_diagonal_ray_through_corners_is_not_a_hit():
    # The ray (1, 1, 1) from the origin passes corners (k, k, k); every cell
    # sharing only a face-diagonal edge or corner with (k, k, k) is occupied.
    shape = (10, 10, 10)
    vox = []
    for k in range(9):
        for off in [
            (1, 0, 0),
            (0, 1, 0),
            (0, 0, 1),
            (1, 1, 0),
            (1, 0, 1),
            (0, 1, 1),
            (-1, 0, 0),
            (0, -1, 0),
            (0, 0, -1),
        ]:
            c = np.array([k, k, k]) + off
            if c.min() >= 0 and c.max() < 10:
                vox.append(c)
    vox = np.unique(np.array(vox), axis=0)
    s = 1 / math.sqrt(3)
    o, d = np.array([[0.0, 0.0, 0.0]]), np.array([[s, s, s]])
    assert exact(Occupancy.build(vox, shape), o, d).kind[0] == MISS
    with_hit = np.vstack([vox, [[6, 6, 6]]])
    got = exact(Occupancy.build(with_hit, shape), o, d)
    assert got.index[0].tolist() == [6, 6, 6]
    assert_matches_reference(with_hit, shape, o, d)
    # Against the reference on many 45-degree rays from integer points.
    rng = np.random.default_rng(4)
    dirs = np.array(
        [[a, b, c] for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1) if (a, b, c) != (0, 0, 0)],
        float,
    )
    dirs = unit(dirs)
    o = rng.integers(-2, 12, size=(2000, 3)).astype(float)
    dd = dirs[rng.integers(0, len(dirs), 2000)]
    assert_matches_reference(rng.integers(0, shape, size=(250, 3)), shape, o, dd)


@pytest.mark.parametrize("depression_deg", [1.0, 0.3, 0.05])
def test_grazing_rays(depression_deg):
    rng = np.random.default_rng(int(depression_deg * 100))
    shape = (200, 40, 6)
    vox = rng.integers(0, shape, size=(600, 3))
    e = math.radians(depression_deg)
    az = rng.uniform(0, 2 * math.pi, 1500)
    d = np.column_stack([np.cos(e) * np.cos(az), np.cos(e) * np.sin(az), -np.full(1500, np.sin(e))])
    o = rng.uniform([0, 0, 0], [200, 40, 7], size=(1500, 3))
    assert_matches_reference(vox, shape, o, d)


def test_origins_on_voxel_boundaries():
    rng = np.random.default_rng(8)
    shape = (16, 16, 16)
    vox = rng.integers(0, shape, size=(500, 3))
    o = rng.integers(-1, 17, size=(3000, 3)).astype(float)
    o[1::2, 0] += 0.5  # boundary on two axes only
    d = unit(rng.normal(size=(3000, 3)))
    assert_matches_reference(vox, shape, o, d)


def test_origin_inside_an_occupied_voxel_hits_it_at_range_zero():
    shape = (8, 8, 8)
    vox = np.array([[3, 4, 5], [3, 4, 2]])
    occ = Occupancy.build(vox, shape)
    rng = np.random.default_rng(9)
    o = np.array([3, 4, 5]) + rng.uniform(0.01, 0.99, size=(200, 3))
    got = exact(occ, o, unit(rng.normal(size=(200, 3))))
    assert np.all(got.kind == VOXEL) and np.all(got.t == 0)
    assert np.all(got.index == [3, 4, 5])


def test_upward_rays_never_reach_the_ground():
    rng = np.random.default_rng(10)
    shape = (16, 16, 16)
    vox = rng.integers(0, shape, size=(300, 3))
    o, d = random_rays(rng, 2000, -2, 18)
    d[:, 2] = np.abs(d[:, 2])
    got = assert_matches_reference(vox, shape, o, d)
    assert not np.any(got.kind == GROUND)


def test_empty_scene_gives_ground_or_miss():
    occ = Occupancy.build(np.zeros((0, 3), int), (20, 20, 5))
    o = np.array([[2.5, 3.5, 10.0], [2.5, 3.5, 10.0], [-5.0, 3.0, 10.0], [2.0, 2.0, 10.0]])
    d = unit([[0, 0, -1], [1, 0, -1], [0, 0, -1], [0, 0, 1]])
    got = exact(occ, o, d)
    assert got.kind.tolist() == [GROUND, GROUND, MISS, MISS]
    assert got.index[0].tolist() == [2, 3, 0] and got.t[0] == 10.0
    assert got.index[1].tolist() == [12, 3, 0]  # x = 2.5 + 10
    assert got.t[1] == pytest.approx(10 * math.sqrt(2))


def test_full_block_hit_on_its_top_face():
    shape = (16, 16, 16)
    g = np.arange(4, 12)
    vox = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    occ = Occupancy.build(vox, shape)
    rng = np.random.default_rng(12)
    top = rng.uniform(4.01, 11.99, size=(500, 2))
    d = unit(np.column_stack([rng.uniform(-0.3, 0.3, size=(500, 2)), -np.ones(500)]))
    t_top = (12 - 30.0) / d[:, 2]
    o = np.column_stack([top - t_top[:, None] * d[:, :2], np.full(500, 30.0)])
    got = exact(occ, o, d)
    assert np.all(got.kind == VOXEL)
    assert np.array_equal(got.index[:, :2], np.floor(top).astype(int))
    assert np.all(got.index[:, 2] == 11)
    assert np.allclose(got.t, t_top)


def test_far_origins():
    rng = np.random.default_rng(13)
    shape = (40, 40, 20)
    vox = rng.integers(0, shape, size=(2000, 3))
    aim = rng.uniform([0, 0, 0], [40, 40, 20], size=(1000, 3))
    far = aim + unit(rng.normal(size=(1000, 3)) + [0, 0, 1.5]) * 10_000.0
    got = assert_matches_reference(vox, shape, far, unit(aim - far))
    assert (got.kind == VOXEL).mean() > 0.3


def test_random_slab_lets_through_the_expected_share():
    # Occupancy probability p in a slab of L layers: a vertical ray reaches
    # the ground with probability (1 - p) ** L.
    rng = np.random.default_rng(14)
    p, layers, side = 0.1, 6, 200
    cells = np.stack(
        np.meshgrid(np.arange(side), np.arange(side), np.arange(2, 2 + layers), indexing="ij"), -1
    ).reshape(-1, 3)
    vox = cells[rng.random(len(cells)) < p]
    occ = Occupancy.build(vox, (side, side, 20))
    xy = rng.uniform(0, side, size=(40_000, 2))
    o = np.column_stack([xy, np.full(len(xy), 19.5)])
    got = exact(occ, o, np.tile([0.0, 0.0, -1.0], (len(xy), 1)))
    expected = (1 - p) ** layers
    share = (got.kind == GROUND).mean()
    # The columns, not the rays, are the independent samples: 40 000 columns.
    sigma = math.sqrt(expected * (1 - expected) / side**2)
    assert abs(share - expected) < 5 * sigma + 0.01


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32 - 1),
    origin=st.tuples(*[st.floats(-50, 50, allow_nan=False) for _ in range(3)]),
    direction=st.tuples(*[st.floats(-1, 1, allow_nan=False) for _ in range(3)]).filter(
        lambda v: max(abs(c) for c in v) > 1e-3
    ),
)
def test_any_ray_gives_a_valid_answer_equal_to_the_reference(seed, origin, direction):
    rng = np.random.default_rng(seed)
    shape = (12, 10, 8)
    vox = rng.integers(0, shape, size=(int(rng.integers(0, 80)), 3))
    o = np.array([origin])
    d = unit([direction])
    got = assert_matches_reference(vox, shape, o, d)
    assert got.kind[0] in (MISS, VOXEL, GROUND)
    if got.kind[0] == MISS:
        assert np.isinf(got.t[0]) and np.all(got.index[0] == -1)
    else:
        assert np.isfinite(got.t[0]) and got.t[0] >= 0
        assert np.all(got.index[0] >= 0) and np.all(got.index[0] < shape)
