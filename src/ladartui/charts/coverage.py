"""Coverage after each scan of a run: how many looks are worth flying.

Cumulative share of the target-model voxels seen after scans 1..k, obscured
(through the scene) and unobscured (target alone), with the first scan count that
reaches 90 % of the final obscured coverage marked, and the scans at which the
target was detected, recognised and identified (``ladartui.levels``; those use
shares of its visible voxels and footprint, so they need not sit on a curve).
With several targets each target's own obscured coverage is drawn too (thin
lines), so the target that needs the most looks shows.
"""

from __future__ import annotations

from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ladartui.charts import coverage_axis, new_figure
from ladartui.measures import ENOUGH_SHARE, Measures

LEVEL_COLOURS = {"detect": "tab:gray", "recognise": "tab:purple", "identify": "tab:red"}
# Colours of the per-target lines, apart from the overall series, the 90 % mark and the
# level lines (a dotted purple target line read as the recognise line).
TARGET_COLOURS = ("tab:brown", "tab:pink", "tab:olive", "tab:cyan", "darkgoldenrod", "teal", "slateblue")
SERIES = (
    ("unobscured", "unobscured_after_scan", "tab:blue", "s"),
    ("obscured", "obscured_after_scan", "tab:green", "o"),
)


def coverage_figure(measures: Measures, width_px: int = 800, height_px: int = 480) -> Figure:
    figure = new_figure(width_px, height_px)
    axes = figure.add_subplot()
    axes.set_title("Target coverage after each scan")
    axes.set_xlabel("scans flown")
    axes.set_ylabel("target coverage (%)")
    drawn = 0
    peak = 0.0  # the highest coverage of the series drawn
    for name, attribute, color, marker in SERIES:
        after = getattr(measures, attribute)
        if not after:
            continue
        peak = max(peak, *after)
        scans = list(range(1, len(after) + 1))
        axes.plot(
            scans, [100.0 * v for v in after], color=color, marker=marker, label=name, gid=f"series-{name}"
        )
        drawn += 1
    targets = getattr(measures.targets, "targets", ())
    if drawn and len(targets) > 1:
        for index, target in enumerate(targets):
            after = target.measures.obscured_after_scan
            if not after:
                continue
            axes.plot(
                range(1, len(after) + 1),
                [100.0 * v for v in after],
                linewidth=1,
                linestyle=":",
                marker=".",
                color=TARGET_COLOURS[index % len(TARGET_COLOURS)],
                # Names come from the scenario: a "$" must not start matplotlib's mathtext.
                label=f"obscured: {target.target_id} {target.name}".replace("$", r"\$"),
                gid=f"target-{target.target_id}",
            )
    enough = measures.scans_for_enough
    obscured = measures.obscured_after_scan
    if enough is not None and obscured:
        value = 100.0 * obscured[enough - 1]
        axes.axvline(enough, color="tab:orange", linestyle="--", linewidth=1)
        axes.plot(
            [enough],
            [value],
            marker="*",
            markersize=14,
            color="tab:orange",
            linestyle="none",
            label=f"{ENOUGH_SHARE:.0%} of final obscured coverage: scan {enough}",
            gid="enough-point",
        )
    _mark_levels(axes, measures)
    if not drawn:
        axes.text(0.5, 0.5, "no per-scan coverage in this run", ha="center", transform=axes.transAxes)
        return figure
    coverage_axis(axes, peak, "the target was not seen in any scan", from_zero=True)
    axes.xaxis.set_major_locator(MaxNLocator(integer=True))
    axes.grid(True, alpha=0.3)
    axes.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0, fontsize=8)
    figure.tight_layout()
    return figure


def _mark_levels(axes, measures: Measures) -> None:
    """A dotted vertical line at the scan where each level was reached."""
    if measures.levels is None:
        return
    for item in measures.levels.levels:
        if item.reached:
            axes.axvline(
                item.scan,
                color=LEVEL_COLOURS.get(item.level, "black"),
                linestyle=":",
                linewidth=1.5,
                label=f"{item.level}: {item.describe()}",
                gid=f"level-{item.level}",
            )
