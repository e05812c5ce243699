"""Bundle starts (tracing/bundle.py): a lower bound for every ray of a chunk, and no change
to any answer, on sensor scans where they do skip empty space."""

import math

import numpy as np
import pytest

from ladartui.flight import ScanPose, aim_at
from ladartui.scene.occupancy import Occupancy
from ladartui.sensor import Sensor
from ladartui.tracing.backend import MISS, VOXEL
from ladartui.tracing.bundle import BUNDLE_REACH, FINE_REACH, bundle_start, bundle_starts, halo_arrays
from ladartui.tracing.reference import reference_trace_cells

CHUNK = 64


@pytest.fixture(scope="module")
def forest():
    """(voxels, occupancy) of the generated "small" forest (0.25 m voxels)."""
    from ladartui.scene.generate import generate_scene

    generated = generate_scene("small")
    return generated.voxels, Occupancy.build(generated.voxels, generated.shape)


def scan_rays(occ, rng, scans, slant_cells, depressions=(1.0, 89.9), sensor=None):
    """Cell-space rays of sensor scans aimed at random points of the scene."""
    sensor = sensor or Sensor(grid=16, ray_grid=4, fov=5.0)
    nx, ny, _ = occ.shape
    origins, directions = [], []
    for _ in range(scans):
        aim = np.array([rng.uniform(0.2, 0.8) * nx, rng.uniform(0.2, 0.8) * ny, rng.uniform(0, occ.zmax + 1)])
        e = math.radians(rng.uniform(*depressions))
        a = rng.uniform(0, 2 * math.pi)
        at = aim + slant_cells * np.array([math.cos(a) * math.cos(e), math.sin(a) * math.cos(e), math.sin(e)])
        pose = aim_at(ScanPose(*at.tolist()), aim.tolist())
        o, d, _ = sensor.rays(pose)
        origins.append(o)
        directions.append(d)
    return np.concatenate(origins), np.concatenate(directions)


