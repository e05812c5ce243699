"""What ``ladartui sweep`` prints: the ranking table, the Pareto front, failures and the
files written (``show_result``), or the same as JSON (``result_dict``)."""

from __future__ import annotations

import shlex

from rich.markup import escape

from ladartui.number_text import plural
from ladartui.textsafe import single_line


def result_dict(result, top) -> dict:
    """The sweep as a JSON-safe dict: files, counts, the best variants and the Pareto front."""

    from ladartui.sweep.columns import LEVEL_FIELDS, target_ids, target_names
    from ladartui.sweep.ranking import LEVEL_NAMES, level_of, levels_text

    def levels(row):
        per_level = {level: level_of(row, level) for level in LEVEL_NAMES}
        ids: list[int | None] = [*target_ids(row)] or [None]
        names = target_names(row)
        return [
            {
                "target": ids[i],
                "name": names[i] or None,
                **{level: dict(zip(LEVEL_FIELDS, per_level[level][i])) for level in LEVEL_NAMES},
            }
            for i in range(len(per_level["identify"]))
        ]

    def entry(ranked):
        row = ranked.row
        return {
            "rank": ranked.rank,
            "variant": row.get("variant"),
            "objective": ranked.value,
            "coverage": ranked.coverage,
            "cost": ranked.cost,
            "pareto": ranked.pareto,
            "parameters": {n: row.get(n) for n in result.parameter_names},
            "levels": levels(row),
            "levels_text": levels_text(row),
        }

    return {
        "objective": result.objective,
        "cost": result.cost,
        "budget": result.budget,
        "variants": len(result.rows),
        "ran": result.ran,
        "resumed": result.resumed,
        "failed": len(result.failed),
        "impossible": len(result.impossible),
        "workers": result.workers,
        "elapsed_s": round(result.elapsed, 3),
        "results": str(result.results_path),
        "ranking": str(result.ranking_path) if result.ranking_path else None,
        "best_scenario": str(result.best_scenario_path) if result.best_scenario_path else None,
        "best_scenario_kept": str(result.best_kept) if result.best_kept else None,
        "best_scenario_earlier": str(result.best_earlier) if result.best_earlier else None,
        "left_out": result.left_out,
        "left_out_earlier_base": result.left_out_earlier_base,
        "unreadable_lines": result.unreadable_lines,
        "best_levels": levels_text(result.best.row) if result.best is not None else None,
        "charts": {fmt: str(path) for fmt, path in result.charts.items()},
        "top": [entry(r) for r in result.ranking[:top] if r.rank is not None],
        "pareto": [entry(r) for r in result.pareto],
        "errors": [{"variant": r.get("variant"), "error": r.get("error")} for r in result.failures],
    }


def _why_not_ok(row: dict) -> str:
    """A failed row's error, or, with none (a hand-edited table), the status it holds."""
    if row.get("error"):
        return str(row["error"])
    return f"no error given; status {row.get('status')!r}, not one a sweep writes (ok, failed, error)"


