"""The speed-against-accuracy study as a screen: chart, table and verdict.

The study is a job (``tui/work.py``): its progress and its end reach the
screen as messages, Cancel (or ``c``) cancels the worker, whose event the
study checks between trace calls, and any failure (expected or not) is
shown on the screen while the app stays open.
"""

from __future__ import annotations

from pathlib import Path

from rich.text import Text
from textual import events, on
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import Screen
from textual.widgets import Button, Footer, ProgressBar, Static
from textual.worker import Worker
from textual_plotext import PlotextPlot

from ladartui.study.chart import TABLE_COLUMNS, draw_chart, label_places, legend_text, table_rows
from ladartui.textsafe import visible
from ladartui.tui.fitted_tables import FittingTable, fill_whole_columns
from ladartui.tui.plain_text import PlainStatic
from ladartui.tui.status import BUSY, READY, StatusBar
from ladartui.tui.work import JobDone, JobProgress, running, start_job

NARROW = 100  # columns


class StudyScreen(Screen):
    """Run the study on the open scenario (or the generated scenes) and show its chart."""

    BINDINGS = [
        # every key, this screen's too; ? as elsewhere; its id: keys.toml remaps it here too
        Binding("f1,question_mark", "app.help", "Help", id="help"),
        Binding("q", "run('quick')", "Quick study"),
        Binding("f", "run('full')", "Full study"),
        Binding("ctrl+x", "cancel", "Cancel", priority=True),  # as on the sweep screen and the main one
        Binding("escape", "close", "Back"),
    ]
    DEFAULT_CSS = """
    StudyScreen { layout: vertical; }
    StudyScreen #study-top { height: 1fr; }
    StudyScreen #study-chart-box { width: 3fr; }
    StudyScreen #study-chart { height: 1fr; min-height: 16; }
    StudyScreen #study-legend { height: auto; padding: 0 1; }
    StudyScreen #study-side { width: 2fr; }
    StudyScreen #study-table { height: 1fr; }
    StudyScreen.-narrow #study-chart-box, StudyScreen.-narrow #study-side { width: 1fr; }
    StudyScreen #study-table-note { height: auto; padding: 0 1; color: $text-muted; }
    StudyScreen #study-verdict { height: auto; max-height: 12; overflow-y: auto; padding: 0 1; }
    StudyScreen #study-bar { height: 1; }
    StudyScreen #study-bar Button { margin-left: 1; }
    StudyScreen #study-status #cancel { display: none; }  /* the row below has the screen's */
    StudyScreen ProgressBar { width: 1fr; }
    /* the bar gives way to its percentage: at 80 columns the buttons leave the row 29,
    less than Textual's 32-column bar, and "100%" fell off its end */
    StudyScreen #study-progress Bar { width: 1fr; max-width: 32; }
    """

    def __init__(self, scenario_path=None, scans: int | None = None, runs: int | None = None, **kwargs):
        super().__init__(**kwargs)
        self.scenario_path = scenario_path
        self.scans = scans
        self.runs = runs
        self.result = None
        self.worker: Worker | None = None  # the study job while it runs

    def compose(self) -> ComposeResult:
        with Horizontal(id="study-top"):
            with Vertical(id="study-chart-box"):
                yield PlotextPlot(id="study-chart")
                yield Static("", id="study-legend")  # beside the points, never over them
            with Vertical(id="study-side"):
                yield FittingTable(self._fill_table, id="study-table", zebra_stripes=True, cursor_type="row")
                yield PlainStatic("", id="study-table-note")
                yield Static("", id="study-verdict")
        # green ready, red busy with its progress, as on the main and sweep screens; one
        # line: a long path gives way, not the keys, and a line cut short (where the study
        # was kept, why the last one is not shown) comes whole as a note
        yield StatusBar(id="study-status", tell=self._tell_cut, tell_states=(READY,))
        with Horizontal(id="study-bar"):
            yield ProgressBar(total=1, id="study-progress", show_eta=False)  # idle: 0 %, not animated
            yield Button("Quick", id="study-quick", compact=True)
            yield Button("Full", id="study-full", compact=True)
            yield Button("Cancel", id="study-cancel", compact=True, variant="error", disabled=True)
        yield Footer()

    def _fill_table(self) -> None:
        """The settings' table: whole columns only, those left out named below it."""
        rows: list[tuple[str, ...]] = table_rows(self.result) if self.result is not None else []
        left_out = fill_whole_columns(self.query_one("#study-table", FittingTable), TABLE_COLUMNS, rows)
        note = self.query_one("#study-table-note", Static)
        from ladartui.study.results import study_folder

        folder = study_folder(self.scenario_path).name
        note.update(f"no room here for {', '.join(left_out)}: see study.csv in {folder}" if left_out else "")
        note.display = bool(left_out and rows)

    def on_mount(self) -> None:
        self._fill_table()
        self._set_status(self._idle_text())
        plot = self.query_one("#study-chart", PlotextPlot).plt
        # short: plotext drops a title wider than the chart (half of 80 columns)
        plot.title("Speed vs accuracy: q quick, f full")
        self._reopen()

    def _reopen(self) -> None:
        """Show the last study of this scenario, if one was kept."""
        from ladartui.errors import LadarError
        from ladartui.study.results import read_study, study_folder

        path = study_folder(self.scenario_path) / "study.json"
        if not path.is_file():
            return
        try:
            result = read_study(path)
        except LadarError as error:
            self._set_status(f"last study not shown: {error}")
            return
        self.show_result(result)
        when = (result.context or {}).get("created_utc", "")
        self._set_status(f"last study{' of ' + when if when else ''} ({path}): q quick, f full to run again")

    def _idle_text(self) -> str:
        # the file's name: a folder cut to fit cut the name too ("/tmp/...fault.toml")
        where = Path(self.scenario_path).name if self.scenario_path else "the generated scenes"
        return f"Study on {where}: q quick, f full, Esc back"

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
        if running(self.worker):
            return
        self._set_busy(True, f"preparing the {mode} study ...", progress=0.0)
        scenario_path, scans, runs = self.scenario_path, self.scans, self.runs
        self.worker = start_job(
            self, "study", lambda cancel, progress: _study(mode, scenario_path, scans, runs, cancel, progress)
        )
        self.refresh_bindings()  # Cancel joins the footer

    def work_going_on(self) -> str | None:
        """What Ctrl+C would be pressed to stop (the app says how): the study, while it runs."""
        return "study" if running(self.worker) else None

    def action_cancel(self) -> None:
        if running(self.worker):
            self.worker.cancel()
            bar = self.query_one("#study-status", StatusBar)
            self._set_status("cancelling after the current trace ...", BUSY, bar.progress)

    def action_close(self) -> None:
        if running(self.worker):
            self.worker.cancel()
        self.dismiss(self.result)

    def on_job_progress(self, message: JobProgress) -> None:
        if message.detail is not None:
            self._show_progress(message.detail)
        else:
            self._set_status(message.text, BUSY, self.query_one("#study-status", StatusBar).progress)

    def on_job_done(self, message: JobDone) -> None:
        if message.cancelled:
            self._finish(None, "study cancelled")
        elif message.error:
            self.notify(f"Study failed: {message.error}", severity="error", markup=False, timeout=15)
            self._finish(None, f"error: {message.error}", said=True)
        else:
            result, text = message.result
            self._finish(result, text)

    # -- updates on the UI thread ---------------------------------------------

    def _show_progress(self, p) -> None:
        self.query_one("#study-progress", ProgressBar).update(total=max(p.total, 1), progress=p.done)
        self._set_status(f"{p.label}, scan {p.scan}/{p.scans}", BUSY, p.done / max(p.total, 1))

    def _finish(self, result, message: str, said: bool = False) -> None:
        self._set_busy(False, message, said=said)
        if result is not None:
            self.show_result(result)
        else:  # cancelled or failed: the bar goes back to idle, not left part-way
            self.query_one("#study-progress", ProgressBar).update(total=1, progress=0)

    def show_result(self, result) -> None:
        """Draw ``result``'s chart, table and verdict."""
        self.result = result
        self._draw_chart()
        self.call_after_refresh(self._draw_chart)  # again once the chart has its size
        self._fill_table()
        # its reasons may come from a study.json: never markup, escapes shown
        self.query_one("#study-verdict", Static).update(Text(visible(result.verdict())))

    def _draw_chart(self) -> None:
        # labels are placed for the chart's size, so that none covers another or a point
        if self.result is None:
            return
        plot = self.query_one("#study-chart", PlotextPlot)
        width, height = plot.size
        draw_chart(plot.plt, self.result, labels=label_places(self.result, width, height))
        plot.refresh()
        legend = self.query_one("#study-legend", Static)
        legend.update(Text.from_ansi(legend_text(self.result, max(20, width - 2))))

    def on_resize(self, event: events.Resize) -> None:
        # a narrow terminal: the settings' table takes half the width, not two fifths
        self.set_class(event.size.width < NARROW, "-narrow")
        self.call_after_refresh(self._draw_chart)

    def check_action(self, action: str, parameters) -> bool | None:
        # Cancel in the footer only while a study runs: idle, the key had nothing to do
        return running(self.worker) if action == "cancel" else True

    def _set_busy(self, busy: bool, message: str, progress: float | None = None, said: bool = False) -> None:
        self.refresh_bindings()
        self.query_one("#study-cancel", Button).disabled = not busy
        self.query_one("#study-quick", Button).disabled = busy
        self.query_one("#study-full", Button).disabled = busy
        self._set_status(message, BUSY if busy else READY, progress, said)

    def _tell_cut(self, message: str) -> None:
        self.notify(message, markup=False, timeout=8)

    def _set_status(
        self, message: str, state: str = READY, progress: float | None = None, said: bool = False
    ) -> None:
        """``said``: the message was just said whole in a note of its own."""
        # it may name files: shown as text, the scenario's path shortened first
        path = str(self.scenario_path) if self.scenario_path else None
        self.query_one("#study-status", StatusBar).show(state, message, progress, name=path, said=said)


