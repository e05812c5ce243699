"""Voxel-list files: one ``x,y,z`` line of non-negative integers per voxel.

This is the report's model and output format (table 2). Accepted: spaces or
tabs around values, LF or CRLF line ends, a UTF-8 byte-order mark, a final
newline or none, blank lines at the very end. Files up to a few megabytes
of plain ``x,y,z`` lines (the layout we write) are read in array passes
without numba, so opening the default scene never imports it; larger files
and any other layout go through one compiled pass that also finds the first
bad line (about 0.1 s for the 3.8 M lines of the report's figure-11 scene,
where ``numpy.loadtxt`` takes tens of seconds); kernels compile on first use.
Anything else stops at the first bad line with ``file:line: what was wrong``.
"""

from __future__ import annotations

import contextlib
import logging
import os
from pathlib import Path

import numpy as np

from ladartui.atomic import atomic_path, write_errors_named
from ladartui.errors import InputFileError
from ladartui.fileprobe import no_such_file, other_file_kind, path_field, refuse_special_file
from ladartui.fingerprint import Digest
from ladartui.scene.lazy_kernels import NUMPY_BYTES, LazyKernels
from ladartui.scene.unique_rows import unique_voxels
from ladartui.scene.voxel_arrays import MAX_TARGET_ID, target_ids_field, voxel_list_field

log = logging.getLogger(__name__)

MAX_INDEX = 2**31 - 1
EXPECTED = "expected three non-negative integers x,y,z separated by commas"
_AXES = ("x", "y", "z")
_BOM = b"\xef\xbb\xbf"

_NEWLINE, _CR, _SPACE, _TAB, _COMMA, _ZERO, _NINE = 10, 13, 32, 9, 44, 48, 57
_MAX_DIGITS = len(str(MAX_INDEX))

_kernel = LazyKernels(globals())


@_kernel
def _is_blank(c):
    return c == _SPACE or c == _TAB


@_kernel
def _line_end(buf, pos, n):
    """True at a line's end: LF, CR LF (files from Windows), or the end of the data.

    A CR anywhere else is a mistake, not a blank."""
    if pos >= n or buf[pos] == _NEWLINE:
        return True
    return buf[pos] == _CR and (pos + 1 >= n or buf[pos + 1] == _NEWLINE)


@_kernel
def _parse_voxel_bytes(buf, start, out):
    """Parse ``buf[start:]`` into ``out`` rows.

    Every line holds ``out.shape[1]`` comma-separated values (3 for ``x,y,z``,
    4 for a target model's ``x,y,z,id``). Returns ``(rows, bad_line,
    bad_offset)``: ``bad_line`` is 0 when every line was good, else the
    1-based number of the first bad line, which starts at byte ``bad_offset``.
    A blank line is bad only if a voxel line follows it.
    """
    n = buf.shape[0]
    columns = out.shape[1]
    pos = start
    line = 1
    rows = 0
    first_blank_line = 0
    first_blank_offset = 0
    while pos < n:
        line_start = pos
        while pos < n and _is_blank(buf[pos]):
            pos += 1
        if _line_end(buf, pos, n):
            if first_blank_line == 0:
                first_blank_line = line
                first_blank_offset = line_start
            if pos < n and buf[pos] == _CR:
                pos += 1
            pos += 1
            line += 1
            continue
        if first_blank_line != 0:
            return rows, first_blank_line, first_blank_offset
        for axis in range(columns):
            while pos < n and _is_blank(buf[pos]):
                pos += 1
            digits = 0
            value = 0
            while pos < n and _ZERO <= buf[pos] <= _NINE:
                value = value * 10 + (buf[pos] - _ZERO)
                digits += 1
                if value > MAX_INDEX:
                    return rows, line, line_start
                pos += 1
            if digits == 0:
                return rows, line, line_start
            out[rows, axis] = value
            while pos < n and _is_blank(buf[pos]):
                pos += 1
            if axis < columns - 1:
                if pos >= n or buf[pos] != _COMMA:
                    return rows, line, line_start
                pos += 1
            elif pos < n:
                if not _line_end(buf, pos, n):
                    return rows, line, line_start
                if buf[pos] == _CR:
                    pos += 1
                pos += 1
        rows += 1
        line += 1
    return rows, 0, 0


