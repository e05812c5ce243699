"""The report's fixed-step march: faithful to section 7.4, measured against the exact answer."""

import math

import numpy as np
import pytest

from ladartui.scene.occupancy import Occupancy
from ladartui.tracing.backend import GROUND, MISS, VOXEL, get_backend


def run(occ, origins, directions, method, step=0.5):
    o = np.asarray(origins, float).reshape(-1, 3)
    d = np.asarray(directions, float).reshape(-1, 3)
    return get_backend("numba").trace_cells(occ, o, d, method=method, step=step)


def march_by_hand(vox, shape, o, d, step):
    """The section 7.4 loop written plainly in Python for one ray."""
    occupied = set(map(tuple, np.asarray(vox).tolist()))
    zmax = max(v[2] for v in occupied)
    top = zmax + 1.0
    t = 0.0
    if o[2] > top:
        t = (top - o[2]) * (1.0 / d[2])
    while True:
        c = o + t * d
        if c[2] < 0:
            if 0 <= c[0] < shape[0] and 0 <= c[1] < shape[1]:
                return GROUND, (math.floor(c[0]), math.floor(c[1]), 0), t
            return MISS, (-1, -1, -1), math.inf
        if not (0 <= c[0] < shape[0] and 0 <= c[1] < shape[1]) or (c[2] >= top and d[2] >= 0):
            return MISS, (-1, -1, -1), math.inf
        cell = tuple(math.floor(x) for x in c)
        if cell in occupied:
            return VOXEL, cell, t
        t += step


def test_march_matches_the_hand_written_loop():
    rng = np.random.default_rng(1)
    shape = (30, 30, 12)
    vox = np.unique(rng.integers(0, shape, size=(800, 3)), axis=0)
    occ = Occupancy.build(vox, shape)
    o = rng.uniform([0, 0, 14], [30, 30, 40], size=(300, 3))
    d = rng.normal(size=(300, 3))
    d[:, 2] = -np.abs(d[:, 2])
    d /= np.linalg.norm(d, axis=1)[:, None]
    for step in (1.0, 0.5, 0.25):
        got = run(occ, o, d, "march", step)
        for r in range(len(o)):
            kind, cell, t = march_by_hand(vox, shape, o[r], d[r], step)
            assert got.kind[r] == kind
            assert tuple(got.index[r]) == cell
            assert got.t[r] == pytest.approx(t, abs=1e-9) or (math.isinf(t) and math.isinf(got.t[r]))


def test_march_misses_a_thin_diagonal_feature_the_exact_method_hits():
    # A one-voxel-thick diagonal wall: 45-degree rays clip a voxel corner for a
    # short length that samples 0.5 apart step over; the exact method does not.
    shape = (40, 10, 40)
    vox = np.array([[i, j, i] for i in range(40) for j in range(10)])  # a staircase along (1, 0, 1)
    occ = Occupancy.build(vox, shape)
    rng = np.random.default_rng(2)
    n = 400
    o = np.column_stack([rng.uniform(0, 40, n), rng.uniform(0, 10, n), np.full(n, 40.0)])
    d = np.tile([1 / math.sqrt(2), 0.0, -1 / math.sqrt(2)], (n, 1))
    exact = run(occ, o, d, "exact")
    march = run(occ, o, d, "march")
    assert np.all(exact.kind == VOXEL)
    differs = np.any(exact.index != march.index, axis=1)
    assert 0.1 < differs.mean() < 0.9
    # The march only ever stops later than the exact answer, never earlier.
    assert np.all(march.t >= exact.t - 1e-9)


def test_march_equals_exact_on_axis_aligned_rays_through_solid_blocks():
    shape = (20, 20, 20)
    g = np.arange(5, 15)
    vox = np.stack(np.meshgrid(g, g, np.arange(3, 12), indexing="ij"), -1).reshape(-1, 3)
    occ = Occupancy.build(vox, shape)
    rng = np.random.default_rng(3)
    xy = rng.uniform(0, 20, size=(500, 2))
    o = np.column_stack([xy, np.full(500, 12.0)])  # on the top face: first sample lands in it
    d = np.tile([0.0, 0.0, -1.0], (500, 1))
    exact = run(occ, o, d, "exact")
    march = run(occ, o, d, "march")
    assert np.array_equal(exact.kind, march.kind)
    assert np.array_equal(exact.index, march.index)
    inside = (xy >= 5).all(axis=1) & (xy < 15).all(axis=1)
    assert np.all(exact.kind[inside] == VOXEL) and np.all(exact.kind[~inside] == GROUND)


def test_march_upward_rays_and_rays_leaving_sideways_miss():
    shape = (10, 10, 10)
    occ = Occupancy.build(np.array([[5, 5, 2]]), shape)
    o = np.array([[5.5, 5.5, 20.0], [5.5, 5.5, 1.0], [1.0, 1.0, 5.0]])
    d = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [-0.99498744, 0.0, -0.1]])
    got = run(occ, o, d, "march")
    assert got.kind.tolist() == [MISS, VOXEL, MISS]
    assert got.index[1].tolist() == [5, 5, 2]


def test_march_on_an_empty_scene_reaches_the_ground():
    occ = Occupancy.build(np.zeros((0, 3), int), (10, 10, 10))
    got = run(occ, [[3.5, 4.5, 8.0]], [[0.0, 0.0, -1.0]], "march", 0.5)
    assert got.kind[0] == GROUND and got.index[0].tolist() == [3, 4, 0]
    assert got.t[0] == pytest.approx(0.5 + 8.0)  # first sample below c_z = 0 (starts at c_z = 0)
