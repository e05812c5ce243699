"""The wgpu backend's exact ray order (tracing/wgpu_hits.py, trace.wgsl's
first_hits): one word a ray back, in batches, bundle starts only where they
pay, and trace_rays where a box's offsets do not fit an i32.
Every answer is checked against the numba backend, bit for bit."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from ladartui.errors import Cancelled
from ladartui.tracing import TINY, VOXEL, wgpu_hits
from ladartui.tracing.prepare import rays_to_cells
from ladartui.tracing.wgpu_backend import WgpuBackend
from ladartui.tracing.wgpu_hits import box_sides
from ladartui.tracing.wgpu_occupancy import PARAMS_BYTES
from test_wgpu_backend import Occupancy, assert_same, random_rays, random_scene

SHAPE = (50, 40, 30)


@pytest.fixture(scope="module")
def case():
    occupancy = random_scene(21, SHAPE, 5000)
    origins, directions = random_rays(22, SHAPE, 3000)
    return occupancy, origins, directions


def test_box_sides_fit_an_i32_or_are_refused():
    def box(lo, hi):
        return type("Box", (), {"bbox_lo": lo, "bbox_hi": hi})()

    assert box_sides(box((2, 3, 4), (12, 8, 5))) == (10, 5, 1)
    assert box_sides(box((0, 0, 0), (1 << 11, 1 << 10, 1 << 10))) == (
        1 << 11,
        1 << 10,
        1 << 10,
    )  # 2^31 offsets
    assert box_sides(box((0, 0, 0), (1 << 11, 1 << 10, (1 << 10) + 1))) is None
    assert box_sides(box((5, 5, 5), (5, 9, 9))) is None  # empty box


def test_offsets_up_to_the_i32_limit_decode_to_their_cells():
    """box_offset_answers decodes offsets in the largest box whose offsets fit an
    i32 (2048 x 1024 x 1024), its last one too, to their cells, entered where a
    ray straight down meets their top faces."""
    sx, sy, sz = 1 << 11, 1 << 10, 1 << 10
    lo = np.array([3, -5, 7], np.int64)
    last = (sx - 1, sy - 1, sz - 1)
    cells = np.array([[0, 0, 0], last, [sx - 1, 0, sz - 1], [5, sy - 1, 0], [1234, 567, 891]])
    words = cells[:, 0] + sx * (cells[:, 1] + sy * cells[:, 2])
    assert words.max() == (1 << 31) - 1
    n = len(words)
    origins = cells + lo + [0.5, 0.5, 10.5]
    directions = np.tile([0.0, 0.0, -1.0], (n, 1))
    kind, index, t = np.empty(n, np.uint8), np.empty((n, 3), np.int32), np.empty(n)
    found = words.astype(np.int32)
    answers = (kind, index, t)
    cut = wgpu_hits.box_offset_answers(found, lo, sx, sy, origins, False, directions, 1e9, 1e9, *answers)
    assert cut == 0 and (kind == VOXEL).all()
    assert np.array_equal(index, cells + lo)
    assert (t == 9.5).all()


def test_batches_in_flight_give_numba_answers(wgpu_backend, numba_backend, case):
    """Batches of 640 rays (five, the last one short) and the one-batch call
    agree with numba, ray for ray."""
    occupancy, origins, directions = case
    reference = numba_backend.trace_cells(occupancy, origins, directions, order="ray")
    assert (reference.kind == 1).sum() > 500 and (reference.kind == 2).sum() > 10
    batched = WgpuBackend(ray_batch=640)
    hits = batched.trace_cells(occupancy, origins, directions, order="ray")
    assert batched._hits.batch == 640 and hits.info["order"] == "ray"
    assert_same(hits, reference)
    batched._hits.bundle_starts = not batched._hits.bundle_starts  # answers on the thread, or not
    assert_same(batched.trace_cells(occupancy, origins, directions, order="ray"), reference)
    assert_same(wgpu_backend.trace_cells(occupancy, origins, directions, order="ray"), reference)


def scan_from(height):
    """A 64 x 64 fan of rays looking down from one point above the scene's middle."""
    angles = np.linspace(-0.3, 0.3, 64)
    ax, ay = np.meshgrid(angles, angles)
    directions = np.column_stack([np.tan(ax).ravel(), np.tan(ay).ravel(), -np.ones(ax.size)])
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    origins = np.tile([SHAPE[0] / 2 + 0.25, SHAPE[1] / 2 + 0.25, height], (len(directions), 1))
    return origins, directions


