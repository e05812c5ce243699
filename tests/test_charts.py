"""Chart files drawn with matplotlib: valid SVG and PNG, the series and the Pareto front's order."""

from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from ladartui.charts import new_figure, save_figure
from ladartui.cli import main

ROOT = Path(__file__).resolve().parents[1]
SVG = "{http://www.w3.org/2000/svg}"


def _groups(svg_path: Path, prefix: str) -> list[ET.Element]:
    tree = ET.parse(svg_path)  # raises on a malformed file
    assert tree.getroot().tag == f"{SVG}svg"
    return [g for g in tree.iter(f"{SVG}g") if g.get("id", "").startswith(prefix)]


def _line_vertices(group: ET.Element) -> list[tuple[float, float]]:
    path = next(group.iter(f"{SVG}path"))
    numbers = [float(n) for n in re.findall(r"-?\d+(?:\.\d+)?", path.get("d", ""))]
    return list(zip(numbers[0::2], numbers[1::2]))


def test_study_chart_from_json_writes_svg_and_png_with_every_series_and_the_front_in_order(tmp_path):
    source = ROOT / "docs" / "study.json"
    assert main(["study", "--chart-from", str(source), "--out", str(tmp_path)]) == 0
    rows = json.loads(source.read_text())["rows"]
    measured = [
        r
        for r in rows
        if r["status"] == "ok"
        and r.get("seconds_per_scan") is not None
        and r.get("coverage_error") is not None
    ]
    families = {
        (r["backend"], r["method"], r["precision"] if r["method"] != "march" else "") for r in measured
    }

    svg = tmp_path / "speed-accuracy.svg"
    assert len(_groups(svg, "series-")) == len(families) == 5
    (front,) = _groups(svg, "pareto-front")
    vertices = _line_vertices(front)
    front_rows = sorted((r for r in measured if r["front"]), key=lambda r: r["seconds_per_scan"])
    assert len(vertices) == len(front_rows) >= 2
    xs = [x for x, _ in vertices]
    assert xs == sorted(xs)  # the line runs fastest to slowest, the front's order
    # faster settings on the front are less accurate: the line falls (SVG y grows downwards)
    errors = [abs(r["coverage_error"]) for r in front_rows]
    ys = [y for _, y in vertices]
    assert [a < b for a, b in zip(errors, errors[1:])] == [a > b for a, b in zip(ys, ys[1:])]

    with Image.open(tmp_path / "speed-accuracy.png") as image:
        assert image.format == "PNG" and image.size == (900, 560)


def test_save_figure_writes_the_pixel_size_asked_and_refuses_unknown_formats(tmp_path):
    figure = new_figure(400, 300)
    figure.add_subplot().plot([0, 1], [1, 0])
    with Image.open(save_figure(figure, tmp_path / "a.png")) as image:
        assert image.size == (400, 300)
    root = ET.parse(save_figure(figure, tmp_path / "a.svg")).getroot()
    assert root.get("width") == "288pt" and root.get("height") == "216pt"  # 4 x 3 inches
    try:
        save_figure(figure, tmp_path / "a.gif")
    except ValueError as error:
        assert "gif" in str(error)
    else:
        raise AssertionError("a .gif chart was accepted")
    assert not (tmp_path / "a.gif").exists()


@pytest.fixture
def three_scan_scenario(tmp_path):
    from ladartui.flight import FlightPlan, Manual, ScanPose, aim_at
    from ladartui.scenario import Scenario
    from ladartui.scene.voxels import save_voxels
    from ladartui.sensor import Sensor

    target = np.array(
        [(x, y, z) for x in range(8, 12) for y in range(8, 11) for z in range(2)], dtype=np.int32
    )
    canopy = np.array(
        [(x, y, 6) for x in range(6, 14) for y in range(6, 13) if (x + 2 * y) % 3], dtype=np.int32
    )
    save_voxels(tmp_path / "woods.txt", np.vstack([target, canopy]))
    save_voxels(tmp_path / "woods_Target.txt", target)
    spots = [(9.5, -10.0), (29.5, 9.0), (9.5, 29.0)]
    poses = tuple(aim_at(ScanPose(x, y, 40.0), (9.5, 9.0, 0.5)) for x, y in spots)
    return Scenario(
        tmp_path / "S.toml",
        "woods.txt",
        1.0,
        Sensor(grid=16, ray_grid=2, fov=20.0),
        FlightPlan(segments=[Manual(poses)]),
        backend="numba",
    ).save()


