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


def march_every_sample(occupied, shape, zmax, o, d, step):
    """The march of docs/architecture.md for one ray with every sample taken (no jumps
    over empty nodes), in numpy, with the kernel's formulas: (kind, cell, t)."""
    nx, ny = float(shape[0]), float(shape[1])
    top = zmax + 1.0
    t_s = 0.0
    if o[2] > top:
        if d[2] >= 0.0:
            return MISS, (-1, -1, -1), math.inf
        t_s = (top - o[2]) * (1.0 / d[2])
    limit = int((math.sqrt(nx * nx + ny * ny + top * top) + 2.0) / step) + 2
    t = t_s + np.arange(limit) * step
    c = o[None, :] + t[:, None] * d[None, :]
    inside = (0.0 <= c[:, 0]) & (c[:, 0] < nx) & (0.0 <= c[:, 1]) & (c[:, 1] < ny)
    cell = np.floor(c).astype(np.int64)
    in_grid = np.all((cell >= 0) & (cell < occupied.shape), axis=1)
    hit = np.zeros(limit, bool)
    hit[in_grid] = occupied[tuple(cell[in_grid].T)]
    ends = (c[:, 2] < 0.0) | ~inside | ((c[:, 2] >= top) & (d[2] >= 0.0)) | hit
    if not ends.any():
        return MISS, (-1, -1, -1), math.inf
    s = int(np.argmax(ends))
    if c[s, 2] < 0.0:
        if inside[s]:
            return GROUND, (int(cell[s, 0]), int(cell[s, 1]), 0), t[s]
        return MISS, (-1, -1, -1), math.inf
    if hit[s]:
        return VOXEL, tuple(int(v) for v in cell[s]), t[s]
    return MISS, (-1, -1, -1), math.inf


def sparse_scene_and_rays(seed, n=400):
    """Clumps in a 700 x 150 x 80 box (two root cells along x, many empty regions
    and bricks) and rays that end (ground, sides, top) or hit just past an empty
    node, along cell faces' planes, from cell corners, inside the box or above it."""
    rng = np.random.default_rng(seed)
    shape = (700, 150, 80)
    clumps = rng.integers([0, 0, 0], [700, 150, 70], size=(12, 3))
    voxels = np.unique(np.concatenate([c + rng.integers(0, 6, size=(30, 3)) for c in clumps]), axis=0)
    voxels = voxels[np.all(voxels < shape, axis=1)]
    occ = Occupancy.build(voxels, shape)
    occupied = np.zeros(shape, bool)
    occupied[tuple(voxels.T)] = True
    origins = rng.uniform([0, 0, 0], [700, 150, 160], size=(n, 3))
    directions = rng.normal(size=(n, 3))
    directions[: n // 4, 2] = -np.abs(directions[: n // 4, 2])  # down: ground or a hit
    directions[n // 4 : n // 3, rng.integers(0, 3)] = 0.0  # along cell faces' planes
    origins[n // 3 : n // 2] = np.floor(origins[n // 3 : n // 2])  # from cell corners
    directions[n // 2 : n // 2 + 40] = (
        voxels[rng.integers(0, len(voxels), 40)] + 0.5 - origins[n // 2 : n // 2 + 40]
    )
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    return voxels, shape, occ, occupied, origins, directions


@pytest.mark.parametrize("seed", range(4))
def test_jumps_over_empty_nodes_keep_every_answer(seed):
    """numba's march jumps over the samples of empty root cells, regions and bricks;
    the answers stay those of taking every sample."""
    voxels, shape, occ, occupied, origins, directions = sparse_scene_and_rays(seed)
    n = len(origins)
    for step in (0.5, 0.37):
        got = run(occ, origins, directions, "march", step)
        for r in range(n):
            kind, cell, t = march_every_sample(
                occupied, shape, float(voxels[:, 2].max()), origins[r], directions[r], step
            )
            assert (got.kind[r], tuple(got.index[r].tolist()), got.t[r]) == (kind, cell, t), (r, step)
        assert {MISS, VOXEL, GROUND} <= set(got.kind.tolist())


@pytest.mark.parametrize("precision", ["f64", "f32"])
def test_the_shaders_jumps_are_numbas(wgpu_backend, numba_backend, precision):
    """The shader's march takes the same jumps: numba's answers (f32: the same kinds
    and cells wherever f32 samples fall where f64 ones do, nearly everywhere)."""
    _, _, occ, _, origins, directions = sparse_scene_and_rays(7)
    reference = numba_backend.trace_cells(occ, origins, directions, method="march", step=0.5)
    got = wgpu_backend.trace_cells(occ, origins, directions, method="march", step=0.5, precision=precision)
    if precision == "f64":
        assert np.array_equal(got.kind, reference.kind) and np.array_equal(got.index, reference.index)
        assert np.array_equal(got.t, reference.t)
    else:
        assert np.mean(got.kind == reference.kind) > 0.98
