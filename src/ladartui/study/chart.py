"""The speed-against-accuracy chart, drawn with plotext, as text and as SVG.

``draw_chart`` draws on any plotext-like object (the ``plotext`` module or a
terminal widget's plot), so the command line, the SVG file and the terminal UI
show the same chart. x: seconds per scan (log scale, left is faster); y: the
obscured coverage error against the converged reference, in percentage
points (absolute, lower is better). Pareto-front settings are drawn again
with a large marker and labelled.
"""

from __future__ import annotations

import io
import math
import threading

from ladartui.study.chart_layout import log_seconds
from ladartui.study.results import OK, StudyResult, format_points, format_seconds, format_share

# Series by tracer family, each with its own colour: fixed xterm-256 colours, not the
# 16 named ones, which a terminal's (or Textual's) theme may draw alike (red and
# magenta both came out pink).
FAMILIES = (
    ("numba exact f64", 40),  # green
    ("wgpu exact f64", 44),  # cyan
    ("wgpu exact f32", 33),  # blue
    ("numba march", 160),  # red
    ("wgpu march", 165),  # violet
)
FRONT_MARKER = "*"
POINT_MARKER = "o"
FRONT_COLOR = 214  # orange
HEADROOM = 1.08  # above the highest point: its label may sit a row above it
TITLE = "Speed against accuracy (* = Pareto front)"
X_LABEL = "seconds per scan (log)"
Y_LABEL = "|coverage error| (pts)"

# The plotext module keeps one global figure: serialise its users.
_PLOTEXT_LOCK = threading.RLock()


def family(setting) -> str:
    if setting.method == "march":
        return f"{setting.backend} march"
    return f"{setting.backend} exact {setting.precision}"


def short_label(setting) -> str:
    """A compact point label, e.g. ``nb ex m4`` or ``wg .25 m8``."""
    backend = {"numba": "nb", "wgpu": "wg"}.get(setting.backend, setting.backend[:2])
    if setting.method == "march":
        what = f"{setting.step:g}".lstrip("0") or "0"
    else:
        what = "ex" + ("32" if setting.precision == "f32" else "")
    return f"{backend} {what} m{setting.ray_grid}"


def chart_points(result: StudyResult):
    """(x seconds, y points, row) for every measured row with both figures."""
    points = []
    for row in result.rows:
        if row.status != OK or row.seconds_per_scan is None or row.coverage_error is None:
            continue
        points.append((row.seconds_per_scan, abs(row.coverage_error) * 100.0, row))
    return points


def chart_limits(points) -> tuple[tuple[float, float], tuple[float, float]]:
    """(log10 seconds at the left and right edges, error points at the bottom and top)."""
    xs = [log_seconds(x) for x, _, _ in points]
    lo, hi = (min(xs), max(xs)) if xs else (0.0, 1.0)
    if hi - lo < 1e-6:
        lo, hi = lo - 0.5, hi + 0.5
    top = max((y for _, y, _ in points), default=0.0)
    return (lo, hi), (0.0, top * HEADROOM if top > 0 else 1.0)


def draw_chart(plt, result: StudyResult, title: str = TITLE, labels=None) -> None:
    """Draw the chart on ``plt`` (plotext or a plotext figure); size and theme are the caller's.

    ``labels``: (text, x, y) of the front's labels as ``label_places`` placed them for
    the chart's size; None draws none. The legend is not drawn here but beside the
    chart (``legend_text``), where it covers no point.
    """
    plt.clear_data()
    points = chart_points(result)
    plt.title(title)
    plt.xlabel(X_LABEL)
    plt.ylabel(Y_LABEL)
    if not points:
        plt.text("no measured settings", 0.5, 0.5)
        return
    # x in log10 seconds on a linear axis, not plotext's log scale: that takes the log
    # of the data it holds in place, so a second drawing (a resize) took log10 twice
    for name, color in FAMILIES:
        xs = [log_seconds(x) for x, _, row in points if family(row.setting) == name]
        ys = [y for _, y, row in points if family(row.setting) == name]
        if xs:
            plt.scatter(xs, ys, marker=POINT_MARKER, color=color)
    front = sorted((p for p in points if p[2].front), key=lambda p: p[0])
    if front:
        plt.scatter(
            [log_seconds(p[0]) for p in front], [p[1] for p in front], marker=FRONT_MARKER, color=FRONT_COLOR
        )
    for text, x, y in labels or []:
        plt.text(text, log_seconds(x), y, color=FRONT_COLOR, alignment="left")
    x_range, y_range = chart_limits(points)
    plt.xlim(*x_range)
    plt.ylim(*y_range)
    plt.xticks(*seconds_ticks(*x_range))


def seconds_ticks(lo: float, hi: float) -> tuple[list[float], list[str]]:
    """Ticks between log10 seconds ``lo`` and ``hi``: each power of ten ("1 ms",
    "10 ms"), with 2 and 5 times it where fewer than three powers fall in the range."""
    steps = (1.0,) if math.floor(hi) - math.ceil(lo) >= 2 else (1.0, 2.0, 5.0)
    where = [
        math.log10(step) + power
        for power in range(math.floor(lo), math.ceil(hi) + 1)
        for step in steps
        if lo - 1e-9 <= math.log10(step) + power <= hi + 1e-9
    ]
    if len(where) < 2:  # within a factor of about two: no round time falls in it
        where = [lo + (hi - lo) * k / 3 for k in range(4)]
    return where, [_tick_label(10**x) for x in where]


