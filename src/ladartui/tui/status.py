"""The status colour bar (report table 1): yellow not ready, green ready, red busy."""

from __future__ import annotations

import math
from typing import Any

from rich.cells import cell_len
from rich.text import Text
from textual.app import ComposeResult
from textual.containers import Horizontal
from textual.widgets import Button, Static

NOT_READY, READY, BUSY = "not-ready", "ready", "busy"
LABELS = {NOT_READY: "NOT READY", READY: "READY", BUSY: "BUSY"}


def format_eta(seconds: float | None) -> str:
    """``1h02m``, ``3m05s`` or ``12s``; ``--`` when unknown."""
    if seconds is None or not math.isfinite(seconds):
        return "--"
    seconds = max(0, int(round(seconds)))
    hours, rest = divmod(seconds, 3600)
    minutes, secs = divmod(rest, 60)
    if hours:
        return f"{hours}h{minutes:02d}m"
    if minutes:
        return f"{minutes}m{secs:02d}s"
    return f"{secs}s"


class StatusText(Static):
    """The message, in one line at any width: a scenario name (its longest word)
    shortened in the middle so that what follows it (modified, scans, keys) stays."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("", markup=False, **kwargs)  # names from files: plain text
        self.message = ""

    def show(self, message: str) -> None:
        self.message = message
        self.refresh()

    def render(self) -> Text:
        room = self.content_size.width
        return Text(self.message if room <= 0 else shortened_name(self.message, room))


class StatusBar(Horizontal):
    """One line: the state word on its colour, the message, and the Cancel button."""

    DEFAULT_CSS = """
    StatusBar { height: 1; background: $panel; }
    StatusBar #status-word { width: 11; text-style: bold; content-align: center middle; }
    StatusBar #status-text { width: 1fr; padding: 0 1; }
    StatusBar.-not-ready #status-word { background: #d7af00; color: #000000; }
    StatusBar.-not-ready #status-text { background: #3a3000; color: #ffffd7; }
    StatusBar.-ready #status-word { background: #00af00; color: #000000; }
    StatusBar.-ready #status-text { background: #003a00; color: #d7ffd7; }
    StatusBar.-busy #status-word { background: #d70000; color: #ffffff; }
    StatusBar.-busy #status-text { background: #3a0000; color: #ffd7d7; }
    StatusBar #cancel { min-width: 10; }
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.state = NOT_READY
        self.message = ""
        self.progress: float | None = None

    def compose(self) -> ComposeResult:
        yield Static(LABELS[NOT_READY], id="status-word")
        yield StatusText(id="status-text")
        yield Button("Cancel", id="cancel", compact=True, variant="error", disabled=True)

    def on_mount(self) -> None:
        self.set_class(True, f"-{self.state}")

    def show(
        self, state: str, message: str, progress: float | None = None, cancellable: bool = False
    ) -> None:
        """Show ``state`` with ``message``; ``progress`` 0..1 adds a percentage."""
        for name in LABELS:
            self.set_class(name == state, f"-{name}")
        self.state, self.message, self.progress = state, message, progress
        word = LABELS[state]
        if progress is not None:
            word = f"{word} {100 * progress:3.0f}%"
        self.query_one("#status-word", Static).update(word)
        self.query_one("#cancel", Button).disabled = not cancellable
        self.query_one(StatusText).show(message)


MIN_NAME = 10  # cells a shortened name keeps


def shortened_name(message: str, room: int) -> str:
    """``message`` with its longest word cut in the middle (``night-app…final.toml``) so
    that the whole fits ``room`` cells, the word keeping at least ``MIN_NAME``."""
    over = cell_len(message) - room
    if over <= 0:
        return message
    word = max(message.split(" "), key=cell_len)
    keep = max(MIN_NAME, cell_len(word) - over - 1)  # one cell for the ellipsis
    if keep >= len(word):
        return message
    head = keep // 3  # the end tells names apart more often (a suffix, the extension)
    return message.replace(word, word[:head] + "\u2026" + word[len(word) - (keep - head) :], 1)
