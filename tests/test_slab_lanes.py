"""Eight rays against a voxel in vector code (tracing/slab_lanes.py), against the
scalar rule it replaces: axis.cube_start and the tile tests' hit rule, lane by lane."""

import numpy as np
import pytest
from numba import njit
from numba.core.errors import TypingError

from ladartui.tracing.axis import cube_start
from ladartui.tracing.config import INF
from ladartui.tracing.slab_lanes import LANES, slab_lanes, slab_lanes_from


@njit
def lanes_one_by_one(rays, s, x, y, z, near, after, q, todo, cols, s_end, bounds, voxels):
    """The scalar code slab_lanes stands for (tile_tests before it)."""
    alive, any_hit, first_hits = 0, 0, 0
    for k in range(s, s + LANES):
        if k >= s_end or (todo >> cols[k]) & 1 == 0:
            continue
        bound = bounds[k]
        if bound > near:
            start, leave = cube_start(
                rays[0, k], rays[1, k], rays[2, k], rays[3, k], rays[4, k], rays[5, k],
                rays[6, k], rays[7, k], rays[8, k], x, y, z,
            )  # fmt: skip
            if start < leave and start < bound:
                first_hits += bound == INF
                bounds[k], voxels[k], bound, any_hit = start, q, start, 1
        if bound > after:
            alive |= np.int64(1) << cols[k]
    return alive, any_hit, first_hits


@njit
def vector(rays, s, x, y, z, near, after, q, todo, cols, s_end, bounds, voxels):
    return slab_lanes(rays, s, x, y, z, near, after, q, todo, cols, s_end, bounds, voxels)


@njit
def vector_from(rays, s, ox, oy, oz, x, y, z, near, after, q, todo, cols, s_end, bounds, voxels):
    return slab_lanes_from(rays, s, ox, oy, oz, x, y, z, near, after, q, todo, cols, s_end, bounds, voxels)


def awkward_rays(rng, n):
    """Rays around voxel (3, 4, 5): origins inside, outside and exactly on its faces,
    directions with zero, tiny and huge components and both signs."""
    origin = rng.choice([2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 5.5, 6.0, 1.0, 8.0, -2.0], size=(n, 3))
    direction = rng.normal(size=(n, 3))
    direction[rng.random((n, 3)) < 0.2] = 0.0
    direction[rng.random((n, 3)) < 0.05] *= 1e-200
    direction[rng.random((n, 3)) < 0.05] *= 1e200
    direction[np.all(direction == 0.0, axis=1), 2] = -1.0
    with np.errstate(divide="ignore"):
        inverse = np.where(direction != 0.0, 1.0 / direction, INF)
    return np.ascontiguousarray(np.hstack([origin, direction, inverse]).T)


@pytest.mark.parametrize("shared", [False, True])
@pytest.mark.parametrize("seed", range(6))
def test_eight_lanes_give_the_scalar_rule_bit_for_bit(seed, shared):
    # shared: one origin for every lane (slab_lanes_from), inside the voxel's slabs,
    # on their faces or outside; it never reads the origin rows, so they hold garbage.
    rng = np.random.default_rng(seed + 100 * shared)
    n = 64 + LANES
    rays = awkward_rays(rng, n)
    cols = np.sort(rng.integers(0, 12, n))
    for _ in range(200):
        scalar_rays = rays
        if shared:
            origin = rng.choice([2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 5.5, 6.0, 1.0, 8.0, -2.0], size=3)
            scalar_rays = rays.copy()
            scalar_rays[:3] = origin[:, None]
            rays[:3] = rng.normal(size=(3, n)) * 1e3
        s = int(rng.integers(0, n - LANES + 1))
        x, y, z = (float(v) for v in rng.integers(2, 7, 3))
        near = float(rng.choice([0.0, 0.5, 1.0, 2.0]))
        after = near + float(rng.choice([0.0, 0.3, 2.0, INF]))
        todo = int(rng.integers(0, 1 << 12))
        s_end = s + int(rng.integers(0, LANES + 2))
        bounds = rng.choice([INF, 0.2, 1.5, 3.0, 6.0, 40.0], n)
        voxels = rng.integers(-1, 9, n)
        want_bounds, want_voxels = bounds.copy(), voxels.copy()
        want = lanes_one_by_one(
            scalar_rays, s, x, y, z, near, after, 77, todo, cols, s_end, want_bounds, want_voxels
        )
        if shared:
            ox, oy, oz = origin.tolist()
            got = vector_from(
                rays, s, ox, oy, oz, x, y, z, near, after, 77, todo, cols, s_end, bounds, voxels
            )
        else:
            got = vector(rays, s, x, y, z, near, after, 77, todo, cols, s_end, bounds, voxels)
        assert got == want
        assert np.array_equal(bounds.view(np.int64), want_bounds.view(np.int64))
        assert np.array_equal(voxels, want_voxels)


