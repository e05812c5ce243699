"""Flight-path sweeps as a screen: launch or open a sweep, watch it, browse the ranking.

The sweep is a job (``tui/work.py``) running ``ladartui.sweep.run_sweep``;
each finished variant reaches the screen as a kept progress report, and the
ranking and chart are redrawn at most a few times a second. Cancel cancels
the worker, whose event the sweep checks between variants (and between
trace chunks): the rows finished so far stay in ``results.csv`` and running
the spec again resumes. Any failure is shown in the status bar; none closes
the app.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from rich.text import Text
from textual import events, on
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal
from textual.message import Message
from textual.validation import ValidationResult, Validator
from textual.widgets import Button, Checkbox, DataTable, Footer, Input, Label, ProgressBar, Static
from textual_plotext import PlotextPlot

from ladartui.errors import FieldError, LadarError
from ladartui.fileprobe import user_path
from ladartui.number_text import plural
from ladartui.recent import recent_paths, remember_path
from ladartui.sweep.ranking import BUDGET_OBJECTIVES, OBJECTIVES
from ladartui.textsafe import single_line
from ladartui.tui.fields import refusal
from ladartui.tui.status import BUSY, NOT_READY, READY, StatusBar, format_eta
from ladartui.tui.sweep_jobs import (
    StoredRows,
    in_form_words,
    spec_to_run,
    start_resource_tracker,
    sweep_job,
    write_best,
)
from ladartui.tui.sweep_opening import SweepOpening
from ladartui.tui.sweep_view import (
    eta_seconds,
    short_path,
)
from ladartui.tui.work import JobDone, JobProgress, start_job

BUDGET_LABEL = "Budget s"  # the field as its label names it, in messages too

if TYPE_CHECKING:
    from textual.worker import Worker

    from ladartui.sweep.ranking import Ranked
    from ladartui.sweep.spec import SweepSpec

OBJECTIVE_ORDER = tuple(OBJECTIVES)  # F6 steps through them in this order
COST_ORDER = ("flight-time", "distance")
VIEWS = ("both", "table", "chart")
WHILE_IDLE = ("run", "open_results", "browse")  # keys off (and out of the footer) while a sweep runs
REDRAW_SECONDS = 0.4  # the ranking and chart are redrawn at most this often while running


class ExistingPath(Validator):
    """An Input validator: the path must exist (a spec, a results.csv or a results folder)."""

    def validate(self, value: str) -> ValidationResult:
        if not value.strip() or user_path(value.strip()).exists():
            return self.success()
        return self.failure(f"{value.strip()}: no such file or folder")


class SweepScreen(SweepOpening):
    """Launch a flight-path sweep (or open an earlier one), watch it and rank its variants."""

    class OpenScenario(Message):
        """The analyst asked to open the best flight path's scenario file."""

        def __init__(self, path) -> None:
            super().__init__()
            self.path = Path(path)

    BINDINGS = [
        # every key, this screen's too; ? as elsewhere; its id: keys.toml remaps it here too
        Binding("f1,question_mark", "app.help", "Help", id="help"),
        Binding("f5", "run", "Run", priority=True),
        Binding("f3", "open_results", "Open", priority=True),
        # its button names its key: the footer's room goes to keys named nowhere else
        Binding("f2", "browse", "Browse", priority=True, show=False),
        Binding("ctrl+x", "cancel", "Cancel", priority=True),
        Binding("f6", "objective", "Rank by", priority=True),
        Binding("f7", "cost", "Cost", priority=True),
        Binding("f8", "best", "Best", priority=True),
        Binding("f9", "view", "View", priority=True),
        Binding("escape", "close", "Back", priority=True),
    ]
    DEFAULT_CSS = """
    SweepScreen { layout: vertical; }
    SweepScreen .sweep-row { height: 1; }
    SweepScreen .sweep-row > Label { padding: 0 1; }  /* not the progress bar's percentage */
    SweepScreen #sweep-path { width: 1fr; }
    SweepScreen #sweep-scheduler, SweepScreen #sweep-certs { width: 1fr; }
    SweepScreen #sweep-budget { width: 9; }
    SweepScreen #sweep-serial { width: auto; margin-left: 1; }
    SweepScreen #sweep-progress { width: auto; padding: 0 1; }
    SweepScreen #sweep-progress Bar { width: 20; }
    SweepScreen #sweep-counts { width: 1fr; }
    SweepScreen #sweep-body { height: 1fr; }
    SweepScreen #sweep-table { width: 3fr; height: 1fr; }
    SweepScreen #sweep-chart { width: 2fr; height: 1fr; margin-left: 2; }  /* apart from the table */
    SweepScreen #sweep-body.-table #sweep-chart { display: none; }
    SweepScreen #sweep-body.-chart #sweep-table { display: none; }
    /* a failed variant's error wraps rather than being cut at 80 columns */
    SweepScreen #sweep-detail { height: auto; max-height: 3; padding: 0 1; background: $panel; }
    """

    def __init__(
        self,
        spec_path=None,
        *,
        scheduler: str | None = None,
        serial: bool = False,
        connect_timeout: float = 30.0,
        certs=None,
        **kwargs,
    ):
        """``spec_path``: a sweep spec, results.csv or results folder to open at once;
        ``scheduler``: a Dask scheduler address to fill in; ``serial``: run without Dask."""
        super().__init__(**kwargs)
        self.connect_timeout = connect_timeout
        self.initial_path = str(spec_path) if spec_path else ""
        self.initial_scheduler = scheduler or ""
        self.initial_certs = str(certs) if certs else ""
        self.serial = serial
        self.spec: SweepSpec | None = None  # launched or opened, when known
        self.out: Path | None = None  # the results folder shown
        self.rows: list[dict] = []
        self.parameter_names: list[str] = []
        self.ranking: list[Ranked] = []
        self.objective = "obscured-coverage"
        self.cost = "flight-time"
        self.budget: float | None = None  # the spec's or the results' budget
        self.view = "both"
        self.progress = None  # the last SweepProgress
        self.last_message = ""
        self._problem = False  # the message shown is an error
        self.running = False
        self.left_running = False  # Esc left the screen while a sweep ran (and cancelled it)
        self.worker: Worker | None = None  # the sweep job while it runs
        self.opening: Worker | None = None  # the last open asked for (read off the UI thread)
        self._opens = 0  # opens asked for: an answer to an earlier one is dropped
        self._focus_table = False  # the last open was asked for: its table takes the focus
        self._focused_at_open = None
        self._dirty = False  # rows arrived since the last redraw (redrawn a few times a second)
        self._row_index: dict[str, int] = {}  # variant id -> position in rows, while running
        self._shown_ids: list = []  # variant ids in table order

    # -- layout ---------------------------------------------------------------

    def compose(self) -> ComposeResult:
        with Horizontal(classes="sweep-row"):
            yield Label("Spec")
            yield Input(
                self.initial_path,
                id="sweep-path",
                compact=True,
                placeholder="sweep spec .toml, or results.csv / results folder",
                validators=[ExistingPath()],
                validate_on=["changed", "submitted"],
                valid_empty=True,
            )
            yield Button("Browse F2", id="sweep-browse", compact=True)
        with Horizontal(classes="sweep-row"):
            yield Label("Scheduler")
            yield Input(
                self.initial_scheduler,
                id="sweep-scheduler",
                compact=True,
                placeholder="tcp://HOST:8786 (empty: this machine)",
            )
            yield Label(BUDGET_LABEL)
            yield Input(id="sweep-budget", compact=True, type="number", placeholder="spec", valid_empty=True)
            yield Checkbox(
                "serial",
                self.serial,
                id="sweep-serial",
                compact=True,
                tooltip="run the variants in this process, without Dask",
            )
        with Horizontal(classes="sweep-row"):
            yield Label("Certificates")
            yield Input(
                self.initial_certs,
                id="sweep-certs",
                compact=True,
                placeholder="folder from 'ladartui certs' (for a tls:// scheduler)",
            )
        with Horizontal(classes="sweep-row"):
            yield ProgressBar(total=1, id="sweep-progress", show_eta=False)  # idle: 0 %, not animated
            yield Static("", id="sweep-counts")
        with Horizontal(id="sweep-body"):
            yield DataTable(id="sweep-table", cursor_type="row", zebra_stripes=True)
            yield PlotextPlot(id="sweep-chart")
        yield Static("", id="sweep-detail")
        # a message the line cuts comes whole as a note (a scheduler's error runs to 200
        # characters; why F6 skipped an objective comes last), a busy sweep's progress aside
        yield StatusBar(id="sweep-status", tell=self._tell_cut, tell_states=(NOT_READY, READY))
        yield Footer(compact=True)

    def on_mount(self) -> None:
        self.set_interval(REDRAW_SECONDS, self._redraw_if_dirty)
        self._draw_table()
        self._draw_chart()
        self._status(NOT_READY, "type a sweep spec (F5 runs it) or a results folder (F3 opens it)")
        self.query_one("#sweep-path", Input).focus()
        if not self.initial_path:  # reopen the last sweep opened or run
            last = recent_paths("sweeps")
            if last:
                self.initial_path = str(last[0])
                self.query_one("#sweep-path", Input).value = self.initial_path
        if self.initial_path:  # not asked for by a key: typing still goes to the Spec field
            self._open(self.initial_path, focus_table=False)

    # -- paths and checks -------------------------------------------------------

    def _path_text(self) -> str:
        return self.query_one("#sweep-path", Input).value.strip()

    def _typed_budget(self) -> float | None:
        """The Budget field (seconds), or None when empty; LadarError naming the field when
        not a finite number above 0."""
        text = self.query_one("#sweep-budget", Input).value.strip()
        if not text:
            return None
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value > 0):
            expected = "a flight time in seconds, greater than 0 and finite (empty: the spec's budget)"
            raise LadarError(refusal(BUDGET_LABEL, text, expected))
        return value

    def _budget(self) -> float | None:
        typed = self._typed_budget()
        return typed if typed is not None else self.budget

    # -- actions ------------------------------------------------------------------

    def action_run(self) -> None:
        """Check the spec and start the sweep in a thread worker (nothing starts on a mistake)."""
        if self.running:
            self._status(BUSY, "a sweep is already running: Ctrl+X cancels it", cancellable=True)
            return
        try:
            spec = spec_to_run(self._path_text())
            typed = self._typed_budget()
            budget = typed if typed is not None else spec.budget
            # The objective and cost chosen here carry over when the same spec runs again.
            same = self.spec is not None and self.spec.path.resolve() == spec.path.resolve()
            objective = self.objective if same else spec.objective
            cost = self.cost if same else spec.cost
            if objective in BUDGET_OBJECTIVES and budget is None:
                expected = f"a flight time in seconds: ranking by {objective} needs a budget"
                raise LadarError(refusal(BUDGET_LABEL, "", expected))
            scheduler = self.query_one("#sweep-scheduler", Input).value.strip()
            security = None
            if scheduler:  # the same rules as the CLI: no plain scheduler off this machine
                from ladartui.sweep.security import folder_security

                security = folder_security(scheduler, self.query_one("#sweep-certs", Input).value.strip())
        except LadarError as error:
            said = in_form_words(error) if isinstance(error, FieldError) else error
            self._status(NOT_READY, str(said), problem=True)
            return
        from ladartui.sweep import default_out_dir

        serial = self.query_one("#sweep-serial", Checkbox).value and not scheduler
        self.spec, self.out = spec, default_out_dir(spec)
        self.objective, self.cost, self.budget = objective, cost, spec.budget
        self.parameter_names = spec.parameter_names
        # The rows already stored for this spec come first from the job (StoredRows).
        ids = {variant.id for variant in spec.variants}
        self.rows, self._row_index = [], {}
        self._opens += 1  # an open still being read is not shown over the sweep
        self._rank()
        if not serial and not scheduler:
            start_resource_tracker()
        self.running, self.left_running = True, False
        self.refresh_bindings()
        self.progress = None
        remember_path("sweeps", spec.path)
        self.query_one("#sweep-progress", ProgressBar).update(total=len(ids), progress=0)
        where = f"scheduler {scheduler}" if scheduler else "this process" if serial else "a local cluster"
        # a first sweep's workers compile the kernels before their first variant (minutes)
        self.query_one("#sweep-counts", Static).update(
            f"0/{len(ids)} starting on {where} (a first run also compiles the kernels)"
        )
        self._status(
            BUSY,
            # the folder before the rest: a line cut at 80 columns loses its end
            f"starting {plural(len(ids), 'variant')} into {short_path(self.out)} on {where}",
            0.0,
            cancellable=True,
        )
        timeout = self.connect_timeout
        self.worker = start_job(
            self,
            "sweep",
            lambda cancel, progress: sweep_job(
                spec, scheduler, security, serial, objective, cost, budget, timeout, cancel, progress
            ),
        )

    def action_open_results(self) -> None:
        """Open the results of an earlier (or running elsewhere) sweep."""
        if self.running:
            self._status(BUSY, "a sweep is running: Ctrl+X cancels it first", cancellable=True)
            return
        self._open(self._path_text())

    def check_action(self, action: str, parameters) -> bool | None:
        # Cancel joins the footer only while a sweep runs, and Run and Open, refused then,
        # leave it: so every key fits 80 columns beside the palette's key, run or not
        if action == "cancel":
            return self.running
        if action in WHILE_IDLE:
            return not self.running
        return True

    def on_key(self, event: events.Key) -> None:
        # Run, Open and Browse are off while a sweep runs (not in the footer): their keys,
        # reaching the screen unbound, say why in a note (the status line shows progress)
        if self.running and any(
            isinstance(b, Binding) and b.key == event.key and b.action in WHILE_IDLE for b in self.BINDINGS
        ):
            event.stop()
            self.notify("A sweep is running: Ctrl+X cancels it first.", markup=False, timeout=5)

    def work_going_on(self) -> str | None:
        """What Ctrl+C would be pressed to stop (the app says how): the sweep, while it runs."""
        return "sweep" if self.running else None

    def action_cancel(self) -> None:
        if self.running and self.worker is not None:
            self.worker.cancel()
            self._status(BUSY, "cancelling after the current variant ...", self._fraction())
        else:
            self._status(self._idle_state(), "nothing is running")

    def action_objective(self) -> None:
        """Rank by the next objective (coverage within budget needs a budget)."""
        self._switch("objective", OBJECTIVE_ORDER)

    def action_cost(self) -> None:
        """Switch the Pareto front's cost axis between flight time and distance."""
        self._switch("cost", COST_ORDER)

    def _switch(self, name: str, order) -> None:
        self._status(
            self._idle_state(),
            self._switch_to_next(name, order),
            self._fraction() if self.running else None,
            cancellable=self.running,
        )

    def action_view(self) -> None:
        self.view = VIEWS[(VIEWS.index(self.view) + 1) % len(VIEWS)]
        body = self.query_one("#sweep-body")
        for view in VIEWS:
            body.set_class(view == self.view and view != "both", f"-{view}")

    def action_best(self) -> None:
        """Show the best flight path's scenario file and ask the app to open it."""
        best = self.ranking[0] if self.ranking and self.ranking[0].rank == 1 else None
        if best is None:
            self._status(self._idle_state(), f"no variant can be ranked by {self.objective}")
            return
        if self.spec is not None and self.out is not None:  # set together
            name = f"{self.spec.name}-best"
            if self.objective != self.spec.objective:
                name += f"-{self.objective}"
            self._write_best(
                self.spec, best.row, list(self.parameter_names), self.out / f"{name}.toml", self.objective
            )
            return
        from ladartui.sweep.best_file import best_files

        found = best_files(self.out) if self.out is not None else []
        if not found:
            self._status(
                self._idle_state(),
                "no best-path scenario in the results folder; open the sweep spec to save one",
            )
            return
        self._announce_best(found[0], "the newest a sweep saved here")

    def action_close(self) -> None:
        if self.running and self.worker is not None:
            self.left_running = True  # what the cancel left is said here, once
            self.worker.cancel()
            said = (
                f"sweep cancelled on leaving its screen; the rows so far are kept in {self.out}; F5 resumes"
            )
            self._status(NOT_READY, said)
            self.app.notify(said, severity="warning", markup=False)  # seen on the screen below
        self.dismiss(None)

    @on(Button.Pressed, "#cancel")
    def _cancel_pressed(self) -> None:
        self.action_cancel()

    @on(Button.Pressed, "#sweep-browse")
    def action_browse(self) -> None:
        """Pick a spec, a results.csv or a results folder in a folder tree."""
        if self.running:
            return
        from ladartui.tui.file_dialogs import PickPathScreen

        typed = user_path(self._path_text()) if self._path_text() else None
        start = (
            typed if typed is not None and typed.is_dir() else (typed.parent if typed is not None else None)
        )

        def picked(path) -> None:
            if path is not None:
                self.query_one("#sweep-path", Input).value = str(path)
                self._open(str(path))

        self.app.push_screen(
            PickPathScreen("Sweep spec or results", (".toml", ".csv"), start, folders=True), picked
        )

    @on(Input.Submitted, "#sweep-path")
    def _path_submitted(self) -> None:
        if not self.running:
            self._open(self._path_text())

    @on(Input.Submitted, "#sweep-budget")
    def _budget_submitted(self) -> None:
        try:
            budget = self._budget()  # checked whether or not the ranking reads it
            self._rank()
        except LadarError as error:
            self._status(BUSY if self.running else NOT_READY, str(error), problem=True)
            return
        self._redraw()
        self._status(
            self._idle_state(), f"budget {budget:g} s" if budget is not None else "budget from the spec"
        )

    @on(DataTable.RowHighlighted, "#sweep-table")
    def _row_highlighted(self, event: DataTable.RowHighlighted) -> None:
        self._show_detail(event.cursor_row)

    # -- the sweep worker ---------------------------------------------------------------

    def on_job_progress(self, message: JobProgress) -> None:
        if isinstance(message.detail, StoredRows):
            self._show_stored_rows(message.detail.rows)
        elif message.detail is not None:
            self._show_progress(message.detail)
        else:
            self._status(BUSY, message.text, 0.0, True)

    def on_job_done(self, message: JobDone) -> None:
        if message.job == "open":
            if message.result is not None:
                self._opened(message.result)
            elif message.error:  # not a LadarError: something broke while reading
                self._status(NOT_READY, f"cannot open: {message.error}", problem=True)
        elif message.job == "best":
            if message.error:
                self._status(NOT_READY, f"cannot save the best path: {message.error}")
            elif message.result is not None:
                written, how = message.result
                kept = f"{written.kept.name} kept: {written.kept_why}" if written.kept is not None else ""
                self._announce_best(written.path, how, kept)
        elif message.cancelled:
            self._finish(None, "cancelled")
        else:
            self._finish(message.result, message.error or "")

    # -- updates on the UI thread ------------------------------------------------

    def _show_stored_rows(self, rows: list[dict]) -> None:
        """The rows already stored for the running spec, shown at once (they resume):
        the job's first report, before any variant finishes."""
        self.rows = list(rows)
        self._row_index = {row["variant"]: i for i, row in enumerate(self.rows)}
        self._rank()

    def _show_progress(self, p) -> None:
        self.progress = p
        if p.row is not None:
            index = self._row_index.get(p.row.get("variant"))
            if index is None:  # a new variant; a resumed one replaces its stored row
                self._row_index[p.row.get("variant")] = len(self.rows)
                self.rows.append(p.row)
            else:
                self.rows[index] = p.row
            self._dirty = True
        self.query_one("#sweep-progress", ProgressBar).update(total=max(p.total, 1), progress=p.done)
        self.query_one("#sweep-counts", Static).update(self._counts_text(p))
        if self.worker is not None and not self.worker.is_cancelled:
            self._status(BUSY, f"sweeping into {short_path(self.out)}", p.fraction, cancellable=True)

    def _counts_text(self, p) -> str:
        impossible = f", {p.impossible} impossible" if p.impossible else ""
        return (
            f"{p.done}/{p.total}, {p.failed} failed{impossible}, {p.resumed} resumed, "
            f"ETA {format_eta(eta_seconds(p))}"
        )

    def _finish(self, result, error: str) -> None:
        self.running = False
        self.refresh_bindings()
        p = self.progress
        if result is not None:
            self.rows, self.ranking = result.rows, result.ranking
            self.objective, self.cost, self.budget = result.objective, result.cost, result.budget
            self.out = result.results_path.parent
            self._redraw(best=True)
            note = "".join(
                f", {len(rows)} {what}"
                for rows, what in ((result.failed, "failed"), (result.impossible, "impossible"))
                if rows
            )
            self.query_one("#sweep-progress", ProgressBar).update(
                total=max(len(result.rows), 1), progress=len(result.rows)
            )
            self.query_one("#sweep-counts", Static).update(self._summary())
            self._status(  # no percentage: only a busy bar has one (the progress row says 100%)
                READY,
                f"swept into {short_path(self.out)}: {result.ran} run, {result.resumed} resumed{note} "
                f"in {format_eta(result.elapsed)}",
            )
            return
        self._rank_quietly()
        self._redraw()
        kept = f"{p.done} of {p.total} variants kept" if p else "finished variants kept"
        if error == "cancelled" and self.left_running:
            return  # said on leaving the screen
        if error == "cancelled":
            # the folder in a note: after the counts on the status line it was cut at 80 columns
            self.notify(f"Sweep cancelled: its rows are kept in {self.out}; F5 resumes.", markup=False)
            self._status(READY, f"sweep cancelled: {kept}; F5 resumes")  # F5 runs: ready
        else:
            self._status(NOT_READY, f"sweep stopped: {error}", problem=True)

    def _fraction(self) -> float | None:
        return self.progress.fraction if self.progress is not None else None

    def _idle_state(self) -> str:
        if self.running:
            return BUSY
        return READY if self.ranking else NOT_READY

    def _status(
        self,
        state: str,
        message: str,
        progress: float | None = None,
        cancellable: bool = False,
        problem: bool = False,
    ) -> None:
        """Show ``message`` on the status line; ``problem``: an error (its note, should
        the line cut it, says so)."""
        message = " ".join(message.split())  # always one line
        self.last_message, self._problem = message, problem
        bar = self.query_one("#sweep-status", StatusBar)
        bar.show(state, message, progress, cancellable or self.running)

    def _tell_cut(self, message: str) -> None:
        if self._problem:
            self.notify(message, severity="error", markup=False, timeout=15)
        else:
            self.notify(message, markup=False, timeout=8)

    # -- best path ----------------------------------------------------------------

    def _write_best(self, spec, row: dict, parameter_names, path: Path, objective: str) -> None:
        start_job(
            self,
            "best",
            lambda cancel, progress: (write_best(spec, row, parameter_names, path), f"best by {objective}"),
        )

    def _announce_best(self, path: Path, how: str, kept: str = "") -> None:
        beside = f"; {kept}" if kept else ""
        if kept:  # the app opens the best path next, over this screen's status line
            self.app.notify(f"Best path written to {path.name}; {kept}.", markup=False, timeout=10)
        # paths: never markup
        self.query_one("#sweep-detail", Static).update(Text(single_line(f"best path: {path}{beside}")))
        said = f"best path ({how}): {path}{beside}"
        self._status(self._idle_state(), said, self._fraction() if self.running else None)
        self.post_message(self.OpenScenario(path))