def test_without_bundle_starts_the_answers_are_the_same(wgpu_backend, numba_backend, case):
    """Starts on, then off for other rays (the starts of the first must not be
    used for them), then on again: numba's answers each time."""
    occupancy = case[0]
    origins, directions = scan_from(SHAPE[2] * 4.0)  # long bundle starts
    other_origins, other_directions = scan_from(SHAPE[2] + 0.5)  # hits before those starts
    wgpu_backend.trace_cells(occupancy, origins[:10], directions[:10])  # opens the device
    hits = wgpu_backend._hits
    assert hits.bundle_starts == (wgpu_backend.describe()["adapter_type"] == "CPU")
    was = hits.bundle_starts
    try:
        for starts, o, d in (
            (True, origins, directions),
            (False, other_origins, other_directions),
            (True, other_origins, other_directions),
        ):
            hits.bundle_starts = starts
            assert_same(
                wgpu_backend.trace_cells(occupancy, o, d, order="ray"),
                numba_backend.trace_cells(occupancy, o, d, order="ray"),
            )
    finally:
        hits.bundle_starts = was


def test_a_box_too_large_for_i32_offsets_goes_through_trace_rays(
    wgpu_backend, numba_backend, case, monkeypatch
):
    occupancy, origins, directions = case
    used = []
    first_hits = WgpuBackend._first_hits
    monkeypatch.setattr(WgpuBackend, "_first_hits", lambda self, *a: used.append(1) or first_hits(self, *a))
    reference = numba_backend.trace_cells(occupancy, origins, directions, order="ray")
    assert_same(wgpu_backend.trace_cells(occupancy, origins, directions, order="ray"), reference)
    assert used
    used.clear()
    monkeypatch.setattr(wgpu_hits, "OFFSET_LIMIT", 100)
    assert_same(wgpu_backend.trace_cells(occupancy, origins, directions, order="ray"), reference)
    assert not used


@pytest.mark.parametrize("staged", [False, True])
def test_cancelled_with_batches_in_flight_leaves_the_backend_usable(numba_backend, case, monkeypatch, staged):
    """Cancelled after the first batch's answers: Cancelled, the read-back buffer
    not left mapped, and the next call answers in full (staged too: its staging
    buffers were being mapped again)."""
    occupancy, origins, directions = case
    backend = WgpuBackend(ray_batch=640, staged_upload=staged)
    cancel = threading.Event()
    answers = wgpu_hits.box_offset_answers

    def answer_then_cancel(*args):
        cancel.set()
        return answers(*args)

    monkeypatch.setattr(wgpu_hits, "box_offset_answers", answer_then_cancel)
    with pytest.raises(Cancelled):
        backend.trace_cells(occupancy, origins, directions, order="ray", cancel=cancel)
    assert [b.map_state for b in backend._hits.buffers(PARAMS_BYTES)["back"]] == ["unmapped"] * 2
    monkeypatch.setattr(wgpu_hits, "box_offset_answers", answers)
    assert_same(
        backend.trace_cells(occupancy, origins, directions, order="ray"),
        numba_backend.trace_cells(occupancy, origins, directions, order="ray"),
    )


def test_hits_in_a_box_away_from_the_origin_decode_to_their_cells(wgpu_backend, numba_backend):
    """Voxels only in x 30..41, y 20..25, z 5..9 of a 64 x 64 x 16 grid: every hit's
    box offset decodes back to the voxel numba finds (the box's corner is not 0)."""
    rng = np.random.default_rng(31)
    voxels = np.column_stack([rng.integers(30, 42, 400), rng.integers(20, 26, 400), rng.integers(5, 10, 400)])
    occupancy = Occupancy.build(voxels, shape=(64, 64, 16))
    assert tuple(occupancy.bbox_lo) == (30, 20, 5) and box_sides(occupancy) == (12, 6, 5)
    origins, directions = random_rays(32, (64, 64, 16), 4000)
    origins[:, :2] = origins[:, :2] * 0.3 + np.array([28.0, 18.0])  # over the box
    reference = numba_backend.trace_cells(occupancy, origins, directions, order="ray")
    assert (reference.kind == 1).sum() > 150
    assert_same(wgpu_backend.trace_cells(occupancy, origins, directions, order="ray"), reference)


