"""The sweep screen's opening of a spec or results: read in a worker, shown when read.

``open_sweep`` reads the results table and hashes the base's models, which can
take seconds, so it runs as a job (tui/work.py); of several opens only the last
asked for is shown, and none over a sweep started meanwhile.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from textual.widget import Widget
from textual.widgets import DataTable

from ladartui.errors import FieldError, LadarError
from ladartui.number_text import plural
from ladartui.recent import remember_path
from ladartui.tui.status import BUSY, NOT_READY, READY
from ladartui.tui.sweep_jobs import in_form_words, open_sweep
from ladartui.tui.sweep_ranking import RankingView
from ladartui.tui.sweep_view import short_path
from ladartui.tui.work import start_job

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from textual.worker import Worker

    from ladartui.sweep.spec import SweepSpec


class SweepOpening(RankingView):
    """Opens a spec, a results.csv or a results folder into the ranking (``_open``)."""

    spec: SweepSpec | None
    out: Path | None
    budget: float | None
    progress: Any  # the last SweepProgress, None before one
    running: bool
    opening: Worker | None  # the last open asked for
    _opens: int  # opens asked for: an answer to an earlier one is dropped
    _focus_table: bool  # the last open was asked for, so its table takes the focus
    _focused_at_open: Widget | None  # where the focus was when it was asked for
    _status: Callable[..., None]  # the screen's status bar (SweepScreen._status)

    def _open(self, text: str, focus_table: bool = True) -> None:
        """Open a spec or results in a worker (``open_sweep`` reads the table and hashes
        the base's models, which can take seconds); ``_show_opened`` shows them.
        ``focus_table``: False for the screen's own reopen, which leaves the focus (and
        what is typed next) in the Spec field."""
        self._opens += 1
        self._focus_table = focus_table
        self._focused_at_open = self.focused
        number = self._opens

        def read(cancel, progress):
            try:
                return number, open_sweep(text), None
            except LadarError as error:  # an empty Spec field named as the form names it
                said = in_form_words(error) if isinstance(error, FieldError) else error
                return number, None, str(said)

        self._status(BUSY, f"opening {text} ...")
        self.opening = start_job(self, "open", read)

    def _opened(self, answer) -> None:
        number, opened, error = answer
        if number != self._opens or self.running:  # another open, or a sweep, came after it
            return
        if error is not None:
            self._status(NOT_READY, error, problem=True)
            return
        self._show_opened(opened)

    def _show_opened(self, opened) -> None:
        spec, result, own, path = opened.spec, opened.result, opened.own, opened.path
        if result is None:  # a spec not run yet
            self.spec, self.out, self.rows, self.ranking = spec, opened.out, [], []
            self.objective, self.cost, self.budget = spec.objective, spec.cost, spec.budget
            self.parameter_names = spec.parameter_names
            self._redraw()
            self._show_stored(len(spec.variants))
            self._status(
                NOT_READY,
                f"{path}: {plural(len(spec.variants), 'variant')}, no results yet: F5 runs the sweep",
            )
            remember_path("sweeps", path)
            return
        self.spec = spec
        self.out = opened.out
        self.rows, self.ranking = result.rows, result.ranking
        self.objective, self.cost, self.budget = result.objective, result.cost, result.budget
        self.parameter_names = spec.parameter_names if spec else result.parameter_names
        left_out = ""
        if own is not None and len(own) < len(result.rows):
            self.rows = own
            # said first: after the ranking's words it was cut off at 80 columns
            earlier = opened.earlier_base
            others = len(result.rows) - len(own) - earlier
            kinds = [
                words for count, words in ((others, "other variants"), (earlier, "an earlier base")) if count
            ]
            left_out = f"{plural(len(result.rows) - len(own), 'row')} not ranked: {', '.join(kinds)}; "
            self._rank_quietly()
        self.progress = None
        self._redraw(best=True)
        self._show_stored(len(spec.variants) if spec else len(self.rows))
        # (unless the analyst has moved the focus since: Enter, F3 or Browse left it put)
        if self._focus_table and self.focused in (None, self._focused_at_open):
            self.query_one("#sweep-table", DataTable).focus()
        table = short_path(result.results_path)
        if not self.rows:  # a header alone, or lines torn or edited by hand (left out)
            self._status(NOT_READY, f"{left_out}no variant rows to rank in {table}")
        else:
            self._status(READY, f"{left_out}ranked by {self.objective}: {self._summary()}; {table}")
        remember_path("sweeps", path)  # the screen reopens it next time