def starts_of(occ, origins, directions):
    out = np.zeros(-(-len(origins) // CHUNK))
    bundle_starts(origins, directions, CHUNK, *halo_arrays(occ), out)
    return np.repeat(out, CHUNK)[: len(origins)]


def same(a, b):
    return np.array_equal(a.kind, b.kind) and np.array_equal(a.index, b.index) and np.array_equal(a.t, b.t)


@pytest.mark.parametrize("level, size", [(0, 8), (1, 4)])
def test_halos_mark_exactly_the_cells_next_to_voxels(level, size):
    rng = np.random.default_rng(3)
    shape = (90, 70, 50)
    vox = rng.integers(0, shape, size=(40, 3))
    occ = Occupancy.build(vox, shape)
    bits, origin, dims = halo_arrays(occ)[3 * level : 3 * level + 3]
    shift = size.bit_length() - 1
    assert origin.tolist() == ((vox.min(axis=0) >> shift) - 1).tolist()
    cells = {tuple(b) for b in (vox >> shift)}
    for x in range(dims[0]):
        for y in range(dims[1]):
            for z in range(dims[2]):
                cell = (origin[0] + x, origin[1] + y, origin[2] + z)
                expected = any(
                    (cell[0] + i, cell[1] + j, cell[2] + k) in cells
                    for i in (-1, 0, 1)
                    for j in (-1, 0, 1)
                    for k in (-1, 0, 1)
                )
                lin = x + dims[0] * (y + dims[1] * z)
                assert bool((bits[lin >> 5] >> (lin & 31)) & 1) == expected, cell


def test_start_stops_before_the_only_voxel():
    # One voxel at z = 100 seen from straight above: the chunk starts one voxel above the
    # 4-voxel halo (two 4-voxel cells over the voxel's cell), never inside or past the voxel.
    occ = Occupancy.build(np.array([[40, 40, 100]]), (80, 80, 200))
    halo = halo_arrays(occ)
    o = np.tile([40.5, 40.5, 1000.0], (CHUNK, 1))
    d = np.tile([0.0, 0.0, -1.0], (CHUNK, 1))
    start = bundle_start(o, d, 0, CHUNK, *halo)
    halo_top = 4 * ((100 >> 2) + 2)
    assert start == pytest.approx(1000.0 - halo_top - 1.0)
    brick_only = bundle_start(o, d, 0, CHUNK, *halo[:3], *halo_arrays(None)[3:])
    assert brick_only == pytest.approx(1000.0 - 8 * ((100 >> 3) + 2) - 1.0)
    assert 1000.0 - start > 101.0  # before the voxel's top face


@pytest.mark.parametrize("voxel_x, reach", [(70, BUNDLE_REACH), (50, FINE_REACH)])
def test_fanned_chunk_starts_no_further_than_its_reach(numba_backend, voxel_x, reach):
    # Half the chunk looks straight down, half leans out to a voxel to the side that the
    # centre ray passes outside the brick halo (x = 70) or inside it but outside the 4-voxel
    # halo (x = 50): the reach of that halo, not its cells, must stop the start.
    occ = Occupancy.build(np.array([[voxel_x, 40, 100]]), (120, 80, 200))
    o = np.tile([40.5, 40.5, 1000.0], (CHUNK, 1))
    d = np.tile([0.0, 0.0, -1.0], (CHUNK, 1))
    d[CHUNK // 2 :, 0] = (voxel_x + 0.5 - 40.5) / 899.5
    d /= np.linalg.norm(d, axis=1)[:, None]
    start = bundle_start(o, d, 0, CHUNK, *halo_arrays(occ))
    spread = np.linalg.norm(d - d.mean(axis=0), axis=1).max()
    hits = numba_backend.trace_cells(occ, o, d)
    assert (hits.kind[CHUNK // 2 :] == VOXEL).all()
    assert start < hits.t[CHUNK // 2 :].min()
    assert same(hits, numba_backend.trace_cells(occ, o, d, bundles=False))
    if reach == BUNDLE_REACH:
        assert start == pytest.approx(reach / spread - 1.0 / np.linalg.norm(d.mean(axis=0)))
    else:  # the brick halo's stop, 8 voxels over the voxel's brick
        assert 1000.0 - start * abs(d.mean(axis=0)[2]) == pytest.approx(113.0, abs=0.5)


def test_start_is_zero_for_scattered_rays_and_an_empty_halo(forest):
    _, occ = forest
    rng = np.random.default_rng(5)
    o = rng.uniform(0, 200, size=(CHUNK, 3))
    d = rng.normal(size=(CHUNK, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    assert bundle_start(o, d, 0, CHUNK, *halo_arrays(occ)) == 0.0
    # Origins further apart than the reach: no bundle even with one direction.
    o = np.zeros((CHUNK, 3)) + [120.0, 120.0, 900.0]
    o[1, 0] += BUNDLE_REACH + 0.5
    d = np.tile([0.0, 0.0, -1.0], (CHUNK, 1))
    assert bundle_start(o, d, 0, CHUNK, *halo_arrays(occ)) == 0.0
    assert bundle_start(o[:1], d[:1], 0, 1, *halo_arrays(occ)) > 0.0
    assert bundle_start(o[:1], d[:1], 0, 1, *halo_arrays(None)) == 0.0
    # So far out that a voxel is below rounding: no start.
    assert bundle_start(o[:1] + [0.0, 0.0, 1e13], d[:1], 0, 1, *halo_arrays(occ)) == 0.0
    # A chunk 2 voxels wide (within the brick reach, not the 4-voxel one) stops at the brick halo.
    o[1, 0] = o[0, 0] + 3.5
    wide = bundle_start(o, d, 0, CHUNK, *halo_arrays(occ))
    assert wide == bundle_start(o, d, 0, CHUNK, *halo_arrays(occ)[:3], *halo_arrays(None)[3:])


@pytest.mark.parametrize(
    "slant_m, depressions, fov",
    [(85.0, (30.0, 89.9), 5.0), (150.0, (1.0, 10.0), 5.0), (10_000.0, (20.0, 60.0), 0.05)],
)
def test_starts_bound_every_first_hit_and_change_nothing(forest, numba_backend, slant_m, depressions, fov):
    vox, occ = forest
    rng = np.random.default_rng(int(slant_m))
    sensor = Sensor(grid=16, ray_grid=4, fov=fov)
    o, d = scan_rays(occ, rng, 6, slant_m / 0.25, depressions, sensor)
    starts = starts_of(occ, o, d)
    plain = numba_backend.trace_cells(occ, o, d, bundles=False)
    bundled = numba_backend.trace_cells(occ, o, d)
    assert same(plain, bundled)
    hit = plain.kind == VOXEL
    assert hit.mean() > 0.3
    assert np.all(plain.t[hit] >= starts[hit] + 0.5)  # at least the one-voxel margin, less rounding
    # They skip real distance: most chunks start well past the aircraft.
    assert np.median(starts) > 0.5 * slant_m / 0.25
    pick = rng.choice(len(o), 1500, replace=False)
    ref = reference_trace_cells(vox, occ.shape, o[pick], d[pick])
    assert np.array_equal(ref.kind, bundled.kind[pick])
    assert np.array_equal(ref.index, bundled.index[pick])


def test_bundles_on_grid_planes_and_axis_directions(numba_backend):
    # Nadir chunks from origins on brick faces and edges (zero direction components in the
    # centre ray), over voxels on those same faces.
    rng = np.random.default_rng(8)
    shape = (64, 64, 48)
    vox = rng.integers(0, shape, size=(20_000, 3))
    occ = Occupancy.build(vox, shape)
    origins, directions = [], []
    for x, y in [(16.0, 16.0), (24.0, 31.5), (8.0, 40.0), (32.5, 32.5)]:
        o = np.tile([x, y, 300.0], (CHUNK, 1))
        d = np.tile([0.0, 0.0, -1.0], (CHUNK, 1))
        d[: CHUNK // 2, 0] = np.linspace(-2e-3, 2e-3, CHUNK // 2)  # half of them lean a little
        origins.append(o)
        directions.append(d / np.linalg.norm(d, axis=1)[:, None])
    o, d = np.concatenate(origins), np.concatenate(directions)
    plain = numba_backend.trace_cells(occ, o, d, bundles=False)
    bundled = numba_backend.trace_cells(occ, o, d)
    assert same(plain, bundled)
    assert (bundled.kind == VOXEL).sum() > CHUNK  # leaning rays and rays off the planes hit
    ref = reference_trace_cells(vox, shape, o, d)
    assert np.array_equal(ref.kind, bundled.kind)
    assert np.array_equal(ref.index, bundled.index)
    assert starts_of(occ, o, d).min() > 200.0


def test_wgpu_scans_match_numba(forest, numba_backend, wgpu_backend):
    _, occ = forest
    rng = np.random.default_rng(17)
    o, d = scan_rays(occ, rng, 8, 85.0 / 0.25, (1.0, 89.9))
    expected = numba_backend.trace_cells(occ, o, d)
    assert (expected.kind != MISS).mean() > 0.5
    got = wgpu_backend.trace_cells(occ, o, d, precision="f64")
    assert same(expected, got)
    f32 = wgpu_backend.trace_cells(occ, o, d, precision="f32")
    agree = (f32.kind == expected.kind) & np.all(f32.index == expected.index, axis=1)
    assert agree.mean() >= 0.999


def test_f32_offsets_fall_back_to_the_box_entry_when_the_start_is_past_the_scene():
    from ladartui.tracing.f32_rays import f32_start_offsets

    o = np.array([[-1000.0, 50.5, 10.5]])
    d = np.array([[1.0, 0.0, 0.0]])
    plain = f32_start_offsets(o, d, (100, 100, 20), 20.0, "exact")
    assert plain[0] == pytest.approx(1000.0)
    for start in (np.inf, 2000.0):  # never, or beyond the far side
        assert f32_start_offsets(o, d, (100, 100, 20), 20.0, "exact", np.array([start])) == pytest.approx(
            plain
        )
    assert f32_start_offsets(o, d, (100, 100, 20), 20.0, "exact", np.array([1040.0]))[0] == pytest.approx(
        1040.0
    )


def test_wgpu_chunks_that_never_meet_the_scene(numba_backend, wgpu_backend):
    # Parallel rays beside the scene: their start is "never" (the last chunk, one ray with
    # no spread at all, gets inf on the host; the shader has no infinity).
    occ = Occupancy.build(np.array([[10, 10, 5], [30, 30, 8]]), (64, 64, 32))
    o = np.tile([-50.5, 200.5, 40.0], (CHUNK + 1, 1))
    d = np.tile([0.6, 0.0, -0.8], (CHUNK + 1, 1))
    assert bundle_start(o, d, 0, CHUNK, *halo_arrays(occ)) > 1e12
    assert bundle_start(o, d, CHUNK, CHUNK + 1, *halo_arrays(occ)) == np.inf
    expected = numba_backend.trace_cells(occ, o, d)
    for precision in ("f64", "f32"):
        got = wgpu_backend.trace_cells(occ, o, d, precision=precision)
        assert np.array_equal(got.kind, expected.kind)
        assert np.array_equal(got.index, expected.index)