@_kernel
def _count_digits(value):
    digits = 1
    while value >= 10:
        value //= 10
        digits += 1
    return digits


@_kernel
def _format_voxel_bytes(voxels):
    """The file's bytes: ``x,y,z\\n`` (or ``x,y,z,id\\n``) per row, in row order."""
    columns = voxels.shape[1]
    total = 0
    for row in range(voxels.shape[0]):
        for axis in range(columns):
            total += _count_digits(voxels[row, axis]) + 1
    out = np.empty(total, dtype=np.uint8)
    pos = 0
    for row in range(voxels.shape[0]):
        for axis in range(columns):
            value = voxels[row, axis]
            digits = _count_digits(value)
            for k in range(digits - 1, -1, -1):
                out[pos + k] = _ZERO + value % 10
                value //= 10
            pos += digits
            out[pos] = _COMMA if axis < columns - 1 else _NEWLINE
            pos += 1
    return out


def load_voxels(path) -> np.ndarray:
    """Read a voxel-list file into a (N, 3) int32 array of unique voxels.

    Duplicate lines are dropped (the first occurrence keeps its place; the
    count is logged). Raises ``InputFileError`` naming the file and the first
    bad line.
    """
    voxels, _ = load_voxels_counted(path)
    return voxels


def load_voxels_counted(path, _target=False, digest: Digest | None = None) -> tuple[np.ndarray, int]:
    """Like :func:`load_voxels`, also returning how many duplicate lines were dropped;
    ``digest`` is fed the file's bytes as they are read."""
    path = path_field("path", path, "a voxel-list file's path")
    parsed = _read_rows(path, 3, _target, digest)
    voxels, duplicates = unique_voxels(parsed)
    if duplicates:
        log.info("%s: dropped %d duplicate voxel lines", path, duplicates)
    return voxels, duplicates


def _parse_file(path: Path, buf: np.ndarray, columns: int, target: bool) -> np.ndarray:
    """Rows of ``columns`` values; ``target``: a target model (errors say x,y,z or x,y,z,id)."""
    start = len(_BOM) if buf[: len(_BOM)].tobytes() == _BOM else 0
    parsed = _parse_plain_lines(buf[start:], columns) if len(buf) <= _PLAIN_BYTES else None
    if parsed is None:  # some other layout, or a mistake: the exact checker decides
        parsed = _parse_checked(path, buf, start, columns, target)
    return parsed


def _first_line_columns(buf: np.ndarray, start: int) -> int:
    """4 when the first line holds three commas (``x,y,z,id``), else 3."""
    head = buf[start : start + 256]
    ends = np.flatnonzero(head == _NEWLINE)
    line = head[: ends[0]] if len(ends) else head
    return 4 if int(np.count_nonzero(line == _COMMA)) == 3 else 3


def _parse_checked(path: Path, buf: np.ndarray, start: int, columns: int, target: bool) -> np.ndarray:
    """Every tolerated layout; ``InputFileError`` naming the first bad line."""
    capacity = int(np.count_nonzero(buf == _NEWLINE)) + 1
    out = np.empty((capacity, columns), dtype=np.int32)
    rows, bad_line, bad_offset = _parse_voxel_bytes(buf, start, out)
    if bad_line:
        end = bad_offset
        while end < len(buf) and buf[end] != _NEWLINE:
            end += 1
        text = buf[bad_offset:end].tobytes().decode("utf-8", errors="replace")
        message = describe_bad_line(text, columns, target)
        raise InputFileError(path, message, line=int(bad_line))
    return out[:rows]


EXPECTED_TARGET = (
    "expected x,y,z or x,y,z,id: three non-negative integers and an optional target id "
    f"1..{MAX_TARGET_ID}, the same number of values on every line"
)


_PLAIN_BYTES = NUMPY_BYTES  # up to this size: array passes, no compiled kernel
# byte -> 0 digit, 1 comma, 2 newline, 3 anything else
_BYTE_CLASS = np.full(256, 3, dtype=np.uint8)
_BYTE_CLASS[_ZERO : _NINE + 1] = 0
_BYTE_CLASS[_COMMA] = 1
_BYTE_CLASS[_NEWLINE] = 2


