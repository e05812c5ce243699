"""The study's timings: what a timed call's seconds hold, and what they leave out."""

from __future__ import annotations

import time

import pytest

from ladartui.study import Setting
from test_study import _tiny_inputs

COMPILE_S = 1.0


def test_a_timed_call_that_compiles_is_run_again_and_its_compile_never_timed(monkeypatch):
    """On a cold cache the warm-up traced a scan in object order and the first timed call
    tried ray order, compiling its kernels: 'study --quick' quoted numba exact m=1 at
    54.54 s a scan (the median of 109 s and 2 ms) where it takes 2 ms, and called it
    beaten by m=2."""
    from numba.core.compiler_lock import global_compiler_lock

    import ladartui.study.run as study_run
    from ladartui.study import run_study

    pytest.importorskip("numba")
    calls = {"n": 0}
    real = study_run._trace

    def first_timed_call_compiles(scene, origins, directions, setting, cancel):
        calls["n"] += 1
        if calls["n"] == 2:  # after the warm-up: a kernel the warm-up did not reach
            with global_compiler_lock:
                time.sleep(COMPILE_S)
        return real(scene, origins, directions, setting, cancel)

    monkeypatch.setattr(study_run, "_trace", first_timed_call_compiles)
    seen: list = []
    result = run_study(
        _tiny_inputs(), [Setting("numba", "exact", "f64", None, 1)], runs=3, warmup=1, progress=seen.append
    )
    (row,) = result.rows
    assert row.timing.runs == 3  # the first scan twice, the second once: every one timed
    assert max(row.timing.seconds) < COMPILE_S / 2, row.timing.seconds
    assert calls["n"] == 1 + 1 + 3  # warm-up, the call that compiled, the three timed
    assert seen[-1].done == seen[-1].total == 1 + 3  # the call run again is not counted twice
