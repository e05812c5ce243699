"""Files opened lately, newest first, kept in the user's config folder.

Two lists: the scenarios opened (the terminal UI's File tab and palette) and
the sweeps opened or run (the sweep screen reopens the last one). They live
in ``recent.json`` under ``$LADARTUI_HOME/config`` when LADARTUI_HOME is set
(tests, portable installs), else in the platform's user config folder
(``~/.config/ladartui`` on Linux). A missing or damaged file is an empty
list: remembering files is a convenience, never a reason to refuse to start.
"""

from __future__ import annotations

import json
from pathlib import Path

from ladartui.atomic import write_text_atomic
from ladartui.fileprobe import user_path
from ladartui.user_data import config_folder

RECENT_LIMIT = 10
RECENT_FILE = "recent.json"
KINDS = ("scenarios", "sweeps")


def _read() -> dict[str, list[str]]:
    try:
        data = json.loads((config_folder() / RECENT_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return {}
    if isinstance(data, list):  # the first format: scenarios only
        data = {"scenarios": data}
    if not isinstance(data, dict):
        return {}
    return {
        kind: [n for n in data.get(kind, []) if isinstance(n, str)]
        for kind in KINDS
        if isinstance(data.get(kind, []), list)
    }


def recent_paths(kind: str, existing_only: bool = True) -> list[Path]:
    """The remembered files of ``kind``, newest first (those still on disk, by default)."""
    paths = [Path(name) for name in _read().get(kind, [])]
    return [p for p in paths if _exists(p)] if existing_only else paths


def _exists(path: Path, is_file: bool = False) -> bool:
    """Whether ``path`` is there; False for a name the system cannot even look up
    (longer than a name may be), which ``Path.exists`` raises for."""
    try:
        return path.is_file() if is_file else path.exists()
    except OSError:
        return False


def remember_path(kind: str, path) -> list[Path]:
    """Put ``path`` first in the ``kind`` list (at most RECENT_LIMIT); the new list.

    A folder that cannot be written is not an error: the list is returned
    as it would have been.
    """
    path = user_path(path).resolve()
    data = _read()
    paths = [path] + [p for p in recent_paths(kind, existing_only=False) if p != path]
    paths = paths[:RECENT_LIMIT]
    data[kind] = [str(p) for p in paths]
    try:
        write_text_atomic(config_folder() / RECENT_FILE, json.dumps(data, indent=1) + "\n")
    except OSError:
        pass
    return paths


def recent_scenarios(existing_only: bool = True) -> list[Path]:
    return [p for p in recent_paths("scenarios", existing_only) if not existing_only or _exists(p, True)]


def remember_scenario(path) -> list[Path]:
    return remember_path("scenarios", path)
