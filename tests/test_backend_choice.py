"""auto's backend where a GPU is there: exact float64 calls go to whichever of the
GPU's backend and numba has traced calls of that size faster (tracing/backend_choice.py).

No GPU is needed: the tests stand a backend in for one, either lavapipe's wgpu
(slower than numba on small calls, answers equal bit for bit) or stand-ins
that add a fixed delay to numba's work, so which wins does not hang on how
busy the machine is.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest

import ladartui.tracing as tracing
from ladartui.scene.occupancy import Occupancy
from ladartui.simulation import simulate
from ladartui.tracing import backend as registry
from ladartui.tracing import backend_choice
from ladartui.tracing.backend_choice import learns, size_class
from ladartui.tracing.learned_choice import TwoWayChoice
from ladartui.tui.bridge import backend_choices
from test_simulation import forest  # noqa: F401  (a fixture)


def scene_and_rays(rays=4096, seed=3):
    rng = np.random.default_rng(seed)
    shape = (40, 40, 12)
    voxels = np.column_stack([rng.integers(0, s, 600) for s in shape])
    occupancy = Occupancy.build(voxels, shape=shape)
    origins = np.tile([20.0, 20.0, 30.0], (rays, 1))
    directions = np.column_stack([rng.normal(0, 0.3, (rays, 2)), -np.ones(rays)])
    return occupancy, origins, directions / np.linalg.norm(directions, axis=1)[:, None]


class Delayed:
    """numba's answers after a fixed delay: a backend as slow as wanted."""

    def __init__(self, name, delay):
        self.name, self.summary, self.delay = name, f"numba after {delay} s", delay

    def probe(self):
        return None

    def describe(self):
        return {"threads": 1}

    def trace_cells(self, *args, **kwargs):
        time.sleep(self.delay)
        return registry.get_backend("numba").trace_cells(*args, **kwargs)


@pytest.fixture
def gpu_is(monkeypatch):
    """Make ``choose_backend`` find a GPU served by the named backend."""

    def stand_in(name):
        monkeypatch.setattr(tracing, "choose_backend", lambda: name)

    return stand_in


def with_delays(monkeypatch, gpu_delay, host_delay):
    """Register stand-ins "gpu" and "host" (the choice's host backend) with these delays."""
    for name, delay in (("gpu", gpu_delay), ("host", host_delay)):
        backend = Delayed(name, delay)
        monkeypatch.setitem(registry._FACTORIES, name, lambda backend=backend: backend)
        monkeypatch.setitem(registry._INSTANCES, name, backend)
    monkeypatch.setattr(backend_choice, "HOST", "host")


def backends_of_auto_calls(calls, occupancy, origins, directions, reference):
    """The backends that ``calls`` auto calls went to, each answer checked against ``reference``."""
    used = []
    for _ in range(calls):
        result = tracing.trace(occupancy, origins, directions)
        used.append(result.backend)
        assert np.array_equal(result.kind, reference.kind)
        assert np.array_equal(result.index, reference.index)
        assert np.array_equal(result.range, reference.range)
    return used


def test_size_classes_are_a_factor_of_four_wide():
    assert size_class(1 << 17) == size_class((1 << 19) - 1) == 9
    assert size_class(1 << 19) == 10 and size_class((1 << 17) - 1) == 8
    assert size_class(0) == size_class(1) == 0


def test_only_exact_float64_calls_with_a_gpu_are_learned():
    assert learns("wgpu", "exact", "f64")
    assert not learns("numba", "exact", "f64")  # no GPU: numba, as before
    assert not learns("wgpu", "march", "f64")  # the march's answers may differ between backends
    assert not learns("wgpu", "exact", "f32")


