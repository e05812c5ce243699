"""The sweep result table: one CSV row per variant, rewritten atomically as rows come.

Why rewrite-and-rename rather than append: the table is replaced whole through
a temporary file, fsync and rename. A reader (another terminal, the TUI, a
spreadsheet) therefore always sees a complete table, a crash can never leave a
torn line, and the column set may grow (an error row written first has no
measure columns; the next success adds them). ``TableWriter`` formats each row
once and spaces the rewrites so that they take at most a tenth of the sweep's
time (20,000 rows took 0.1 s to write: about once a second), and ``flush``
writes the rows held back. The
reader still skips a malformed row (a hand edit, a file from elsewhere) rather
than failing the whole table.
"""

from __future__ import annotations

import csv
import io
import json
import math
import time
from pathlib import Path

from ladartui.atomic import write_errors_named, write_text_atomic
from ladartui.errors import InputFileError
from ladartui.fileprobe import read_utf8

# Columns that lead every table, in this order; parameters and measures follow.
LEAD_COLUMNS = ("variant", "status", "base")
RUN_COLUMNS = ("path_length_m", "flight_time_s", "scan_count", "run_time_s", "backend", "method", "worker")
TAIL_COLUMNS = ("error",)
# Never parsed as numbers: a hex id such as "1e50..." would otherwise read as a float.
TEXT_COLUMNS = frozenset({"variant", "status", "base", "backend", "method", "worker", "error", "preset"})


