"""What the sweep screen draws: the ranking table, the detail line, the Pareto chart,
and the time left (no widgets are kept here; the screen hands them in)."""

from __future__ import annotations

from pathlib import Path

from rich.text import Text

from ladartui.sweep.ranking import COVERAGE_OBJECTIVES, OBJECTIVE_HEADERS
from ladartui.sweep.table import column_formats, display_cell

COST_HEADERS = {"flight-time": "time s", "distance": "dist m"}
# Each label with its axis's arrow: plotext sets them side by side on one line, which
# read as one phrase; short, so that both fit a chart 30 columns wide.
COST_LABELS = {"flight-time": "flight time (s) \u2192", "distance": "distance (m) \u2192"}
COVERAGE_LABEL = "\u2191 cov %"
FRONT_MARKER = "◆"
BEST_MARKER = "★"  # the best variant's, in the table as on the chart (over its front mark)
ERROR_WIDTH = 60  # error text in the table; the detail line shows it whole


def eta_seconds(progress) -> float | None:
    """Time left at the pace of the variants run so far (resumed ones cost nothing)."""
    ran = progress.done - progress.resumed
    left = progress.total - progress.done
    if left <= 0:
        return 0.0
    if ran <= 0 or progress.elapsed <= 0:
        return None
    return progress.elapsed / ran * left


def short_path(path) -> str:
    """``path`` relative to the working folder when inside it (status lines are 80 wide)."""
    path = Path(path)
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def fill_ranking_table(
    table, ranking, objective: str, cost: str, parameter_names, shown_ids: list, best: bool = False
) -> list:
    """Refill ``table`` with ``ranking``, keeping the cursor on the same variant, or with
    ``best`` (results just arrived) putting it on the best one (``row_mark``'s star); the
    variant ids in table order."""
    current = shown_ids[table.cursor_row] if 0 <= table.cursor_row < len(shown_ids) else None
    ids = [entry.row.get("variant") for entry in ranking]
    if best:
        cursor = next((i for i, entry in enumerate(ranking) if entry.rank == 1), 0)
    else:
        cursor = ids.index(current) if current in ids else 0
    table.clear(columns=True)
    table.add_column("#", key="rank")
    table.add_column("P", key="pareto")
    table.add_column(OBJECTIVE_HEADERS[objective], key="objective")
    if objective != "obscured-coverage":
        table.add_column("cov %", key="coverage")
    table.add_column(COST_HEADERS[cost], key="cost")
    table.add_column("status", key="status")
    for name in parameter_names:
        table.add_column(Text(name), key=f"param:{name}")
    table.add_column("variant", key="variant")
    # only with an error to show: an empty column ran past 80 columns before any results
    errors = any(entry.row.get("error") for entry in ranking)
    if errors:
        table.add_column("error", key="error")
    formats = column_formats(ranking, parameter_names)
    for index, entry in enumerate(ranking):
        table.add_row(*ranking_cells(entry, objective, parameter_names, errors, formats), key=str(index))
    if ranking:
        table.move_cursor(row=cursor)
    return ids


def ranking_cells(entry, objective: str, parameter_names, errors: bool, formats: dict) -> list:
    """One table row: rank, mark (``row_mark``), objective, (coverage), cost, status, parameters,
    variant and (with ``errors``) error; text from the results file is never markup.
    Coverages read in percent: the objective's when it is one ("68.75%"), the cov % column's.
    ``formats``: ``column_formats`` of the whole ranking."""
    row = entry.row
    status = row.get("status") or "?"
    if objective in COVERAGE_OBJECTIVES:  # in percent, as the cov % column and the chart
        value = "-" if entry.value is None else f"{100 * entry.value:.2f}%"
    else:
        value = formats["value"](entry.value)
    cells = [
        "-" if entry.rank is None else str(entry.rank),
        row_mark(entry),
        value,
    ]
    if objective != "obscured-coverage":
        cells.append("-" if entry.coverage is None else f"{100 * entry.coverage:.2f}")
    cells.append(Text(formats["cost"](entry.cost)))
    cells.append(Text(status, style="green" if status == "ok" else "bold red"))
    cells.extend(Text(formats[name](row.get(name))) for name in parameter_names)
    cells.append(Text(str(row.get("variant") or "")))
    if errors:
        error = str(row.get("error") or "")
        cells.append(Text(error[:ERROR_WIDTH] + ("…" if len(error) > ERROR_WIDTH else ""), style="red"))
    return cells


def row_mark(entry) -> Text | str:
    """The P column's mark, as on the chart: the best variant's star, else the front's."""
    if entry.rank == 1:
        return Text(BEST_MARKER, style="bold green")
    return Text(FRONT_MARKER, style="bold #ffaf00") if entry.pareto else ""


def detail_text(entry, parameter_names) -> Text:
    """The detail line of one ranked variant: its parameters, and why it failed or
    what its mark says."""
    row = entry.row
    params = ", ".join(
        f"{name}={display_cell(row.get(name))}" for name in parameter_names if row.get(name) is not None
    )
    text = Text(f"{row.get('variant')}: {params or 'base scenario'}")
    if row.get("status") != "ok":
        text.append(f"  {row.get('status')}: {row.get('error') or ''}", style="bold red")
        return text
    if entry.rank == 1:
        text.append(f"  {BEST_MARKER} best", style="green")
    if entry.pareto:
        text.append("  on the Pareto front", style="#ffaf00")
    return text


def draw_pareto(plt, ranking, cost: str) -> None:
    """Coverage against cost on a plotext figure: every variant, the front as a line
    joining its points, the best marked."""
    plt.clear_data()
    plt.title(f"{FRONT_MARKER} Pareto front  {BEST_MARKER} best")
    points = [(e.cost, 100 * e.coverage, e) for e in ranking if e.cost is not None and e.coverage is not None]
    # named beside their tick labels only: with none, the names ran together
    plt.xlabel(COST_LABELS[cost] if points else None)
    plt.ylabel(COVERAGE_LABEL if points else None)
    if not points:
        return
    others = [p for p in points if not p[2].pareto]
    if others:
        plt.scatter([p[0] for p in others], [p[1] for p in others], marker="●", color="cyan")
    front = sorted((p for p in points if p[2].pareto), key=lambda p: p[0])
    # a thin line joins the front; its own points sit on it (a line of markers would
    # read as many points)
    plt.plot([p[0] for p in front], [p[1] for p in front], marker="braille", color="orange")
    plt.scatter([p[0] for p in front], [p[1] for p in front], marker=FRONT_MARKER, color="orange")
    if max(p[1] for p in points) <= 0:  # flat at 0: plotext's own axis runs from -1 to 1 %
        plt.ylim(0, 100)
    best = [p for p in points if p[2].rank == 1]
    if best:
        plt.scatter([best[0][0]], [best[0][1]], marker=BEST_MARKER, color="green")
