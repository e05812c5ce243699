"""The Results tab: the last run's measures in a table, and the ways to look further."""

from __future__ import annotations

from rich.text import Text
from textual import on
from textual.containers import Grid, VerticalScroll
from textual.widgets import Button, DataTable, Static

from ladartui.measures import Measures
from ladartui.tui.host import host_of
from ladartui.tui.measures_view import compact_rows, level_rows, target_rows
from ladartui.tui.plain_text import PlainStatic


class ResultsPanel(VerticalScroll):
    DEFAULT_CLASSES = "pane"

    def compose(self):
        yield PlainStatic(self._no_results(), id="results-info", classes="info")
        yield DataTable(id="measures", cursor_type="row", zebra_stripes=True)
        with Grid(classes="button-grid run-buttons"):
            yield Button("Measures", id="btn-measures", compact=True)
            yield Button("Compare", id="btn-compare", compact=True)
            yield Button("Threshold", id="btn-threshold", compact=True)
        with Grid(classes="button-grid run-buttons two-buttons"):
            yield Button(
                "Export LAS",
                id="btn-export-las",
                compact=True,
                tooltip="The outputs as LAS point clouds beside them",
            )

    def on_mount(self) -> None:
        self.query_one("#measures", DataTable).add_columns("Measure", "Value")

    def _no_results(self) -> str:
        runs = host_of(self).key_says("run", "runs the scenario")
        return "No results yet" + (f": {runs}." if runs else ".")

    def show_measures(self, measures, name: str = "", made_with: str | None = None) -> None:
        """The measures of ``name``'s outputs; ``made_with``: the other settings that
        made them (None: the scenario's now)."""
        table = self.query_one("#measures", DataTable)
        table.clear()
        info = self.query_one("#results-info", Static)
        if measures is None:
            info.update(self._no_results())
            return
        info.update(f"Measures of {name}" + (f", from {made_with}" if made_with else ":"))
        for label, value in compact_rows(measures):
            table.add_row(Text(label), Text(value))  # text from a file: never markup
        if isinstance(measures, Measures):
            for label, value in level_rows(measures, short=True):
                table.add_row(Text(label), Text(value))
            targets = target_rows(measures, short=True)
            if targets:
                table.add_row(Text("Targets", style="bold"), Text("obsc. lvl@scan", style="dim"))
            for target, coverage, level in targets:
                table.add_row(target, Text(f"{coverage} {level}" if level else coverage))

    @on(Button.Pressed, "#btn-measures,#btn-compare,#btn-threshold,#btn-export-las")
    async def _pressed(self, event: Button.Pressed) -> None:
        event.stop()
        await self.app.run_action((event.button.id or "").removeprefix("btn-").replace("-", "_"))
