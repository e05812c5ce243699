"""Line numbers of the keys of a TOML file, for error messages that name the line.

TOML readers give values, not where they were written; these map dotted keys
("flight.segments[1].radius") to the 1-based line that sets them, so a bad
value in a scenario or a settings file is reported as ``file:line``.
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

from ladartui.fileprobe import SPECIAL_FILE, file_problem, text_lines

_HEADER = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_.\-]+)\s*\]\]?")
_BARE_KEY_CHARACTERS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")
_KEY = re.compile(r"""^\s*(?:([A-Za-z0-9_\-]+)|"([^"\\]*)"|'([^']*)')\s*=""")  # bare or quoted


_AT_LINE = re.compile(r"\s*\(at line (\d+), column \d+\)")
_AT_END = " (at end of document)"  # tomllib's words for a mistake it met at the end


def toml_mistake(error: tomllib.TOMLDecodeError, text: str) -> tuple[str, int | None]:
    """What a TOML syntax error in ``text`` says, less its "(at line L, column C)", and L:
    so every message reads ``file:line: ...``. One "at end of document" (a value cut
    off) is at the last line holding anything, "at the end of the file"."""
    said = str(error)
    found = _AT_LINE.search(said)
    if found:
        line = int(found.group(1))
        return _written_twice(said, text, line) or _AT_LINE.sub("", said), line
    if said.endswith(_AT_END):
        held = [number for number, line in enumerate(text_lines(text), start=1) if line.strip()]
        return said.removesuffix(_AT_END) + " at the end of the file", held[-1] if held else None
    return said, None


def _written_twice(said: str, text: str, line: int) -> str | None:
    """tomllib's words for a key or table written again ("Cannot overwrite a value",
    "Cannot declare ('sensor',) twice") as the key or table and the line it was first
    written on; None for other mistakes, or where the line holds no key this reads."""
    if not said.startswith(("Cannot overwrite a value", "Cannot declare ")):
        return None
    rows = list(_key_rows(text))
    here = [(name, header) for number, name, header in rows if number == line]
    if not here:
        return None
    name, header = here[0]
    first = next(number for number, written, _ in rows if written == name)
    if first == line:
        return None
    what = f"table [{name}]" if header else f"key '{name}'"
    return f"{what} written twice (first on line {first}); expected each key and table once"


def key_lines(path: Path) -> dict[str, int]:
    """``key_lines_from_text`` of a file; empty when it cannot be read."""
    try:
        return key_lines_from_text(path.read_text(encoding="utf-8-sig"))
    except (OSError, UnicodeDecodeError):
        return {}


def key_lines_from_text(text: str) -> dict[str, int]:
    """Map dotted keys ("flight.segments[1].radius") to their 1-based line numbers.

    A light scan of bare keys and table headers, enough to point at the line of
    a bad value; anything it does not recognise is simply not mapped.
    """
    lines: dict[str, int] = {}
    for number, name, _ in _key_rows(text):
        lines.setdefault(name, number)
    return lines


def _key_rows(text: str):
    """(line, dotted key, whether a table header) for each header and key, in order;
    an array of tables' header gives the array, then its new table. An array of inline
    tables written over lines (``segments = [`` then one ``{ ... }`` a line, as a saved
    scenario has its segments and poses) gives each item and its keys on their line."""
    arrays: dict[str, int] = {}  # array-of-tables name -> current index
    current = ""
    inline: list = []  # the array of inline tables open over lines: [dotted name, next index]
    for number, line in enumerate(text_lines(text), start=1):
        if inline:
            for name in _inline_items(line, inline):
                yield number, name, False
            continue
        header = _HEADER.match(line)
        if header:
            name = _indexed(header.group(2), arrays)
            if header.group(1) == "[[":
                yield number, name, True  # the array itself: its first table
                arrays[header.group(2)] = arrays.get(header.group(2), -1) + 1
                name = f"{name}[{arrays[header.group(2)]}]"
            current = name
            yield number, current, True
            continue
        key = _KEY.match(line)
        if key:
            name = next(part for part in key.groups() if part is not None)
            dotted = f"{current}.{name}" if current else name
            yield number, dotted, False
            value = line[key.end() :].lstrip()
            if value.startswith("["):  # an array: perhaps of inline tables, perhaps over lines
                inline = [dotted, 0]
                for name in _inline_items(value[1:], inline):
                    yield number, name, False


