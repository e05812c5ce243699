"""The sweep screen's ranking: its rows ranked by the objective chosen, drawn as the
table, the detail line of the selected variant and the Pareto chart.

``SweepScreen`` (tui/sweep_screen.py) is a ``RankingView``: it fills ``rows``
and chooses the objective, cost and budget; this class ranks and draws.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from textual.screen import Screen
from textual.widgets import DataTable, ProgressBar, Static
from textual_plotext import PlotextPlot

from ladartui.errors import LadarError
from ladartui.number_text import plural
from ladartui.sweep.ranking import BUDGET_OBJECTIVES
from ladartui.tui.sweep_view import detail_text, draw_pareto, fill_ranking_table

if TYPE_CHECKING:
    from ladartui.sweep.ranking import Ranked


class RankingView(Screen):
    """Ranks ``rows`` by ``objective`` (and ``cost``, the budget) and draws the result."""

    rows: list[dict]
    parameter_names: list[str]
    ranking: list[Ranked]
    objective: str
    cost: str
    _dirty: bool  # rows arrived since the last redraw (redrawn a few times a second)
    _shown_ids: list  # variant ids in table order

    def _budget(self) -> float | None:
        """The flight-time budget the ranking uses (the screen's field, else the spec's)."""
        raise NotImplementedError

    def _summary(self) -> str:
        ok = sum(row.get("status") == "ok" for row in self.rows)
        impossible = sum(row.get("status") == "error" for row in self.rows)  # final, never rerun
        failed = len(self.rows) - ok - impossible
        return f"{plural(len(self.rows), 'variant')}, {ok} ok, {failed} failed" + (
            f", {impossible} impossible" if impossible else ""
        )

    def _show_stored(self, total: int) -> None:
        """Progress row of opened results: variants in the table out of the spec's."""
        self.query_one("#sweep-progress", ProgressBar).update(total=max(total, 1), progress=len(self.rows))
        text = self._summary()
        if total != len(self.rows):
            text = f"{len(self.rows)}/{total} stored: " + text.split(" ", 2)[2]
        self.query_one("#sweep-counts", Static).update(text)

    def _redraw_if_dirty(self) -> None:
        if self._dirty:
            self._rank_quietly()
            self._redraw()

    def _rank(self) -> None:
        from ladartui.sweep import rank_rows

        budget = self._budget() if self.objective in BUDGET_OBJECTIVES else None
        self.ranking = rank_rows(self.rows, self.objective, budget, self.cost)

    def _rank_quietly(self) -> None:
        try:
            self._rank()
        except LadarError:
            from ladartui.sweep import rank_rows

            self.ranking = rank_rows(self.rows, "obscured-coverage", None, self.cost)
            self.objective = "obscured-coverage"

    def _switch_to_next(self, name: str, order) -> str:
        """Rank by the choice of ``name`` ("objective" or "cost") after the current one in
        ``order``, passing over objectives that need a budget there is not; returns the
        status line saying what it ranks by (first: a status line is cut at the edge)."""
        start = order.index(getattr(self, name))
        skipped = []
        for step in range(1, len(order) + 1):
            setattr(self, name, order[(start + step) % len(order)])
            try:
                self._rank()
                break
            except LadarError:  # no usable budget: go on to the next choice
                skipped.append(getattr(self, name))
        self._redraw()
        if skipped:
            return (
                f"ranking by {self.objective}; {', '.join(skipped)} skipped: it needs a budget "
                "(type one in Budget s)"
            )
        text = f"ranking by {self.objective}"
        if self.objective in BUDGET_OBJECTIVES:
            text += f" (budget {self._budget():g} s)"
        return f"{text}, Pareto front against {self.cost}"

    def _redraw(self, best: bool = False) -> None:
        """Draw the ranking; ``best``: results arrived (a sweep done, a folder opened),
        so the cursor goes to the best variant, not the one it was on."""
        self._dirty = False
        self._draw_table(best)
        self._draw_chart()

    def _draw_table(self, best: bool = False) -> None:
        table = self.query_one("#sweep-table", DataTable)
        self._shown_ids = fill_ranking_table(
            table, self.ranking, self.objective, self.cost, self.parameter_names, self._shown_ids, best
        )
        if self.ranking:
            self._show_detail(table.cursor_row)
        else:
            self.query_one("#sweep-detail", Static).update("")

    def _show_detail(self, index: int) -> None:
        entry = self.ranking[index] if 0 <= index < len(self.ranking) else None
        self.query_one("#sweep-detail", Static).update(
            detail_text(entry, self.parameter_names) if entry is not None else ""
        )

    def _draw_chart(self) -> None:
        plot = self.query_one("#sweep-chart", PlotextPlot)
        draw_pareto(plot.plt, self.ranking, self.cost)
        plot.refresh()