def test_run_chart_plots_coverage_after_each_scan_with_the_90_percent_point(
    three_scan_scenario, tmp_path, capsys
):
    svg, png = tmp_path / "cov.svg", tmp_path / "cov.png"
    assert main(["run", str(three_scan_scenario.path), "--no-write", "--json", "--chart", str(svg)]) == 0
    measures = json.loads(capsys.readouterr().out)["measures"]
    assert main(["run", str(three_scan_scenario.path), "--no-write", "--chart", str(png)]) == 0
    assert f"wrote chart: {png}" in capsys.readouterr().out

    series = _groups(svg, "series-")
    assert sorted(g.get("id") for g in series) == ["series-obscured", "series-unobscured"]
    for group in series:  # one vertex per scan
        assert len(_line_vertices(group)) == 3
    (enough,) = _groups(svg, "enough-point")
    k = measures["scans_for_enough"]
    assert k in (1, 2, 3)
    (obscured,) = [g for g in series if g.get("id") == "series-obscured"]
    marker = next(enough.iter(f"{SVG}use"))
    assert _line_vertices(obscured)[k - 1] == pytest.approx(
        (float(marker.get("x")), float(marker.get("y"))), abs=0.01
    )
    with Image.open(png) as image:
        assert image.size == (800, 480)


def test_a_run_that_never_saw_the_target_charts_it_on_a_0_to_100_percent_axis_and_says_so():
    """A run whose scans missed the target drew its flat lines on an axis from 0.00 to
    0.05 %, ticks of hundredths of a per cent that no run measured, with no word."""
    from ladartui.charts.coverage import coverage_figure
    from ladartui.measures import Measures

    never = Measures(target_voxels=2, obscured_after_scan=(0.0,) * 12, unobscured_after_scan=(0.0,) * 12)
    figure = coverage_figure(never)
    (axes,) = figure.axes
    assert axes.get_ylim() == (0.0, 100.0)
    assert [t.get_text() for t in axes.texts] == ["the target was not seen in any scan"]
    # a run that saw a little keeps an axis fitted to what it saw
    little = Measures(
        target_voxels=200, obscured_after_scan=(0.005, 0.01), unobscured_after_scan=(0.01, 0.02)
    )
    (axes,) = coverage_figure(little).axes
    assert axes.get_ylim()[0] == 0.0 and 2.0 <= axes.get_ylim()[1] < 3.0 and not axes.texts


def test_each_targets_line_has_a_colour_no_series_or_level_line_has():
    """With three targets, 'obscured: 1 netted truck' was drawn dotted in tab:purple, as
    the recognise line is: the legend could not tell them apart (the fourth target took
    detect's grey, the seventh identify's red)."""
    from matplotlib.colors import to_hex

    from ladartui.charts.coverage import coverage_figure
    from ladartui.levels import levels_from_curves
    from ladartui.measures import Measures
    from ladartui.target_measures import PerTarget, TargetMeasures

    curve = (0.2, 0.4, 0.6, 0.7)
    levels = levels_from_curves(curve, (0.2, 0.8, 0.9, 0.9), (0.0, 1.0, 2.0, 3.0), (0.0, 30.0, 60.0, 90.0))
    each = Measures(obscured_after_scan=curve)
    targets = PerTarget(tuple(TargetMeasures(i, f"truck {i}", each) for i in range(1, 9)))
    measures = Measures(
        obscured_after_scan=curve,
        unobscured_after_scan=curve,
        scans_for_enough=3,
        levels=levels,
        targets=targets,
    )
    (axes,) = coverage_figure(measures).axes
    colours = {line.get_gid() or "": to_hex(line.get_color()) for line in axes.lines}
    assert {"level-detect", "level-recognise", "level-identify", "enough-point"} <= set(colours)
    others = {c for gid, c in colours.items() if not gid.startswith("target-")}
    target_colours = [colours[f"target-{i}"] for i in range(1, 9)]
    assert not set(target_colours) & others
    assert len(set(target_colours[:7])) == 7  # seven targets, seven colours