def _parse_plain_lines(data: np.ndarray, columns: int = 3) -> np.ndarray | None:
    """Rows of ``data`` when every line is exactly ``x,y,z`` (digits only), else None.

    ``columns`` values a line (4 for a target model's ``x,y,z,id``).

    The common case, in array passes without numba; anything else (spaces,
    CR, blank lines, mistakes, values beyond ``MAX_INDEX``) returns None.
    """
    if len(data) == 0:
        return np.zeros((0, columns), dtype=np.int32)
    if data[-1] != _NEWLINE:
        data = np.append(data, np.uint8(_NEWLINE))
    classes = _BYTE_CLASS[data]
    if classes.max() > 2:
        return None
    separators = np.flatnonzero(classes)
    kinds = classes[separators]
    if len(kinds) % columns or not (
        all(np.all(kinds[axis::columns] == 1) for axis in range(columns - 1))
        and np.all(kinds[columns - 1 :: columns] == 2)
    ):
        return None
    starts = np.empty_like(separators)
    starts[0] = 0
    starts[1:] = separators[:-1] + 1
    lengths = separators - starts
    longest = int(lengths.max())
    if lengths.min() < 1 or longest > _MAX_DIGITS:
        return None
    values = np.zeros(len(separators), dtype=np.int64)
    for place in range(longest):  # Horner's rule, one digit place of every field at a time
        inside = lengths > place
        digit = data[np.where(inside, starts + place, separators)].astype(np.int64) - _ZERO
        values = np.where(inside, values * 10 + digit, values)
    if values.max() > MAX_INDEX:
        return None
    return values.astype(np.int32).reshape(-1, columns)


# Files larger than this are read in blocks of _BLOCK_BYTES (cut at line ends) and
# parsed as they come: the peak is the parsed rows plus one block, not the file's
# bytes and its rows together.
_BLOCK_BYTES = 4 << 20


def _read_rows(path: Path, columns: int, target: bool, digest: Digest | None = None) -> np.ndarray:
    """The rows of a voxel list (``columns`` values a line), read whole when small,
    else streamed block by block; ``InputFileError`` naming the first bad line.
    ``digest`` is fed every byte of the file once. One open file throughout: a file
    replaced meanwhile (written atomically, as generate does) is read whole, old or
    new, never part of each."""
    try:
        return _read_opened(path, columns, target, digest)
    except InputFileError as error:
        # A point cloud or mesh fails on a line: say what it is. An error of no line (no
        # such file, a folder, too large) is about the path, whatever its suffix.
        kind = other_file_kind(path) if error.line is not None else None
        if kind is None:
            raise
        expected = EXPECTED_TARGET if target else EXPECTED
        raise InputFileError(path, f"{kind} ({path.suffix}), not a voxel list; {expected}") from None


