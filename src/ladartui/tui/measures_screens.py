"""The measures dialog of a run (report figure 10) and the comparison of several runs'
measures (.cmf files) side by side."""

from __future__ import annotations

import shlex
from pathlib import Path

from rich.text import Text
from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, DataTable, Input, Static

from ladartui.errors import LadarError
from ladartui.fileprobe import user_path
from ladartui.measures import Measures
from ladartui.measures_compare import (
    column_names,
    read_compared,
    side_by_side,
    styled,
)
from ladartui.textsafe import single_line
from ladartui.tui.file_tree import FileTree
from ladartui.tui.measures_view import level_rows, measure_rows, target_rows
from ladartui.tui.plain_text import PathInput, PlainStatic
from ladartui.tui.screens import Dialog, TreeDialog, _row


class MeasuresScreen(Dialog):
    """The measures of the last run (report figure 10)."""

    def __init__(self, measures, title="Comparison measures", stale: str = ""):
        """``stale``: why the measures are out of date, said above them (empty: they are not)."""
        super().__init__()
        self.measures = measures
        self.title_text = title + (" (out of date)" if stale else "")
        self.stale = stale

    DEFAULT_CSS = """
    MeasuresScreen DataTable { height: auto; max-height: 18; }
    /* the status bar's not-ready colours: out of date reads the same everywhere */
    MeasuresScreen #measures-stale { height: auto; padding: 0 1; background: #3a3000; color: #ffffd7; }
    """

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog") as box:
            box.border_title = self.title_text
            if self.stale:  # words from settings and file names: never markup
                yield PlainStatic(self.stale, id="measures-stale")
            yield DataTable(cursor_type="row", zebra_stripes=True)
            with Horizontal(classes="buttons"):
                yield Button("Close", id="measures-close", variant="primary", compact=True)

    def on_mount(self) -> None:
        table = self.query_one(DataTable)
        table.add_columns("Measure", "Value")
        for label, value in measure_rows(self.measures):
            table.add_row(label, value)
        if isinstance(self.measures, Measures):
            for label, value in level_rows(self.measures):
                table.add_row(label, value)
            for target, coverage, level in target_rows(self.measures):
                table.add_row(target, f"{coverage} obscured" + (f", {level}" if level else ""))
        table.focus()

    @on(Button.Pressed, "#measures-close")
    def _close(self) -> None:
        self.dismiss(None)


class CompareScreen(TreeDialog):
    """Two or more runs' measures side by side, differences highlighted: .cmf files, or
    scenarios (.toml, typed) for the measures their last runs wrote."""

    def __init__(self, paths: list[Path], folder: Path | None = None):
        super().__init__()
        self.paths = list(paths)
        self.folder = folder or (self.paths[0].parent if self.paths else Path.cwd())
        self.base = self.folder  # typed names are read here, as Open and Save As read them

    DEFAULT_CSS = """
    CompareScreen > .dialog { width: 100%; height: 100%; max-height: 100%; }
    CompareScreen DataTable { height: 1fr; }
    CompareScreen FileTree { height: 8; min-height: 3; }
    """

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog") as box:
            box.border_title = "Compare scenarios"
            yield _row(
                ".cmf files",
                PathInput(
                    shlex.join(self.relative(p) for p in self.paths),  # in the folder: by name
                    id="cmf-files",
                    compact=True,
                    suggester=self.path_suggester((".cmf",), several=True),
                ),
            )
            yield from self.tree_rows((".cmf",))
            yield Static(
                "Paths separated by spaces (quote one that has spaces; a scenario's "
                ".toml stands for its last run's), or pick files in the tree (again "
                "to drop one); Enter compares. Green best, red worst, yellow differs.",
                classes="info",
            )
            yield PlainStatic("", id="compare-message", classes="message")
            yield DataTable(id="compare-table", zebra_stripes=True)
            with Horizontal(classes="buttons"):
                yield Button("Compare", id="compare-go", compact=True, variant="primary")
                yield Button("Close", id="compare-close", compact=True)

    def on_mount(self) -> None:
        super().on_mount()
        self.compare()

    @on(FileTree.FileSelected, "#tree")
    def _picked(self, event: FileTree.FileSelected) -> None:
        event.stop()
        field = self.query_one("#cmf-files", Input)
        chosen = self._typed() or []
        picked = self.relative(Path(event.path))
        field.value = shlex.join(
            [c for c in chosen if c != picked] if picked in chosen else chosen + [picked]
        )
        self.compare()

    def _typed(self) -> list[str] | None:
        """The paths in the field, split as a shell would (quotes keep spaces); None,
        with the reason said, when a quote is not closed."""
        try:
            return shlex.split(self.query_one("#cmf-files", Input).value)
        except ValueError:  # shlex's only complaint: "No closing quotation"
            self.query_one("#compare-message", Static).update(
                ".cmf files: a quotation mark is not closed; expected paths separated by spaces, "
                "one with spaces in quotes"
            )
            return None

    @on(Input.Submitted, "#cmf-files")
    @on(Button.Pressed, "#compare-go")
    def compare(self) -> None:
        message = self.query_one("#compare-message", Static)
        table = self.query_one("#compare-table", DataTable)
        table.clear(columns=True)
        text = self._typed()
        if text is None:
            return
        if len(text) < 2:
            message.update("Give two or more .cmf files to compare.")
            return
        paths = [self.base / user_path(t) for t in text]
        try:
            # a scenario stands for its last run's measures: say so where it has changed since
            loaded, notes = read_compared(paths)
        except LadarError as error:
            message.update(str(error))
            return
        message.update(" ".join(f"Note: {note}" for note in notes))
        table.add_column("Measure")
        for name in column_names([Path(t) for t in text]):
            table.add_column(Text(single_line(name)))  # names from files: never markup, controls written out
        for row in side_by_side(loaded):
            table.add_row(*styled(row))

    @on(Button.Pressed, "#compare-close")
    def _close(self) -> None:
        self.dismiss(None)
