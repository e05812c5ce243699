"""Unsaved edits: fields typed but not committed, and the save / discard / cancel
question asked before they would be lost; and the question before quitting cancels
a run."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from textual import on
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button

from ladartui.errors import LadarError
from ladartui.textsafe import single_line
from ladartui.tui.host import Host
from ladartui.tui.params import ParamField, field_message
from ladartui.tui.plain_text import PlainStatic

Answer = TypeVar("Answer")


class QuestionScreen(ModalScreen[Answer]):
    """A question about the scenario in a warning box, its answers as buttons below."""

    DEFAULT_CSS = """
    QuestionScreen { align: center middle; }
    QuestionScreen > Vertical { width: 60; height: auto; border: thick $warning;
                                background: $surface; padding: 1 2; }
    QuestionScreen Horizontal { height: auto; margin-top: 1; }
    QuestionScreen Button { margin-right: 2; }
    """


class UnsavedScreen(QuestionScreen[str | None]):
    """Dismissed with "save", "discard" or None (cancel, Esc)."""

    BINDINGS = [Binding("escape", "cancel", "Cancel")]

    def __init__(self, name: str, doing: str, rereads: bool = False):
        """``rereads``: what is being done opens the file being edited, so saving first
        would only be undone by the file it opens (no Save is offered)."""
        super().__init__()
        self.scenario_name, self.doing, self.rereads = name, doing, rereads

    def compose(self) -> ComposeResult:
        name = self.scenario_name
        if self.rereads:
            question = (
                f"{name} has unsaved edits, and opening it reads the file again: they would be "
                "lost. Discard them, or Cancel (Save As keeps them under another name)."
            )
        else:
            question = f"{name} has unsaved edits. Save them before you {self.doing}?"
        with Vertical():
            yield PlainStatic(single_line(question))
            with Horizontal():
                if not self.rereads:
                    yield Button("Save", id="unsaved-save", variant="primary", compact=True)
                yield Button("Discard", id="unsaved-discard", variant="error", compact=True)
                yield Button("Cancel", id="unsaved-cancel", compact=True)

    @on(Button.Pressed)
    def _chosen(self, event: Button.Pressed) -> None:
        choice = (event.button.id or "").removeprefix("unsaved-")
        self.dismiss(None if choice == "cancel" else choice)

    def action_cancel(self) -> None:
        self.dismiss(None)


class QuitRunScreen(QuestionScreen[bool]):
    """Dismissed with True to quit (cancelling the run), False to keep it running (Esc)."""

    BINDINGS = [Binding("escape", "keep", "Keep running")]

    def __init__(self, name: str, progress: float | None):
        super().__init__()
        self.scenario_name, self.progress = name, progress

    def compose(self) -> ComposeResult:
        done = f" ({100 * self.progress:.0f}%)" if self.progress is not None else ""
        with Vertical():
            yield PlainStatic(
                single_line(
                    f"A run of {self.scenario_name} is going on{done}. Quit and cancel it? "
                    "The outputs on disk stay as they were."
                ),
                id="quit-run-question",
            )
            with Horizontal():
                yield Button("Keep running", id="quit-run-keep", variant="primary", compact=True)
                yield Button("Quit", id="quit-run-quit", variant="error", compact=True)

    @on(Button.Pressed)
    def _chosen(self, event: Button.Pressed) -> None:
        self.dismiss(event.button.id == "quit-run-quit")

    def action_keep(self) -> None:
        self.dismiss(False)


class EditGuard(Host):
    """The app's guard over pending and unsaved edits (mixed into ``LadarApp``, which
    provides ``scenario``, ``modified``, ``commit_field``, ``tell`` and ``action_save``)."""

    def commit_pending(self) -> bool:
        """Commit every field whose text differs from its committed value.

        Run, Save and every action that reads the scenario call this first, so
        nothing runs or is saved that differs from the screen. An invalid
        pending value stops the action: the field is focused and the app says
        why; False is returned.
        """
        if self.scenario is None:
            return True
        for field in self.query(".param").results(ParamField):
            if field.value == field.committed:
                continue
            try:
                field.parsed()
            except LadarError as error:  # said as Enter says it: the form's label and units
                field.focus()
                self.tell(
                    f"{field_message(field.param, field.value, error)}. Correct the value and try again.",
                    title="Not done: invalid value",
                    severity="error",
                    timeout=8,
                )
                return False
            self.commit_field(field)
        return True

    def unsaved(self) -> bool:
        """Edits that a save would keep: committed ones, or text typed in a field."""
        return self.scenario is not None and (
            self.modified or any(f.value != f.committed for f in self.query(".param").results(ParamField))
        )

    def confirm_quit(self) -> None:
        """Quit: a run going on is cancelled only when the analyst says so, then unsaved
        edits are asked about as ever."""
        scenario = self.scenario
        if not self.run_in_progress() or scenario is None:
            self.confirm_discard("quit", self.exit)
            return

        def chosen(quit_anyway: bool | None) -> None:
            if quit_anyway:
                self.confirm_discard("quit", self.exit)

        self.push_screen(QuitRunScreen(scenario.path.name, self.progress), chosen)

    def confirm_discard(self, doing: str, then: Callable[[], None], opens: Path | None = None) -> None:
        """Call ``then`` once unsaved edits are saved or the analyst chose to discard them;
        ``opens``: the file ``then`` opens (when it is this one, saving is not offered)."""
        scenario = self.scenario
        if scenario is None or not self.unsaved():
            then()
            return

        def chosen(choice):
            if choice == "save":
                self.save_before_leaving()
                if not self.unsaved():
                    then()
            elif choice == "discard":
                then()

        rereads = opens is not None and Path(opens).resolve() == Path(scenario.path).resolve()
        self.push_screen(UnsavedScreen(scenario.path.name, doing, rereads), chosen)
