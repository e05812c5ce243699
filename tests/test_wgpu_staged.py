"""The wgpu backend's exact ray order through staging buffers of its own (a GPU's
default, ``staged_upload``): a batch's uniform block, origins and directions
written into one mapped buffer and copied on the device ahead of the dispatch,
with no queue writes and one submit a batch. Answers checked against numba's,
bit for bit, on the adapter here (lavapipe runs the same path when asked)."""

from __future__ import annotations

import numpy as np
import pytest

from ladartui.tracing import TINY, wgpu_hits, wgpu_scans
from ladartui.tracing.prepare import rays_to_cells
from ladartui.tracing.wgpu_backend import WgpuBackend
from test_wgpu_backend import assert_same, random_rays, random_scene
from test_wgpu_hits import SHAPE, scan_from
from test_wgpu_mapped_writes import RangedBuffer, WriteOnlyBuffer


@pytest.fixture(scope="module")
def case():
    occupancy = random_scene(41, SHAPE, 5000)
    origins, directions = random_rays(42, SHAPE, 3000)
    return occupancy, origins, directions


def staged_backend(wgpu_backend, **caps):
    """A backend that stages its rays (``wgpu_backend`` only makes the test skip
    where there is no adapter)."""
    backend = WgpuBackend(staged_upload=True, **caps)
    assert backend.probe() is None
    return backend


@pytest.mark.parametrize("ray_batch", [1 << 20, 640])
def test_staged_rays_give_numba_answers(wgpu_backend, numba_backend, case, ray_batch):
    """Rays of their own origins, a scan from one origin, and calls of other
    lengths in between (another uniform block each): numba's answers every time,
    in one batch and in five (the last one short)."""
    occupancy, origins, directions = case
    backend = staged_backend(wgpu_backend, ray_batch=ray_batch)
    scan_origins, scan_directions = scan_from(SHAPE[2] + 3.5)
    cells, unit, bounds = rays_to_cells(scan_origins, scan_directions, 1.0, TINY)
    calls = [
        (origins, directions, None),
        (cells, unit, bounds),
        (origins[:10], directions[:10], None),
        (cells, unit, bounds),
        (origins, directions, None),
    ]
    for o, d, b in calls:
        hits = backend.trace_cells(occupancy, o, d, order="ray", block_bounds=b)
        assert_same(hits, numba_backend.trace_cells(occupancy, o, d, order="ray"))
    assert backend._hits.staged and backend._hits.batch == min(ray_batch, 1 << 20)
    assert (numba_backend.trace_cells(occupancy, cells, unit, order="ray").kind == 1).sum() > 500


def test_staged_rays_use_no_queue_writes_and_one_submit_a_batch(wgpu_backend, case, monkeypatch):
    occupancy, origins, directions = case
    backend = staged_backend(wgpu_backend, ray_batch=640)
    backend.trace_cells(occupancy, origins[:10], directions[:10], order="ray")  # opens the device
    backend._hits.bundle_starts = False  # (their buffer is the one the queue writes)
    backend.trace_cells(occupancy, origins[:10], directions[:10], order="ray")  # clears a CPU's starts
    queue = type(backend._device.queue)
    calls = []
    for name in ("write_buffer", "submit"):
        method = getattr(queue, name)
        monkeypatch.setattr(
            queue, name, lambda self, *a, name=name, method=method: calls.append(name) or method(self, *a)
        )
    backend.trace_cells(occupancy, origins, directions, order="ray")
    assert calls == ["submit"] * 5


def test_a_cpu_adapter_writes_through_the_queue_by_default(wgpu_backend, case):
    """There the queue's copy costs nothing beside the trace, and bundle starts are written."""
    occupancy, origins, directions = case
    wgpu_backend.trace_cells(occupancy, origins[:10], directions[:10], order="ray")
    on_cpu = wgpu_backend.describe()["adapter_type"] == "CPU"
    assert wgpu_backend._hits.staged is not on_cpu


# --- the pieces of one staging buffer ---------------------------------------------


def test_pieces_go_to_their_offsets_and_nothing_else_is_touched(monkeypatch):
    """The uniform block, one origin and a scan's directions: each at its offset,
    the large one on numba's threads, the bytes between them untouched."""
    params = np.arange(44, dtype=np.uint32).view(np.uint8)  # 176 bytes
    origin = np.array([[1.5, -2.25, 3.0]])
    directions = np.random.default_rng(7).normal(size=(4096, 3))
    pieces = [(0, params), (184, origin), (184 + 24 * 10, directions)]
    end = 184 + 240 + directions.nbytes
    buffer = RangedBuffer(end + 32)
    buffer.memory[:] = b"\xee" * len(buffer.memory)
    copied = []
    copy = wgpu_scans.copy_in_parts
    monkeypatch.setattr(wgpu_scans, "copy_in_parts", lambda t, s: copied.append(s.nbytes) or copy(t, s))
    wgpu_scans.write_pieces(buffer, pieces)
    memory = bytes(buffer.memory)
    assert buffer.writes == [] and copied == [directions.nbytes]
    assert memory[:176] == params.tobytes() and memory[176:184] == b"\xee" * 8
    assert memory[184:208] == origin.tobytes() and memory[208:424] == b"\xee" * 216
    assert memory[424:end] == directions.tobytes() and memory[end:] == b"\xee" * 32