def _tick_label(seconds: float) -> str:
    for scale, unit in ((1.0, "s"), (1e-3, "ms"), (1e-6, "us")):
        if seconds >= scale * 0.999:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds * 1e9:.3g} ns"


def label_places(result: StudyResult, width: int, height: int) -> list[tuple[str, float, float]]:
    """Places for the front's labels on a width x height chart where none touches another
    label or a marker (see ``chart_layout``); labels with no room are left out."""
    import plotext

    from ladartui.study.chart_layout import PlotArea, frame_size, place_labels

    points = chart_points(result)
    if not points or width < 20 or height < 8:
        return []
    with _PLOTEXT_LOCK:
        plotext.clear_figure()
        plotext.limit_size(False, False)
        plotext.plotsize(width, height)
        plotext.theme("clear")
        draw_chart(plotext, result)
        text = plotext.uncolorize(plotext.build())
        plotext.clear_figure()
    size = frame_size(text)
    if size is None or size[0] < 2 or size[1] < 2:
        return []
    area = PlotArea(size[0], size[1], *chart_limits(points))
    front = sorted((p for p in points if p[2].front), key=lambda p: p[0])
    return place_labels(
        area,
        [(x, y) for x, y, _ in points],
        [(short_label(row.setting), x, y) for x, y, row in front],
    )


def legend_entries(result: StudyResult) -> list[tuple[str, str, int]]:
    """(marker, name, plotext colour) of each series drawn, then the front."""
    names = {family(row.setting) for _, _, row in chart_points(result)}
    entries = [(POINT_MARKER, name, color) for name, color in FAMILIES if name in names]
    if any(row.front for _, _, row in chart_points(result)):
        entries.append(
            (
                FRONT_MARKER,
                "Pareto front (labels: backend, ex = exact or march step, m = ray grid)",
                FRONT_COLOR,
            )
        )
    return entries


def legend_text(result: StudyResult, width: int = 100, color: bool = True) -> str:
    """The legend as lines of at most ``width`` characters (ANSI colours unless not ``color``)."""
    import plotext

    lines: list[str] = []
    line, length = "", 0
    for marker, name, colour in legend_entries(result):
        entry = f"{marker} {name}"
        if length and length + 2 + len(entry) > width:
            lines.append(line)
            line, length = "", 0
        shown = plotext.colorize(entry, colour) if color else entry
        line, length = (line + "  " + shown, length + 2 + len(entry)) if length else (shown, len(entry))
    if line:
        lines.append(line)
    return "\n".join(lines)


def chart_text(result: StudyResult, width: int = 100, height: int = 30, color: bool = True) -> str:
    """The chart as terminal text, its legend below it (ANSI colours unless ``color`` is False)."""
    import plotext

    legend = legend_text(result, width, color)
    chart_height = max(8, height - (legend.count("\n") + 1 if legend else 0))
    labels = label_places(result, width, chart_height)
    with _PLOTEXT_LOCK:
        plotext.clear_figure()
        plotext.limit_size(False, False)  # the size asked for, not the terminal's
        plotext.plotsize(width, chart_height)
        plotext.theme("pro" if color else "clear")
        draw_chart(plotext, result, labels=labels)
        text = plotext.build()
        plotext.clear_figure()
    text = text if color else plotext.uncolorize(text)
    return text.rstrip("\n") + ("\n" + legend if legend else "")


def chart_svg(
    result: StudyResult,
    width: int = 100,
    height: int = 30,
    title: str = "ladartui study: speed against accuracy",
) -> str:
    """The chart as an SVG document: the coloured terminal text recorded by rich."""
    from rich.console import Console
    from rich.text import Text

    console = Console(
        record=True,
        width=width,
        file=io.StringIO(),
        color_system="256",
        force_terminal=True,
        legacy_windows=False,
    )
    console.print(Text.from_ansi(chart_text(result, width, height)), soft_wrap=True)
    return console.export_svg(title=title)


TABLE_COLUMNS = ("setting", "s/scan", "rays/s", "differ", "cov. error", "front", "note")


def table_rows(result: StudyResult) -> list[tuple[str, ...]]:
    """Rows of text for a table of all settings (same columns as ``TABLE_COLUMNS``)."""
    from ladartui.study.results import format_rate

    out: list[tuple[str, ...]] = []
    for row in result.rows:
        if row.status != OK:
            out.append((row.label, "-", "-", "-", "-", "", f"{row.status}: {row.reason}"))
            continue
        note = f"beaten by {row.dominated_by}" if row.dominated_by else ""
        out.append(
            (
                row.label,
                format_seconds(row.seconds_per_scan),
                format_rate(row.rays_per_second),
                format_share(row.hit_differs),
                format_points(row.coverage_error),
                "*" if row.front else "",
                note,
            )
        )
    return out
