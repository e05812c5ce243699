"""Style-preserving save: a scenario's new values written into the analyst's own file.

A hand-written scenario carries comments, key order and alignment that a
fresh dump would throw away. ``restyle`` parses the existing text with
tomlkit and changes only the values that differ from the new data, so a
load-edit-save round trip changes nothing else. Keys the new data no longer
has are removed (a default written by hand, which the old data lacks as well,
stays); new keys are appended to their table.
"""

from __future__ import annotations

from typing import TypeGuard

import tomlkit
from tomlkit.exceptions import TOMLKitError
from tomlkit.items import AoT, Comment, InlineTable, Whitespace


def restyle(old_text: str, data: dict, old_data: dict | None = None) -> str | None:
    """``old_text`` with ``data``'s values in place, or None if it is not a TOML table.

    ``old_data`` is what ``old_text`` meant (defaults filled in); a value equal
    to it is left as the file has it, written or left out. A file's Windows line
    ends (CRLF) stay, on its new lines too.
    """
    plain = old_text.replace("\r\n", "\n")
    text = _restyled(plain, data, old_data)
    if text is None or text == plain:
        return None if text is None else old_text  # unchanged: byte for byte
    return text.replace("\n", "\r\n") if "\r\n" in old_text else text


def _restyled(old_text: str, data: dict, old_data: dict | None) -> str | None:
    """``restyle`` of text whose lines end in LF alone."""
    ended = old_text if old_text.endswith("\n") or not old_text else old_text + "\n"
    try:
        document = tomlkit.parse(ended)  # with its last line ended, as tables added expect
    except TOMLKitError:
        return None
    _merge_table(document, data, old_data)
    text = tomlkit.dumps(document)
    if text == ended:
        return old_text  # unchanged: not even the newline added
    if not ended.endswith("\n\n"):
        text = text.rstrip("\n") + "\n"  # the blank line after a table written last
    return text


def _meant(old_data: dict | None, key: str) -> bool:
    """Whether the file's ``key`` meant a value that new data without it drops. A key
    that what the file meant lacks too is a default the program leaves unwritten
    (``mount = "stabilised"``) but the analyst wrote: it means the same as before."""
    return not isinstance(old_data, dict) or key in old_data


def _plain(item):
    return item.unwrap() if hasattr(item, "unwrap") else item


def _merge_table(table, data: dict, old_data: dict | None) -> None:
    for key in [k for k in table if k not in data and _meant(old_data, k)]:
        del table[key]
    for key, value in data.items():
        before = old_data.get(key) if isinstance(old_data, dict) else None
        if before is not None and _same(before, value):
            continue  # unchanged: as the file has it, even if left out there
        if key not in table:
            table[key] = _spaced(table, value)
        elif isinstance(value, dict) and isinstance(_plain(table[key]), dict):
            _merge_table(table[key], value, before)
        elif (
            _is_table_list(value)
            and _is_table_list(_plain(table[key]))
            and _merge_list(table[key], value, before)
        ):
            pass  # segments keep their comments, appended ones after them
        elif not _same(_plain(table[key]), value):
            table[key] = _spaced(table, value)


def _merge_list(tables, values: list[dict], befores) -> bool:
    """New values into a list of tables (``[[flight.segments]]``): of the same length,
    each table takes its item's values (its comments stay), or is made anew where the
    item is of another kind (an orbit's notes are no fly-past's); longer by items appended
    after an unchanged list (the TUI's Add segment), those go after the last table.
    False otherwise (the caller rewrites the list): a table's comment line is kept by
    tomlkit with the table before it, so a deleted or moved table would take the
    wrong comments along, and an inline array holds no tables to add."""
    if len(values) == len(tables):
        befores = befores if _is_table_list(befores) and len(befores) == len(values) else [None] * len(values)
        for k, (table, value, before) in enumerate(zip(tables, values, befores)):
            if isinstance(tables, AoT) and _plain(table).get("kind") != value.get("kind"):
                # another kind: the old one's notes are not its own, but the lines after its
                # keys (a note over the next table) are the file's
                tables[k] = _new_table(value, _trailing(table))
            else:
                _merge_table(table, value, before)
        return True
    appended = (
        isinstance(tables, AoT)
        and _is_table_list(befores)
        and len(befores) == len(tables) < len(values)
        and all(_same(b, v) for b, v in zip(befores, values))
    )
    if not appended:
        return False
    for value in values[len(tables) :]:
        tables.append(_new_table(value))
    return True


def _new_table(value: dict, after=()):
    """``value`` as a table followed by the lines ``after`` (items of the table it
    replaces), else by a blank line before whatever table follows, as the others have."""
    table = tomlkit.item(value)
    for item in after or [tomlkit.nl()]:
        table.add(item)
    return table


def _trailing(table) -> list:
    """The comments and blank lines after a table's last key: tomlkit keeps a note over
    the next table's header there."""
    body = table.value.body
    last_key = max((n for n, (key, _) in enumerate(body) if key is not None), default=-1)
    return [item for key, item in body[last_key + 1 :] if isinstance(item, Comment | Whitespace)]


def _spaced(container, value):
    """A new table, or list of tables, written as its own lines with a blank line after
    each, as the file's tables have (tomlkit keeps that line with the table before the
    next one, so a list written afresh would lose it); anything else as it is."""
    if isinstance(container, InlineTable) or not (_is_table_list(value) or isinstance(value, dict)):
        return value
    if isinstance(value, dict):
        return _new_table(value)
    written = tomlkit.item(value)  # a list's tables come apart by a blank line already
    written[-1].add(tomlkit.nl())
    return written


def _is_table_list(value: object) -> TypeGuard[list[dict]]:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def _same(old, new) -> bool:
    """Equal values, 8 and 8.0 alike (a loaded int comes back a float), True never 1."""
    return old == new and isinstance(old, bool) == isinstance(new, bool)