def format_cell(value) -> str:
    """One CSV cell: '' for None, repr for floats (exact round trip), JSON for lists."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        return repr(value)
    if isinstance(value, (list, tuple, dict)):
        return json.dumps(value, separators=(",", ":"))
    if hasattr(value, "tolist"):  # numpy scalars and arrays
        return format_cell(value.tolist())
    return str(value)


def display_cell(value, digits=4) -> str:
    """A cell for people: '-' for None, floats to ``digits`` significant figures."""
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


# Magnitudes fixed decimals show well in a column; beyond them each cell keeps its figures.
FIXED_RANGE = (1e-3, 1e6)


def column_format(values, digits=4):
    """A formatter for the cells of one column holding ``values``: its numbers with the
    decimals that give the largest ``digits`` significant figures, so that they line
    up (4.00, 8.03, 10.04, not 4, 8.029, 10.04); ``display_cell`` (each cell its own
    figures) where the largest lies outside ``FIXED_RANGE`` (an exponent reads
    better), where those decimals would show two values alike or one as nought, and
    for other values."""
    numbers = {
        float(v)
        for v in values
        if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
    }
    if not any(isinstance(v, float) for v in values):
        return lambda value: display_cell(value, digits)
    top = max((abs(v) for v in numbers), default=0.0)
    if not FIXED_RANGE[0] <= top < FIXED_RANGE[1]:
        return lambda value: display_cell(value, digits)
    decimals = max(0, digits - (math.floor(math.log10(top)) + 1))
    shown = {v: f"{v:.{decimals}f}" for v in numbers}
    if len(set(shown.values())) < len(shown) or any(v and not float(text) for v, text in shown.items()):
        return lambda value: display_cell(value, digits)

    def cell(value) -> str:
        if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
            return f"{float(value):.{decimals}f}"
        return display_cell(value, digits)

    return cell


def column_formats(ranking, parameter_names) -> dict:
    """A formatter per number column of a ranking table ("value", "coverage", "cost",
    each parameter), so that each column's numbers share their decimals
    (``column_format``); the CLI and the TUI draw their tables with the same."""
    formats = {name: column_format([e.row.get(name) for e in ranking]) for name in parameter_names}
    formats["value"] = column_format([e.value for e in ranking])
    formats["coverage"] = column_format([e.coverage for e in ranking], 3)
    formats["cost"] = column_format([e.cost for e in ranking])
    return formats


def parse_cell(text: str):
    """The value a cell was written from (numbers, booleans, lists, None, text)."""
    if text == "":
        return None
    if text in ("true", "false"):
        return text == "true"
    if text[0] in "[{":
        try:
            return json.loads(text)
        except ValueError:
            return text
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def order_columns(rows, parameter_names=()) -> list[str]:
    """Lead columns, parameters, run columns, then other columns as first seen, error last."""
    fixed = [*LEAD_COLUMNS, *parameter_names, *RUN_COLUMNS]
    seen = []
    for row in rows:
        for key in row:
            if key not in fixed and key not in TAIL_COLUMNS and key not in seen:
                seen.append(key)
    present = set().union(*(row.keys() for row in rows)) if rows else set()
    lead = [c for c in fixed if c in present or c in LEAD_COLUMNS or c in parameter_names]
    return [*lead, *seen, *TAIL_COLUMNS]


def table_text(rows, parameter_names=(), columns=None) -> str:
    """The CSV text of ``rows`` (dicts), header first; ``columns`` fixes the columns."""
    columns = list(columns) if columns is not None else order_columns(rows, parameter_names)
    return _csv_line(columns) + "".join(_row_line(row, columns) for row in rows)


def _csv_line(cells) -> str:
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow(cells)
    return buffer.getvalue()


def _row_line(row, columns) -> str:
    return _csv_line([format_cell(row.get(column)) for column in columns])


def write_table(path, rows, parameter_names=()) -> None:
    """Replace ``path`` with the table of ``rows``: temporary file, fsync, rename."""
    write_text_atomic(path, table_text(rows, parameter_names), durable=True)


# A rewrite waits this many times the last one's duration after it: at most a tenth
# of a sweep's time goes to rewriting its table (20,000 rows took 5.4 s to format
# and write whole; formatted once, the writing alone is left).
REWRITE_SPACING = 9.0


class TableWriter:
    """A result table kept in memory and written to ``path`` as rows come (``put``).

    A row is formatted once, and again only when a later row changes the columns.
    A row for a variant and base already held replaces it in place. Rewrites are
    spaced ``spacing`` times their own duration apart; ``flush`` writes what is
    held back (a sweep calls it however it ends). Nothing is formatted before the
    first row is put.
    """

    def __init__(
        self, path, rows, parameter_names=(), spacing: float = REWRITE_SPACING, clock=time.monotonic
    ):
        self.path = Path(path)
        self.rows = list(rows)
        self.parameter_names = tuple(parameter_names)
        self.spacing = spacing
        self.clock = clock
        self._position = {(row["variant"], row.get("base")): i for i, row in enumerate(self.rows)}
        self._lines: list[str] | None = None  # formatted on the first put
        self._columns: list[str] = []
        self._known: set[str] = set()  # the columns, to look up
        self.unwritten = 0  # rows put since the last write (a row put twice counts twice)
        self._next_write = 0.0  # clock() from which a rewrite may start
        self.written = False  # whether the file was rewritten

    def held(self, variant: str, base: str | None) -> dict | None:
        """The row held for ``variant`` made from ``base``, if any."""
        at = self._position.get((variant, base))
        return None if at is None else self.rows[at]

    def _format_all(self) -> list[str]:
        self._columns = order_columns(self.rows, self.parameter_names)
        self._known = set(self._columns)
        self._lines = [_row_line(row, self._columns) for row in self.rows]
        return self._lines

    def put(self, row: dict) -> None:
        key = (row["variant"], row.get("base"))
        at = self._position.get(key)
        lines = self._lines if self._lines is not None else self._format_all()
        # a key a replaced row held (a value, not a column read back empty) may leave the columns
        dropped = at is not None and any(v is not None and k not in row for k, v in self.rows[at].items())
        if at is None:
            self._position[key] = len(self.rows)
            self.rows.append(row)
        else:
            self.rows[at] = row
        if dropped or not row.keys() <= self._known:  # the columns change
            self._format_all()
        elif at is None:
            lines.append(_row_line(row, self._columns))
        else:
            lines[at] = _row_line(row, self._columns)
        self.unwritten += 1
        if self.clock() >= self._next_write:
            self.flush()

    def flush(self) -> None:
        """Write the rows held back, if any; ``OutputFileError`` naming the table when it
        cannot be written."""
        if not self.unwritten:  # (rows are held only once put formatted them)
            return
        started = self.clock()
        with write_errors_named(self.path):
            text = _csv_line(self._columns) + "".join(self._lines or ())
            write_text_atomic(self.path, text, durable=True)
        finished = self.clock()
        self._next_write = finished + self.spacing * (finished - started)
        self.written, self.unwritten = True, 0


def read_table(path, unreadable: list[int] | None = None) -> tuple[list[dict], list[str]]:
    """Rows (dicts of parsed values) and the header of a result table.

    A missing file gives no rows. Rows with the wrong number of cells or no
    variant id are dropped (a torn or hand-edited line), never fatal; their
    line numbers are added to ``unreadable`` when given.
    """
    path = Path(path)
    try:
        text = read_utf8(path, "expected the sweep results table (CSV)")
    except FileNotFoundError:
        return [], []
    except OSError as error:
        raise InputFileError(path, f"cannot read the sweep results: {error.strerror or error}") from None
    reader = csv.reader(io.StringIO(text))
    try:
        header = next(reader)
    except (StopIteration, csv.Error):
        return [], []
    if "variant" not in header:
        raise InputFileError(path, "not a sweep result table: expected a 'variant' column", line=1)
    rows = []
    while True:
        start = reader.line_num + 1  # the record's first line (a stray quote spans several)
        try:
            cells = next(reader)
        except StopIteration:
            break
        except csv.Error:
            _note(unreadable, start)
            continue
        if not cells:  # a blank line
            continue
        if len(cells) != len(header):
            _note(unreadable, start)
            continue
        row = {
            column: (cell or None) if column in TEXT_COLUMNS else parse_cell(cell)
            for column, cell in zip(header, cells)
        }
        if not row.get("variant"):
            _note(unreadable, start)
            continue
        rows.append(row)
    return rows, header


def _note(unreadable: list[int] | None, line: int) -> None:
    if unreadable is not None:
        unreadable.append(line)
