"""The question asked before unsaved edits would be discarded: save, discard or cancel."""

from __future__ import annotations

from rich.markup import escape
from textual import on
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Static


class UnsavedScreen(ModalScreen[str | None]):
    """Dismissed with "save", "discard" or None (cancel, Esc)."""

    BINDINGS = [Binding("escape", "cancel", "Cancel")]
    DEFAULT_CSS = """
    UnsavedScreen { align: center middle; }
    UnsavedScreen > Vertical { width: 60; height: auto; border: thick $warning;
                               background: $surface; padding: 1 2; }
    UnsavedScreen Horizontal { height: auto; margin-top: 1; }
    UnsavedScreen Button { margin-right: 2; }
    """

    def __init__(self, name: str, doing: str):
        super().__init__()
        self.scenario_name, self.doing = name, doing

    def compose(self) -> ComposeResult:
        with Vertical():
            yield Static(f"{escape(self.scenario_name)} has unsaved edits. "
                         f"Save them before you {escape(self.doing)}?")
            with Horizontal():
                yield Button("Save", id="unsaved-save", variant="primary", compact=True)
                yield Button("Discard", id="unsaved-discard", variant="error", compact=True)
                yield Button("Cancel", id="unsaved-cancel", compact=True)

    @on(Button.Pressed)
    def _chosen(self, event: Button.Pressed) -> None:
        choice = event.button.id.removeprefix("unsaved-")
        self.dismiss(None if choice == "cancel" else choice)

    def action_cancel(self) -> None:
        self.dismiss(None)
