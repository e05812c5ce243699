"""Importing ladartui picks numba's TBB layer where the runtime is installed, and
shortens OpenMP's spin for where numba falls back to it; a user's settings stand."""

import os
import platform
import subprocess
import sys

import pytest

from ladartui import threads
from ladartui.cli.bench import _device

# A parallel kernel runs, so numba has picked its layer.
LAYER_AFTER_TRACE = (
    "import numpy as np, numba, ladartui\n"
    "from ladartui import Occupancy, trace\n"
    "occ = Occupancy.build(np.array([[1, 1, 1]]), (4, 4, 4))\n"
    "r = trace(occ, np.full((8, 3), 0.15), np.tile([0.0, 0.0, 1.0], (8, 1)), backend='numba')\n"
    "assert (r.kind == 0).all()  # upward rays: misses\n"
    "print(numba.threading_layer())\n"
)
TBB_WHEEL_PLATFORM = sys.platform == "linux" and platform.machine() == "x86_64"


def _run(code, **settings):
    unset = ("GOMP_SPINCOUNT", "OMP_WAIT_POLICY", "NUMBA_THREADING_LAYER")
    env = {k: v for k, v in os.environ.items() if k not in unset}
    env.update(settings)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


@pytest.mark.parametrize(
    ("settings", "expected"),
    [
        ({}, "30000"),
        ({"GOMP_SPINCOUNT": "7"}, "7"),  # the user's own count stands
        ({"OMP_WAIT_POLICY": "ACTIVE"}, "None"),  # so does a wait policy, with libgomp's count
    ],
)
def test_spin_count(settings, expected):
    assert _run("import os, ladartui; print(os.environ.get('GOMP_SPINCOUNT'))", **settings) == expected


@pytest.mark.skipif(not TBB_WHEEL_PLATFORM, reason="the tbb wheel is locked for x86-64 Linux only")
def test_traces_run_on_tbb():
    assert threads.tbb_runtime() is not None  # the locked tbb wheel put it in the environment
    assert _run(LAYER_AFTER_TRACE) == "tbb"


def test_the_users_layer_stands():
    assert _run(LAYER_AFTER_TRACE, NUMBA_THREADING_LAYER="omp") == "omp"


@pytest.mark.parametrize(
    ("name", "value", "message"),
    [
        (
            "NUMBA_THREADING_LAYER",
            "opm",
            "NUMBA_THREADING_LAYER = 'opm': expected one of default, safe, threadsafe, forksafe, "
            "tbb, omp, workqueue",
        ),
        ("NUMBA_NUM_THREADS", "0", "NUMBA_NUM_THREADS = '0': expected a whole number of threads, 1 or more"),
        (
            "NUMBA_NUM_THREADS",
            "two",
            "NUMBA_NUM_THREADS = 'two': expected a whole number of threads, 1 or more",
        ),
        # a digit that is not 0-9 passed the check, and int() then raised
        (
            "NUMBA_NUM_THREADS",
            "\u00b2",
            "NUMBA_NUM_THREADS = '\u00b2': expected a whole number of threads, 1 or more",
        ),
    ],
)
def test_a_bad_numba_thread_setting_is_one_line_naming_it(
    monkeypatch, capsys, tmp_path, name, value, message
):
    """A misspelt layer or a thread count of 0 ended a run in numba's ValueError traceback."""
    from cli_support import one_error_line
    from ladartui.cli import main

    monkeypatch.setenv(name, value)
    assert main(["trace", "--scene", str(tmp_path / "s.txt"), "--rays", "r.npy", "--out", "h.npy"]) == 2
    assert one_error_line(capsys) == f"ladartui: error: {message}"
    for good in ("OMP", "tbb", "") if name == "NUMBA_THREADING_LAYER" else ("1", "16", ""):
        monkeypatch.setenv(name, good)
        assert threads.environment_problem() is None


def test_no_runtime_no_load(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "prefix", str(tmp_path))
    monkeypatch.setattr(sys, "base_prefix", str(tmp_path))
    assert threads.tbb_runtime() is None
    assert threads.load_tbb() is False


def test_a_runtime_that_does_not_load(tmp_path, monkeypatch):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / threads.TBB_RUNTIME).write_bytes(b"not a library")
    monkeypatch.setattr(sys, "prefix", str(tmp_path))
    assert threads.tbb_runtime() == tmp_path / "lib" / threads.TBB_RUNTIME
    assert threads.load_tbb() is False


def test_bench_names_the_layer():
    assert _device({"device": "cpu", "threads": 2, "threading_layer": "tbb"}) == "cpu, 2 threads (tbb)"
    assert _device({"adapter": "llvmpipe", "threads": 2}) == "llvmpipe"