def test_auto_takes_the_gpu_when_it_is_faster_and_numba_when_it_is_not(monkeypatch, gpu_is):
    occupancy, origins, directions = scene_and_rays()
    reference = tracing.trace(occupancy, origins, directions, backend="numba")
    gpu_is("gpu")
    for gpu_delay, host_delay, winner in ((0.0, 0.05, "gpu"), (0.05, 0.0, "host")):
        with_delays(monkeypatch, gpu_delay, host_delay)
        occupancy = dataclasses.replace(occupancy)  # a new occupancy learns afresh
        used = backends_of_auto_calls(8, occupancy, origins, directions, reference)
        # Turns until each is timed twice, the GPU first; then the faster.
        assert used == ["gpu", "host", "gpu", "host"] + [winner] * 4


def test_each_size_of_call_and_occupancy_learns_on_its_own(monkeypatch, gpu_is):
    occupancy, origins, directions = scene_and_rays()
    gpu_is("gpu")
    with_delays(monkeypatch, 0.05, 0.0)
    for _ in range(4):
        tracing.trace(occupancy, origins, directions)
    assert tracing.trace(occupancy, origins, directions).backend == "host"
    # 64 times the rays: another size class, learned from the GPU again.
    big = np.repeat(origins, 64, axis=0), np.repeat(directions, 64, axis=0)
    assert tracing.trace(occupancy, *big).backend == "gpu"
    assert tracing.trace(dataclasses.replace(occupancy), origins, directions).backend == "gpu"
    # Named backends and the march are not the choice's to make.
    assert tracing.trace(occupancy, origins, directions, backend="gpu").backend == "gpu"
    assert tracing.trace(occupancy, origins, directions, method="march").backend == "gpu"


def test_lavapipe_standing_in_for_a_gpu_loses_to_numba_with_equal_answers(wgpu_backend, gpu_is):
    occupancy, origins, directions = scene_and_rays(rays=512)
    reference = tracing.trace(occupancy, origins, directions, backend="numba")
    tracing.trace(occupancy, origins, directions, backend="wgpu")  # opens the device, builds pipelines
    occupancy = dataclasses.replace(occupancy)
    gpu_is("wgpu")
    used = backends_of_auto_calls(6, occupancy, origins, directions, reference)
    # A dispatch and a wait on lavapipe cost more than numba's whole call.
    assert used == ["wgpu", "numba", "wgpu", "numba", "numba", "numba"]


def test_a_run_with_a_gpu_says_which_backends_traced_it(forest, monkeypatch, gpu_is):  # noqa: F811
    reference = simulate(forest, write=False)
    gpu_is("gpu")
    with_delays(monkeypatch, 0.0, 0.0)
    result = simulate(forest, backend="auto", write=False)
    # Each run's four calls (one a scan, all one size) were the choice's turns.
    assert set(result.backend.split("+")) == {"gpu", "host"}
    for mine, theirs in zip(result.scene_per_scan, reference.scene_per_scan):
        assert np.array_equal(mine, theirs)
    assert simulate(forest, backend="auto", method="march", write=False).backend == "gpu"


def test_the_backend_list_says_what_auto_does(gpu_is):
    gpu_is("numba")
    assert backend_choices()[0] == ("auto", "numba, the fastest here (no GPU adapter)", True)
    gpu_is("wgpu")
    auto = backend_choices()[0][1]
    assert auto == "wgpu (a GPU) or numba, whichever has traced calls of that size faster"


def test_two_way_choice_retries_the_loser_less_often_as_it_keeps_losing():
    choice = TwoWayChoice(("a", "b"), settled_gap=float("inf"))
    picks = ""
    for _ in range(200):
        pick = choice.pick()
        picks += pick
        choice.record(pick, {"a": 2.0, "b": 1.0}[pick], 1)
    assert picks[:4] == "abab" and choice.leader() == "b"
    # "b" took the lead at call 2: "a" is retried 16 calls later, then 32, then 64.
    assert [k + 1 for k, p in enumerate(picks) if p == "a"] == [1, 3, 18, 50, 114, 178]
