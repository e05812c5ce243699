"""The TUI's warm-up compiles a run's kernels ahead, in two child processes: together
the two halves must leave the run nothing to compile."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import threading
import time
import types
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"

# In a fresh process (one test's earlier calls would hide a kernel the halves miss):
# the halves, then the default scenario's whole run; prints each kernel (module-level
# numba function) that the run still had to compile or load for a new type.
AFTER_THE_HALVES = textwrap.dedent(
    """
    import sys
    import numba
    from ladartui.precompile import HALVES, compile_half
    from ladartui.scenario import load_scenario
    from ladartui.simulation import simulate
    from ladartui.user_data import bundled_or_path

    def kernels():
        found = {}
        for module_name, module in list(sys.modules.items()):
            if module_name.startswith("ladartui"):
                for name, value in vars(module).items():
                    if isinstance(value, numba.core.dispatcher.Dispatcher):
                        found[value.py_func.__module__ + "." + name] = set(value.signatures)
        return found

    backend, method, model = sys.argv[1:]
    scenario = load_scenario(bundled_or_path("default")).with_changes(backend=backend, method=method)
    if model == "geiger":
        from ladartui.detection.settings import DetectionSettings
        scenario = scenario.with_changes(detection=DetectionSettings(model="geiger", pulses=10))
    for half in HALVES:
        compile_half(half, scenario)
    before = kernels()
    simulate(scenario, write=False)
    for name, signatures in kernels().items():
        if signatures - before.get(name, set()):
            print("compiled in the run:", name)
    print("object-order kernels ready:", bool(before["ladartui.tracing.tile_tests.test_tiles"]))
    """
)


@pytest.mark.parametrize(
    "backend, method, model",
    [
        ("auto", "exact", "ideal"),
        ("wgpu", "exact", "ideal"),
        ("numba", "march", "ideal"),
        ("auto", "exact", "geiger"),
    ],
)
def test_the_two_halves_leave_a_run_nothing_to_compile(tmp_path, backend, method, model):
    if backend == "wgpu":
        from ladartui.errors import BackendUnavailable
        from ladartui.tracing.backend import get_backend

        try:
            get_backend("wgpu")
        except BackendUnavailable as error:
            pytest.skip(str(error))
    env = dict(os.environ, PYTHONPATH=str(SRC))
    done = subprocess.run(
        [sys.executable, "-c", AFTER_THE_HALVES, backend, method, model],
        capture_output=True,
        text=True,
        env=env,
        timeout=900,
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    numba_scans = backend == "auto" and method == "exact"  # numba here (no GPU): its own tile tests
    assert done.stdout.splitlines() == [f"object-order kernels ready: {numba_scans}"], done.stdout


def _settings(path, backend="numba", method="exact"):
    return types.SimpleNamespace(path=path, backend=backend, method=method, precision="f64")


@pytest.fixture
def children(monkeypatch):
    """The child processes compile_in_children starts."""
    import ladartui.precompile as precompile

    started = []
    popen = subprocess.Popen

    def recorded(*args, **kwargs):
        started.append(popen(*args, **kwargs))
        return started[-1]

    monkeypatch.setattr(precompile.subprocess, "Popen", recorded)
    return started


def test_the_children_end_when_asked(tmp_path, children):
    from ladartui.precompile import HALVES, compile_in_children

    scenario = tmp_path / "none.toml"
    scenario.write_text("", encoding="utf-8")
    stop = threading.Event()
    stop.set()
    started = time.monotonic()
    assert compile_in_children(_settings(scenario), stop=stop) is False
    assert time.monotonic() - started < 10.0
    assert len(children) == len(HALVES) and all(child.poll() is not None for child in children)


def test_a_child_that_fails_says_so(tmp_path, children):
    from ladartui.precompile import compile_in_children

    missing = tmp_path / "missing.toml"  # each child fails to load it
    assert compile_in_children(_settings(missing), timeout=120.0) is False
    assert [child.returncode != 0 for child in children] == [True, True]


def test_the_children_compile_a_scenario_of_theirs(tmp_path, children):
    from ladartui.precompile import compile_in_children
    from tiny_sweep import write_tiny_scenario

    path = write_tiny_scenario(tmp_path).path
    assert compile_in_children(_settings(path), timeout=600.0) is True
    assert [child.returncode for child in children] == [0, 0]


CACHED = textwrap.dedent(
    """
    import sys
    from types import SimpleNamespace
    from ladartui.precompile import kernels_cached
    for backend, method in (("numba", "exact"), ("numba", "march"), ("wgpu", "exact")):
        print(kernels_cached(SimpleNamespace(backend=backend, method=method, precision="f64")))
    """
)


def test_an_empty_kernel_cache_is_told_from_a_filled_one(tmp_path):
    from ladartui.errors import BackendUnavailable
    from ladartui.precompile import HALVES, compile_half, kernels_cached
    from ladartui.tracing.backend import get_backend
    from tiny_sweep import write_tiny_scenario

    scenario = write_tiny_scenario(tmp_path)
    for backend, method in (("numba", "exact"), ("numba", "march"), ("wgpu", "exact")):
        if backend == "wgpu":
            try:
                get_backend("wgpu")
            except BackendUnavailable:
                continue
        chosen = scenario.with_changes(backend=backend, method=method)
        for half in HALVES:  # fills this cache, if need be
            compile_half(half, chosen)
        assert kernels_cached(chosen) is True, (backend, method)
    env = dict(os.environ, PYTHONPATH=str(SRC), NUMBA_CACHE_DIR=str(tmp_path / "empty"))
    done = subprocess.run(
        [sys.executable, "-c", CACHED], capture_output=True, text=True, env=env, timeout=300
    )
    assert done.stdout.split() == ["False", "False", "False"], done.stderr[-2000:]


@pytest.fixture
def ahead(monkeypatch):
    """An empty kernel cache, as the commands see it: the scenarios they compile ahead for."""
    import ladartui.precompile as precompile

    asked = []
    monkeypatch.setattr(precompile, "kernels_cached", lambda scenario: False)
    monkeypatch.setattr(precompile, "compile_in_children", lambda scenario, stop=None: asked.append(scenario))
    return asked


def test_a_run_on_an_empty_cache_compiles_ahead_with_its_flags(ahead, tmp_path, capsys):
    from ladartui.cli import main
    from tiny_sweep import write_tiny_scenario

    path = write_tiny_scenario(tmp_path).path
    assert main(["run", str(path), "--no-write", "--method", "march", "--json"]) == 0
    assert [(s.path, s.method) for s in ahead] == [(path, "march")]
    assert json.loads(capsys.readouterr().out)["method"] == "march"


def test_a_pulse_study_compiles_ahead_for_its_backend(ahead, tmp_path, capsys):
    from ladartui.cli import main
    from tiny_sweep import write_tiny_scenario

    path = write_tiny_scenario(tmp_path).path
    assert main(["pulses", str(path), "--pulses", "1", "--backend", "numba", "--json"]) == 0
    assert [(s.path, s.backend, s.geiger) for s in ahead] == [(path, "numba", True)]


def test_a_sweep_compiles_ahead_once_for_its_variants(ahead, tmp_path):
    from ladartui.sweep import run_sweep
    from tiny_sweep import write_spec, write_tiny_scenario

    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nscans = [1, 2]\n")
    run_sweep(spec, serial=True, out=tmp_path / "out", simulate_options={"method": "march"})
    assert [(s.path.name, s.method) for s in ahead] == [("base.toml", "march")]
    run_sweep(spec, serial=True, out=tmp_path / "out", simulate_options={"method": "march"})
    assert len(ahead) == 1  # every variant resumed: nothing to run, nothing to compile


def test_a_filled_cache_is_not_compiled_again(monkeypatch, tmp_path, capsys):
    import ladartui.precompile as precompile
    from ladartui.cli import main
    from tiny_sweep import write_tiny_scenario

    monkeypatch.setattr(precompile, "kernels_cached", lambda scenario: True)
    monkeypatch.setattr(precompile, "compile_in_children", lambda *a, **k: pytest.fail("compiled again"))
    assert main(["run", str(write_tiny_scenario(tmp_path).path), "--no-write"]) == 0


def test_the_tuis_warm_up_compiles_ahead_only_on_an_empty_cache(ahead, monkeypatch, tmp_path):
    import ladartui.precompile as precompile
    from ladartui.tui.loading import _warm_up
    from tiny_sweep import write_tiny_scenario

    scenario = write_tiny_scenario(tmp_path)
    _warm_up(scenario, None, True, threading.Event())
    assert [s.path for s in ahead] == [scenario.path]
    monkeypatch.setattr(precompile, "kernels_cached", lambda scenario: True)
    _warm_up(scenario, None, True, threading.Event())
    assert len(ahead) == 1


def test_a_mistake_in_the_scene_is_told_before_any_compiling(ahead, tmp_path, capsys):
    """It came after the compiling: over a minute on two cores with an empty cache."""
    from ladartui.cli import main
    from tiny_sweep import write_tiny_scenario

    scenario = write_tiny_scenario(tmp_path)
    with open(scenario.scene_file, "a", encoding="utf-8") as model:
        model.write("1,2,oops\n")
    assert main(["run", str(scenario.path), "--no-write"]) == 2
    assert "oops" in capsys.readouterr().err
    assert ahead == []
