"""What a sweep writes once its variants are done, as one output set.

``ranking.csv``, the best path (``NAME-best.toml``, or the numbered file beside an
edited one) and, when asked, the Pareto charts ``pareto.svg`` and ``pareto.png``
are made in memory first, then replaced together or not at all (``OutputSet``):
a full disk or a kill part way leaves the earlier ranking's files whole, never a
new ranking beside an earlier one's charts. ``results.csv`` is not part of it: it
is rewritten as rows come, and keeps them whatever happens here.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ladartui.errors import OutputFileError
from ladartui.number_text import plural
from ladartui.sweep.best_file import best_files, best_scenario_text
from ladartui.sweep.table import table_text

if TYPE_CHECKING:
    from ladartui.sweep.execute import SweepResult
    from ladartui.sweep.ranking import Ranked

RANKING_NAME = "ranking.csv"
# The sweep command's Pareto charts beside the tables.
CHART_STEM = "pareto"
CHART_NAMES = (f"{CHART_STEM}.svg", f"{CHART_STEM}.png")
# Held while the set is written (made and removed by ``OutputSet``).
SET_LOCK_NAME = ".ranking.outputs.lock"


def ranking_text(ranking: list[Ranked], parameter_names) -> str:
    """The ranking as CSV: rank, objective value, Pareto flag, then the row."""
    columns = [
        "rank",
        "variant",
        "objective",
        "pareto",
        "coverage",
        "cost",
        "status",
        *parameter_names,
        "path_length_m",
        "flight_time_s",
        "error",
    ]
    rows = []
    for entry in ranking:
        row = entry.row
        rows.append(
            {
                **{name: row.get(name) for name in columns},
                "rank": entry.rank,
                "objective": entry.value,
                "pareto": entry.pareto,
                "coverage": entry.coverage,
                "cost": entry.cost,
            }
        )
    return table_text(rows, columns=columns)


def write_ranked_set(result: SweepResult, name: str, base, scene_loader, charts: bool = False) -> None:
    """Write ``result``'s ranking, best path and (``charts``) Pareto charts beside its
    results table, all or none, and set the paths written on ``result``."""
    from ladartui.outputset import OutputSet

    out = result.results_path.parent
    paths = {"ranking": out / RANKING_NAME}
    contents = {"ranking": ranking_text(result.ranking, result.parameter_names).encode("utf-8")}
    best = None
    if result.best is not None:
        best, text = best_scenario_text(
            out / f"{name}-best.toml", base, result.best.row, result.parameter_names, scene_loader
        )
        paths["best"], contents["best"] = best.path, text.encode("utf-8")
    chart_paths: dict[str, Path] = {}
    if charts:
        from ladartui.charts import FORMATS, figure_bytes
        from ladartui.charts.sweep import sweep_figure

        figure = sweep_figure(result)
        chart_paths = {fmt: out / f"{CHART_STEM}.{fmt}" for fmt in FORMATS}
        paths.update(chart_paths)
        contents.update({fmt: figure_bytes(figure, fmt) for fmt in FORMATS})
    try:
        with OutputSet(paths, set_lock(out)) as output_set:
            output_set.write_contents(contents)
    except OutputFileError as error:  # the rows are kept: what to do to rank them
        rows = plural(len(result.rows), "variant")
        raise type(error)(
            error.path,
            f"{error.reason}; {result.results_path} keeps this sweep's rows ({rows}): "
            "the same command ranks them, running none again",
        ) from None
    result.ranking_path = paths["ranking"]
    result.charts = chart_paths
    if best is not None:
        result.best_scenario_path, result.best_kept, result.best_kept_why = (
            best.path,
            best.kept,
            best.kept_why,
        )
    else:  # what an earlier ranking found: kept, named
        result.best_earlier = next(iter(best_files(out, name)), None)


def set_lock(out) -> Path:
    """The lock file of the set ``write_ranked_set`` writes into ``out``."""
    return Path(out) / SET_LOCK_NAME
