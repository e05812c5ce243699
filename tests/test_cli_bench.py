"""``ladartui bench``: the orbit bench's sensor and its flags."""

from __future__ import annotations

import contextlib
import json

import numpy as np
import pytest

from ladartui.cli import main


@pytest.fixture
def tiny_bench(monkeypatch):
    """The bench on a small scene and a 2-scan orbit, with no status line."""
    bench = pytest.importorskip("ladartui.cli.bench")
    pytest.importorskip("numba")
    small = np.array([[i, j, k] for i in range(0, 40, 3) for j in range(0, 40, 2) for k in range(6)])

    def tiny_scene(progress=None):
        from ladartui.scene.model import Scene

        return Scene(small, small[:4], 0.25, shape=(40, 40, 30), name="tiny"), "tiny"

    @contextlib.contextmanager
    def status():
        yield lambda text: None

    monkeypatch.setattr(bench, "load_bench_scene", tiny_scene)
    monkeypatch.setattr(bench, "ORBIT_SCANS", 2)
    monkeypatch.setattr(bench, "_status", status)
    return bench


def test_quick_orbit_traces_the_64x64_sensor_quick_promises(tiny_bench, capsys):
    """'bench --quick --orbit' said '128x128 detectors': the orbit ignored --quick."""
    assert main(["bench", "--quick", "--orbit", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["sensor"].startswith("64x64 detectors, 4x4 rays each")
    assert report["rays"] == 2 * 2 * 64 * 64 * 16  # both runs of each scan: the sensor traced
    assert report["runs"] == 1  # fewer runs too


def test_passes_with_orbit_is_refused_before_any_tracing(monkeypatch, capsys):
    """'bench --orbit --passes' timed the orbit and dropped --passes without a word."""
    from ladartui.cli import bench

    def refuse(*args, **kwargs):
        raise AssertionError("the bench ran")

    monkeypatch.setattr(bench, "load_bench_scene", refuse)
    assert main(["bench", "--orbit", "--passes"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        "ladartui: error: --passes and --orbit do not combine: --orbit times whole orbits, "
        "with no time by pass; drop one"
    )


@pytest.mark.parametrize("command", ["bench", "study", "pulses"])
def test_every_flag_that_takes_a_value_states_its_default(command):
    """'pulses -h' did not say --pulses was 1,10,100, nor 'bench -h' what --runs was."""
    import argparse

    from ladartui.cli import build_parser

    subparsers = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    parser = subparsers.choices[command]
    for action in parser._actions:
        if action.nargs == 0 or action.required:  # switches, -h, required values
            continue
        if (command, action.dest) == ("study", "chart_from"):  # a mode: without it, a new study
            continue
        text = " ".join((action.help or "").split())
        assert "default" in text, f"{command} {action.dest}: {text!r}"
        if action.default is not None:
            assert str(action.default) in text, f"{command} {action.dest}: {text!r}"


def test_one_call_and_one_run_are_singular(monkeypatch, capsys):
    """The bench said 'numba 1 calls' (a --quick warm-up) and 'median of 1 runs'."""
    from rich.console import Console

    from ladartui.cli import bench
    from ladartui.cli.bench_passes import print_passes

    monkeypatch.setenv("COLUMNS", "200")
    report = {
        "scene": "tiny",
        "shape": [40, 40, 30],
        "voxels": 1200,
        "occupancy_bytes": 2**20,
        "setup_seconds": 0.1,
        "setup_cpu_seconds": 0.1,
        "sensor": "64x64 detectors, 4x4 rays each",
        "runs": 1,
        "warm_up": {"numba": {"calls": 1, "seconds": 0.5}, "wgpu": {"calls": 12, "seconds": 0.3}},
        "results": [
            {
                "backend": "numba",
                "method": "exact",
                "view": "wide",
                "depression": 45.0,
                "order": "ray",
                "rays_per_second": 1e6,
                "vs_numba": 1.0,
                "rays_per_cpu_second": 1e6,
                "voxel_hits": 0.5,
                "ground_hits": 0.5,
                "device": "cpu",
                "passes": {"bins": 0.001},
                "median_seconds": 0.002,
            }
        ],
        "views": {"wide": "wide view", "narrow": "narrow view"},
        "backends": {"numba": "available"},
    }
    bench._print_table(report)
    print_passes(Console(), report)
    out = " ".join(capsys.readouterr().out.split())
    assert "median of 1 run after a warm-up (numba 1 call in 0.5 s, wgpu 12 calls in 0.3 s)" in out
    assert "milliseconds by pass (medians of 1 run)" in out


def test_the_orbit_line_says_one_run(tiny_bench, capsys):
    assert main(["bench", "--quick", "--orbit"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "over 1 run after a warm-up" in out
