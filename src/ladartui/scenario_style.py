"""Style-preserving save: a scenario's new values written into the analyst's own file.

A hand-written scenario carries comments, key order and alignment that a
fresh dump would throw away. ``restyle`` parses the existing text with
tomlkit and changes only the values that differ from the new data, so a
load-edit-save round trip changes nothing else. Keys the new data no longer
has are removed; new keys are appended to their table.
"""

from __future__ import annotations

import json
from difflib import SequenceMatcher
from typing import TypeGuard

import tomlkit
from tomlkit.exceptions import TOMLKitError


def restyle(old_text: str, data: dict, old_data: dict | None = None) -> str | None:
    """``old_text`` with ``data``'s values in place, or None if it is not a TOML table.

    ``old_data`` is what ``old_text`` meant (defaults filled in); a value equal
    to it is left as the file has it, written or left out.
    """
    try:
        document = tomlkit.parse(old_text)
    except TOMLKitError:
        return None
    _merge_table(document, data, old_data)
    return tomlkit.dumps(document)


def _plain(item):
    return item.unwrap() if hasattr(item, "unwrap") else item


def _merge_table(table, data: dict, old_data: dict | None) -> None:
    for key in [k for k in table if k not in data]:
        del table[key]
    for key, value in data.items():
        before = old_data.get(key) if isinstance(old_data, dict) else None
        if before is not None and _same(before, value):
            continue  # unchanged: as the file has it, even if left out there
        if key not in table:
            table[key] = value
        elif isinstance(value, dict) and isinstance(_plain(table[key]), dict):
            _merge_table(table[key], value, before)
        elif (
            _is_table_list(value)
            and _is_table_list(_plain(table[key]))
            and _merge_list(table[key], value, before)
        ):
            pass  # segments keep their comments, added or deleted ones beside them
        elif not _same(_plain(table[key]), value):
            table[key] = value


def _merge_list(tables, values: list[dict], befores) -> bool:
    """New values into a list of tables (``[[flight.segments]]``), each table kept where
    it stands for the same item: an added item inserts its table, a deleted one's
    table goes, an edited one changes its values only. False (the caller rewrites
    the list) when the file's meaning is unknown and the lengths differ."""
    if not (_is_table_list(befores) and len(befores) == len(tables)):
        if len(values) != len(tables):
            return False
        befores = [None] * len(values)
        pairs = dict(zip(range(len(values)), range(len(values))))
    else:
        pairs = dict((j, i) for i, j in _aligned(befores, values))
    kept = set(pairs.values())
    for i in reversed(range(len(tables))):
        if i not in kept:
            del tables[i]
    at = 0
    for j, value in enumerate(values):
        if j in pairs:
            _merge_table(tables[at], value, befores[pairs[j]])
        elif at < len(tables):  # between tables: a blank line after it, as between the others
            table = tomlkit.item(value)
            table.add(tomlkit.nl())
            tables.insert(at, table)
        else:
            tables.append(value)
        at += 1
    return True


def _aligned(befores: list[dict], values: list[dict]) -> list[tuple[int, int]]:
    """(old, new) index pairs of the items that stand for the same one, in order:
    equal items first, then, between them, items of the same kind."""
    pairs: list[tuple[int, int]] = []
    exact = SequenceMatcher(None, [_key(b) for b in befores], [_key(v) for v in values], autojunk=False)
    for tag, i1, i2, j1, j2 in exact.get_opcodes():
        if tag == "equal":
            pairs += zip(range(i1, i2), range(j1, j2))
            continue
        old_kinds = [str(b.get("kind")) for b in befores[i1:i2]]
        new_kinds = [str(v.get("kind")) for v in values[j1:j2]]
        for block in SequenceMatcher(None, old_kinds, new_kinds, autojunk=False).get_matching_blocks():
            pairs += [(i1 + block.a + k, j1 + block.b + k) for k in range(block.size)]
    return pairs


def _key(item: dict) -> str:
    return json.dumps(item, sort_keys=True, default=str)


def _is_table_list(value: object) -> TypeGuard[list[dict]]:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def _same(old, new) -> bool:
    """Equal values, 8 and 8.0 alike (a loaded int comes back a float), True never 1."""
    return old == new and isinstance(old, bool) == isinstance(new, bool)
