"""The study's speed-against-accuracy chart as a plotted figure.

x: seconds per scan (log, left is faster); y: |coverage error| in points. One
colour and marker per tracer family, each point labelled by its ray grid (m),
the Pareto front joined by a line in order of time, the legend outside the axes.
"""

from __future__ import annotations

from matplotlib.figure import Figure

from ladartui.charts import new_figure
from ladartui.study.chart import FAMILIES, X_LABEL, Y_LABEL, chart_points, family, short_label
from ladartui.study.results import StudyResult

# matplotlib colours and markers, in the order of the study's FAMILIES.
STYLES = {
    "numba exact f64": ("tab:green", "o"),
    "wgpu exact f64": ("tab:cyan", "s"),
    "wgpu exact f32": ("tab:blue", "D"),
    "numba march": ("tab:red", "^"),
    "wgpu march": ("tab:purple", "v"),
}
FRONT_LABEL = "Pareto front"
TITLE = "Speed against accuracy"


def front_points(result: StudyResult) -> list[tuple[float, float, str]]:
    """(seconds, error points, short label) of the front, fastest first: the line's order."""
    front = sorted((p for p in chart_points(result) if p[2].front), key=lambda p: p[0])
    return [(x, y, short_label(row.setting)) for x, y, row in front]


def speed_accuracy_figure(result: StudyResult, width_px: int = 900, height_px: int = 560) -> Figure:
    figure = new_figure(width_px, height_px)
    axes = figure.add_subplot()
    axes.set_title(TITLE)
    axes.set_xlabel(X_LABEL)
    axes.set_ylabel(Y_LABEL)
    points = chart_points(result)
    if not points:
        axes.text(0.5, 0.5, "no measured settings", ha="center", transform=axes.transAxes)
        return figure
    for name, _ in FAMILIES:
        rows = [(x, y, row) for x, y, row in points if family(row.setting) == name]
        if not rows:
            continue
        color, marker = STYLES.get(name, ("tab:gray", "o"))
        axes.scatter(
            [x for x, _, _ in rows],
            [y for _, y, _ in rows],
            color=color,
            marker=marker,
            s=[18 + 6 * row.setting.ray_grid for _, _, row in rows],
            label=name,
            zorder=3,
            gid=f"series-{name}",
        )
        for x, y, row in rows:
            axes.annotate(
                f"m{row.setting.ray_grid}",
                (x, y),
                xytext=(4, 3),
                textcoords="offset points",
                fontsize=7,
                color=color,
            )
    front = front_points(result)
    if front:
        axes.plot(
            [x for x, _, _ in front],
            [y for _, y, _ in front],
            color="tab:orange",
            linewidth=1.5,
            zorder=2,
            label=FRONT_LABEL,
            gid="pareto-front",
        )
    if all(x > 0 for x, _, _ in points):
        axes.set_xscale("log")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(
        loc="upper left",
        bbox_to_anchor=(1.02, 1.0),
        borderaxespad=0,
        fontsize=8,
        title="backend / method (size: ray grid m)",
        title_fontsize=8,
    )
    figure.tight_layout()
    return figure
