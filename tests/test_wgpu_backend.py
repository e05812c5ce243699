"""The wgpu backend's plumbing: registration, adapter choice, device limits,
occupancy upload (cached, split over bindings), batching and dispatch grids,
march passes for rays longer than lavapipe's loop guard, cancellation, and the
clear errors when there is no adapter or a loop was ended early.

Answers are checked against the numba backend (an independent implementation
of the same contract); precision is tests/test_wgpu_precision.py's subject.
"""

from __future__ import annotations

import gc
import subprocess
import sys
import threading
from types import SimpleNamespace

import numpy as np
import pytest

from ladartui.errors import BackendUnavailable, Cancelled
from ladartui.tracing import backend as registry
from ladartui.tracing import wgpu_occupancy, wgpu_rays
from ladartui.tracing.f32_rays import floor_preserving_f32
from ladartui.tracing.wgpu_adapter import INSTALL_HINT, choose_adapter
from ladartui.tracing.wgpu_backend import WgpuBackend
from ladartui.tracing.wgpu_occupancy import chunk_words_for
from ladartui.tracing.wgpu_scans import dispatch_grid

Occupancy = pytest.importorskip("ladartui.scene.occupancy").Occupancy


@pytest.fixture(scope="module")
def gpu(wgpu_backend):
    # wgpu_backend and numba_backend come from tests/conftest.py.
    return wgpu_backend


def random_scene(seed, shape, n):
    rng = np.random.default_rng(seed)
    voxels = np.column_stack([rng.integers(0, s, n) for s in shape])
    return Occupancy.build(voxels, shape=shape)


def random_rays(seed, shape, n):
    rng = np.random.default_rng(seed)
    origins = rng.uniform(-0.2, 1.2, (n, 3)) * np.array(shape, float)
    origins[:, 2] += shape[2]
    directions = rng.normal(size=(n, 3))
    directions[:, 2] -= 1.0
    return origins, directions / np.linalg.norm(directions, axis=1)[:, None]


def assert_same(hits, reference):
    assert np.array_equal(hits.kind, reference.kind)
    assert np.array_equal(hits.index, reference.index)
    assert np.array_equal(hits.t, reference.t)


# --- pure helpers (no adapter needed) ---------------------------------------


def adapter(kind, graphics="Vulkan", name="x"):
    return SimpleNamespace(info={"adapter_type": kind, "backend_type": graphics, "device": name})


def test_adapter_choice_prefers_real_gpus_then_cpu():
    cpu, igpu, dgpu = adapter("CPU"), adapter("IntegratedGPU"), adapter("DiscreteGPU")
    assert choose_adapter([cpu, igpu, dgpu]) is dgpu
    assert choose_adapter([cpu, igpu]) is igpu
    assert choose_adapter([cpu]) is cpu
    assert choose_adapter([]) is None
    gl_cpu, vk_cpu = adapter("CPU", "OpenGL"), adapter("CPU", "Vulkan")
    assert choose_adapter([gl_cpu, vk_cpu]) is vk_cpu
    assert choose_adapter([adapter("Unknown"), cpu]) is cpu


def test_chunk_words_are_the_largest_power_of_two_in_a_binding():
    assert chunk_words_for(128 * 2**20) == 32 * 2**20
    assert chunk_words_for(2**31 - 1) == 2**28
    assert chunk_words_for(4096) == 1024
    assert chunk_words_for(4100) == 1024


def test_dispatch_grid_stays_within_the_per_dimension_limit():
    for groups, limit in [(1, 65535), (65535, 65535), (65536, 65535), (10**6, 65535), (16, 4), (13, 4)]:
        x, y = dispatch_grid(groups, limit)
        assert x <= limit and y <= limit
        assert x * y >= groups
        assert x * (y - 1) < groups  # no whole row of idle workgroups
    with pytest.raises(ValueError):
        dispatch_grid(10, 3)


def test_floor_preserving_f32_keeps_each_value_in_its_cell():
    values = np.array([72.99999999999999, 73.0, 0.9999999999, 1e-12, -1e-12, 250.99999997, 3.25])
    v32 = floor_preserving_f32(values)
    assert v32.dtype == np.float32
    assert np.array_equal(np.floor(v32), np.floor(values))
    assert np.all(np.abs(v32.astype(np.float64) - values) <= 2 * np.spacing(np.float32(300)))


