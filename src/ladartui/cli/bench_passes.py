"""``ladartui bench --passes``: where each backend's exact scans spend their time.

``run_bench`` keeps, for every row, the median seconds of each pass of its
timed runs (``TraceResult.info["passes"]``, tracing/passes.py) and ``other``
for the rest of a call (argument checks, allocations, the order choice's
bookkeeping). ``print_passes`` shows them per backend: a pass a line, a case
a column, in milliseconds a scan.
"""

from __future__ import annotations

import statistics

from ladartui.number_text import plural

# The passes in the order a scan runs them (tracing/passes.py names them).
PASS_ORDER = (
    "rays to cells",
    "bins",
    "voxels in view",
    "tile lists",
    "tile tests",
    "device",
    "answers",
    "ray order",
    "march",
    "to metres",
)


def pass_medians(run_seconds: list[float], run_passes: list[dict[str, float]]) -> dict[str, float]:
    """Median seconds of each pass over the runs (0 in a run without it), in
    PASS_ORDER, then any others, then ``other``: the rest of each run's time."""
    names = [name for name in PASS_ORDER if any(name in passes for passes in run_passes)]
    names += sorted({name for passes in run_passes for name in passes} - set(names))
    medians = {name: statistics.median(passes.get(name, 0.0) for passes in run_passes) for name in names}
    rest = [max(0.0, seconds - sum(passes.values())) for seconds, passes in zip(run_seconds, run_passes)]
    medians["other"] = statistics.median(rest) if rest else 0.0
    return medians


def print_passes(console, report) -> None:
    """Per backend, a table of its exact rows' pass medians in milliseconds (fits 80 columns)."""
    from rich import box
    from rich.table import Table

    rows = [row for row in report["results"] if row["method"] == "exact" and row.get("passes")]
    for backend in dict.fromkeys(row["backend"] for row in rows):
        cases = [row for row in rows if row["backend"] == backend]
        names = list(dict.fromkeys(name for row in cases for name in row["passes"]))
        runs = plural(report["runs"], "run")
        console.print(f"{backend}, exact scans: milliseconds by pass (medians of {runs})")
        table = Table(
            box=box.SIMPLE_HEAD,
            pad_edge=False,
            show_edge=False,
        )
        table.add_column("pass", no_wrap=True)
        for row in cases:
            table.add_column(f"{row['view']} {row['depression']:g}", no_wrap=True, justify="right")
        for k, name in enumerate(names):
            table.add_row(
                name, *(_ms(row["passes"].get(name)) for row in cases), end_section=k == len(names) - 1
            )
        table.add_row("total", *(_ms(row["median_seconds"]) for row in cases))
        console.print(table)


def _ms(seconds: float | None) -> str:
    return "-" if seconds is None else f"{seconds * 1e3:.2f}"
