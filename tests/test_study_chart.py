"""The study's terminal chart: labels that never touch one another or a marker, and a
legend outside the plot, measured on plotext's own output."""

from __future__ import annotations

import math
import random

import pytest

from ladartui.study.chart import chart_points, chart_text, family, label_places, short_label
from ladartui.study.chart_layout import PlotArea, frame_size, place_labels
from ladartui.study.misses import MissSummary
from ladartui.study.results import StudyResult, StudyRow
from ladartui.study.settings import full_settings


def crowded_result(seed: int = 1) -> StudyResult:
    """Every setting of the full study, timed and scored as a real study spreads them:
    a dozen front points, several within a cell or two of each other."""
    rng = random.Random(seed)
    rows = []
    for setting in full_settings():
        row = StudyRow(setting, rays_per_scan=1000 * setting.ray_grid**2, scans=2)
        seconds = (0.02 if setting.backend == "numba" else 0.05) * setting.ray_grid**2
        if setting.method == "march":
            seconds *= 0.4 / setting.step
        if setting.precision == "f32":
            seconds *= 0.7
        for _ in range(3):
            row.timing.add(seconds * rng.uniform(0.95, 1.05))
        error = 0.04 / setting.ray_grid + (0.01 * setting.step if setting.method == "march" else 0.0)
        row.coverage = 0.5 + error * rng.uniform(0.8, 1.2)
        row.misses = MissSummary(rays=1000, voxel_rays=800, differing=10)
        rows.append(row)
    result = StudyResult(rows, reference_label=rows[-1].setting.label, reference_coverage=0.5)
    result.finish()
    return result


def _plot_rows(text: str) -> list[str]:
    lines = text.splitlines()
    top = next(i for i, line in enumerate(lines) if "┌" in line)
    bottom = next(i for i, line in enumerate(lines) if "└" in line)
    return [
        line[line.index("┤" if "┤" in line else "│") + 1 : line.rindex("│")]
        for line in lines[top + 1 : bottom]
    ]


@pytest.mark.parametrize("size", [(100, 30), (80, 24), (70, 22), (60, 18)])
def test_every_drawn_label_stands_clear_of_other_labels_and_markers(size):
    result = crowded_result()
    width, height = size
    text = chart_text(result, width, height, color=False)
    legend_lines = text.count("\n") - text[: text.index("└")].count("\n") - 2
    labels = label_places(result, width, height - legend_lines)
    front = [row for row in result.rows if row.front]
    assert len(front) >= 10
    assert len(labels) >= min(len(front), 6)  # most of the front is named even at 60 x 18
    rows = _plot_rows(text)
    for label, _, _ in labels:
        # each label once, whole, with a blank (or the frame) on both sides
        hits = [(r, line.index(label)) for r, line in enumerate(rows) if label in line]
        assert len(hits) == 1, (label, hits)
        r, start = hits[0]
        line = rows[r]
        before = line[start - 1] if start > 0 else " "
        after = line[start + len(label)] if start + len(label) < len(line) else " "
        assert before == " " and after == " ", (label, line)
    # no label was drawn but the placed ones: the words left in the plot are theirs
    words = " ".join(rows).split()
    names = {part for label, _, _ in labels for part in label.split()}
    assert {w for w in words if not set(w) <= {"o", "*"}} <= names


def test_the_legend_sits_below_the_plot_and_covers_no_point():
    result = crowded_result()
    text = chart_text(result, 80, 24, color=False)
    plot = "\n".join(_plot_rows(text))
    below = text[text.index("└") :]
    for name in ("numba exact f64", "wgpu exact f32", "numba march", "wgpu march", "Pareto front"):
        assert name in below and name not in plot
    # every point shows: one marker per distinct cell (points can share one)
    points = chart_points(result)
    markers = sum(line.count("o") + line.count("*") for line in _plot_rows(text))
    assert markers >= len({(round(x, 2), round(y, 1)) for x, y, _ in points}) * 0.6


