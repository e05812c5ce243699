"""Where a trace's time goes: ``TraceResult.info["passes"]`` (tracing/passes.py)."""

import threading
import time

import numpy as np
import pytest

from ladartui.tracing import trace
from ladartui.tracing.passes import recording, timed
from ladartui.tracing.prepare import rays_to_cells
from scans import forest_scene, one_scan

# The wgpu_backend and numba_backend fixtures come from tests/conftest.py.
OBJECT_ORDER_PASSES = {"bins", "voxels in view", "tile lists"}


@pytest.fixture(scope="module")
def forest():
    return forest_scene()


def test_a_pass_adds_its_time_to_the_open_recording_only():
    with timed("outside"):  # no recording open: nothing is kept, nothing fails
        pass
    with recording() as seconds:
        with timed("sleep"):
            time.sleep(0.02)
        with timed("sleep"):
            time.sleep(0.01)
        with timed("quick"):
            pass
    assert set(seconds) == {"sleep", "quick"}
    assert 0.03 <= seconds["sleep"] < 1.0
    assert 0.0 <= seconds["quick"] < seconds["sleep"]
    with timed("after"):
        pass
    assert "after" not in seconds


def test_an_inner_recording_keeps_its_own_and_adds_them_to_the_outer():
    with recording() as outer:
        with timed("a"):
            time.sleep(0.01)
        with recording() as inner:
            with timed("a"):
                time.sleep(0.01)
            with timed("b"):
                pass
        assert set(inner) == {"a", "b"}
    assert set(outer) == {"a", "b"}
    assert outer["a"] > inner["a"] >= 0.01


def test_a_pass_timed_in_failure_still_counts():
    with recording() as seconds:
        with pytest.raises(ValueError):
            with timed("failing"):
                raise ValueError("boom")
    assert "failing" in seconds


def test_recordings_of_two_threads_stay_apart():
    ready, results = threading.Barrier(2), {}

    def record(name):
        with recording() as seconds:
            ready.wait()
            with timed(name):
                time.sleep(0.01)
            ready.wait()  # both passes done before either recording ends
        results[name] = seconds

    threads = [threading.Thread(target=record, args=(name,)) for name in ("left", "right")]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert set(results["left"]) == {"left"} and set(results["right"]) == {"right"}


def _scan(forest):
    voxels, occ = forest
    origins, directions = one_scan([120, 120, 20], 45.0, 0.3, 200.0)
    return occ, origins, directions


@pytest.mark.parametrize("backend", ["numba", "wgpu"])
def test_a_scan_in_object_order_says_where_its_time_went(forest, backend, request):
    """Each backend's object-order passes, every one timed, together within the call."""
    engine = request.getfixturevalue(f"{backend}_backend")
    if backend == "wgpu" and "f64" not in engine.describe()["precisions"]:
        pytest.skip("the adapter has no shader-f64: object order runs in f64 only")
    occ, origins, directions = _scan(forest)
    cells, unit, bounds = rays_to_cells(origins, directions, 1.0, 1e-200)
    engine.trace_cells(occ, cells, unit, order="object", block_bounds=bounds)  # compiles
    started = time.perf_counter()
    with recording() as seconds:
        hits = engine.trace_cells(occ, cells, unit, order="object", block_bounds=bounds)
    wall = time.perf_counter() - started
    assert hits.info["order"] == "object"
    own = {"numba": {"tile tests"}, "wgpu": {"device", "answers"}}[backend]
    assert set(seconds) == OBJECT_ORDER_PASSES | own
    assert all(value > 0.0 for value in seconds.values())
    assert sum(seconds.values()) <= wall


def test_trace_reports_its_passes(forest):
    occ, origins, directions = _scan(forest)
    few = trace(occ, origins[:50], directions[:50], backend="numba")  # too few for a scan: ray order
    assert set(few.info["passes"]) == {"rays to cells", "ray order", "to metres"}
    march = trace(occ, origins[:50], directions[:50], backend="numba", method="march")
    assert set(march.info["passes"]) == {"rays to cells", "march", "to metres"}
    started = time.perf_counter()
    result = trace(occ, origins, directions, backend="numba")
    wall = time.perf_counter() - started
    passes = result.info["passes"]
    assert {"rays to cells", "to metres"} <= set(passes)
    for order in result.info["order"].split("+"):  # each order that ran has its passes
        assert ({"ray order"} if order == "ray" else OBJECT_ORDER_PASSES | {"tile tests"}) <= set(passes)
    assert sum(passes.values()) <= wall
    assert np.all(np.isfinite(list(passes.values())))
