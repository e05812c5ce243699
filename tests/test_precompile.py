"""The TUI's warm-up compiles a run's kernels ahead, in two child processes: together
the two halves must leave the run nothing to compile."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

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

    scenario = load_scenario(bundled_or_path("default"))
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


def test_the_two_halves_leave_a_run_nothing_to_compile(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(SRC))
    done = subprocess.run(
        [sys.executable, "-c", AFTER_THE_HALVES],
        capture_output=True,
        text=True,
        env=env,
        timeout=900,
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    lines = done.stdout.splitlines()
    assert lines == ["object-order kernels ready: True"], done.stdout


def test_the_children_end_when_asked(tmp_path):
    from ladartui.precompile import compile_in_children

    scenario = tmp_path / "none.toml"
    scenario.write_text("", encoding="utf-8")
    stop = threading.Event()
    stop.set()
    started = time.monotonic()
    assert compile_in_children(scenario, stop=stop) is False
    assert time.monotonic() - started < 10.0


def test_a_child_that_fails_says_so(tmp_path):
    from ladartui.precompile import compile_in_children

    missing = tmp_path / "missing.toml"  # each child fails to load it
    assert compile_in_children(missing, timeout=120.0) is False