def test_without_the_mapped_range_each_piece_goes_the_public_way():
    buffer = WriteOnlyBuffer()
    a, b = np.arange(4, dtype=np.uint32), np.array([[1.0, 2.0, 3.0]])
    wgpu_scans.write_pieces(buffer, [(0, a), (16, b)])
    assert buffer.writes == [(a.tobytes(), 0), (b.tobytes(), 16)]


# --- the read-back's map ----------------------------------------------------------


class MapRecorder:
    def __init__(self, known_modes):
        self.known_modes = known_modes
        self.maps = []

    def map_sync(self, mode, offset, size):
        if isinstance(mode, str) and mode not in self.known_modes:
            raise ValueError(f"unknown map mode {mode!r}")  # as an older wgpu-py's flag lookup
        self.maps.append((mode, offset, size))


def test_reading_maps_skip_wgpus_extra_submit_where_it_knows_how(monkeypatch):
    import wgpu

    monkeypatch.setattr(wgpu_hits, "_READ_WITHOUT_SUBMIT", ["READ_NOSYNC"])
    knows = MapRecorder({"READ_NOSYNC"})
    wgpu_hits.map_for_reading(knows, 64)
    assert knows.maps == [("READ_NOSYNC", 0, 64)]
    older = MapRecorder(set())
    wgpu_hits.map_for_reading(older, 64)
    wgpu_hits.map_for_reading(older, 32)  # not asked again
    assert older.maps == [(wgpu.MapMode.READ, 0, 64), (wgpu.MapMode.READ, 0, 32)]
    assert wgpu_hits._READ_WITHOUT_SUBMIT == []


# --- numba's workqueue layer, and a wait for a mapping cut short ---------------------

WORKQUEUE_SCRIPT = """
import sys
import numpy as np
import numba
sys.path.insert(0, {tests!r})
from ladartui.tracing.numba_backend import NumbaBackend
from ladartui.tracing.wgpu_backend import WgpuBackend
from test_wgpu_backend import random_rays, random_scene
from test_wgpu_hits import SHAPE

occupancy = random_scene(41, SHAPE, 5000)
origins, directions = random_rays(42, SHAPE, 40000)
backend = WgpuBackend(staged_upload=True, ray_batch=8192)  # five batches, staged in parts on threads
backend.trace_cells(occupancy, origins[:10], directions[:10], order="ray")
backend._hits.bundle_starts = False  # as on a GPU: batches answered on the thread
hits = backend.trace_cells(occupancy, origins, directions, order="ray")
reference = NumbaBackend().trace_cells(occupancy, origins, directions, order="ray")
assert numba.threading_layer() == "workqueue"
assert np.array_equal(hits.kind, reference.kind) and np.array_equal(hits.t, reference.t)
print("same")
"""


def test_staged_batches_do_not_overlap_numba_regions_under_workqueue(wgpu_backend, tmp_path):
    """Under numba's workqueue layer two parallel regions at once end the process:
    staging a batch (numba's threads) must not run while the thread answers another."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    tests = str(Path(__file__).parent)
    script = tmp_path / "workqueue.py"
    script.write_text(WORKQUEUE_SCRIPT.format(tests=tests))
    env = {**os.environ, "NUMBA_THREADING_LAYER": "workqueue"}
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().endswith("same")


def test_a_wait_for_a_staging_map_cut_short_leaves_the_backend_usable(
    wgpu_backend, numba_backend, case, monkeypatch
):
    """Ctrl-C (or a failed map) while waiting for a staging buffer's mapping: the next
    calls still map it and answer in full."""
    occupancy, origins, directions = case
    backend = staged_backend(wgpu_backend, ray_batch=640)
    backend.trace_cells(occupancy, origins, directions, order="ray")
    pending = backend._hits._mapping[0]

    def interrupted():
        raise KeyboardInterrupt

    monkeypatch.setattr(pending, "sync_wait", interrupted)
    with pytest.raises(KeyboardInterrupt):
        backend.trace_cells(occupancy, origins, directions, order="ray")
    monkeypatch.undo()
    reference = numba_backend.trace_cells(occupancy, origins, directions, order="ray")
    for _ in range(2):
        assert_same(backend.trace_cells(occupancy, origins, directions, order="ray"), reference)
