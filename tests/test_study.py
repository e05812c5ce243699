"""The speed-against-accuracy study: Pareto front, timing, miss classes, files, chart, CLI."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import threading
from pathlib import Path

import numpy as np
import pytest

from ladartui.errors import Cancelled
from ladartui.pareto import dominator
from ladartui.study import (
    MissSummary,
    Setting,
    StudyResult,
    StudyRow,
    Timing,
    chart_svg,
    chart_text,
    dominates,
    full_settings,
    measure,
    pareto_front,
    quick_settings,
    voxel_geometry,
)
from ladartui.study.misses import differing, summarise
from ladartui.tracing.backend import GROUND, MISS, VOXEL

# --------------------------------------------------------------------------- Pareto front


def test_pareto_front_of_a_hand_drawn_set():
    # (seconds, error): (3, 3) loses to (2, 3); (2, 4) loses to (2, 3).
    points = [(1, 5), (2, 3), (3, 3), (2, 4), (4, 1)]
    assert pareto_front(points, ("min", "min")) == [True, True, False, False, True]
    assert dominator(points, 2, ("min", "min")) == 1
    assert dominator(points, 3, ("min", "min")) == 1
    assert dominator(points, 0, ("min", "min")) is None


def test_points_on_a_trade_off_curve_are_all_on_the_front_and_any_worse_point_is_not():
    xs = np.linspace(0.1, 10, 25)
    curve = [(float(x), float(1 / x)) for x in xs]
    worse = [(x * 1.01, y * 1.01) for x, y in curve]
    front = pareto_front(curve + worse, ("min", "min"))
    assert all(front[:25]) and not any(front[25:])


def test_equal_points_do_not_dominate_each_other_and_missing_values_never_count():
    assert not dominates((1, 1), (1, 1))
    assert pareto_front([(1, 1), (1, 1), None, (0, float("nan"))], ("min", "min")) == [
        True,
        True,
        False,
        False,
    ]


# --------------------------------------------------------------------------- timing


def test_measure_times_only_after_warm_up_and_quotes_the_median():
    ticks = iter([0.0, 5.0, 10.0, 12.0, 20.0, 21.0])  # three timed calls: 5, 2, 1 seconds
    calls = []
    result, timing = measure(
        lambda: calls.append(1) or len(calls), runs=3, warmup=2, clock=lambda: next(ticks)
    )
    assert len(calls) == 5 and result == 5
    assert timing.seconds == [5.0, 2.0, 1.0]
    assert timing.median == 2.0


def test_measure_stops_on_cancel():
    cancel = threading.Event()
    cancel.set()
    with pytest.raises(Cancelled):
        measure(lambda: None, runs=2, cancel=cancel)
    assert Timing().median is None


# --------------------------------------------------------------------------- miss classes


def test_a_vertical_ray_through_a_voxel_centre_is_in_no_class():
    classes = voxel_geometry([[5.5, 5.5, 20.0]], [[0, 0, -1.0]], [[5, 5, 3]])
    assert not any(mask[0] for mask in classes.values())


def test_a_slanted_ray_clipping_a_corner_is_thin_diagonal_and_not_thin_when_the_next_voxel_is_full():
    from ladartui.scene.occupancy import Occupancy

    # Direction (1, 0, -1)/sqrt2 through voxel (0, 0, 0): entering the top face at
    # x = 0.9 it leaves through x = 1 at z = 0.9, a chord of 0.1 * sqrt(2).
    o = np.array([[0.9 - 5.0, 0.5, 1.0 + 5.0]])
    d = np.array([[1.0, 0.0, -1.0]]) / math.sqrt(2)
    alone = voxel_geometry(o, d, [[0, 0, 0]], Occupancy.build(np.array([[0, 0, 0]])))
    assert alone["thin"][0] and alone["diagonal"][0]
    assert not alone["grazing"][0] and not alone["edge"][0]
    # With voxel (1, 0, 0) occupied the ray carries on through occupied space.
    joined = voxel_geometry(o, d, [[0, 0, 0]], Occupancy.build(np.array([[0, 0, 0], [1, 0, 0]])))
    assert not joined["thin"][0]


def test_grazing_and_edge_entries():
    # Nearly vertical (3 degrees off), entering the x-low side face of voxel (0, 0, 0).
    a = math.radians(3.0)
    d = np.array([[math.sin(a), 0.0, -math.cos(a)]])
    o = np.array([[0.0, 0.5, 0.5]]) - 10.0 * d
    classes = voxel_geometry(o, d, [[0, 0, 0]])
    assert classes["grazing"][0] and not classes["diagonal"][0]
    # A vertical ray entering the top face 0.005 from the y = 1 edge.
    classes = voxel_geometry([[0.5, 0.995, 9.0]], [[0.0, 0.0, -1.0]], [[0, 0, 0]])
    assert classes["edge"][0] and not classes["grazing"][0]


def test_summary_counts_differing_rays_and_which_way_they_err():
    exact = (
        np.array([VOXEL, VOXEL, GROUND, MISS], np.uint8),
        np.array([[1, 1, 1], [2, 2, 2], [3, 3, 0], [-1, -1, -1]], np.int32),
        np.array([5.0, 6.0, 9.0, np.inf]),
    )
    other = (
        np.array([VOXEL, GROUND, GROUND, MISS], np.uint8),
        np.array([[1, 1, 1], [2, 3, 0], [3, 4, 0], [-1, -1, -1]], np.int32),
        np.array([5.5, 8.0, 7.0, np.inf]),
    )
    assert differing(exact[0], exact[1], other[0], other[1]).tolist() == [False, True, True, False]
    o = np.zeros((4, 3))
    d = np.tile([0.0, 0.0, -1.0], (4, 1))
    summary = summarise(o, d, exact, other)
    assert (summary.rays, summary.voxel_rays, summary.differing) == (4, 2, 2)
    assert (summary.later, summary.earlier) == (1, 1)
    assert summary.no_voxel == 1  # ray 2: ground in a neighbouring cell
    assert summary.share == 0.5
    total = MissSummary()
    total.add(summary)
    total.add(summary)
    assert total.differing == 4 and total.share == 0.5


# --------------------------------------------------------------------------- settings


def test_full_study_covers_every_backend_method_and_setting():
    settings = full_settings()
    tracers = {s.tracer for s in settings}
    assert ("numba", "exact", "f64", None) in tracers
    assert {("wgpu", "exact", p, None) for p in ("f64", "f32")} <= tracers
    for backend in ("numba", "wgpu"):
        assert {s.step for s in settings if s.backend == backend and s.method == "march"} == {
            1.0,
            0.5,
            0.25,
            0.1,
        }
    assert {s.ray_grid for s in settings} == {1, 2, 4, 8}
    assert len(settings) == len(set(settings)) == 11 * 4
    assert len(quick_settings()) < len(settings) / 2


# --------------------------------------------------------------------------- results


def _row(label_setting, seconds, error, share, status="ok"):
    row = StudyRow(label_setting, status=status, rays_per_scan=1000, scans=2)
    for s in seconds:
        row.timing.add(s)
    row.coverage = 0.5 + error if error is not None else None
    row.misses = MissSummary(rays=1000, voxel_rays=800, differing=int(round(share * 1000)))
    if status != "ok":
        row.reason = "backend 'wgpu' is unavailable: no adapter"
    return row


def _result():
    exact1 = Setting("numba", "exact", "f64", None, 1)
    exact4 = Setting("numba", "exact", "f64", None, 4)
    march = Setting("numba", "march", "f64", 0.5, 4)
    slow_march = Setting("numba", "march", "f64", 0.1, 4)
    gpu = Setting("wgpu", "exact", "f32", None, 4)
    rows = [
        _row(exact1, [1.0, 1.2, 1.1], -0.10, 0.0),  # fast, coarse
        _row(exact4, [4.0, 4.4, 4.2], 0.0, 0.0),  # the converged reference
        _row(march, [2.0, 2.0, 2.0], +0.02, 0.06),  # in between: on the front
        _row(slow_march, [9.0, 9.0], +0.01, 0.02),  # slower than exact and worse
        _row(gpu, [], None, 0.0, status="skipped"),
    ]
    result = StudyResult(rows, reference_label=exact4.label, reference_coverage=0.5)
    result.finish()
    return result


def test_finish_scores_coverage_error_and_marks_the_front():
    result = _result()
    fronts = {row.label: row.front for row in result.rows}
    assert fronts == {
        "numba exact f64 m=1": True,
        "numba exact f64 m=4": True,
        "numba march 0.5 f64 m=4": True,
        "numba march 0.1 f64 m=4": False,
        "wgpu exact f32 m=4": False,
    }
    assert result.rows[3].dominated_by == "numba exact f64 m=4"
    assert result.rows[0].coverage_error == pytest.approx(-0.10)
    assert result.rows[0].seconds_per_scan == pytest.approx(1.1)
    assert result.rows[0].rays_per_second == pytest.approx(1000 / 1.1)
    verdict = result.verdict()
    assert "numba march 0.1 f64 m=4: beaten by numba exact f64 m=4" in verdict
    assert "Not measured (1 settings): backend 'wgpu' is unavailable" in verdict


def test_csv_and_json_files_are_written_atomically_and_read_back(tmp_path):
    result = _result()
    paths = result.write(tmp_path)
    rows = list(csv.DictReader(io.StringIO(paths["csv"].read_text())))
    assert [r["label"] for r in rows] == [r.label for r in result.rows]
    assert float(rows[2]["seconds_per_scan"]) == 2.0
    assert rows[4]["status"] == "skipped" and rows[4]["seconds_per_scan"] == ""
    data = json.loads(paths["json"].read_text())
    assert data["reference"]["coverage"] == 0.5
    assert [r["front"] for r in data["rows"]] == [True, True, True, False, False]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.csv", "study.json"]


def test_chart_marks_the_front_as_text_and_svg():
    result = _result()
    text = chart_text(result, width=90, height=26, color=False)
    assert "\x1b[" not in text
    assert "Pareto front" in text and "nb ex m4" in text and "nb .5 m4" in text
    assert "nb .1 m4" not in text  # dominated points carry no label
    svg = chart_svg(result, width=90, height=26)
    assert svg.lstrip().startswith("<svg") and "Pareto" in svg
    assert len(svg) < 300_000


# --------------------------------------------------------------------------- a real study


def _tiny_inputs(depth_resolution=0.0):
    from ladartui.flight import orbit
    from ladartui.scene.model import Scene
    from ladartui.sensor import Sensor
    from ladartui.study.inputs import StudyInputs

    rng = np.random.default_rng(7)
    canopy = rng.integers([0, 0, 6], [24, 24, 10], size=(500, 3))
    target = np.array([(i, j, k) for i in range(9, 15) for j in range(10, 13) for k in range(0, 2)])
    voxels = np.unique(np.vstack([canopy, target]), axis=0)
    scene = Scene(voxels, target, 0.5, shape=(24, 24, 12), name="tiny")
    poses = orbit((6.0, 5.75, 0.25), 12.0, 14.0, 2)
    sensor = Sensor(grid=12, ray_grid=1, fov=40.0, depth_resolution=depth_resolution)
    return StudyInputs(scene, sensor, poses, "tiny test scene")


def _reference_answers(inputs, m):
    """Independent answers: the slow float64 slab-test tracer over every scan at grid m."""
    from dataclasses import replace

    from ladartui.tracing.reference import reference_trace_cells

    scene = inputs.scene
    sensor = replace(inputs.sensor, ray_grid=m)
    out = []
    for pose in inputs.poses:
        origins, directions, _ = sensor.rays(pose)
        out.append(
            reference_trace_cells(scene.voxels, scene.shape, origins / scene.voxel_size + 0.5, directions)
        )
    return out


def test_run_study_scores_against_an_independent_reference_and_skips_unknown_backends():
    from ladartui.study import run_study

    pytest.importorskip("numba")
    inputs = _tiny_inputs()
    settings = [
        Setting("numba", "exact", "f64", None, 1),
        Setting("numba", "march", "f64", 1.0, 1),
        Setting("numba", "exact", "f64", None, 2),
        Setting("nosuch", "exact", "f64", None, 2),
    ]
    seen = []
    result = run_study(inputs, settings, runs=2, warmup=1, progress=seen.append)
    rows = {row.label: row for row in result.rows}
    # Coverage with no depth rule: target voxels hit by any ray of any scan.
    target = {tuple(v) for v in inputs.scene.target.tolist()}
    for m in (1, 2):
        hits = set()
        for cells in _reference_answers(inputs, m):
            hits |= {tuple(v) for v in cells.index[cells.kind == VOXEL].tolist()}
        assert rows[f"numba exact f64 m={m}"].coverage == pytest.approx(len(hits & target) / len(target))
    assert rows["numba exact f64 m=2"].coverage_error == 0.0
    assert result.reference_label == "numba exact f64 m=2"
    march = rows["numba march 1 f64 m=1"]
    answers = _reference_answers(inputs, 1)
    assert march.misses.voxel_rays == sum(int((a.kind == VOXEL).sum()) for a in answers)
    assert march.misses.rays == 2 * 12 * 12 and march.scans == 2 and march.timing.runs == 2
    # The report's march only ever ends later than the exact answer.
    assert march.misses.earlier == 0 and march.misses.later == march.misses.differing
    assert rows["numba exact f64 m=1"].hit_differs == 0.0
    skipped = rows["nosuch exact f64 m=2"]
    assert skipped.status == "skipped" and "nosuch" in skipped.reason
    assert seen and seen[-1].done == seen[-1].total


def test_run_study_is_cancellable():
    from ladartui.study import run_study

    cancel = threading.Event()
    cancel.set()
    with pytest.raises(Cancelled):
        run_study(_tiny_inputs(), [Setting("numba", "exact", "f64", None, 1)], runs=1, cancel=cancel)


def test_cli_quick_writes_data_and_chart_files(tmp_path, monkeypatch, capsys):
    from ladartui.cli import main
    from ladartui.study import inputs as study_inputs

    monkeypatch.setattr(study_inputs, "generated_inputs", lambda *a, **k: _tiny_inputs(1.0))
    status = main(["study", "--quick", "--runs", "1", "--out", str(tmp_path)])
    out = capsys.readouterr()
    assert status == 0, out.err
    assert "Pareto front" in out.out
    err = " ".join(out.err.split())
    assert "median of 1 run" in err and "1 runs" not in err
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == [
        "speed-accuracy.png",
        "speed-accuracy.svg",
        "speed-accuracy.txt",
        "study.csv",
        "study.json",
    ]
    data = json.loads((tmp_path / "study.json").read_text())
    assert data["reference"]["label"] == "numba exact f64 m=2"
    assert main(["study", "--scans", "0"]) == 2
    assert "--scans = 0: expected 1 or more" in capsys.readouterr().err


# --------------------------------------------------------------------------- the screen


async def test_study_screen_runs_in_a_worker_and_shows_chart_table_and_verdict(monkeypatch, tmp_path):
    pytest.importorskip("textual")
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path))  # where the screen keeps its study
    from textual.app import App
    from textual.widgets import DataTable, Static

    from ladartui.study import inputs as study_inputs
    from ladartui.study import settings as study_settings
    from ladartui.tui.study_screen import StudyScreen

    monkeypatch.setattr(study_inputs, "generated_inputs", lambda *a, **k: _tiny_inputs(1.0))
    monkeypatch.setattr(
        study_settings,
        "quick_settings",
        lambda: [Setting("numba", "exact", "f64", None, 1), Setting("numba", "march", "f64", 1.0, 1)],
    )
    import ladartui.study as study_package

    monkeypatch.setattr(study_package, "quick_settings", study_settings.quick_settings)

    class Host(App):
        def on_mount(self):
            self.push_screen(StudyScreen(None, runs=1))

    app = Host()
    async with app.run_test(size=(140, 40)) as pilot:
        await pilot.press("q")
        await app.workers.wait_for_complete()
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, StudyScreen)
        assert screen.result is not None
        assert screen.query_one("#study-table", DataTable).row_count == 2
        assert "Pareto front" in str(screen.query_one("#study-verdict", Static).render())
        await pilot.press("escape")
        assert not isinstance(app.screen, StudyScreen)
        # opened again, the screen shows the study it kept, without measuring again
        again = StudyScreen(None, runs=1)
        app.push_screen(again)
        await pilot.pause()
        assert again.result is not None and not list(again.workers)
        assert again.query_one("#study-table", DataTable).row_count == 2
        assert "last study" in str(again.query_one("#study-status StatusText", Static).render())


def test_a_study_json_reads_back_to_the_same_table_and_verdict(tmp_path):
    result = _result()
    paths = result.write(tmp_path)
    again = StudyResult.from_dict(json.loads(paths["json"].read_text()))
    assert again.to_csv() == result.to_csv()
    assert again.verdict() == result.verdict()


def test_an_exact_settings_warm_up_traces_the_whole_scan(monkeypatch):
    """A warm-up on a slice of the rays missed what a whole scan compiles (object order):
    on a cold cache the first timed call of numba exact m=2 took 30 s against 6 ms after,
    and the study's verdict was wrong."""
    import ladartui.study.run as study_run
    from ladartui.study import run_study

    pytest.importorskip("numba")
    traced = []
    real = study_run._trace

    def counting(scene, origins, directions, setting, cancel):
        traced.append((setting.method, len(origins)))
        return real(scene, origins, directions, setting, cancel)

    monkeypatch.setattr(study_run, "WARMUP_RAYS", 10)
    monkeypatch.setattr(study_run, "_trace", counting)
    settings = [Setting("numba", "exact", "f64", None, 1), Setting("numba", "march", "f64", 1.0, 1)]
    run_study(_tiny_inputs(), settings, runs=1, warmup=1)
    scan = 12 * 12
    assert traced[0] == ("exact", scan) and traced[1] == ("exact", scan)  # warm-up, then timed
    march = [count for method, count in traced if method == "march"]
    assert march[0] == 10 and set(march[1:]) == {scan}  # a march's warm-up stays short


