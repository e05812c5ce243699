"""A sweep's Pareto front: obscured coverage against flight cost, best path marked.

Every ranked variant is a grey point; the front (no variant both cheaper and
covering more) is joined cheapest first; the top-ranked variant is a star.
"""

from __future__ import annotations

from matplotlib.figure import Figure

from ladartui.charts import coverage_axis, new_figure

COST_AXIS = {"flight-time": "flight time (s)", "distance": "path length (m)"}


def sweep_figure(result, width_px: int = 800, height_px: int = 480) -> Figure:
    """``result`` is a ``ladartui.sweep.SweepResult``."""
    figure = new_figure(width_px, height_px)
    axes = figure.add_subplot()
    axes.set_title(f"Sweep: obscured coverage against {result.cost} ({result.objective})")
    axes.set_xlabel(COST_AXIS.get(result.cost, result.cost))
    axes.set_ylabel("obscured target coverage (%)")
    placed = [r for r in result.ranking if r.cost is not None and r.coverage is not None]
    if not placed:
        axes.text(0.5, 0.5, "no finished variants", ha="center", transform=axes.transAxes)
        return figure
    axes.scatter(
        [r.cost for r in placed],
        [100.0 * r.coverage for r in placed],
        color="tab:gray",
        alpha=0.6,
        s=20,
        label=f"variants ({len(placed)})",
        gid="series-variants",
        zorder=2,
    )
    front = result.pareto  # cheapest first
    if front:
        axes.plot(
            [r.cost for r in front],
            [100.0 * r.coverage for r in front],
            color="tab:orange",
            marker="o",
            linewidth=1.5,
            label=f"Pareto front ({len(front)})",
            gid="pareto-front",
            zorder=3,
        )
    best = result.best
    if best is not None and best.cost is not None and best.coverage is not None:
        name = str(best.row.get("variant", ""))[:8]
        axes.plot(
            [best.cost],
            [100.0 * best.coverage],
            marker="*",
            markersize=16,
            color="tab:red",
            linestyle="none",
            label=f"best by {result.objective}: {name}",
            gid="best",
            zorder=4,
        )
    peak = max(r.coverage for r in placed)
    coverage_axis(axes, peak, "no variant saw the target", from_zero=False)
    axes.grid(True, alpha=0.3)
    axes.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0, fontsize=8)
    figure.tight_layout()
    return figure
