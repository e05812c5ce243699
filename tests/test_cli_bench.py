"""``ladartui bench``: its table, narrow and wide views, warm-up, orbit and flags."""

from __future__ import annotations

import contextlib
import json
import math

import numpy as np
import pytest

from ladartui.cli import main


def _bench_row(backend, method, view, depression, rate, vs_numba, per_cpu, order="object"):
    return {
        "backend": backend,
        "method": method,
        "view": view,
        "depression": depression,
        "order": order,
        "rays_per_second": rate,
        "vs_numba": vs_numba,
        "rays_per_cpu_second": per_cpu,
        "voxel_hits": 0.684,
        "ground_hits": 0.316,
        "device": "cpu" if backend == "numba" else "a GPU",
    }


def _bench_report(rows):
    """A bench report of ``rows`` on the reference scene, as run_bench makes it."""
    return {
        "scene": "reference",
        "shape": [1500, 1500, 900],
        "voxels": 3829919,
        "occupancy_bytes": 18_000_000,
        "setup_seconds": 1.1,
        "setup_cpu_seconds": 1.1,
        "sensor": "128x128 detectors, 4x4 rays each",
        "runs": 7,
        "warm_up": {"numba": {"calls": 53, "seconds": 0.5}},
        "results": rows,
        "views": {"wide": "wide view", "narrow": "narrow view"},
        "backends": {"numba": "available", "wgpu": "available"},
    }


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


def test_bench_quick_json(monkeypatch, tmp_path, capsys):
    bench = pytest.importorskip("ladartui.cli.bench")
    small = np.array([[i, j, k] for i in range(0, 40, 3) for j in range(0, 40, 2) for k in range(6)])

    def tiny_scene(progress=None):
        from ladartui.scene.model import Scene

        return Scene(small, small[:1], 0.25, shape=(40, 40, 30), name="tiny"), "tiny"

    heard = []

    @contextlib.contextmanager
    def status():  # the status line a terminal shows
        yield heard.append

    monkeypatch.setattr(bench, "load_bench_scene", tiny_scene)
    monkeypatch.setattr(bench, "SLANT_RANGE_M", 5.0)
    monkeypatch.setattr(bench, "_status", status)
    assert main(["bench", "--quick", "--json", "--runs", "3"]) == 0
    report = json.loads(capsys.readouterr().out)
    # it says what it does: it ran a minute in silence
    assert heard[0] == "building the occupancy" and "exact wide 45 deg: run 1 of 3" in heard
    assert heard[-1] == "march wide 90 deg: run 3 of 3"
    assert report["voxels"] == len(small)
    assert report["occupancy_bytes"] > 0
    assert report["warm_up"]["numba"]["calls"] == 1  # --quick: the compiling call alone
    rows = {(r["backend"], r["method"], r["view"], r["depression"]) for r in report["results"]}
    assert {
        ("numba", "exact", "wide", 45.0),
        ("numba", "exact", "wide", 90.0),
        ("numba", "march", "wide", 45.0),
        ("numba", "march", "wide", 90.0),
        ("numba", "exact", "narrow", 45.0),
        ("numba", "exact", "narrow", 90.0),
    } <= rows
    assert not any(r["view"] == "narrow" and r["method"] == "march" for r in report["results"])
    assert all(r["rays_per_second"] > 0 for r in report["results"])
    # Which order each traced in: the march always walks the rays.
    assert all(set(r["order"].split("/")) <= {"object", "ray", "object+ray"} for r in report["results"])
    assert all(r["order"] == "ray" for r in report["results"] if r["method"] == "march")
    # Each row's share of numba's speed on the same method and angle: the median of
    # the runs' ratios, each against numba's run of the same turn.
    numba = {
        (r["method"], r["view"], r["depression"]): r["run_seconds"]
        for r in report["results"]
        if r["backend"] == "numba"
    }
    for r in report["results"]:
        assert len(r["run_seconds"]) == 3
        # Where the time went (``--passes``): median seconds by pass, the rest as "other".
        assert {"rays to cells", "to metres", "other"} <= set(r["passes"])
        assert ("march" if r["method"] == "march" else "ray order") in r["passes"] or "bins" in r["passes"]
        assert r["rays_per_second"] == pytest.approx(r["rays"] / sorted(r["run_seconds"])[1])
        base = numba[r["method"], r["view"], r["depression"]]
        assert r["vs_numba"] == pytest.approx(sorted(b / t for b, t in zip(base, r["run_seconds"]))[1])
        if r["backend"] == "numba":
            assert r["vs_numba"] == 1.0


@pytest.mark.parametrize("depression", [45.0, 90.0])
def test_bench_narrow_view_is_the_peer_geometry(depression):
    """The narrow view: 3 degrees across, from 150 m up, its central ray through the target."""
    from ladartui.cli import bench
    from ladartui.scene.model import Scene

    target = np.array([[200, 300, 5], [201, 300, 5]])
    scene = Scene(target, target, 0.1, shape=(1500, 1500, 900))
    origins, directions = bench.bench_rays(scene, depression, grid=8, ray_grid=2, view="narrow")
    centre = target.mean(axis=0) * 0.1
    assert np.allclose(origins[:, 2], 150.0, atol=0.01)
    mean = directions.mean(axis=0)
    mean /= np.linalg.norm(mean)
    to_target = centre - origins.mean(axis=0)
    assert np.allclose(mean, to_target / np.linalg.norm(to_target), atol=1e-3)
    assert math.degrees(math.asin(-mean[2])) == pytest.approx(depression, abs=0.1)
    # 16 rays across a 3 degree view: the first and last of the first row (detector 7, sub-ray 1).
    spread = math.degrees(math.acos(np.clip(directions[0] @ directions[29], -1, 1)))
    assert spread == pytest.approx(3.0 * 15 / 16, rel=0.02)
    if depression < 90.0:
        bearing = math.degrees(math.atan2(mean[0], mean[1])) % 360
        assert bearing == pytest.approx(bench.NARROW_BEARING, abs=0.1)