def _study(mode: str, scenario_path, scans, runs, cancel, progress):
    """The study job (worker thread): (result, what was done)."""
    from ladartui.resources import RAISE_IN_TUI, RayLimitError
    from ladartui.study import full_settings, quick_settings
    from ladartui.study.inputs import generated_inputs, scenario_inputs
    from ladartui.study.results import study_folder
    from ladartui.study.run import check_outputs, run_study, write_outputs

    folder = study_folder(scenario_path)
    check_outputs(folder)  # before the study, not after it
    quick = mode == "quick"
    scans = scans or (2 if quick else 3)
    runs = runs or (3 if quick else 5)
    if scenario_path:
        inputs = scenario_inputs(scenario_path, scans)
    else:
        inputs = generated_inputs(
            "small" if quick else "reference", scans, progress=lambda text: progress(None, text)
        )
    settings = quick_settings() if quick else full_settings()
    try:
        result = run_study(
            inputs,
            settings,
            runs=runs,
            cancel=cancel,
            progress=lambda p: progress(p.done / max(p.total, 1), p.label, p),
        )
    except RayLimitError as refused:  # raised here as F5 says it: the variable, set before starting
        raise refused.advising(RAISE_IN_TUI) from None
    write_outputs(result, folder)  # kept, so the screen reopens it next time
    return result, f"{mode} study done on {inputs.name}; kept in {folder}"
