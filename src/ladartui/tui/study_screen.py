"""The speed-against-accuracy study as a screen: chart, table and verdict.

The study runs in a thread worker; progress reaches the screen through
``call_from_thread`` and Cancel (or ``c``) sets the event the study checks
between trace calls, so nothing blocks the interface.
"""

from __future__ import annotations

import threading

from textual import on, work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import Screen
from textual.widgets import Button, DataTable, Footer, ProgressBar, Static
from textual.worker import get_current_worker
from textual_plotext import PlotextPlot

from ladartui.errors import Cancelled, LadarError
from ladartui.study.chart import TABLE_COLUMNS, draw_chart, table_rows


class StudyScreen(Screen):
    """Run the study on the open scenario (or the generated scenes) and show its chart."""

    BINDINGS = [
        Binding("q", "run('quick')", "Quick study"),
        Binding("f", "run('full')", "Full study"),
        Binding("c", "cancel", "Cancel"),
        Binding("escape", "close", "Back"),
    ]
    DEFAULT_CSS = """
    StudyScreen { layout: vertical; }
    StudyScreen #study-top { height: 1fr; }
    StudyScreen #study-chart { width: 3fr; min-height: 16; }
    StudyScreen #study-side { width: 2fr; }
    StudyScreen #study-table { height: 1fr; }
    StudyScreen #study-verdict { height: auto; max-height: 12; overflow-y: auto; padding: 0 1; }
    StudyScreen #study-bar { height: 1; }
    StudyScreen #study-bar Button { margin-left: 1; }
    StudyScreen #study-status { width: 1fr; padding: 0 1; }
    StudyScreen ProgressBar { width: 30; }
    """

    def __init__(self, scenario_path=None, scans: int | None = None, runs: int | None = None,
                 **kwargs):
        super().__init__(**kwargs)
        self.scenario_path = scenario_path
        self.scans = scans
        self.runs = runs
        self.result = None
        self._cancel_event = threading.Event()
        self._busy = False

    def compose(self) -> ComposeResult:
        with Horizontal(id="study-top"):
            yield PlotextPlot(id="study-chart")
            with Vertical(id="study-side"):
                yield DataTable(id="study-table", zebra_stripes=True, cursor_type="row")
                yield Static("", id="study-verdict")
        with Horizontal(id="study-bar"):
            yield Static(self._idle_text(), id="study-status")
            yield ProgressBar(id="study-progress", show_eta=False)
            yield Button("Quick", id="study-quick", compact=True)
            yield Button("Full", id="study-full", compact=True)
            yield Button("Cancel", id="study-cancel", compact=True, variant="error",
                         disabled=True)
        yield Footer()

    def on_mount(self) -> None:
        table = self.query_one("#study-table", DataTable)
        table.add_columns(*TABLE_COLUMNS)
        plot = self.query_one("#study-chart", PlotextPlot).plt
        plot.title("Speed against accuracy: press q (quick) or f (full)")

    def _idle_text(self) -> str:
        where = self.scenario_path or "the generated scenes"
        return f"Study on {where}: q quick, f full, c cancel, Esc back"

    # -- actions ---------------------------------------------------------------

    @on(Button.Pressed, "#study-quick")
    def _quick_pressed(self) -> None:
        self.action_run("quick")

    @on(Button.Pressed, "#study-full")
    def _full_pressed(self) -> None:
        self.action_run("full")

    @on(Button.Pressed, "#study-cancel")
    def _cancel_pressed(self) -> None:
        self.action_cancel()

    def action_run(self, mode: str) -> None:
        if self._busy:
            return
        self._busy = True
        self._cancel_event = threading.Event()
        self._set_busy(True, f"preparing the {mode} study ...")
        self._study(mode, self._cancel_event)

    def action_cancel(self) -> None:
        if self._busy:
            self._cancel_event.set()
            self._set_status("cancelling after the current trace ...")

    def action_close(self) -> None:
        self._cancel_event.set()
        self.dismiss(self.result)

    # -- the worker ------------------------------------------------------------

    @work(thread=True, exclusive=True, group="study")
    def _study(self, mode: str, cancel: threading.Event) -> None:
        from ladartui.study import full_settings, quick_settings
        from ladartui.study.inputs import generated_inputs, scenario_inputs
        from ladartui.study.run import run_study

        worker = get_current_worker()
        quick = mode == "quick"
        scans = self.scans or (2 if quick else 3)
        runs = self.runs or (3 if quick else 5)
        try:
            if self.scenario_path:
                inputs = scenario_inputs(self.scenario_path, scans)
            else:
                inputs = generated_inputs("small" if quick else "reference", scans,
                                          progress=lambda text: self._post(self._set_status, text))
            settings = quick_settings() if quick else full_settings()

            def progress(p):
                if worker.is_cancelled:
                    cancel.set()
                self._post(self._show_progress, p)

            result = run_study(inputs, settings, runs=runs, progress=progress, cancel=cancel)
        except Cancelled:
            self._post(self._finish, None, "study cancelled")
            return
        except LadarError as error:
            self._post(self._finish, None, f"error: {error}")
            return
        self._post(self._finish, result, f"{mode} study done on {inputs.name}")

    def _post(self, callback, *args) -> None:
        def on_screen():
            if self.is_mounted:  # the screen may have been closed meanwhile
                callback(*args)

        try:
            self.app.call_from_thread(on_screen)
        except RuntimeError:
            pass  # the app has closed

    # -- updates on the UI thread ---------------------------------------------

    def _show_progress(self, p) -> None:
        self.query_one("#study-progress", ProgressBar).update(total=max(p.total, 1),
                                                              progress=p.done)
        self._set_status(f"{p.label}, scan {p.scan}/{p.scans}")

    def _finish(self, result, message: str) -> None:
        self._busy = False
        self._set_busy(False, message)
        if result is not None:
            self.show_result(result)

    def show_result(self, result) -> None:
        """Draw ``result``'s chart, table and verdict."""
        self.result = result
        plot = self.query_one("#study-chart", PlotextPlot)
        draw_chart(plot.plt, result)
        plot.refresh()
        table = self.query_one("#study-table", DataTable)
        table.clear()
        for row in table_rows(result):
            table.add_row(*row)
        self.query_one("#study-verdict", Static).update(result.verdict())

    def _set_busy(self, busy: bool, message: str) -> None:
        self.query_one("#study-cancel", Button).disabled = not busy
        self.query_one("#study-quick", Button).disabled = busy
        self.query_one("#study-full", Button).disabled = busy
        self._set_status(message)

    def _set_status(self, message: str) -> None:
        self.query_one("#study-status", Static).update(message)