def test_rays_from_one_origin_give_numba_answers_with_one_origin_written(
    wgpu_backend, numba_backend, case, monkeypatch
):
    """A scan traced in ray order writes its one origin for all its rays, and the
    shader reads that one for every ray, not what an earlier call left in the
    buffer (other rays' origins are traced first): numba's answers, bit for bit.
    The host never makes a row per ray of that origin: the batches and the
    answers read its one row (on either thread), and so does the f32 shader's
    ground rule."""
    occupancy, origins, directions = case
    scan_origins, scan_directions = scan_from(SHAPE[2] + 3.5)
    cells, unit, bounds = rays_to_cells(scan_origins, scan_directions, 1.0, TINY)
    shared = []
    trace = wgpu_hits.FirstHits.trace

    def record_then_trace(self, *args, **kwargs):
        shared.append((args[-1], len(args[5])))  # shared_origin, origin rows given
        return trace(self, *args, **kwargs)

    monkeypatch.setattr(wgpu_hits.FirstHits, "trace", record_then_trace)
    assert_same(
        wgpu_backend.trace_cells(occupancy, origins, directions, order="ray"),
        numba_backend.trace_cells(occupancy, origins, directions, order="ray"),
    )
    reference = numba_backend.trace_cells(occupancy, cells, unit, order="ray")
    assert (reference.kind == 1).sum() > 500
    for order in ("ray", "auto"):  # auto: the scan's blocks in ray order too, if chosen
        assert_same(
            wgpu_backend.trace_cells(occupancy, cells, unit, order=order, block_bounds=bounds), reference
        )
    assert shared[:2] == [(False, len(origins)), (True, 1)]
    batched = WgpuBackend(ray_batch=640)
    for bundle_starts in (False, True):
        batched.trace_cells(occupancy, origins[:10], directions[:10])  # opens the device
        batched._hits.bundle_starts = bundle_starts
        assert_same(batched.trace_cells(occupancy, cells, unit, order="ray", block_bounds=bounds), reference)
    assert shared[-1] == (True, 1)
    f32 = wgpu_backend.trace_cells(occupancy, cells, unit, precision="f32", block_bounds=bounds)
    ground = (f32.kind == 2) & (reference.kind == 2)
    assert ground.sum() > 100
    assert np.array_equal(f32.index[ground], reference.index[ground])
    assert np.array_equal(f32.t[ground], reference.t[ground])


@pytest.mark.parametrize("bundle_starts", [False, True])
def test_a_failure_in_the_answers_reaches_the_caller(numba_backend, case, monkeypatch, bundle_starts):
    """Without bundle starts, batch 0 is answered on the worker thread while batch
    2 is written; with them (numba runs in the writing too) on the calling thread.
    Either way its error comes back to the caller, no read-back buffer stays
    mapped, and the next call answers in full."""
    occupancy, origins, directions = case
    backend = WgpuBackend(ray_batch=640)
    backend.trace_cells(occupancy, origins[:10], directions[:10])  # opens the device
    backend._hits.bundle_starts = bundle_starts
    answers = wgpu_hits.box_offset_answers
    threads = []

    def fail(*args):
        threads.append(threading.current_thread())
        raise RuntimeError("answers failed")

    monkeypatch.setattr(wgpu_hits, "box_offset_answers", fail)
    with pytest.raises(RuntimeError, match="answers failed"):
        backend.trace_cells(occupancy, origins, directions, order="ray")
    assert len(threads) == 1
    assert (threads[0] is threading.current_thread()) == bundle_starts
    assert [b.map_state for b in backend._hits.buffers(PARAMS_BYTES)["back"]] == ["unmapped"] * 2
    monkeypatch.setattr(wgpu_hits, "box_offset_answers", answers)
    assert_same(
        backend.trace_cells(occupancy, origins, directions, order="ray"),
        numba_backend.trace_cells(occupancy, origins, directions, order="ray"),
    )


def test_an_origin_on_a_voxels_face_gives_a_range_of_plus_zero_as_numba_does(wgpu_backend, numba_backend):
    """A ray starting on a face of an occupied voxel and going into it enters it at
    range 0; entering through a face it moves down across, the slab test's
    ``(b - o) / d`` is -0.0 there, and the answer must still be numba's +0.0 bit for
    bit (a range printed as "-0.0")."""
    occupancy = Occupancy.build(np.array([[0, 0, 0], [2, 2, 2]]), shape=(5, 5, 5))
    # Cell space: the top face of (2, 2, 2), its top corner, (0, 0, 0)'s upper corner.
    origins = np.array([[2.5, 2.5, 3.0], [3.0, 3.0, 3.0], [1.0, 1.0, 1.0], [2.5, 2.5, 2.0]])
    directions = np.array([[0.0, 0.0, -1.0], [-1.0, -1.0, -1.0], [-1.0, -1.0, -1.0], [0.0, 0.0, 1.0]])
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    expected = numba_backend.trace_cells(occupancy, origins, directions, order="ray")
    assert (expected.kind == VOXEL).all() and (expected.t == 0.0).all()
    assert not np.signbit(expected.t).any()
    got = wgpu_backend.trace_cells(occupancy, origins, directions, order="ray")
    assert_same(got, expected)
    assert not np.signbit(got.t).any(), got.t
