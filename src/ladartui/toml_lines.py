"""Line numbers of the keys of a TOML file, for error messages that name the line.

TOML readers give values, not where they were written; these map dotted keys
("flight.segments[1].radius") to the 1-based line that sets them, so a bad
value in a scenario or a settings file is reported as ``file:line``.
"""

from __future__ import annotations

import re
from pathlib import Path

_HEADER = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_.\-]+)\s*\]\]?")
_KEY = re.compile(r"""^\s*(?:([A-Za-z0-9_\-]+)|"([^"\\]*)"|'([^']*)')\s*=""")  # bare or quoted


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
    arrays: dict[str, int] = {}  # array-of-tables name -> current index
    current = ""
    for number, line in enumerate(text.splitlines(), start=1):
        header = _HEADER.match(line)
        if header:
            name = _indexed(header.group(2), arrays)
            if header.group(1) == "[[":
                arrays[header.group(2)] = arrays.get(header.group(2), -1) + 1
                name = f"{name}[{arrays[header.group(2)]}]"
            current = name
            lines.setdefault(current, number)
            continue
        key = _KEY.match(line)
        if key:
            name = next(part for part in key.groups() if part is not None)
            lines.setdefault(f"{current}.{name}" if current else name, number)
    return lines


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
