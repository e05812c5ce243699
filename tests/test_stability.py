"""Stability of every available tracer, and the cases where tracing methods fail.

Property-based over random rays and random small scenes: every call returns
(within a time bound, run on a watchdog thread), gives no NaN, and every answer
is an occupied voxel, a ground cell (layer 0 inside the extent) or a miss, at
a range consistent with the ray. Exact methods must equal the slow float64
reference tracer on every case, including the named hard ones: rays along
grid planes and axes, through edges and corners, grazing rays, origins on
voxel boundaries and inside voxels, an aircraft 10 km away, very long rays
over a large sparse scene, and sensors below the canopy top. The fixed-step
march is checked for validity and for only ever ending later than the exact
answer; how often it differs is measured and recorded (``record_property``),
not hidden. Geometry is written in cell space (voxel i spans [i, i+1)) and
converted to metres for ``trace``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ladartui.scene.occupancy import Occupancy
from ladartui.tracing import GROUND, MISS, VOXEL, trace
from stability_support import (
    EXACT,
    EXAMPLES,
    MARCH,
    MARCH_STEPS,
    TRACERS,
    Case,
    assert_never_earlier,
    assert_valid,
    check_all,
    differ_rate,
    random_scene,
    tracer_param,
)

# --------------------------------------------------------------------------- random cases


@st.composite
def random_cases(draw):
    nx, ny, nz = draw(st.integers(1, 10)), draw(st.integers(1, 10)), draw(st.integers(1, 8))
    density = draw(st.sampled_from([0.0, 0.05, 0.2, 0.5, 0.9]))
    seed = draw(st.integers(0, 2**32 - 1))
    snap = draw(st.sampled_from(["free", "integer", "half"]))
    lattice = draw(st.booleans())
    voxel_size = draw(st.sampled_from([0.1, 0.5, 1.0, 2.0]))
    rng = np.random.default_rng(seed)
    voxels = random_scene(rng, nx, ny, nz, density)
    n = 24
    lo = np.array([-3.0, -3.0, 0.6])  # sensors are above the ground plane
    hi = np.array([nx + 3.0, ny + 3.0, nz + 5.0])
    origins = lo + rng.random((n, 3)) * (hi - lo)
    if snap == "integer":
        origins = np.round(origins)
    elif snap == "half":
        origins = np.round(origins * 2) / 2
    if lattice:
        directions = rng.integers(-2, 3, size=(n, 3)).astype(np.float64)
        directions[np.all(directions == 0, axis=1)] = (0.0, 0.0, -1.0)
    else:
        directions = rng.normal(size=(n, 3))
    return Case(voxels, (nx, ny, nz), origins, directions, voxel_size)


@EXAMPLES
@given(case=random_cases())
def test_random_rays_in_random_scenes_give_valid_answers_and_exact_ones_match_the_reference(case):
    check_all(case, TRACERS)


# --------------------------------------------------------------------------- named hard cases


@tracer_param(EXACT + MARCH)
def test_rays_along_grid_planes_and_axes(tracer, record_property):
    # Two full columns side by side: x in [2, 4), y in [2, 3), every layer.
    voxels = [(x, 2, z) for x in (2, 3) for z in range(6)]
    shape = (8, 6, 6)
    # Down the shared face x = 3, and down the outer faces: faces only, never interiors.
    origins = [(3.0, 2.5, 9.0), (2.0, 2.5, 9.0), (4.0, 2.5, 9.0), (3.0, 2.0, 9.0)]
    case = Case(voxels, shape, origins, [(0, 0, -1)] * 4)
    kind, index, t = case.run(tracer)
    if tracer[1] == "exact":
        # Half-open cells: a point on x = 3 belongs to cell 3, on y = 2 to cell 2.
        assert kind.tolist() == [GROUND] * 4
        assert index.tolist() == [[3, 2, 0], [2, 2, 0], [4, 2, 0], [3, 2, 0]]
        np.testing.assert_allclose(t, 9.0)
    else:
        # The march's samples on x = 3 and x = 2 fall to the occupied cells: a false hit.
        record_property("march hits on faces, of 4", int((kind == VOXEL).sum()))
    # Random rays in grid planes (one or two coordinates on integers, directions in the plane).
    rng = np.random.default_rng(11)
    voxels = random_scene(rng, 9, 9, 7, 0.3)
    origins = rng.random((400, 3)) * (9, 9, 10)
    directions = rng.normal(size=(400, 3))
    for axis in range(3):
        rows = slice(axis * 100, axis * 100 + 100)
        origins[rows, axis] = np.round(origins[rows, axis])
        directions[rows, axis] = 0.0
    origins[300:, :2] = np.round(origins[300:, :2])  # vertical grid lines
    directions[300:] = (0.0, 0.0, -1.0)
    check_all(Case(voxels, (9, 9, 7), origins, directions), [tracer], record_property, "planes")


@tracer_param(EXACT + MARCH)
def test_rays_through_edges_and_corners(tracer, record_property):
    # (1, 0, 0) and (2, 0, 1) share only the edge x = 2, z = 1; a ray along (1, 0, -1)
    # through that edge enters neither and reaches the ground at x = 3.
    case = Case([(1, 0, 0), (2, 0, 1)], (5, 1, 3), [(0.0, 0.5, 3.0)], [(1, 0, -1)])
    kind, index, t = case.run(tracer)
    if tracer[1] == "exact":
        assert (kind[0], index[0].tolist()) == (GROUND, [3, 0, 0])
        assert t[0] == pytest.approx(3 * math.sqrt(2))
    # Corner-only contact in 3D: (1,1,0) and (2,2,1) touch at the point (2, 2, 1).
    case = Case([(1, 1, 0), (2, 2, 1)], (5, 5, 3), [(0.0, 0.0, 3.0)], [(1, 1, -1)])
    kind, index, t = case.run(tracer)
    if tracer[1] == "exact":
        assert (kind[0], index[0].tolist()) == (GROUND, [3, 3, 0])
    # Lattice origins with lattice directions: rays through edges and corners everywhere.
    rng = np.random.default_rng(5)
    voxels = random_scene(rng, 10, 10, 8, 0.25)
    origins = rng.integers(-2, 12, size=(600, 3)).astype(float)
    origins[:, 2] = rng.integers(1, 12, size=600)  # on the ground plane: see the origins test
    directions = rng.integers(-3, 4, size=(600, 3)).astype(float)
    directions[np.all(directions == 0, axis=1)] = (1.0, 1.0, -1.0)
    check_all(Case(voxels, (10, 10, 8), origins, directions), [tracer], record_property, "edges")


@tracer_param(EXACT + MARCH)
def test_grazing_rays_at_one_degree_and_below(tracer, record_property):
    # A flat layer of voxels at z = 0 over 200 cells; rays 1.5 cells up, descending
    # by depression D, hit it where they cross z = 1: at 0.5 / tan(D) cells.
    nx = 200
    voxels = [(x, y, 0) for x in range(nx) for y in range(2)]
    depressions = np.array([1.0, 0.75, 0.5, 0.3])
    origins = np.array([[0.25, 0.3 + 0.4 * i, 1.5] for i in range(4)])  # off the y faces
    r = np.radians(depressions)
    directions = np.stack([np.cos(r), np.zeros(4), -np.sin(r)], axis=1)
    case = Case(voxels, (nx, 2, 1), origins, directions)
    kind, index, t = case.run(tracer)
    expected_x = np.floor(0.25 + 0.5 / np.tan(r)).astype(int)
    if tracer[1] == "exact":
        assert kind.tolist() == [VOXEL] * 4
        assert index[:, 0].tolist() == expected_x.tolist()
        np.testing.assert_allclose(t, 0.5 / np.sin(r), rtol=1e-5)
    # Random grazing rays (depression 0.01 to 1 degree) across a random canopy.
    rng = np.random.default_rng(3)
    voxels = random_scene(rng, 60, 60, 6, 0.02)
    n = 300
    dep = np.radians(rng.uniform(0.01, 1.0, n))
    azimuth = rng.uniform(0, 2 * np.pi, n)
    directions = np.stack(
        [np.cos(dep) * np.sin(azimuth), np.cos(dep) * np.cos(azimuth), -np.sin(dep)], axis=1
    )
    centre = np.array([30.0, 30.0, 0.0])
    origins = centre - 40.0 * directions * np.array([1, 1, 0]) + np.array([0, 0, 1])
    origins[:, 2] = rng.uniform(0.2, 6.5, n)
    check_all(Case(voxels, (60, 60, 6), origins, directions), [tracer], record_property, "grazing")


@tracer_param(EXACT + MARCH)
def test_origins_on_voxel_boundaries_and_inside_occupied_voxels(tracer, record_property):
    voxels = [(2, 2, 2), (5, 2, 2)]
    origins = [
        (2.5, 2.5, 2.5),  # inside (2, 2, 2), looking down
        (2.3, 2.9, 2.1),  # inside, looking sideways
        (3.0, 2.5, 2.5),  # on the +x face of (2, 2, 2), looking into it
        (3.0, 2.5, 2.5),  # on the same face, looking away: on to (5, 2, 2)
        (2.0, 2.0, 3.0),  # on a corner of (2, 2, 2), looking into it
        (6.5, 3.5, 0.0),  # on the ground plane, looking down: not above it, so a miss
    ]
    directions = [(0, 0, -1), (1, 0.2, 0), (-1, 0, 0), (1, 0, 0), (1, 1, -1), (0.3, 0, -1)]
    case = Case(voxels, (8, 5, 4), origins, directions)
    kind, index, t = case.run(tracer)
    if tracer[1] == "exact":
        assert kind.tolist() == [VOXEL] * 5 + [MISS]
        assert index.tolist() == [[2, 2, 2], [2, 2, 2], [2, 2, 2], [5, 2, 2], [2, 2, 2], [-1, -1, -1]]
        np.testing.assert_allclose(t[:5], [0.0, 0.0, 0.0, 2.0, 0.0], atol=1e-6)
    else:
        # The march's first sample is below the ground plane: a ground return the
        # exact rule does not give (the origin is not above the ground).
        record_property("march answer for an origin on the ground plane", int(kind[5]))
    # Random origins on boundaries (integer coordinates) and inside occupied voxels.
    rng = np.random.default_rng(9)
    voxels = random_scene(rng, 8, 8, 6, 0.4)
    inside = voxels[rng.integers(0, len(voxels), 200)] + rng.uniform(0.05, 0.95, (200, 3))
    on_grid = rng.integers(0, 9, size=(200, 3)).astype(float)
    on_grid[:, 2] = rng.integers(1, 9, size=200)  # above the ground plane
    origins = np.vstack([inside, on_grid])
    directions = rng.normal(size=(400, 3))
    check_all(Case(voxels, (8, 8, 6), origins, directions), [tracer], record_property, "origins")


@tracer_param(EXACT + MARCH)
def test_aircraft_ten_km_away(tracer, record_property):
    # 0.1 m voxels: the aircraft is 100,000 cells from a 64 x 64 forest.
    rng = np.random.default_rng(21)
    voxels = random_scene(rng, 64, 64, 12, 0.03)
    n = 400
    aim = rng.uniform([4, 4, 0], [60, 60, 8], (n, 3))
    bearing = rng.uniform(0, 2 * np.pi, n)
    depression = np.radians(rng.uniform(2.0, 40.0, n))
    distance = 100_000.0
    away = np.stack(
        [np.cos(depression) * np.sin(bearing), np.cos(depression) * np.cos(bearing), np.sin(depression)],
        axis=1,
    )
    origins = aim + distance * away
    case = Case(voxels, (64, 64, 12), origins, -away, voxel_size=0.1)
    reference = check_all(case, [tracer], record_property, "10 km")
    assert (reference[0] == VOXEL).mean() > 0.1  # the rays do reach the forest


@tracer_param(EXACT + MARCH)
def test_very_long_rays_across_a_large_sparse_scene(tracer, record_property):
    # 20,000 x 20,000 cells with scattered voxels: memory follows content, rays cross it all.
    rng = np.random.default_rng(4)
    nx = ny = 20_000
    voxels = np.unique(
        np.column_stack([rng.integers(0, nx, 3000), rng.integers(0, ny, 3000), rng.integers(0, 30, 3000)]),
        axis=0,
    )
    n = 64
    start = np.column_stack([rng.uniform(0, 50, n), rng.uniform(0, 50, n), rng.uniform(20, 31, n)])
    end = np.column_stack([rng.uniform(nx - 50, nx, n), rng.uniform(ny - 50, ny, n), np.zeros(n)])
    case = Case(voxels, (nx, ny, 30), start, end - start)
    check_all(case, [tracer], record_property, "long")


@pytest.mark.parametrize("tracer", [pytest.param(t, id="-".join(t)) for t in MARCH])
def test_march_over_more_than_65536_samples_still_reaches_the_ground(tracer):
    # One voxel in the far corner, above the ray: the march must reach the ground at
    # the ray's ground point (11998.0, 11998.0) -> cell (11998, 11998), 67,882 samples on.
    n = 12_000
    case = Case([(n - 1, n - 1, 29)], (n, n, 30), [(1.0, 1.0, 25.0)], [(n - 3.0, n - 3.0, -25.0)])
    kind, index, t = case.run(tracer, 0.25)
    assert (kind[0], index[0].tolist()) == (GROUND, [n - 2, n - 2, 0])
    assert t[0] == pytest.approx(math.sqrt(2 * (n - 3.0) ** 2 + 25.0**2), abs=0.3)


@tracer_param(EXACT + MARCH)
def test_sensors_below_the_canopy_top(tracer, record_property):
    rng = np.random.default_rng(8)
    canopy = random_scene(rng, 24, 24, 4, 0.35) + (0, 0, 8)  # layers 8..11
    understorey = random_scene(rng, 24, 24, 3, 0.05)
    voxels = np.unique(np.vstack([canopy, understorey]), axis=0)
    n = 400
    origins = np.column_stack([rng.uniform(0, 24, n), rng.uniform(0, 24, n), rng.uniform(3, 7.9, n)])
    directions = rng.normal(size=(n, 3))
    directions[: n // 2, 2] = -np.abs(directions[: n // 2, 2])
    case = Case(voxels, (24, 24, 12), origins, directions)
    check_all(case, [tracer], record_property, "below canopy")


# --------------------------------------------------------------------------- march, measured


@tracer_param(MARCH)
def test_march_misses_thin_diagonal_features_and_the_rate_is_recorded(tracer, record_property):
    # One-voxel-thick diagonal branches (6-connected staircases) under rays at 45 degrees.
    rng = np.random.default_rng(12)
    branches = []
    for _ in range(80):
        x, y, z = rng.integers(5, 55), rng.integers(5, 55), rng.integers(4, 14)
        dx, dy = rng.choice([-1, 1], 2)
        for k in range(8):
            branches += [
                (x + k * dx, y + k * dy, z + k),
                (x + k * dx + dx, y + k * dy, z + k),
                (x + (k + 1) * dx, y + (k + 1) * dy, z + k),
            ]
    voxels = np.unique(np.clip(np.array(branches), 0, 63), axis=0)
    n = 3000
    azimuth = rng.uniform(0, 2 * np.pi, n)
    dep = np.radians(45.0)
    directions = np.stack(
        [np.cos(dep) * np.sin(azimuth), np.cos(dep) * np.cos(azimuth), -np.full(n, np.sin(dep))], axis=1
    )
    origins = np.column_stack([rng.uniform(0, 64, n), rng.uniform(0, 64, n), np.full(n, 40.0)])
    origins -= 0 * directions
    case = Case(voxels, (64, 64, 24), origins, directions)
    reference = case.reference()
    assert (reference[0] == VOXEL).mean() > 0.2
    rates = {}
    for step in MARCH_STEPS:
        answer = case.run(tracer, step)
        assert_valid(case, answer, "march", tracer[2])
        assert assert_never_earlier(case, answer, reference) == 0
        rates[step] = differ_rate(answer, reference)
        record_property(f"march step {step} differ rate", rates[step])
    # The failure is real and shrinks with the step; it is not hidden.
    assert rates[1.0] > 0.02
    assert rates[1.0] > rates[0.25] > rates[0.1]


# --------------------------------------------------------------------------- measures


def test_measures_stay_defined_or_say_undefined_on_degenerate_inputs():
    import json

    from ladartui.measures import compute_measures

    empty = np.zeros((0, 3), np.int32)
    # No target voxel seen, one scan: coverage is a defined 0, directions undefined.
    target = np.array([[4, 4, 0], [5, 4, 0]])
    m = compute_measures(
        target, np.array([[0, 0, 3]]), target, scene_per_scan=[empty], target_per_scan=[target]
    )
    assert m.obscured_coverage == 0.0 and m.unobscured_coverage == 1.0
    assert m.obscured_directions.mean_direction is None and m.direction_shift_rad is None
    assert m.obscured_after_scan == (0.0,) and m.scans == 1
    # A target of one voxel: seen, but a single voxel at its own centroid has no direction.
    one = np.array([[3, 3, 0]])
    m = compute_measures(one, one, one, scene_per_scan=[one], target_per_scan=[one])
    assert m.obscured_coverage == 1.0 and m.maximum_coverage == 1.0
    assert m.obscured_directions.count == 0 and m.obscured_directions.mean_direction is None
    # No target at all: every share is undefined, written as "undefined".
    m = compute_measures(empty, empty, empty)
    assert m.obscured_coverage is None and m.maximum_coverage is None
    for measures in (m,):
        json.dumps(measures.to_dict(), allow_nan=False)
        assert "target_coverage = undefined" in measures.to_cmf()


def test_measures_of_a_hidden_one_voxel_target_traced_in_one_scan():
    from ladartui.measures import compute_measures
    from ladartui.returns import scan_returns

    # A roof over a one-voxel target: a nadir ray sees the roof, never the target.
    voxels = np.array([(4, 4, 0)] + [(x, y, 3) for x in range(3, 6) for y in range(3, 6)])
    occupancy = Occupancy.build(voxels, (9, 9, 5))
    origins = np.array([[4.0, 4.0, 20.0]])
    hits = trace(occupancy, origins, [[0.0, 0.0, -1.0]], backend="numba")
    returns = scan_returns(hits, np.zeros(1, np.int32), 1.0)
    assert returns.tolist() == [[4, 4, 3]]
    m = compute_measures(
        np.array([[4, 4, 0]]),
        returns,
        np.array([[4, 4, 0]]),
        scene_per_scan=[returns],
        target_per_scan=[np.array([[4, 4, 0]])],
    )
    assert m.obscured_coverage == 0.0 and m.obscured_directions.mean_direction is None
    assert m.missed_share == 1.0