def _inline_items(line: str, array: list) -> list[str]:
    """The items of ``array`` ([dotted name, next index]) begun on ``line`` and the keys of
    their tables, as dotted keys; empties ``array`` where the line closes it. (An inline
    table is one line long in TOML; strings and comments are skipped.)"""
    name, index = array
    found: list[str] = []
    depth, quote, skip = 0, "", False  # depth 0: in the array, 1: in an item's table
    for at, char in enumerate(line):
        if skip:
            skip = False
        elif quote:
            skip = char == "\\" and quote == '"'
            quote = "" if char == quote else quote
        elif char in "\"'":
            quote = char
        elif char == "#":
            break
        elif char in "[{":
            if depth == 0 and char == "{":
                found.append(f"{name}[{index}]")
                index += 1
            depth += 1
        elif char in "]}":
            depth -= 1
            if depth < 0:  # the array's own closing bracket
                array.clear()
                return found
        elif char == "=" and depth == 1 and (key := _key_before(line, at)):
            found.append(f"{name}[{index - 1}].{key}")
    array[1] = index
    return found


def _key_before(line: str, at: int) -> str:
    """The bare key that ends just before ``line[at]`` (an inline table's '='), spaces
    between; "" where there is none. Read backwards from ``at``: 20,000 poses on one
    line each searched from the line's start took minutes."""
    end = at
    while end > 0 and line[end - 1] in " \t":
        end -= 1
    start = end
    while start > 0 and line[start - 1] in _BARE_KEY_CHARACTERS:
        start -= 1
    return line[start:end]


def _indexed(dotted: str, arrays: dict[str, int]) -> str:
    # "flight.segments.poses" -> "flight.segments[2].poses" inside segment 2.
    parts = dotted.split(".")
    out = []
    for i, part in enumerate(parts):
        out.append(part)
        prefix = ".".join(parts[: i + 1])
        if i < len(parts) - 1 and prefix in arrays:
            out[-1] = f"{part}[{arrays[prefix]}]"
    return ".".join(out)


@dataclass
class ConfigTable:
    """One ``[name]`` table of a user's config file, with what was wrong, file and line."""

    table: dict  # empty when the file or the table is absent or unreadable
    problems: list[str]
    lines: dict[str, int]
    path: Path

    def at(self, key: str) -> str:
        """``path:line`` of a dotted key (the path alone when it is not found)."""
        return f"{self.path}:{self.lines[key]}" if key in self.lines else str(self.path)


def read_config_table(path: Path, name: str, what: str) -> ConfigTable:
    """``[name]`` of the config file at ``path``; a missing file is an empty table. A file
    that cannot be read, is not UTF-8 or TOML, is nested too deep, holds other tables
    (a misspelt one) or a ``name`` that is not a table is reported, never fatal.
    ``what`` says what the table holds ("command id = key")."""
    from ladartui.textsafe import one_line

    def failed(problem: str, line: int | None = None) -> ConfigTable:
        where = f"{path}:{line}" if line else str(path)
        return ConfigTable({}, [one_line(f"{where}: {problem}")], {}, path)

    if file_problem(path) == SPECIAL_FILE:  # a pipe would wait for ever
        return failed(SPECIAL_FILE)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        return ConfigTable({}, [], {}, path)
    except UnicodeDecodeError:
        return failed("not UTF-8 text")
    except OSError as error:
        return failed(f"{error.strerror or error}")
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        said, line = toml_mistake(error, text)
        return failed(f"not valid TOML: {said}", line)
    except RecursionError:
        return failed("nested too deep to read")
    config = ConfigTable({}, [], key_lines_from_text(text), path)
    config.problems = [
        one_line(f"{config.at(other)}: [{other}]: no such table; expected [{name}]")
        for other in document
        if other != name
    ]
    table = document.get(name, {})
    if isinstance(table, dict):
        config.table = table
    else:
        config.problems.append(f"{config.at(name)}: {name} must be a table, [{name}], of {what}")
    return config
