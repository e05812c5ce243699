"""The status colour bar (report table 1): yellow not ready, green ready, red busy."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from rich.cells import cell_len
from rich.text import Text
from textual.app import ComposeResult
from textual.containers import Horizontal
from textual.widgets import Button, Static

from ladartui.textsafe import single_line

NOT_READY, READY, BUSY = "not-ready", "ready", "busy"
LABELS = {NOT_READY: "NOT READY", READY: "READY", BUSY: "BUSY"}


def format_eta(seconds: float | None) -> str:
    """``1h02m``, ``3m05s``, ``12s`` or ``<1s``; ``--`` when unknown."""
    if seconds is None or not math.isfinite(seconds):
        return "--"
    if seconds < 0.5:  # not "about 0s left" of work still going
        return "<1s"
    seconds = int(seconds + 0.5)  # half up: 0.5 is "1s", never "0s"
    hours, rest = divmod(seconds, 3600)
    minutes, secs = divmod(rest, 60)
    if hours:
        return f"{hours}h{minutes:02d}m"
    if minutes:
        return f"{minutes}m{secs:02d}s"
    return f"{secs}s"


class StatusText(Static):
    """The message, in one line at any width: the scenario's name shortened in its
    middle so that what follows it (modified, scans, keys) stays, else the end cut."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("", markup=False, **kwargs)  # names from files: plain text
        self.message = ""
        self.name_shown: str | None = None

    def show(self, message: str, name: str | None = None) -> None:
        """``message`` and ``name`` as one line each (``StatusBar.show`` writes them so)."""
        self.message, self.name_shown = message, name
        self.refresh()

    def render(self) -> Text:
        room = self.content_size.width
        return Text(self.message if room <= 0 else fitted(self.message, room, self.name_shown))


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

    def __init__(
        self, tell: Callable[[str], None] | None = None, tell_states=(NOT_READY,), **kwargs: Any
    ) -> None:
        """``tell``: says a message of one of ``tell_states`` whole, once, when the line
        has to cut it (why Run is off must not be cut away)."""
        super().__init__(**kwargs)
        self.tell_states = frozenset(tell_states)
        self.state = NOT_READY
        self.message = ""
        self.progress: float | None = None
        self.tell = tell
        self.told = ""  # the cut message last said whole

    def compose(self) -> ComposeResult:
        yield Static(LABELS[NOT_READY], id="status-word")
        yield StatusText(id="status-text")
        yield Button("Cancel", id="cancel", compact=True, variant="error", disabled=True)

    def on_mount(self) -> None:
        self.set_class(True, f"-{self.state}")

    def show(
        self,
        state: str,
        message: str,
        progress: float | None = None,
        cancellable: bool = False,
        name: str | None = None,
        said: bool = False,
    ) -> None:
        """Show ``state`` with ``message``; ``progress`` 0..1 adds a percentage; ``name``
        (the scenario's, in the message) is what gets shortened when the line is short;
        ``said``: the message was just said whole elsewhere, so a cut is not told again."""
        # one line: a name's controls (a newline, a terminal escape) are written out, before
        # the message is measured against the line (an escape takes no cell, written out four)
        message = single_line(message)
        name = single_line(name) if name is not None else None
        for label in LABELS:
            self.set_class(label == state, f"-{label}")
        self.state, self.message, self.progress = state, message, progress
        word = LABELS[state]
        if progress is not None:
            word = f"{word} {100 * progress:3.0f}%"
        self.query_one("#status-word", Static).update(word)
        self.query_one("#cancel", Button).disabled = not cancellable
        self.query_one(StatusText).show(message, name)
        if said:
            self.told = message
        if state not in self.tell_states:
            self.told = ""
        elif self.tell is not None and message != self.told:
            if self.query_one(StatusText).content_size.width > 0:
                self._tell_if_cut(message)  # laid out: told now, with the message it explains
            else:  # (not yet, on mount: its width is known after a refresh)
                self.call_after_refresh(self._tell_if_cut, message)

    def _tell_if_cut(self, message: str) -> None:
        room = self.query_one(StatusText).content_size.width
        if self.tell is None or message != self.message or message == self.told or room <= 0:
            return
        if cell_len(message) > room:
            self.told = message
            self.tell(message)


MIN_NAME = 10  # cells a shortened name keeps
LONG_NAME = 2 * MIN_NAME  # longer: cut in its middle even when the line's end is cut too
ELLIPSIS = "\u2026"


def fitted(message: str, room: int, name: str | None = None) -> str:
    """``message`` in ``room`` cells: ``name`` (where it occurs; by default the longest
    path in it) cut in its middle (``nigh…final.toml``, keeping at least ``MIN_NAME``
    cells), then the end cut if that is not enough, unless that cut would fall in the
    name (a name cut twice, ``sw/…resu…``, reads as neither) or the name is no longer
    than ``LONG_NAME``: then only the end is cut."""
    over = cell_len(message) - room
    if over <= 0:
        return message
    if name is None:  # a message of the sweep screen: its longest path, if it names one
        paths = [word.strip(";,:()") for word in message.split(" ") if "/" in word]
        name = max(paths, key=cell_len, default=None)
    if name and name in message and cell_len(name) > MIN_NAME:
        keep = max(MIN_NAME, cell_len(name) - over - 1)  # one cell for the ellipsis
        head = keep // 3  # the end tells names apart more often (a suffix, the extension)
        short = _first_cells(name, head) + ELLIPSIS + _last_cells(name, keep - head)
        shortened = message.replace(name, short, 1)
        through_name = cell_len(shortened[: shortened.index(short) + len(short)])
        fits = cell_len(shortened) <= room
        # the end cut, if any, after it; a short name ("default.toml") is kept whole then:
        # cut for a cell or two, it read "def…lt.toml" while the end was cut all the same
        if fits or (through_name < room and cell_len(name) > LONG_NAME):
            message = shortened
    if cell_len(message) > room:
        cut = Text(message)
        cut.truncate(room, overflow="ellipsis")  # rich's cut, by cells
        message = cut.plain
    return message


def _first_cells(text: str, cells: int) -> str:
    """The longest start of ``text`` at most ``cells`` wide."""
    out, used = [], 0
    for char in text:
        used += cell_len(char)
        if used > cells:
            break
        out.append(char)
    return "".join(out)


def _last_cells(text: str, cells: int) -> str:
    return _first_cells(text[::-1], cells)[::-1]