def test_run_chart_refuses_another_suffix_before_tracing(three_scan_scenario, tmp_path, capsys):
    assert main(["run", str(three_scan_scenario.path), "--chart", str(tmp_path / "c.pdf")]) == 2
    err = capsys.readouterr().err
    assert "--chart" in err and "ending in .svg or .png" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "S_Scene.txt").exists()


def test_sweep_writes_the_pareto_chart_with_the_front_cheapest_first_and_the_best_marked(tmp_path, capsys):
    from tiny_sweep import write_tiny_scenario

    write_tiny_scenario(tmp_path)
    spec = tmp_path / "spec.toml"
    spec.write_text(
        '[sweep]\nscenario = "base.toml"\n[grid]\nradius = [10.0, 20.0, 30.0]\nscans = [2, 4]\n',
        encoding="utf-8",
    )
    out = tmp_path / "out"
    assert main(["sweep", str(spec), "--serial", "--out", str(out), "--json", "--top", "6"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["charts"] == {"svg": str(out / "pareto.svg"), "png": str(out / "pareto.png")}
    from ladartui.sweep.execute import CHART_NAMES  # checked before a sweep runs

    assert sorted(Path(path).name for path in report["charts"].values()) == sorted(CHART_NAMES)

    svg = out / "pareto.svg"
    (variants,) = _groups(svg, "series-variants")
    assert len(list(variants.iter(f"{SVG}use"))) == report["variants"] == 6
    (front,) = _groups(svg, "pareto-front")
    vertices = _line_vertices(front)
    assert len(vertices) == len(report["pareto"]) >= 1
    costs = [entry["cost"] for entry in report["pareto"]]
    assert costs == sorted(costs)  # the report's front, cheapest first ...
    xs = [x for x, _ in vertices]
    assert xs == sorted(xs)  # ... drawn in that order
    (best,) = _groups(svg, "best")
    marker = next(best.iter(f"{SVG}use"))
    top = report["top"][0]
    assert top["pareto"]  # the best by coverage is on the front: its marker sits on a vertex
    index = [entry["variant"] for entry in report["pareto"]].index(top["variant"])
    assert vertices[index] == pytest.approx((float(marker.get("x")), float(marker.get("y"))), abs=0.01)
    with Image.open(out / "pareto.png") as image:
        assert image.size == (800, 480)


def test_a_sweep_chart_never_shows_a_negative_coverage():
    """A sweep whose variants all saw nothing charted them on an axis from -0.05 % to
    0.05 %; one with a variant at 0 % ran below 0."""
    from ladartui.charts.sweep import sweep_figure
    from ladartui.sweep.execute import SweepResult
    from ladartui.sweep.ranking import Ranked

    def chart(coverages):
        rows = [{"variant": f"v{i}"} for i in range(len(coverages))]
        ranking = [
            Ranked(r, c, i + 1, i == 0, 100.0 + 10 * i, c) for i, (r, c) in enumerate(zip(rows, coverages))
        ]
        (axes,) = sweep_figure(
            SweepResult(rows, ranking, "coverage", "distance", None, [], Path("r.csv"))
        ).axes
        return axes

    axes = chart([0.0] * 5)
    assert axes.get_ylim() == (0.0, 100.0)
    assert [t.get_text() for t in axes.texts] == ["no variant saw the target"]
    axes = chart([0.0, 0.02, 0.05])
    assert axes.get_ylim()[0] == 0.0 and 5.0 <= axes.get_ylim()[1] < 6.0 and not axes.texts
    axes = chart([0.3, 0.4])  # far from 0: fitted to the variants, as before
    assert 29.0 < axes.get_ylim()[0] < 30.0


def test_study_chart_from_prints_an_output_folder_with_markup_as_it_is(tmp_path, capsys):
    out = tmp_path / "a[" / "bold]st"  # the path holds "[/bold]": a closing tag to rich
    assert main(["study", "--chart-from", str(ROOT / "docs" / "study.json"), "--out", str(out)]) == 0
    assert str(out) in capsys.readouterr().out.replace("\n", "")
