"""``ladartui bench --passes``: the medians by pass, and their table at 80 columns."""

import pytest

from ladartui.cli.bench_passes import PASS_ORDER, pass_medians, print_passes


def test_medians_by_pass_in_scan_order_with_the_rest_as_other():
    runs = [
        {"tile tests": 0.004, "rays to cells": 0.001, "bins": 0.002},
        {"rays to cells": 0.003, "bins": 0.001, "tile tests": 0.005, "extra": 0.001},
        {"rays to cells": 0.002, "bins": 0.003, "tile tests": 0.006},
    ]
    medians = pass_medians([0.010, 0.012, 0.011], runs)
    assert list(medians) == ["rays to cells", "bins", "tile tests", "extra", "other"]
    assert medians["rays to cells"] == pytest.approx(0.002)
    assert medians["tile tests"] == pytest.approx(0.005)
    assert medians["extra"] == 0.0  # absent from two runs of three
    # other: each run's time less its passes (0.003, 0.002, 0.000), then the median
    assert medians["other"] == pytest.approx(0.002)
    assert set(PASS_ORDER) >= {"rays to cells", "bins", "tile tests", "device", "answers"}


def test_the_pass_tables_fit_an_80_column_terminal(monkeypatch, capsys):
    from rich.console import Console

    monkeypatch.setenv("COLUMNS", "80")
    numba = {
        "rays to cells": 0.00084,
        "bins": 0.00112,
        "voxels in view": 0.00093,
        "tile lists": 0.00035,
        "tile tests": 0.00281,
        "to metres": 0.00008,
        "other": 0.00042,
    }
    wgpu = {
        "rays to cells": 0.00131,
        "bins": 0.00114,
        "voxels in view": 0.00146,
        "tile lists": 0.00238,
        "device": 0.01228,
        "answers": 0.00121,
        "to metres": 0.00008,
        "other": 0.00069,
    }
    results = []
    for backend, passes in (("numba", numba), ("wgpu", wgpu)):
        for view in ("wide", "narrow"):
            for depression in (45.0, 90.0):
                seconds = sum(passes.values())
                row = {
                    "backend": backend,
                    "method": "exact",
                    "view": view,
                    "depression": depression,
                    "passes": passes,
                    "median_seconds": seconds,
                }
                results.append(row)
    results.append(
        {
            "backend": "numba",
            "method": "march",
            "view": "wide",
            "depression": 45.0,
            "passes": {"march": 0.3},
            "median_seconds": 0.3,
        }
    )
    print_passes(Console(), {"runs": 7, "results": results})
    lines = capsys.readouterr().out.splitlines()
    assert max(len(line) for line in lines) <= 80
    assert not any("\u2026" in line for line in lines)
    assert [line for line in lines if "by pass" in line] == [
        "numba, exact scans: milliseconds by pass (medians of 7 runs)",
        "wgpu, exact scans: milliseconds by pass (medians of 7 runs)",
    ]
    cells = {line.split()[0]: line.split() for line in lines if line.split()[:1] in (["pass"], ["total"])}
    assert cells["pass"] == ["pass", "wide", "45", "wide", "90", "narrow", "45", "narrow", "90"]
    totals = [line.split()[1:] for line in lines if line.startswith("total")]
    assert totals == [["6.55"] * 4, ["20.55"] * 4]  # the runs' median times
    rows = [line for line in lines if line.startswith(("tile tests", "device"))]
    assert rows[0].split()[2:] == ["2.81"] * 4
    assert rows[1].split()[1:] == ["12.28"] * 4
    assert not any(line.startswith("march") for line in lines)  # exact scans only


@pytest.mark.parametrize("signum, status", [(2, 130), (15, 143)], ids=["Ctrl-C", "SIGTERM"])
def test_a_stopped_bench_says_it_measured_nothing(monkeypatch, capsys, signum, status):
    """Ctrl-C said only 'interrupted'; SIGTERM ended the bench without a word."""
    import signal

    import ladartui.cli.bench as bench
    from ladartui.cli import main

    def stopped(*args, **kwargs):
        handler = signal.getsignal(signum)
        if signum == signal.SIGINT or not callable(handler):
            raise KeyboardInterrupt
        handler(signum, None)  # as `kill` would

    monkeypatch.setattr(bench, "run_bench", stopped)
    assert main(["bench", "--quick"]) == status
    assert capsys.readouterr().err.splitlines()[-1] == "ladartui: bench cancelled; nothing was measured"
