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
import threading

from ladartui.study.results import OK, StudyResult, format_points, format_seconds, format_share

# Series by tracer family, each with its own colour (plotext colour names).
FAMILIES = (
    ("numba exact f64", "green"),
    ("wgpu exact f64", "cyan"),
    ("wgpu exact f32", "blue"),
    ("numba march", "red"),
    ("wgpu march", "magenta"),
)
FRONT_MARKER = "*"
POINT_MARKER = "o"
FRONT_COLOR = "orange"
LEGEND_HEADROOM = 1.5
TITLE = "Speed against accuracy (* = Pareto front)"
X_LABEL = "seconds per scan (log)"
Y_LABEL = "|coverage error| (pts)"

# The plotext module keeps one global figure: serialise its users.
_PLOTEXT_LOCK = threading.Lock()


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


def draw_chart(plt, result: StudyResult, title: str = TITLE, labels: bool = True) -> None:
    """Draw the chart on ``plt`` (plotext or a plotext figure); size and theme are the caller's."""
    plt.clear_data()
    points = chart_points(result)
    plt.title(title)
    plt.xlabel(X_LABEL)
    plt.ylabel(Y_LABEL)
    if not points:
        plt.text("no measured settings", 0.5, 0.5)
        return
    for name, color in FAMILIES:
        xs = [x for x, _, row in points if family(row.setting) == name]
        ys = [y for _, y, row in points if family(row.setting) == name]
        if xs:
            plt.scatter(xs, ys, marker=POINT_MARKER, color=color, label=name)
    front = sorted((p for p in points if p[2].front), key=lambda p: p[0])
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    if front:
        plt.scatter(
            [p[0] for p in front],
            [p[1] for p in front],
            marker=FRONT_MARKER,
            color=FRONT_COLOR,
            label="Pareto front",
        )
        if labels:
            # Labels start a little right of their marker (log axis: a factor).
            shift = (max(xs) / min(xs)) ** 0.02 if min(xs) > 0 else 1.0
            for x, y, row in front:
                plt.text(short_label(row.setting), x * shift, y, color=FRONT_COLOR, alignment="left")
    # Head room above the data for the legend, which plotext puts top left.
    top = max(ys) if max(ys) > 0 else 1.0
    plt.ylim(0.0, top * LEGEND_HEADROOM)
    plt.xscale("log")


def chart_text(result: StudyResult, width: int = 100, height: int = 30, color: bool = True) -> str:
    """The chart as terminal text (ANSI colours unless ``color`` is False)."""
    import plotext

    with _PLOTEXT_LOCK:
        plotext.clear_figure()
        plotext.limit_size(False, False)  # the size asked for, not the terminal's
        plotext.plotsize(width, height)
        plotext.theme("pro" if color else "clear")
        draw_chart(plotext, result)
        text = plotext.build()
        plotext.clear_figure()
    return text if color else plotext.uncolorize(text)


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