def _read_opened(path: Path, columns: int, target: bool, digest: Digest | None) -> np.ndarray:
    with _opened(path) as handle:
        head = _read_from(path, handle, _PLAIN_BYTES + 1)
        if len(head) <= _PLAIN_BYTES:  # the whole file
            if digest is not None:
                digest.update(head)
            return _parse_file(path, np.frombuffer(head, dtype=np.uint8), columns, target)
        # At most one row per 6 bytes ("0,0,0\n"); pages never written are never taken.
        # Bytes past the size seen here (appended meanwhile) are not read: no room for them.
        size = max(os.fstat(handle.fileno()).st_size, len(head))
        out = np.empty((size // (2 * columns) + 1, columns), dtype=np.int32)
        rows = 0
        lines = 0  # lines before the current block
        blank_line = 0  # a blank line at the end of the blocks read so far (0: none)
        first = True
        for block in _blocks(path, handle, size, digest, head):
            start = len(_BOM) if first and block[: len(_BOM)].tobytes() == _BOM else 0
            first = False
            got, bad_line, bad_offset = _parse_voxel_bytes(block, start, out[rows:])
            if blank_line and (got or bad_line):  # voxels after a blank line of an earlier block
                raise InputFileError(path, describe_bad_line("", columns, target), line=blank_line)
            if bad_line:
                end = bad_offset
                while end < len(block) and block[end] != _NEWLINE:
                    end += 1
                text = block[bad_offset:end].tobytes().decode("utf-8", errors="replace")
                raise InputFileError(
                    path, describe_bad_line(text, columns, target), line=lines + int(bad_line)
                )
            in_block = int(np.count_nonzero(block == _NEWLINE)) + (1 if block[-1] != _NEWLINE else 0)
            if in_block > got and not blank_line:  # the block ended in blank lines
                blank_line = lines + got + 1
            rows += got
            lines += in_block
    out.resize((rows, columns), refcheck=False)  # in place: no copy of the rows
    return out


def _blocks(path: Path, handle, size: int, digest: Digest | None, head: bytes):
    """The file's first ``size`` bytes in blocks of about _BLOCK_BYTES, each ending at a
    line end (the last may not), as uint8 arrays; ``digest`` is fed them as read.
    ``head``: the first bytes, already read from ``handle``, which reads the rest."""
    left = size - len(head)
    carry = b""
    data = head
    while True:
        if not data and left > 0:
            data = _read_from(path, handle, min(_BLOCK_BYTES, left))
            left -= len(data)
        if not data:
            if carry:
                yield np.frombuffer(carry, dtype=np.uint8)
            return
        if digest is not None:
            digest.update(data)
        data = carry + data
        cut = data.rfind(b"\n") + 1
        carry = data[cut:]
        if cut:
            yield np.frombuffer(data[:cut], dtype=np.uint8)
        data = b""


def _read_from(path: Path, handle, limit: int) -> bytes:
    try:
        return handle.read(limit)
    except OSError as error:
        raise InputFileError(path, f"cannot be read: {error.strerror or error}") from None


@contextlib.contextmanager
def _opened(path: Path):
    """The voxel list open for reading, after the checks (a special file, its size
    against memory); ``InputFileError`` for one that cannot be opened."""
    refuse_special_file(path, "expected a voxel-list file")
    try:
        _check_read_size(path)
        handle = open(path, "rb")  # noqa: SIM115 (closed below)
    except FileNotFoundError:
        raise InputFileError(path, f"{no_such_file(path)}; expected a voxel-list file") from None
    except IsADirectoryError:
        raise InputFileError(path, "is a folder; expected a voxel-list file") from None
    except PermissionError:
        raise InputFileError(path, "cannot be read: permission denied") from None
    except OSError as error:
        raise InputFileError(path, f"cannot be read: {error.strerror or error}") from None
    with handle:
        yield handle


def _read_bytes(path: Path, limit: int) -> np.ndarray:
    """The file's first ``limit`` bytes, after the checks of ``_opened``."""
    with _opened(path) as handle:
        return np.frombuffer(_read_from(path, handle, limit), dtype=np.uint8)


def _check_read_size(path: Path) -> None:
    """Refuse a file whose bytes and parsed rows would not fit in memory (a sparse 50 GB file)."""
    from ladartui.errors import ResourceLimitError
    from ladartui.resources import available_memory, gib

    size = os.stat(path).st_size
    # Up to 12 bytes of int32 row per 6-byte line "0,0,0\n", plus the bytes (small files,
    # read whole) or one block (large ones, streamed).
    need = 2 * size + min(size, _BLOCK_BYTES)
    limit = available_memory()
    if need > limit:
        raise ResourceLimitError(
            f"{path}: a voxel list of {gib(size)} needs about {gib(need)} "
            f"to read, more than the {gib(limit)} of memory available"
        )


QUOTE_CHARS = 60  # of a rejected line or value: the message keeps room for what was expected


def _quoted(text: str) -> str:
    """``text`` in quotes, cut to its first QUOTE_CHARS characters when longer."""
    if len(text) <= QUOTE_CHARS:
        return repr(text)
    return repr(f"{text[:QUOTE_CHARS]}... ({len(text)} characters)")


def describe_bad_line(text: str, columns: int = 3, target: bool = False) -> str:
    """What is wrong with one rejected line, and what was expected.

    ``columns`` values a line were expected (4: a target model's ``x,y,z,id``,
    as its first line set); ``target``: the file is a target model.
    """
    expected = EXPECTED_TARGET if target else EXPECTED
    body = text[:-1] if text.endswith("\r") else text  # CR LF line ends are fine
    if "\x00" in body or "\ufffd" in body:  # NUL bytes, or bytes that are not UTF-8 text
        return f"binary data, not text; {expected}"
    if "\r" in body:
        shown = body.strip(" \t")
        return f"stray carriage return (\\r) in {_quoted(shown)}; {expected}"
    if not body.strip(" \t"):
        return "blank line before more voxels; blank lines are allowed only at the end of the file"
    fields = body.split(",")
    if len(fields) != columns:
        if target and len(fields) in (3, 4):
            return (
                f"{len(fields)} comma-separated values in {_quoted(body.strip())} but the file's first "
                f"line has {columns}; {EXPECTED_TARGET}"
            )
        if not target and columns == 3 and len(fields) == 4 and all(f.strip(" \t").isdigit() for f in fields):
            # a target model's lines with ids, as save_voxels(ids=...) writes them
            return (
                f"4 comma-separated values in {_quoted(body.strip())} (a target model's x,y,z,id "
                f"lines, which ladartui.scene.target_model.load_target reads with their ids); {expected}"
            )
        return f"{len(fields)} comma-separated values in {_quoted(body.strip())}; {expected}"
    for axis, field in zip((*_AXES, "id"), fields):
        token = field.strip(" \t")
        if not token:
            return f"{axis} is empty in {_quoted(body.strip())}; {expected}"
        if token.startswith("-") and token[1:].isascii() and token[1:].isdigit():
            if axis == "id":
                return f"id = {token} is not a target id; {EXPECTED_TARGET}"
            return f"{axis} = {token} is negative; voxel indices start at 0"
        if not (token.isascii() and token.isdigit()):
            return f"{axis} = {_quoted(token)} is not a whole number; {expected}"
        # Length first: int() refuses strings of more than 4,300 digits.
        if len(token.lstrip("0")) > len(str(MAX_INDEX)) or int(token) > MAX_INDEX:
            shown = token if len(token) <= 24 else f"{token[:12]}...({len(token)} digits)"
            if axis == "id":
                return f"id = {shown} is not a target id; {EXPECTED_TARGET}"
            return f"{axis} = {shown} is too large; expected at most {MAX_INDEX}"
    return f"cannot read {_quoted(body.strip())}; {expected}"


def save_voxels(path, voxels, ids=None) -> None:
    """Write ``voxels`` ((N, 3) non-negative integers) as an ``x,y,z`` list, atomically,
    making the file's folder if there is none.

    With ``ids`` ((N,) target ids 1..``MAX_TARGET_ID``) the lines are ``x,y,z,id``. A path
    that cannot be written is an ``OutputFileError`` naming it.
    """
    path = path_field("path", path, "a voxel-list file's path")
    with write_errors_named(path):
        write_voxels(path, voxels, ids)


def write_voxels(path, voxels, ids=None) -> None:
    """``save_voxels`` with its OSErrors as raised: an output set's writer, given the set's
    temporary file, leaves the set to name the output."""
    data = voxel_file_bytes(voxels, ids)
    with atomic_path(path) as tmp, open(tmp, "wb") as stream:
        stream.write(data)


def voxel_file_bytes(voxels, ids=None) -> bytes | memoryview:
    """The bytes ``write_voxels`` writes: checked rows as ``x,y,z`` lines (``x,y,z,id``
    with ``ids``)."""
    voxels = np.ascontiguousarray(voxel_list_field("voxels", voxels, MAX_INDEX), dtype=np.int64)
    if ids is not None:
        voxels = np.column_stack([voxels, target_ids_field("ids", ids, len(voxels)).astype(np.int64)])
    return format_voxel_lines(voxels)


# Below this many rows plain Python formats faster than the compiled kernel's first load.
_COMPILED_FORMAT_ROWS = 200_000


def format_voxel_lines(voxels: np.ndarray) -> bytes | memoryview:
    """The ``x,y,z\\n`` text of non-negative integer rows, as bytes (``x,y,z,id`` for 4 columns)."""
    voxels = np.ascontiguousarray(voxels, dtype=np.int64)
    if len(voxels) < _COMPILED_FORMAT_ROWS:
        line = ",".join(["{}"] * voxels.shape[1]) + "\n"
        return "".join(map(line.format, *voxels.T.tolist())).encode("ascii")
    return memoryview(_format_voxel_bytes(voxels))
