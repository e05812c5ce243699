"""The wgpu backend against the numba backend, ray for ray.

float64: identical answers on an edge-case suite (with hand-derived expected
answers) and on random rays over a generated forest. float32: identical on
the edge-case suite; on random rays at least 99.99 % identical, every
difference a near-tie: some ray within NEAR_TIE cells of the traced one
(parallel, shifted sideways or along the axes) gets the float32 answer from
the exact float64 tracer, or the two ranges agree within NEAR_TIE; for the
march, the first sample where the two differ lies within NEAR_TIE of a cell
face. The same bar holds for an aircraft 10 km from the scene origin.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ladartui.tracing.backend import GROUND, MISS, VOXEL

Occupancy = pytest.importorskip("ladartui.scene.occupancy").Occupancy

NEAR_TIE = 1e-3  # cells: float32 coordinates of a ~1000-cell scene are good to ~1e-4
F32_AGREEMENT = 0.9999


# The wgpu_backend and numba_backend fixtures come from tests/conftest.py.


def unit(*v):
    v = np.array(v, dtype=np.float64)
    return v / np.linalg.norm(v)


# --- the edge-case suite ----------------------------------------------------
#
# Scene 16 x 16 x 8 cells. A = (4, 4, 2) and B = (5, 5, 2) share the vertical
# edge x = y = 5, z in [2, 3]; C = (10, 10, 0) stands on the ground.
EDGE_SHAPE = (16, 16, 8)
A, B, C = (4, 4, 2), (5, 5, 2), (10, 10, 0)
S3 = math.sqrt(3.0)
S2 = math.sqrt(2.0)


def edge_cases():
    """(name, origin, direction, expected kind, expected cell, expected t) in cell space."""
    far = 20000.0
    d45 = unit(1.0, 0.0, -1.0)
    top_of_a = np.array([4.5, 4.5, 3.0])
    d_corner = unit(1.0, 1.0, -1.0)
    return [
        # Axis-aligned.
        ("nadir onto A", (4.5, 4.5, 10.0), (0, 0, -1), VOXEL, A, 7.0),
        ("nadir through empty", (2.5, 2.5, 10.0), (0, 0, -1), GROUND, (2, 2, 0), 10.0),
        ("nadir onto C", (10.5, 10.5, 10.0), (0, 0, -1), VOXEL, C, 9.0),
        ("+x into A", (0.5, 4.5, 2.5), (1, 0, 0), VOXEL, A, 3.5),
        ("-x into B", (15.5, 5.5, 2.5), (-1, 0, 0), VOXEL, B, 9.5),
        ("+y into A", (4.5, 0.25, 2.75), (0, 1, 0), VOXEL, A, 3.75),
        ("-y past A", (4.5, 15.5, 3.5), (0, -1, 0), MISS, None, None),
        ("up into A", (4.5, 4.5, 0.5), (0, 0, 1), VOXEL, A, 1.5),
        ("up through empty", (2.5, 2.5, 0.5), (0, 0, 1), MISS, None, None),
        # Along grid planes: on faces between cells, never inside one.
        ("down the face x = 5", (5.0, 4.5, 10.0), (0, 0, -1), GROUND, (5, 4, 0), 10.0),
        ("down the edge of A and B", (5.0, 5.0, 10.0), (0, 0, -1), GROUND, (5, 5, 0), 10.0),
        ("along the top face of A", (0.5, 4.5, 3.0), (1, 0, 0), MISS, None, None),
        ("along the side face of A", (4.0, 0.5, 2.5), (0, 1, 0), MISS, None, None),
        ("down the face x = nx", (16.0, 3.5, 10.0), (0, 0, -1), MISS, None, None),
        ("down the face x = 0", (0.0, 3.5, 10.0), (0, 0, -1), GROUND, (0, 3, 0), 10.0),
        # Through edges and corners: tied axes step together.
        ("diagonal touching the A-B edge", (3.5, 6.5, 2.5), unit(1, -1, 0), MISS, None, None),
        ("diagonal through corners into A", (0.5, 0.5, 2.5), unit(1, 1, 0), VOXEL, A, 3.5 * S2),
        ("3-D diagonal through a corner into B", (2.5, 2.5, 5.5), d_corner, VOXEL, B, 2.5 * S3),
        ("3-D diagonal onto the ground corner", (1.0, 1.0, 1.0), unit(-1, -1, -1), GROUND, (0, 0, 0), S3),
        # Grazing: along a face is no hit, a hair inside is.
        ("grazing into A", (0.5, 4.5, 3.0), unit(1.0, 0.0, -1e-9), VOXEL, A, 3.5),
        ("grazing above A", (0.5, 4.5, 3.0), unit(1.0, 0.0, 1e-9), MISS, None, None),
        # Origins on boundaries and inside voxels.
        ("on the face of A going in", (4.0, 4.5, 2.5), (1, 0, 0), VOXEL, A, 0.0),
        ("on the far face of A going in", (5.0, 4.5, 2.5), (-1, 0, 0), VOXEL, A, 0.0),
        ("on the face of A going out", (4.0, 4.5, 2.5), (-1, 0, 0), MISS, None, None),
        ("on the top face of A going down", (4.5, 4.5, 3.0), (0, 0, -1), VOXEL, A, 0.0),
        ("inside A going up", (4.25, 4.75, 2.5), (0, 0, 1), VOXEL, A, 0.0),
        ("inside C going sideways", (10.5, 10.5, 0.5), unit(1, 2, 0), VOXEL, C, 0.0),
        ("on the ground going down", (2.5, 2.5, 0.0), (0, 0, -1), MISS, None, None),
        # Far origins (20 000 cells, 10 km at 0.5 m voxels).
        ("far 45 degrees onto A", tuple(top_of_a - far * d45), d45, VOXEL, A, far),
        ("far nadir onto the ground", (7.5, 12.5, far), (0, 0, -1), GROUND, (7, 12, 0), far),
        ("far horizontal into B", (5.5 - far, 5.5, 2.5), (1, 0, 0), VOXEL, B, far - 0.5),
        ("far outside the extent", (-far, -far, far), unit(-1, 0, -1), MISS, None, None),
    ]


@pytest.fixture(scope="module")
def edge_scene():
    return Occupancy.build(np.array([A, B, C]), shape=EDGE_SHAPE)


def edge_arrays():
    cases = edge_cases()
    origins = np.array([c[1] for c in cases], dtype=np.float64)
    directions = np.array([unit(*c[2]) for c in cases])
    return cases, origins, directions


def assert_edge_answers(hits, cases, t_tolerance):
    for r, (name, _o, _d, kind, cell, t) in enumerate(cases):
        assert hits.kind[r] == kind, f"{name}: kind {hits.kind[r]}, expected {kind}"
        if kind == MISS:
            assert tuple(hits.index[r]) == (-1, -1, -1), name
            assert hits.t[r] == np.inf, name
        else:
            assert tuple(hits.index[r]) == cell, f"{name}: cell {tuple(hits.index[r])}, expected {cell}"
            assert hits.t[r] == pytest.approx(t, rel=1e-12, abs=t_tolerance), name


@pytest.mark.parametrize("precision", ["f64", "f32"])
def test_edge_cases_have_the_expected_answers(wgpu_backend, edge_scene, precision):
    cases, origins, directions = edge_arrays()
    hits = wgpu_backend.trace_cells(edge_scene, origins, directions, precision=precision)
    assert hits.info["precision"] == precision
    assert_edge_answers(hits, cases, 1e-9 if precision == "f64" else 1e-4)


def test_edge_cases_match_numba(wgpu_backend, numba_backend, edge_scene):
    cases, origins, directions = edge_arrays()
    reference = numba_backend.trace_cells(edge_scene, origins, directions)
    assert_edge_answers(reference, cases, 1e-9)
    for precision in ("f64", "f32"):
        hits = wgpu_backend.trace_cells(edge_scene, origins, directions, precision=precision)
        assert np.array_equal(hits.kind, reference.kind), precision
        assert np.array_equal(hits.index, reference.index), precision
    hits = wgpu_backend.trace_cells(edge_scene, origins, directions, precision="f64")
    assert np.array_equal(hits.t, reference.t)


@pytest.mark.parametrize("step", [1.0, 0.5, 0.3])
def test_edge_cases_march_matches_numba(wgpu_backend, numba_backend, edge_scene, step):
    _cases, origins, directions = edge_arrays()
    reference = numba_backend.trace_cells(edge_scene, origins, directions, method="march", step=step)
    hits = wgpu_backend.trace_cells(
        edge_scene, origins, directions, method="march", step=step, precision="f64"
    )
    assert np.array_equal(hits.kind, reference.kind)
    assert np.array_equal(hits.index, reference.index)
    assert np.array_equal(hits.t, reference.t)
    # The march lands on boundaries often here; nadir samples are exact in float32 too.
    nadir = directions[:, 2] == -1.0
    hits32 = wgpu_backend.trace_cells(
        edge_scene, origins[nadir], directions[nadir], method="march", step=step, precision="f32"
    )
    assert np.array_equal(hits32.kind, reference.kind[nadir])
    assert np.array_equal(hits32.index, reference.index[nadir])


def test_empty_scene(wgpu_backend, numba_backend):
    empty = Occupancy.build(np.zeros((0, 3), np.int64), shape=(8, 8, 4))
    # Ground points at cell centres or on the extent's faces (exact in float32 too).
    origins = np.array(
        [
            [3.5, 2.5, 5.0],
            [8.0, 2.5, 5.0],
            [0.0, 7.5, 5.0],
            [2.5, 2.5, 6.0],
            [2.5, 2.5, 6.0],
            [2.5, 2.5, 0.5],
            [2.5, 2.5, 0.5],
            [-20000.0, 4.5, 20000.5],
        ]
    )
    directions = np.array(
        [
            [0, 0, -1],
            unit(0, 0, -1),
            unit(0, 0, -1),
            unit(1, 1, -2),
            unit(-2, 1, -2),
            unit(0, 0, 1),
            unit(1, 0, 0),
            unit(1, 0, -1),
        ]
    )
    expected_kind = [GROUND, MISS, GROUND, GROUND, MISS, MISS, MISS, GROUND]
    expected_index = [
        [3, 2, 0],
        [-1, -1, -1],
        [0, 7, 0],
        [5, 5, 0],
        [-1, -1, -1],
        [-1, -1, -1],
        [-1, -1, -1],
        [0, 4, 0],
    ]
    expected_t = [5.0, np.inf, 5.0, 3 * math.sqrt(6.0), np.inf, np.inf, np.inf, 20000.5 * S2]
    reference = numba_backend.trace_cells(empty, origins, directions)
    assert reference.kind.tolist() == expected_kind
    for precision in ("f64", "f32"):
        hits = wgpu_backend.trace_cells(empty, origins, directions, precision=precision)
        assert hits.kind.tolist() == expected_kind, precision
        assert hits.index.tolist() == expected_index, precision
        # Exact ground returns come from the float64 rule in both precisions.
        assert np.allclose(hits.t, expected_t, rtol=1e-9, atol=0.0), precision
    # The whole edge-case set over an empty scene: as numba, the march in float64,
    # exact in both precisions (the ground rule runs on the host in float64).
    _cases, origins, directions = edge_arrays()
    empty = Occupancy.build(np.zeros((0, 3), np.int64), shape=EDGE_SHAPE)
    for method, precision in (("exact", "f64"), ("exact", "f32"), ("march", "f64")):
        reference = numba_backend.trace_cells(empty, origins, directions, method=method)
        assert not np.any(reference.kind == VOXEL)
        hits = wgpu_backend.trace_cells(empty, origins, directions, method=method, precision=precision)
        assert np.array_equal(hits.kind, reference.kind), (method, precision)
        assert np.array_equal(hits.index, reference.index), (method, precision)
        assert np.array_equal(hits.t, reference.t), (method, precision)


# --- random rays over a generated forest -----------------------------------


def forest_scene():
    """(occupancy, voxel size in metres) of the generated "small" forest."""
    generate_scene = pytest.importorskip("ladartui.scene.generate").generate_scene
    generated = generate_scene("small")
    return Occupancy.build(generated.voxels, generated.shape), generated.voxel_size


@pytest.fixture(scope="module")
def forest_and_voxel_size():
    return forest_scene()


@pytest.fixture(scope="module")
def forest(forest_and_voxel_size):
    return forest_and_voxel_size[0]


def aircraft_rays(rng, occupancy, n, distance):
    """Rays from points ``distance`` cells from the scene centre, aimed into the scene."""
    nx, ny, _ = occupancy.shape
    top = max(occupancy.zmax + 1, 1)
    heading = rng.uniform(0, 2 * np.pi, n)
    elevation = np.radians(rng.uniform(15, 89.9, n))
    centre = np.array([nx / 2, ny / 2, 0.0])
    origins = centre + distance * np.column_stack(
        [np.cos(heading) * np.cos(elevation), np.sin(heading) * np.cos(elevation), np.sin(elevation)]
    )
    aims = np.column_stack(
        [rng.uniform(-0.1, 1.1, n) * nx, rng.uniform(-0.1, 1.1, n) * ny, rng.uniform(0, top, n)]
    )
    directions = aims - origins
    return origins, directions / np.linalg.norm(directions, axis=1)[:, None]


def scattered_rays(rng, occupancy, n):
    """Origins in and around the scene box, directions uniform on the sphere."""
    nx, ny, nz = occupancy.shape
    top = occupancy.zmax + 1
    origins = np.column_stack(
        [rng.uniform(-0.2, 1.2, n) * nx, rng.uniform(-0.2, 1.2, n) * ny, rng.uniform(0, 2 * top + 2, n)]
    )
    directions = rng.normal(size=(n, 3))
    return origins, directions / np.linalg.norm(directions, axis=1)[:, None]


@pytest.fixture(scope="module")
def random_rays(forest):
    rng = np.random.default_rng(20260)
    o1, d1 = aircraft_rays(rng, forest, 70_000, distance=400.0)
    o2, d2 = scattered_rays(rng, forest, 40_000)
    return np.concatenate([o1, o2]), np.concatenate([d1, d2])


def differing(a, b):
    return (a.kind != b.kind) | np.any(a.index != b.index, axis=1)


def assert_same_hits(hits, reference, t_rtol):
    bad = differing(hits, reference)
    assert not bad.any(), f"{bad.sum()} rays differ, first {np.flatnonzero(bad)[:5]}"
    hit = reference.kind != MISS
    assert np.allclose(hits.t[hit], reference.t[hit], rtol=t_rtol, atol=0.0)
    assert np.all(np.isinf(hits.t[~hit]))


@pytest.mark.parametrize("method", ["exact", "march"])
def test_f64_random_rays_identical(wgpu_backend, numba_backend, forest, random_rays, method):
    origins, directions = random_rays
    reference = numba_backend.trace_cells(forest, origins, directions, method=method, step=0.5)
    assert np.count_nonzero(reference.kind == VOXEL) > len(origins) // 4  # a real workout
    hits = wgpu_backend.trace_cells(forest, origins, directions, method=method, step=0.5, precision="f64")
    assert_same_hits(hits, reference, t_rtol=1e-12)


def perpendiculars(d):
    a = np.eye(3)[np.argmin(np.abs(d))]
    u = np.cross(d, a)
    u /= np.linalg.norm(u)
    return u, np.cross(d, u)


def is_near_tie(numba_backend, occupancy, o, d, method, got_kind, got_index, got_t, ref_t):
    """Is the float32 answer (got_*) one a ray within NEAR_TIE of (o, d) would give?

    Exact: the two ranges agree within NEAR_TIE (two voxels meeting where the ray
    enters), or a parallel ray shifted by NEAR_TIE (16 directions across the ray,
    6 along the axes) gets the float32 answer from the float64 tracer. March:
    the first sample where the two differ (the earlier of the two ranges) lies
    within NEAR_TIE of a cell face, so its cell is decided by rounding.
    """
    if method == "march":
        t = min(got_t, ref_t)
        if not np.isfinite(t):
            return False
        sample = o + t * d
        return bool(np.min(np.abs(sample - np.round(sample))) <= NEAR_TIE)
    if got_kind != MISS and np.isfinite(ref_t) and abs(got_t - ref_t) <= NEAR_TIE:
        return True
    u, v = perpendiculars(d)
    angles = np.linspace(0, 2 * math.pi, 16, endpoint=False)
    shifts = [NEAR_TIE * (math.cos(a) * u + math.sin(a) * v) for a in angles]
    shifts += [NEAR_TIE * s * e for e in np.eye(3) for s in (1, -1)]
    origins = o + np.array(shifts)
    perturbed = numba_backend.trace_cells(occupancy, origins, np.tile(d, (len(origins), 1)), method=method)
    same = (perturbed.kind == got_kind) & np.all(perturbed.index == got_index, axis=1)
    return bool(same.any())


def check_f32(wgpu_backend, numba_backend, occupancy, origins, directions, method):
    reference = numba_backend.trace_cells(occupancy, origins, directions, method=method, step=0.5)
    hits = wgpu_backend.trace_cells(occupancy, origins, directions, method=method, step=0.5, precision="f32")
    assert hits.info["precision"] == "f32"
    hit = reference.kind != MISS
    far_t = np.zeros(len(origins), bool)
    far_t[hit] = np.abs(hits.t[hit] - reference.t[hit]) > NEAR_TIE
    bad = np.flatnonzero(differing(hits, reference) | far_t)
    agreement = 1.0 - len(bad) / len(origins)
    assert agreement >= F32_AGREEMENT, f"{method}: {len(bad)} of {len(origins)} rays differ"
    for r in bad:
        assert is_near_tie(
            numba_backend,
            occupancy,
            origins[r],
            directions[r],
            method,
            hits.kind[r],
            hits.index[r],
            hits.t[r],
            reference.t[r],
        ), (
            f"ray {r} ({origins[r].tolist()}, {directions[r].tolist()}): float32 says "
            f"{hits.kind[r]} {hits.index[r].tolist()} t={hits.t[r]}, float64 says "
            f"{reference.kind[r]} {reference.index[r].tolist()} t={reference.t[r]}"
        )
    assert np.all(np.isinf(hits.t[hits.kind == MISS]))


@pytest.mark.parametrize("method", ["exact", "march"])
def test_f32_random_rays_near_identical(wgpu_backend, numba_backend, forest, random_rays, method):
    origins, directions = random_rays
    check_f32(wgpu_backend, numba_backend, forest, origins, directions, method)


def test_f32_exact_rays_without_a_voxel_get_numbas_ground_answer(
    wgpu_backend, numba_backend, forest, random_rays
):
    """Exact f32: where the shader finds no voxel, the host applies the ground rule in
    float64 to the ray as given, so the answer is numba's bit for bit however the
    device rounds. (A GPU that fused the rule's multiply and add in float32 sent the
    edge cases' ray onto the ground corner to a miss.)"""
    origins, directions = random_rays
    reference = numba_backend.trace_cells(forest, origins, directions)
    hits = wgpu_backend.trace_cells(forest, origins, directions, precision="f32")
    no_voxel = (hits.kind != VOXEL) & (reference.kind != VOXEL)
    assert np.count_nonzero(no_voxel & (reference.kind == GROUND)) > 1000
    assert np.array_equal(hits.kind[no_voxel], reference.kind[no_voxel])
    assert np.array_equal(hits.index[no_voxel], reference.index[no_voxel])
    assert np.array_equal(hits.t[no_voxel], reference.t[no_voxel])


@pytest.mark.parametrize("method", ["exact", "march"])
def test_f32_far_aircraft(wgpu_backend, numba_backend, forest_and_voxel_size, method):
    """An aircraft 10 km from the scene origin: float32 keeps the same bar."""
    forest, voxel_size = forest_and_voxel_size
    rng = np.random.default_rng(99)
    ten_km = 10_000.0 / voxel_size
    origins, directions = aircraft_rays(rng, forest, 30_000, distance=ten_km)
    assert np.all(np.linalg.norm(origins, axis=1) > 0.95 * ten_km)
    check_f32(wgpu_backend, numba_backend, forest, origins, directions, method)


def offset_scene_and_rays(offset, n):
    """A random 20 x 20 x 10 block of voxels at x and y index ``offset`` (a scene in
    absolute map indices), and rays from 200 cells above aimed into and around it."""
    rng = np.random.default_rng(8)
    block = np.argwhere(rng.random((20, 20, 10)) < 0.15)
    occupancy = Occupancy.build(block + [offset, offset, 0], shape=(offset + 50, offset + 50, 10))
    aims = np.column_stack([rng.uniform(-10, 25, (n, 2)) + offset, rng.uniform(0, 10, n)])
    origins = aims + np.column_stack([rng.uniform(-50, 50, (n, 2)), np.full(n, 200.0)])
    directions = aims - origins
    return occupancy, origins, directions / np.linalg.norm(directions, axis=1)[:, None]


@pytest.mark.parametrize("method", ["exact", "march"])
@pytest.mark.parametrize("offset", [1_000_037, 1 << 24])
def test_f32_voxels_far_from_index_0(wgpu_backend, numba_backend, method, offset):
    """Voxels at large indices (UTM metres at 0.25 m are ~2e6): float32 keeps the same
    bar, the rays seen by the shader being near the voxels, not near index 0."""
    occupancy, origins, directions = offset_scene_and_rays(offset, 1500)
    reference = numba_backend.trace_cells(occupancy, origins, directions, method=method, step=0.5)
    assert np.count_nonzero(reference.kind == VOXEL) > 300
    assert np.count_nonzero(reference.kind == GROUND) > 300
    assert np.count_nonzero(reference.index[:, 0] < offset) > 100  # ground short of the block
    check_f32(wgpu_backend, numba_backend, occupancy, origins, directions, method)