def test_labels_are_dropped_rather_than_drawn_over_each_other():
    area = PlotArea(30, 5, (0.0, 1.0), (0.0, 4.0))
    # three points in neighbouring cells of one row: not all labels can fit
    markers = [(10 ** (c / 29), 2.0) for c in (10, 11, 12)]
    labels = [("abcdef", x, y) for x, y in markers]
    placed = place_labels(area, markers, labels)
    spans = set()
    for text, x, y in placed:
        start, row = round(area.column(x)), round(area.row(y))
        cells = {(c, row) for c in range(start - 1, start + len(text) + 1)}
        assert not cells & {(round(area.column(mx)), round(area.row(my))) for mx, my in markers}
        assert not {(c, row) for c in range(start, start + len(text))} & spans
        spans |= cells
    assert 1 <= len(placed) <= 3


def test_frame_size_reads_plotexts_frame():
    text = chart_text(crowded_result(), 60, 20, color=False)
    columns, rows = frame_size(text)
    assert rows == len(_plot_rows(text)) and columns == len(_plot_rows(text)[0])
    assert short_label(crowded_result().rows[0].setting) == "nb ex m1"


def test_each_series_has_its_own_colour_in_the_chart_and_its_legend():
    import re

    result = crowded_result()
    text = chart_text(result, 100, 30, color=True)
    plot, legend = text[: text.index("└")], text[text.index("└") :]
    # the colour each legend entry is drawn in, and the colours the plot's markers use
    entries = dict(re.findall(r"\x1b\[38;5;(\d+)m[o*] ([a-zA-Z0-9 ]+?)(?:\x1b|\s\()", legend))
    assert len(entries) == 6 and len(set(entries.values())) == 6
    marker_colours = set(re.findall(r"\x1b\[38;5;(\d+)m[^\x1b]*[o*]", plot))
    # every series with points off the front shows its own colour (front points are drawn as *)
    off_front = {family(row.setting) for row in result.rows if not row.front}
    assert {colour for colour, name in entries.items() if name in off_front} <= marker_colours
    assert len(off_front) >= 4


def test_the_time_axis_is_ticked_at_round_seconds():
    from ladartui.study.chart import seconds_ticks

    where, labels = seconds_ticks(-2.2, 1.3)  # 6.3 ms to 20 s: whole powers of ten
    assert labels == ["10 ms", "100 ms", "1 s", "10 s"]
    assert where == pytest.approx([-2.0, -1.0, 0.0, 1.0])
    where, labels = seconds_ticks(-2.2, -1.1)  # under two powers: 2 and 5 times them too
    assert labels == ["10 ms", "20 ms", "50 ms"]
    assert where == pytest.approx([-2.0, math.log10(0.02), math.log10(0.05)])
    assert seconds_ticks(-6.1, -5.5)[1] == ["1 us", "2 us"]


def test_a_narrow_time_range_still_has_ticks_and_a_zero_time_draws():
    """12 to 18 ms holds no 1, 2 or 5 times a power of ten: the axis had no numbers."""
    from ladartui.study.chart import _tick_label, draw_chart, seconds_ticks

    lo, hi = math.log10(0.012), math.log10(0.018)
    where, labels = seconds_ticks(lo, hi)
    assert len(where) >= 3 and lo <= min(where) and max(where) <= hi
    assert labels == [_tick_label(10**x) for x in where] and labels[0] == "12 ms"

    class Recorder:  # a plotext-like object that keeps what is drawn
        def __getattr__(self, name):
            return lambda *args, **kwargs: None

    result = crowded_result()
    fastest = result.rows[0]
    fastest.timing = type(fastest.timing)()
    for _ in range(3):
        fastest.timing.add(0.0)  # a clock too coarse for it
    assert fastest.seconds_per_scan == 0.0
    draw_chart(Recorder(), result)  # log10 of 0 s raised 'math domain error'
    assert chart_text(result, 100, 30, color=False)  # the labels placed too
