"""Optional skips never change an answer: the exact tracer with and without the empty
cubes agrees ray for ray, and both agree with the slab reference."""

import dataclasses
import math

import numpy as np
import pytest

from ladartui.scene.generate import generate_scene
from ladartui.scene.occupancy import Occupancy
from ladartui.tracing.backend import VOXEL, get_backend
from ladartui.tracing.reference import reference_trace_cells


def exact(occ, o, d):
    return get_backend("numba").trace_cells(occ, o, d, method="exact")


def without_cubes(occ):
    return dataclasses.replace(occ, cubes=None, cube_origin=None, cube_dims=None)


def assert_same(a, b):
    assert np.array_equal(a.kind, b.kind)
    assert np.array_equal(a.index, b.index)
    assert np.array_equal(a.t, b.t)  # bit for bit: the same boundaries are crossed


def looks_at(centre, n, rng, depression_deg):
    """Rays from about 300 cells away towards points around ``centre``, all azimuths."""
    e = np.radians(depression_deg)
    az = rng.uniform(0, 2 * math.pi, n)
    d = np.column_stack([np.cos(e) * np.cos(az), np.cos(e) * np.sin(az), np.full(n, -np.sin(e))])
    aim = centre + rng.normal(scale=[40, 40, 3], size=(n, 3))
    return aim - 300 * d, d


@pytest.fixture(scope="module")
def forest():
    scene = generate_scene("small", 3)
    return scene, Occupancy.build(scene.voxels, scene.shape)


@pytest.mark.parametrize("depression", [90.0, 60.0, 45.0, 20.0, 3.0])
def test_generated_forest_same_answers_with_and_without_cube_jumps(forest, depression):
    scene, occ = forest
    rng = np.random.default_rng(int(depression))
    o, d = looks_at(np.array(scene.shape) / 2 * [1, 1, 0], 20_000, rng, depression)
    if depression == 90.0:
        d = np.tile([0.0, 0.0, -1.0], (len(o), 1))
        o[::2, :2] = np.round(o[::2, :2])  # half on brick and voxel faces
    got = exact(occ, o, d)
    assert_same(got, exact(without_cubes(occ), o, d))
    assert (got.kind == VOXEL).mean() > 0.1


def test_random_rays_everywhere_same_with_and_without_jumps(forest):
    scene, occ = forest
    rng = np.random.default_rng(5)
    n = 30_000
    o = rng.uniform([-20, -20, -5], np.array(scene.shape) + 20, size=(n, 3))
    o[::3] = np.round(o[::3] * 2) / 2  # many origins on cell faces
    d = rng.normal(size=(n, 3))
    d[::5, rng.integers(0, 3)] = 0.0  # axis-parallel components
    d /= np.linalg.norm(d, axis=1)[:, None]
    assert_same(exact(occ, o, d), exact(without_cubes(occ), o, d))


def test_jumps_through_sparse_scene_match_the_reference():
    # Wide empty spaces with a few voxels give long jumps and leave tiles between jumps.
    rng = np.random.default_rng(21)
    shape = (300, 260, 200)
    vox = rng.integers(0, shape, size=(150, 3))
    aim = vox[rng.integers(0, len(vox), 3000)] + rng.uniform(0, 1, size=(3000, 3))
    o = rng.uniform(-40, 340, size=(3000, 3))
    d = aim - o
    d /= np.linalg.norm(d, axis=1)[:, None]
    occ = Occupancy.build(vox, shape)
    got = exact(occ, o, d)
    ref = reference_trace_cells(vox, shape, o, d)
    assert np.array_equal(got.kind, ref.kind) and np.array_equal(got.index, ref.index)
    finite = np.isfinite(ref.t)
    assert np.array_equal(np.isfinite(got.t), finite)
    assert np.allclose(got.t[finite], ref.t[finite], rtol=0, atol=1e-9)
    assert (got.kind == VOXEL).mean() > 0.5
    assert_same(got, exact(without_cubes(occ), o, d))