def test_module_import_is_cheap_and_registers_the_backend():
    code = (
        "import sys, ladartui.tracing.wgpu_backend as m; "
        "from ladartui.tracing.backend import _FACTORIES; "
        "print('wgpu' in sys.modules, _FACTORIES.get('wgpu') is m.WgpuBackend)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "True"]
    assert "wgpu" in registry.backend_names()


# --- no adapter --------------------------------------------------------------


@pytest.fixture
def no_adapter(monkeypatch):
    """wgpu finds no adapter; the registry hands out a fresh, unprobed backend."""
    wgpu = pytest.importorskip("wgpu")
    pytest.importorskip("ladartui.tracing.numba_backend")  # registered, whatever loaded first
    monkeypatch.setattr(wgpu.gpu, "enumerate_adapters_sync", lambda: [])
    monkeypatch.setitem(registry._INSTANCES, "wgpu", WgpuBackend())
    tracing = pytest.importorskip("ladartui.tracing")
    tracing.choose_backend.cache_clear()
    yield tracing
    tracing.choose_backend.cache_clear()


def test_no_adapter_gives_one_clear_line(no_adapter):
    backend = WgpuBackend()
    assert backend.probe() == INSTALL_HINT
    assert "mesa-vulkan-drivers" in INSTALL_HINT
    with pytest.raises(BackendUnavailable, match="mesa-vulkan-drivers"):
        backend.describe()
    with pytest.raises(BackendUnavailable, match="mesa-vulkan-drivers"):
        registry.get_backend("wgpu")
    assert "mesa-vulkan-drivers" in registry.backend_status()["wgpu"]


def test_no_adapter_trace_names_the_fix_and_auto_falls_back(no_adapter):
    occupancy = Occupancy.build(np.array([[1, 1, 1]]), shape=(4, 4, 4))
    o = np.array([[0.15, 0.15, 1.0]])  # metres; cell (1, 1) at 0.1 m voxels
    d = np.array([[0.0, 0.0, -1.0]])
    with pytest.raises(BackendUnavailable, match="install Debian's mesa-vulkan-drivers"):
        no_adapter.trace(occupancy, o, d, backend="wgpu", voxel_size=0.1)
    result = no_adapter.trace(occupancy, o, d, backend="auto", voxel_size=0.1)
    assert result.backend == "numba"
    assert result.kind.tolist() == [1] and result.index.tolist() == [[1, 1, 1]]


def test_describe_on_the_adapter_here(gpu):
    info = gpu.describe()
    assert info["backend"] == "wgpu"
    assert info["adapter"] and info["adapter_type"] and info["graphics_backend"]
    assert isinstance(info["f64"], bool)
    assert info["precisions"][-1] == "f32"
    assert info["limits"]["max-storage-buffer-binding-size"] > 0
    assert info["limits"]["max-compute-workgroups-per-dimension"] >= 1


# --- uploads, batches, grids -------------------------------------------------


def test_occupancy_uploaded_once_per_object(gpu, numba_backend, monkeypatch):
    backend = WgpuBackend()
    calls = []
    make = backend._make_upload
    monkeypatch.setattr(backend, "_make_upload", lambda occ: calls.append(occ) or make(occ))
    shape = (40, 30, 20)
    first = random_scene(1, shape, 2000)
    o, d = random_rays(2, shape, 500)
    for method in ("exact", "march"):
        for precision in ("f64", "f32"):
            backend.trace_cells(first, o, d, method=method, precision=precision)
    assert calls == [first]
    second = random_scene(1, shape, 2000)  # equal content, another object
    assert_same(backend.trace_cells(second, o, d), backend.trace_cells(first, o, d))
    assert calls == [first, second]
    del calls[:]
    del second
    gc.collect()
    assert len(backend._uploads) == 1  # the device copy goes with its occupancy


def test_occupancy_split_over_bindings(gpu, numba_backend):
    """A binding cap of 4 KiB (1024 words) splits the occupancy over several bindings."""
    shape = (120, 100, 40)
    occupancy = random_scene(3, shape, 6000)
    words = sum(len(part) for part in wgpu_occupancy.occupancy_arrays(occupancy))
    small = WgpuBackend(max_binding_bytes=4096)
    upload = small._upload(occupancy)
    assert len(upload.buffers) == -(-words // 1024) >= 3
    o, d = random_rays(4, shape, 1500)
    for method in ("exact", "march"):
        reference = numba_backend.trace_cells(occupancy, o, d, method=method)
        assert (reference.kind == 1).sum() > 150
        assert_same(small.trace_cells(occupancy, o, d, method=method), reference)


def test_scene_too_large_for_the_adapter_fails_clearly(gpu):
    shape = (120, 100, 40)
    occupancy = random_scene(3, shape, 6000)
    tiny = WgpuBackend(max_binding_bytes=64)  # 16 words a binding: far too many bindings
    with pytest.raises(BackendUnavailable, match="cannot hold this scene.*use backend 'numba'"):
        tiny.trace_cells(occupancy, np.zeros((1, 3)), np.array([[0.0, 0.0, -1.0]]))


def test_batches_and_two_dimensional_dispatch(gpu, numba_backend):
    """1000-ray batches over a grid capped at 3 workgroups a dimension: all rays traced."""
    shape = (50, 40, 30)
    occupancy = random_scene(5, shape, 4000)
    o, d = random_rays(6, shape, 5000)
    batched = WgpuBackend(ray_batch=576, max_workgroups_per_dimension=3)  # 9 groups of 64 a batch
    for method in ("exact", "march"):
        reference = numba_backend.trace_cells(occupancy, o, d, method=method)
        assert_same(batched.trace_cells(occupancy, o, d, method=method), reference)


def test_no_rays(gpu):
    occupancy = random_scene(5, (8, 8, 8), 10)
    hits = gpu.trace_cells(occupancy, np.zeros((0, 3)), np.zeros((0, 3)))
    assert hits.kind.shape == (0,) and hits.index.shape == (0, 3) and hits.t.shape == (0,)


def test_cancel_between_batches(gpu):
    occupancy = random_scene(5, (16, 16, 16), 100)
    o, d = random_rays(6, (16, 16, 16), 100)
    cancel = threading.Event()
    cancel.set()
    with pytest.raises(Cancelled):
        gpu.trace_cells(occupancy, o, d, cancel=cancel)


def test_bad_arguments(gpu):
    from ladartui.errors import FieldError

    occupancy = random_scene(5, (8, 8, 8), 10)
    o, d = random_rays(6, (8, 8, 8), 4)
    with pytest.raises(FieldError):
        gpu.trace_cells(occupancy, o, d, method="walk")
    with pytest.raises(FieldError):
        gpu.trace_cells(occupancy, o, d, precision="f16")
    with pytest.raises(FieldError):
        gpu.trace_cells(occupancy, o, d, method="march", step=0.0)


def test_through_trace_api(gpu, numba_backend):
    """ladartui.trace(backend="wgpu") in metres agrees with backend="numba"."""
    tracing = pytest.importorskip("ladartui.tracing")
    shape = (30, 30, 20)
    occupancy = random_scene(7, shape, 1500)
    o, d = random_rays(8, shape, 2000)
    o_m = (o - 0.5) * 0.25
    for method in ("exact", "march"):
        ours = tracing.trace(occupancy, o_m, d, backend="wgpu", method=method, voxel_size=0.25)
        theirs = tracing.trace(occupancy, o_m, d, backend="numba", method=method, voxel_size=0.25)
        assert ours.backend == "wgpu"
        assert np.array_equal(ours.kind, theirs.kind)
        assert np.array_equal(ours.index, theirs.index)
        assert np.allclose(ours.range, theirs.range, rtol=1e-12)


def test_adapter_without_f64_traces_in_f32_and_says_so(gpu, numba_backend):
    backend = WgpuBackend()
    backend.probe()
    backend._has_f64 = False  # as on most GPUs: no shader-f64
    assert backend.describe()["precisions"] == ["f32"]
    shape = (30, 30, 20)
    occupancy = random_scene(9, shape, 1500)
    o, d = random_rays(10, shape, 2000)
    hits = backend.trace_cells(occupancy, o, d, precision="f64")
    assert hits.info["precision"] == "f32" and "shader-f64" in hits.info["precision_note"]
    reference = numba_backend.trace_cells(occupancy, o, d)
    assert np.mean(hits.kind == reference.kind) > 0.999


# --- long rays: more loop iterations than lavapipe allows in one invocation ----

LOOP_GUARD = 65_535  # lavapipe's loop iterations per shader invocation, all loops together


def on_lavapipe(backend):
    return "llvmpipe" in backend.describe()["adapter"]


@pytest.fixture(scope="module")
def long_march_case():
    """A 12,000-cell scene and rays whose answers lie 66,000 to 68,000 samples
    (step 0.25) down the ray: a 100 x 100 block one layer high near the far
    corner, and the ground around it."""
    n = 12_000
    block = np.array([(x, y, 0) for x in range(11_800, 11_900) for y in range(11_800, 11_900)])
    voxels = np.vstack([block, [(n - 1, n - 1, 29)]])  # the corner voxel raises the top to 30
    occupancy = Occupancy.build(voxels, shape=(n, n, 30))
    rng = np.random.default_rng(21)
    count = 64
    origins = np.column_stack(
        [rng.uniform(0, 2, count), rng.uniform(0, 2, count), rng.uniform(20, 29, count)]
    )
    targets = np.column_stack(
        [rng.uniform(11_700, 11_990, count), rng.uniform(11_700, 11_990, count), np.zeros(count)]
    )
    directions = targets - origins
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    return occupancy, origins, directions


def test_long_march_rays_agree_with_numba(gpu, numba_backend, long_march_case):
    occupancy, o, d = long_march_case
    step = 0.25
    reference = numba_backend.trace_cells(occupancy, o, d, method="march", step=step)
    assert np.all(reference.t / step > LOOP_GUARD + 500)  # every answer beyond one invocation's loops
    assert (reference.kind == 1).sum() >= 8 and (reference.kind == 2).sum() >= 8
    assert_same(gpu.trace_cells(occupancy, o, d, method="march", step=step, precision="f64"), reference)
    hits = gpu.trace_cells(occupancy, o, d, method="march", step=step, precision="f32")
    # float32 samples sit up to ~1e-3 cells off: a sample that close to a face may
    # fall in the next cell; t is k * 0.25 exactly in both precisions.
    same = (hits.kind == reference.kind) & np.all(hits.index == reference.index, axis=1)
    assert np.all(hits.kind != 0) and same.mean() >= 0.95
    assert np.array_equal(hits.t[same], reference.t[same])


def test_long_exact_rays_agree_with_numba(gpu, numba_backend, long_march_case):
    occupancy, o, d = long_march_case
    reference = numba_backend.trace_cells(occupancy, o, d, method="exact")
    assert_same(gpu.trace_cells(occupancy, o, d, method="exact", precision="f64"), reference)
    hits = gpu.trace_cells(occupancy, o, d, method="exact", precision="f32")
    assert np.array_equal(hits.kind, reference.kind)
    assert np.array_equal(hits.index, reference.index)
    assert np.allclose(hits.t, reference.t, rtol=1e-6)


def brick_corridor(n):
    """An n-cell corridor along x whose every brick is occupied (voxel (x, 7, 7) each
    8 cells) and a voxel at its far end: a ray along y = z = 0.5 visits all n cells."""
    voxels = np.array([(x, 7, 7) for x in range(0, n, 8)] + [(n - 1, 0, 0)])
    occupancy = Occupancy.build(voxels, shape=(n, 8, 8))
    return occupancy, np.array([[0.5, 0.5, 0.5]]), np.array([[1.0, 0.0, 0.0]])


def test_exact_ray_through_40000_cells_of_occupied_bricks(gpu, numba_backend):
    occupancy, o, d = brick_corridor(40_000)
    reference = numba_backend.trace_cells(occupancy, o, d)
    assert reference.index.tolist() == [[39_999, 0, 0]]
    assert_same(gpu.trace_cells(occupancy, o, d, precision="f64"), reference)


def test_a_loop_ended_by_the_adapter_is_reported_not_taken_for_a_miss(
    gpu, numba_backend, long_march_case, monkeypatch
):
    """On lavapipe, 70,000 voxel steps (exact) or 131,072 samples in one pass (march)
    exceed the loop guard: the backend says so. Elsewhere the answers are numba's."""
    occupancy, o, d = brick_corridor(70_000)
    march_occupancy, mo, md = long_march_case
    monkeypatch.setattr(wgpu_rays, "MARCH_SAMPLES_PER_PASS", 1 << 17)
    calls = [(occupancy, o, d, {}), (march_occupancy, mo[:4], md[:4], {"method": "march", "step": 0.25})]
    for scene, origins, directions, options in calls:
        if on_lavapipe(gpu):
            with pytest.raises(
                BackendUnavailable,
                match="could not finish .* rays.*ended their loops early.*use backend 'numba'",
            ):
                gpu.trace_cells(scene, origins, directions, precision="f64", **options)
        else:
            assert_same(
                gpu.trace_cells(scene, origins, directions, precision="f64", **options),
                numba_backend.trace_cells(scene, origins, directions, **options),
            )


def test_march_in_many_short_passes_equals_one_pass(gpu, numba_backend, monkeypatch):
    """Passes of 5 samples: rays resume where the last pass stopped, none skipped or repeated."""
    shape = (40, 30, 20)
    occupancy = random_scene(11, shape, 2000)
    o, d = random_rays(12, shape, 1000)
    monkeypatch.setattr(wgpu_rays, "MARCH_SAMPLES_PER_PASS", 5)
    reference = numba_backend.trace_cells(occupancy, o, d, method="march", step=0.5)
    assert (reference.kind == 1).sum() > 100
    assert_same(gpu.trace_cells(occupancy, o, d, method="march", step=0.5, precision="f64"), reference)


def test_the_driver_prints_nothing_on_stderr_without_a_runtime_dir():
    # Mesa complains about a missing XDG_RUNTIME_DIR on stderr, which would
    # scribble over the terminal UI; the backend gives it a private folder.
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k != "XDG_RUNTIME_DIR"}
    code = (
        "from ladartui.tracing.backend import get_backend\n"
        "from ladartui.errors import BackendUnavailable\n"
        "try:\n    get_backend('wgpu')\nexcept BackendUnavailable:\n    pass\n"
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert "XDG_RUNTIME_DIR" not in out.stderr