def test_cli_refuses_a_file_for_out_before_it_studies_and_shows_file_text_escaped(tmp_path, capsys):
    """--out naming a file ended in a FileExistsError traceback after the whole study; a
    reason read from --chart-from reached the terminal raw (ESC [2J cleared the screen)."""
    from ladartui.cli import main

    source = Path(__file__).parent.parent / "docs" / "study.json"
    taken = tmp_path / "o.toml"
    taken.write_text("x = 1\n")
    assert main(["study", "--chart-from", str(source), "--out", str(taken)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"ladartui: error: {taken}: is a file, expected a folder"
    data = json.loads(source.read_text())
    data["rows"][1]["status"], data["rows"][1]["reason"] = "skipped", "no gpu\x1b[2J [b]here[/b]"
    tampered = tmp_path / "e.json"
    tampered.write_text(json.dumps(data))
    assert main(["study", "--chart-from", str(tampered), "--out", str(tmp_path / "rp")]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "no gpu\\x1b[2J [b]here[/b]" in out.replace("\n", "")


def test_every_text_of_a_study_file_reaches_the_terminal_escaped(tmp_path, capsys):
    """The reference label went into the table's title raw: ESC [31m coloured the terminal."""
    from ladartui.cli import main

    data = json.loads((Path(__file__).parent.parent / "docs" / "study.json").read_text())
    data["reference"]["label"] = "\x1b[31mX [b]y[/b]"
    tampered = tmp_path / "label.json"
    tampered.write_text(json.dumps(data))
    assert main(["study", "--chart-from", str(tampered), "--out", str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "[b]y[/b]" in out


@pytest.mark.parametrize(
    ("value", "said"),
    [(math.nan, "NaN"), (math.inf, "Infinity"), (-0.5, "a time of -0.5 s")],
)
def test_a_study_file_with_a_time_no_study_writes_is_refused_in_one_line(tmp_path, capsys, value, said):
    """NaN seconds (json.dump writes them by default) crashed the chart with a
    ValueError traceback; a negative time was drawn on the log axis."""
    from ladartui.cli import main

    data = json.loads((Path(__file__).parent.parent / "docs" / "study.json").read_text())
    data["rows"][0]["seconds"][0] = value
    tampered = tmp_path / "t.json"
    tampered.write_text(json.dumps(data))
    assert main(["study", "--chart-from", str(tampered), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"ladartui: error: {tampered}") and said in err and "\n" not in err
    assert "expected a study.json written by 'ladartui study'" in err and not (tmp_path / "o").exists()


def test_a_study_is_written_as_one_set(tmp_path, monkeypatch):
    """study.csv and study.json were replaced before the charts were drawn: a Ctrl-C or a
    failure then left this study's tables beside the last one's charts."""
    from ladartui.study.results import read_study
    from ladartui.study.run import write_outputs

    result = read_study(Path(__file__).parent.parent / "docs" / "study.json")
    paths = write_outputs(result, tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in paths.values())
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    from ladartui.study import figure

    def broken(result):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(figure, "speed_accuracy_figure", broken)
    changed = dataclasses.replace(result, reference_label="another")
    with pytest.raises(OSError):
        write_outputs(changed, tmp_path)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    # a failure while the set is written (the PNG's temporary): nothing replaced either
    monkeypatch.undo()
    real = Path.write_bytes

    def full_at_the_png(self, data):
        if ".png." in self.name:
            raise OSError(28, "No space left on device")
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", full_at_the_png)
    from ladartui.errors import OutputFileError

    with pytest.raises(OutputFileError, match="nothing was replaced"):
        write_outputs(changed, tmp_path)
    monkeypatch.undo()
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_chart_from_refuses_the_flags_of_a_new_study(tmp_path, capsys):
    """'--runs 3 --chart-from J' redrew J, the runs ignored without a word."""
    from ladartui.cli import main

    source = str(Path(__file__).parent.parent / "docs" / "study.json")
    assert (
        main(["study", "--chart-from", source, "--runs", "3", "--quick", "--out", str(tmp_path / "o")]) == 2
    )
    err = capsys.readouterr().err.strip()
    assert err == (
        "ladartui: error: --chart-from redraws a study already run: --quick, --runs would shape a new one; "
        "drop them"
    )
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("warmup", ["1", "0", "3"])
def test_chart_from_refuses_warmup_even_at_its_default_value(tmp_path, capsys, warmup):
    """'--warmup 1 --chart-from J' slipped through: 1 was taken for 'not given'."""
    from ladartui.cli import main

    source = str(Path(__file__).parent.parent / "docs" / "study.json")
    assert main(["study", "--chart-from", source, "--warmup", warmup, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        "ladartui: error: --chart-from redraws a study already run: --warmup would shape a new one; drop it"
    )
    assert not (tmp_path / "o").exists()


def test_the_progress_log_ends_at_its_total(tmp_path, monkeypatch, capsys):
    """A log of 'study --quick' went 1, 4, 7 ... 40 and ended '[40/48 traces]': the
    last line was the last setting's start, never the end."""
    import re

    import ladartui.study as study_package
    from ladartui.cli import main
    from ladartui.study import inputs as study_inputs

    pytest.importorskip("numba")
    monkeypatch.setattr(study_inputs, "generated_inputs", lambda *a, **k: _tiny_inputs(1.0))
    settings = [Setting("numba", "exact", "f64", None, 1), Setting("numba", "march", "f64", 1.0, 1)]
    monkeypatch.setattr(study_package, "quick_settings", lambda: settings)
    assert main(["study", "--quick", "--runs", "3", "--out", str(tmp_path)]) == 0
    counts = re.findall(r"^\[(\d+)/(\d+) traces\]", capsys.readouterr().err, re.MULTILINE)
    # 2 settings x (2 scans + 1 warm-up + 1 repeat of the first scan)
    assert counts[-1] == ("8", "8")
    done = [int(d) for d, _ in counts]
    assert done == sorted(done) and len(set(done)) == len(done)


def test_a_failed_setting_counts_its_later_scans_as_done(monkeypatch):
    """A setting that failed on its first scan left its later scans out of the count:
    the counter fell behind and leapt to its total at the end."""
    import ladartui.study.run as study_run
    from ladartui.study import run_study

    pytest.importorskip("numba")
    real = study_run._trace

    def failing(scene, origins, directions, setting, cancel):
        if setting.method == "march":
            raise RuntimeError("out of device memory")
        return real(scene, origins, directions, setting, cancel)

    monkeypatch.setattr(study_run, "_trace", failing)
    settings = [Setting("numba", "exact", "f64", None, 1), Setting("numba", "march", "f64", 1.0, 1)]
    seen: list = []
    result = run_study(_tiny_inputs(), settings, runs=1, warmup=0, progress=seen.append)
    assert {row.label: row.status for row in result.rows}["numba march 1 f64 m=1"] == "failed"
    # 2 settings x 2 scans; the last call traced is the reference's second scan
    assert [(p.done, p.label) for p in seen] == [
        (0, "numba exact f64 m=1"),
        (1, "numba march 1 f64 m=1"),
        (3, "numba exact f64 m=1"),
        (4, "scoring"),
    ]
    assert seen[-1].total == 4