def show_result(console, result, top) -> None:
    """The top of the ranking, the Pareto front, failures and the files written."""
    from rich import box
    from rich.table import Table
    from rich.text import Text

    from ladartui.sweep.columns import target_ids
    from ladartui.sweep.ranking import OBJECTIVE_HEADERS as short
    from ladartui.sweep.ranking import OBJECTIVES, identified_count, never_identified
    from ladartui.sweep.table import column_formats, display_cell

    cost_unit = "s" if result.cost == "flight-time" else "m"
    table = Table(
        title=f"Best flight paths by {result.objective}: {OBJECTIVES[result.objective]}",
        title_justify="left",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
    )
    shown = [r for r in result.ranking if r.rank is not None][:top]
    # each column's numbers with its decimals, so that they line up
    formats = column_formats(shown, result.parameter_names)
    value_cell, coverage_cell, cost_cell = formats["value"], formats["coverage"], formats["cost"]

    def number_column(header: str, values) -> None:
        # A narrow terminal folds the header, never a value: a cut number reads as another one.
        width = max((len(v) for v in values), default=1)
        table.add_column(header, justify="right", min_width=width, overflow="fold")

    table.add_column("#", justify="right")
    table.add_column("variant", no_wrap=True)
    for name in result.parameter_names:
        number_column(name, [formats[name](r.row.get(name)) for r in shown])
    separate = result.objective not in ("obscured-coverage", "coverage-within-budget")
    if separate:
        number_column(short[result.objective], [value_cell(r.value) for r in shown])
    # Several targets: how many each path identifies by its last scan, e.g. "2/3".
    several = any(len(target_ids(r.row)) > 1 for r in shown)
    if several:
        table.add_column("targets id.", justify="right")
    number_column("coverage", [coverage_cell(r.coverage) for r in shown])
    cost_header = f"{'time' if cost_unit == 's' else 'dist.'} {cost_unit}"
    number_column(cost_header, [cost_cell(r.cost) for r in shown])
    table.add_column("front")

    def read(value) -> Text:  # text read from the results table: never markup or escapes
        return Text(single_line(value))

    for ranked in shown:
        row = ranked.row
        table.add_row(
            str(ranked.rank),
            read(str(row.get("variant", ""))[:8]),
            *(read(formats[n](row.get(n))) for n in result.parameter_names),
            *([value_cell(ranked.value)] if separate else []),
            *([f"{identified_count(row)}/{len(target_ids(row))}"] if several else []),
            coverage_cell(ranked.coverage),
            cost_cell(ranked.cost),
            "*" if ranked.pareto else "",
        )
    console.print(table)
    front = result.pareto
    if front:
        points = ", ".join(
            f"{str(r.row.get('variant'))[:8]} ({display_cell(r.coverage, 3)} at "
            f"{display_cell(r.cost, 4)} {cost_unit})"
            for r in front
        )
        console.print(
            single_line(f"Pareto front of obscured coverage against {result.cost}, cheapest first: {points}"),
            highlight=False,
            markup=False,
        )
    unranked = sum(1 for r in result.ranking if r.rank is None and r.row.get("status") == "ok")
    if unranked:
        reason = {
            "time-to-identify": "a target not identified",
            "distance-to-identify": "a target not identified",
            "identified-within-budget": "no target identified within the budget",
        }.get(result.objective, "objective undefined or over the budget")
        console.print(f"{plural(unranked, 'finished variant')} not ranked ({reason})", highlight=False)
        missed = never_identified(result.rows)
        if missed and result.objective in ("time-to-identify", "distance-to-identify"):
            console.print(
                single_line("no variant identifies " + ", ".join(missed)), highlight=False, markup=False
            )
    for rows, what in (
        (result.impossible, "with impossible values (kept as errors, not run again)"),
        (result.failed, "failed (run again when the sweep resumes)"),
    ):
        if rows:
            console.print(
                f"[bold]{plural(len(rows), 'variant')} {what}[/]; first: "
                + escape(single_line(f"{rows[0].get('variant')}: {_why_not_ok(rows[0])}")),
                highlight=False,
            )
    ran, resumed = result.ran, result.resumed
    if ran:
        rate = f" ({60 * ran / result.elapsed:.1f} variants/min)" if result.elapsed else ""
        earlier = f"; {resumed:,} resumed from earlier runs" if resumed else ""
        console.print(
            f"{plural(ran, 'variant')} run in {result.elapsed:.1f} s{rate} on "
            f"{plural(result.workers, 'worker')}{earlier}",
            highlight=False,
        )
    elif resumed:  # no worker started: "0 variants run ... on 0 workers" said nothing
        every = "the variant" if resumed == 1 else f"all {resumed:,} variants"
        console.print(f"nothing to run: {every} resumed from earlier runs", highlight=False)
    if result.left_out:
        earlier = result.left_out_earlier_base
        others = result.left_out - earlier
        parts = [f"{plural(others, 'row')} of other variants (not in the spec now)"] if others else []
        if earlier:
            parts.append(
                f"{plural(earlier, 'row')} of an earlier base (a run of this spec runs its variants "
                "again for the base as it is now)"
            )
        console.print("left out: " + "; ".join(parts), highlight=False)
    if lines := result.unreadable_lines:
        listed = ", ".join(map(str, lines[:5])) + (", ..." if len(lines) > 5 else "")
        which = f"{plural(len(lines), 'row')} of {result.results_path.name} could not be read"
        gone = "; the table was rewritten without " + ("it" if len(lines) == 1 else "them")
        console.print(
            f"{which} (line{'s' if len(lines) > 1 else ''} {listed}) and "
            f"{'is' if len(lines) == 1 else 'are'} left out{gone if result.unreadable_removed else ''}",
            highlight=False,
        )
    console.print(single_line(f"results  {result.results_path}"), highlight=False, markup=False)
    if result.ranking_path:
        console.print(single_line(f"ranking  {result.ranking_path}"), highlight=False, markup=False)
    for path in result.charts.values():
        console.print(single_line(f"chart    {path}"), highlight=False, markup=False)
    if result.best_scenario_path:
        console.print(
            single_line(
                f"best     {result.best_scenario_path}  "
                f"(open it with: ladartui {shlex.quote(str(result.best_scenario_path))})"  # runs as written
            ),
            highlight=False,
            markup=False,
        )
    if result.best_earlier:
        console.print(
            single_line(
                f"earlier  {result.best_earlier}  (the best path of an earlier ranking: none is ranked now)"
            ),
            highlight=False,
            markup=False,
        )
    if result.best_kept:
        console.print(
            single_line(f"kept     {result.best_kept}  ({result.best_kept_why}: not replaced)"),
            highlight=False,
            markup=False,
        )
    if result.best is not None:
        from ladartui.sweep.ranking import levels_text

        console.print(f"best path {levels_text(result.best.row)}", highlight=False, markup=False)