def test_lanes_hit_where_expected_and_leave_the_rest():
    # Eight rays straight down onto voxel (3, 4, 5) from z = 10: lanes 0-5 over it
    # (x = 3.5), lanes 6-7 beside it; lane 2 is not to do, lane 4 already nearer.
    rays = np.zeros((9, 2 * LANES))
    rays[0, :] = [3.5] * 6 + [7.5] * 10
    rays[1, :], rays[2, :] = 4.5, 10.0
    rays[5, :], rays[8, :] = -1.0, -1.0
    rays[6, :] = rays[7, :] = INF
    cols = np.arange(2 * LANES)
    bounds = np.full(2 * LANES, INF)
    bounds[4] = 2.0
    voxels = np.full(2 * LANES, -1)
    todo = 0b11111011
    alive, any_hit, first_hits = vector(rays, 0, 3.0, 4.0, 5.0, 0.0, 4.5, 9, todo, cols, 8, bounds, voxels)
    assert list(voxels[:8]) == [9, 9, -1, 9, -1, 9, -1, -1]
    assert list(bounds[:8]) == [4.0, 4.0, INF, 4.0, 2.0, 4.0, INF, INF]
    assert (any_hit, first_hits) == (1, 4)
    assert alive == 0b11000000  # the lanes that missed keep an infinite bound
    assert np.all(bounds[8:] == INF)


def test_the_intrinsic_is_vector_code_and_rejects_other_layouts():
    ir = vector.inspect_llvm(vector.signatures[0])
    assert "<8 x double>" in ir
    # With one origin, its rows are not loaded: six rows of eight doubles, not nine.
    vector_from(np.zeros((9, 16)), 0, 0.5, 0.5, 9.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1, 1,
                np.zeros(16, np.int64), 8, np.full(16, INF), np.zeros(16, np.int64))  # fmt: skip
    shared_ir = vector_from.inspect_llvm(vector_from.signatures[0])
    assert "<8 x double>" in shared_ir
    assert shared_ir.count("load <8 x double>") == 7 and ir.count("load <8 x double>") == 10
    rays = np.asfortranarray(np.zeros((9, 16)))
    with pytest.raises(TypingError):
        vector(
            rays,
            0,
            1.0,
            1.0,
            1.0,
            0.0,
            0.0,
            1,
            1,
            np.zeros(16, np.int64),
            8,
            np.zeros(16),
            np.zeros(16, np.int64),
        )


@pytest.mark.parametrize("shared", [False, True])
def test_lanes_bound_at_or_before_near_take_no_test_and_keep_their_answers(shared):
    # Every taking-part lane already has a bound no further than the voxel's near, so
    # none can hit it (the early way out): nothing is written, and the lanes whose
    # bound lies beyond ``after`` are still alive. The rays would hit the voxel.
    rays = np.zeros((9, 2 * LANES))
    rays[0, :], rays[1, :], rays[2, :] = 3.5, 4.5, 10.0
    rays[5, :], rays[8, :] = -1.0, -1.0
    rays[6, :] = rays[7, :] = INF
    cols = np.arange(2 * LANES)
    bounds = np.array([3.0, 3.5, 2.0, 3.5, 3.2, 1.0, 5.0, 2.0] + [INF] * LANES)
    voxels = np.arange(2 * LANES)
    todo = 0b10111111  # lane 6 is not to do (its bound would let it hit)
    want_bounds, want_voxels = bounds.copy(), voxels.copy()
    near, after = 3.5, 3.1  # (later voxels may come nearer than this one)

    def call():
        if shared:
            return vector_from(
                rays, 0, 3.5, 4.5, 10.0, 3.0, 4.0, 5.0, near, after, 9, todo, cols, 8, bounds, voxels
            )
        return vector(rays, 0, 3.0, 4.0, 5.0, near, after, 9, todo, cols, 8, bounds, voxels)

    got = call()
    assert got == (0b00011010, 0, 0)  # lanes 1, 3 and 4 lie beyond after
    assert np.array_equal(bounds, want_bounds) and np.array_equal(voxels, want_voxels)
    # One lane beyond near: the call now tests, and that lane alone hits, at t = 4.
    bounds[4] = 5.5
    got = call()
    assert got == (0b00011010, 1, 0) and bounds[4] == 4.0 and voxels[4] == 9
    assert np.array_equal(np.delete(bounds, 4), np.delete(want_bounds, 4))