def test_bench_table_fits_an_80_column_terminal(monkeypatch, capsys):
    """Every figure of every row, whole, in 80 columns (an SSH terminal's width)."""
    from ladartui.cli import bench

    monkeypatch.setenv("COLUMNS", "80")
    rows = [
        _bench_row("numba", "exact", "narrow", 45.0, 26.87e6, 1.0, 13.48e6),
        _bench_row("wgpu", "exact", "narrow", 45.0, 133.27e6, 4.96, 98.65e6),
        _bench_row("numba", "march", "wide", 90.0, 0.86e6, 1.0, 0.44e6, order="object+ray/ray"),
        _bench_row("wgpu", "march", "wide", 90.0, 1.08e6, None, None, order="ray"),
    ]
    report = _bench_report(rows)
    bench._print_table(report)
    lines = capsys.readouterr().out.splitlines()
    assert max(len(line) for line in lines) <= 80
    assert not any("\u2026" in line for line in lines)  # nothing cut short
    rule = next(k for k, line in enumerate(lines) if line.startswith("\u2500"))
    end = next(k for k, line in enumerate(lines) if line.startswith("views:"))
    table = [line.split() for line in lines[rule + 1 : end] if line.split()[:1] in (["numba"], ["wgpu"])]
    assert [cells[:4] for cells in table] == [
        ["numba", "exact", "narrow", "45"],
        ["wgpu", "exact", "narrow", "45"],
        ["numba", "march", "wide", "90"],
        ["wgpu", "march", "wide", "90"],
    ]
    assert [cells[4] for cells in table] == ["obj", "obj", "mix", "ray"]  # the third: mix, then ray below
    assert [cells[5:] for cells in table] == [
        ["26.87", "1.00", "13.48", "68.4%", "31.6%"],
        ["133.27", "4.96", "98.65", "68.4%", "31.6%"],
        ["0.86", "1.00", "0.44", "68.4%", "31.6%"],
        ["1.08", "-", "-", "68.4%", "31.6%"],
    ]


def test_bench_rejects_a_run_count_below_one(capsys):
    from ladartui.cli import main

    for runs in ("0", "1000000000"):  # the latter ran for ever, silently
        assert main(["bench", "--runs", runs]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert err == [f"ladartui: error: --runs = {runs}: expected a whole number from 1 to 1000"]


class FakeClock:
    """A clock that each traced call moves on by the next of ``durations`` seconds."""

    def __init__(self, durations):
        self.now, self.durations = 0.0, iter(durations)

    def __call__(self):
        return self.now

    def trace_once(self):
        self.now += next(self.durations)


@pytest.mark.parametrize(
    "durations, calls",
    [
        # Compiling (40 s), then a GPU raising its clocks: calls of 1/8 s,
        # then 1/16, then steady at 1/32 (windows of 1/4 s: 2, 4, 8 and 8 calls).
        ([40.0] + [1 / 8] * 2 + [1 / 16] * 4 + [1 / 32] * 100, 1 + 2 + 4 + 8 + 8),
        ([40.0] + [1 / 32] * 100, 1 + 8 + 8),  # steady from the start: two windows
    ],
)
def test_warm_up_runs_until_the_speed_settles(durations, calls):
    from ladartui.cli.bench import warm_up

    clock = FakeClock(durations)
    done = warm_up(clock.trace_once, most=5.0, window=0.25, clock=clock)
    assert done["calls"] == calls and done["seconds"] == clock.now  # the compiling call too


def test_warm_up_stops_at_its_limit_and_calls_at_least_once():
    from ladartui.cli.bench import warm_up

    # Never settles: windows of 1/64 s calls and of 1/16 s calls by turns.
    clock = FakeClock([40.0] + ([1 / 64] * 16 + [1 / 16] * 4) * 10)
    assert warm_up(clock.trace_once, most=1.0, window=0.25, clock=clock) == {"calls": 41, "seconds": 41.0}
    # --quick: the compiling call alone, its time said ("1 call in 0.0 s" told nothing)
    clock = FakeClock([3.0])
    assert warm_up(clock.trace_once, most=0.0, clock=clock) == {"calls": 1, "seconds": 3.0}


def test_bench_says_when_a_backend_traced_in_f32(monkeypatch, capsys):
    """An adapter without shader-f64 traces wgpu's exact rows in f32: the ratios then
    compare f32 with numba's f64, and the table says so (it did not)."""
    from ladartui.cli import bench

    monkeypatch.setenv("COLUMNS", "80")
    rows = [
        _bench_row("numba", "exact", "wide", 45.0, 26.87e6, 1.0, 13.48e6),
        _bench_row("wgpu", "exact", "wide", 45.0, 33.27e6, 1.24, 18.65e6),
    ]
    rows[1]["precision"] = "f32"
    report = _bench_report(rows)
    bench._print_table(report)
    out = capsys.readouterr().out
    assert "wgpu traced in f32 (its adapter has no float64): its x numba compares f32 with f64" in " ".join(
        out.split()
    )
    rows[1]["precision"] = "f64"
    bench._print_table(report)
    assert "traced in f32" not in capsys.readouterr().out
