"""Tables drawn to their width and never scrolled sideways.

A column cut at a table's edge reads as another value (a depression of 44.6
cut to "4", "r 60 m at 6", 19.1 ms as "19."), so these tables either wrap a
long last column onto more lines, whole (the Flight tab's segments; a file
name breaks after a hyphen or a dot), or show
whole columns only and name the ones there is no room for (its scans, the
study screen's settings). Widths are counted in terminal cells (a wide
character takes two).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from rich.cells import cell_len
from rich.text import Text
from textual import events
from textual.widgets import DataTable

SEGMENT_COLUMNS = ("#", "Kind", "Scans", "Detail")  # the Flight tab's
# words kept on the line of the number before them: units, and "off" (a fly-past's
# standoff, "80 m off")
KEPT_WITH_NUMBER = frozenset({"m", "deg", "Hz", "times", "pose", "poses", "off"})
BREAK_AFTER = ("-_/", ".")  # where a long file name breaks, the first kind preferred
PUNCTUATION = ",;:."  # never a line's start on its own


class FittingTable(DataTable):
    """A table drawn to its own width: a new width (the sidebar's scrollbar coming or
    going changes it too) calls ``refit`` to draw it again."""

    def __init__(self, refit: Callable[[], None], **kwargs):
        super().__init__(**kwargs)
        self.refit = refit
        self.fitted_width = 0  # the width it was last drawn to

    def on_resize(self, event: events.Resize) -> None:
        if event.size.width != self.fitted_width:
            self.refit()


def fill_segments(table: FittingTable, rows: Sequence[tuple[str, str, str, str]]) -> None:
    """The segments' rows (#, kind, scans, detail), each detail wrapped where it is
    wider than the room the other columns leave."""
    cursor = table.cursor_row
    table.clear(columns=True)  # a column keeps the widest text it ever held otherwise
    room = _detail_room(table, rows)
    table.fitted_width = table.size.width
    _add_columns(table, SEGMENT_COLUMNS[:-1], _widths(table, SEGMENT_COLUMNS[:-1], rows))
    table.add_column(SEGMENT_COLUMNS[-1], width=room)
    for cells in rows:
        lines = wrap_detail(cells[-1], room) if room is not None else [cells[-1]]
        # Text cells: a detail may hold a file's name, never to be read as markup
        table.add_row(*(Text(cell) for cell in cells[:-1]), Text("\n".join(lines)), height=len(lines))
    if table.row_count:
        table.move_cursor(row=min(max(cursor, 0), table.row_count - 1))


def wrap_detail(text: str, room: int) -> list[str]:
    """``text`` in lines of at most ``room`` cells, broken between words, a unit kept on
    the line of its number ("300 m", never "300" then "m") and "at" on the line of the
    number it goes with; a word wider than the room is broken where it must."""
    words: list[str] = []
    for word in text.split(" "):
        if words and word.rstrip(PUNCTUATION) in KEPT_WITH_NUMBER:
            words[-1] += " " + word
        elif word:
            words.append(word)
    lines: list[str] = []
    line = ""
    for word in words:
        joined = f"{line} {word}" if line else word
        if cell_len(joined) <= room:
            line = joined
            continue
        if line:
            lines.append(line)
        while cell_len(word) > room:  # a long file name: cut where it reads best
            cut = _cut(word, room)
            lines.append(word[:cut])
            word = word[cut:]
        line = word
    lines = [*lines, line] if line or not lines else lines
    for n in range(len(lines) - 1):  # "at" goes with the number after it: "at 60 m"
        if lines[n].endswith(" at") and cell_len("at " + lines[n + 1]) <= room:
            lines[n], lines[n + 1] = lines[n][:-3], "at " + lines[n + 1]
    return lines


def _cut(word: str, room: int) -> int:
    """Where to break ``word``, wider than ``room``: after the last hyphen, underscore or
    slash that fits, else a dot, else at the room's edge, but never leaving only
    punctuation for the next line (a file name's comma began one: ", 2 Hz")."""
    fits = len(word)
    while fits > 1 and cell_len(word[:fits]) > room:
        fits -= 1
    for marks in BREAK_AFTER:
        after = max((i + 1 for i, char in enumerate(word[:fits]) if char in marks), default=0)
        if after:
            return after
    return fits - 1 if fits > 1 and not word[fits:].strip(PUNCTUATION) else fits


def fill_whole_columns(
    table: FittingTable, labels: Sequence[str], rows: Sequence[tuple[str, ...]]
) -> list[str]:
    """``rows`` (one cell per label) with as many whole columns, from the left, as the
    table's width holds; returns the labels left out."""
    cursor = table.cursor_row
    widths = _widths(table, labels, rows)
    room = _room(table, len(rows))
    shown = len(labels)
    if room is not None:
        used = 0
        for index, width in enumerate(widths):
            used += width
            if used > room:
                shown = index
                break
    table.clear(columns=True)
    table.fitted_width = table.size.width
    _add_columns(table, labels[:shown], widths)
    for cells in rows:
        table.add_row(*(Text(cell) for cell in cells[:shown]))
    if table.row_count:
        table.move_cursor(row=min(max(cursor, 0), table.row_count - 1))
    return list(labels[shown:])


def _add_columns(table: DataTable, labels: Sequence[str], widths: Sequence[int]) -> None:
    """Columns of the given widths (``_widths``, padding included). Sized from their
    cells only when Textual next measures them, a frame drawn before that (a resize
    does) would cut every value to its label's width, and stay so."""
    pad = 2 * table.cell_padding
    for label, width in zip(labels, widths):
        table.add_column(label, width=width - pad)


def _widths(table: DataTable, labels: Sequence[str], rows) -> list[int]:
    """Each column's width in cells, its padding included."""
    pad = 2 * table.cell_padding
    return [
        pad + max([cell_len(label), *(cell_len(cells[c]) for cells in rows)])
        for c, label in enumerate(labels)
    ]


def _room(table: DataTable, lines: int) -> int | None:
    """Cells across for the columns: the table's width, less a vertical scrollbar where
    ``lines`` and the header are more than its height holds; None before it has a width."""
    if table.size.width <= 0:
        return None
    tallest = table.styles.max_height
    bar = table.styles.scrollbar_size_vertical if tallest is not None and lines + 1 > tallest.value else 0
    return table.size.width - bar


def _detail_room(table: DataTable, rows) -> int | None:
    """Cells left for the segments' details once the other columns are drawn whole;
    None before the table has a width."""
    across = _room(table, len(rows))
    if across is None:
        return None
    others = sum(_widths(table, SEGMENT_COLUMNS[:-1], rows))
    pad = 2 * table.cell_padding
    room = max(across - others - pad, 1)
    lines = sum(-(-cell_len(cells[-1]) // room) for cells in rows)  # the rows, wrapped
    return max((_room(table, lines) or 0) - others - pad, 1)
