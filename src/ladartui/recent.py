"""The scenarios opened lately, newest first, kept in the user's config folder.

The list lives in ``recent.json`` under ``$LADARTUI_HOME/config`` when
LADARTUI_HOME is set (tests, portable installs), else in the platform's
user config folder (``~/.config/ladartui`` on Linux). A missing or damaged
file is an empty list: remembering files is a convenience, never a reason
to refuse to start.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import platformdirs

from ladartui.atomic import write_text_atomic

RECENT_LIMIT = 10
RECENT_FILE = "recent.json"


def config_folder() -> Path:
    if os.environ.get("LADARTUI_HOME"):
        return Path(os.environ["LADARTUI_HOME"]).expanduser() / "config"
    return platformdirs.user_config_path("ladartui")


def recent_scenarios(existing_only: bool = True) -> list[Path]:
    """The remembered scenario files, newest first (those still on disk, by default)."""
    try:
        names = json.loads((config_folder() / RECENT_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    if not isinstance(names, list):
        return []
    paths = [Path(name) for name in names if isinstance(name, str)]
    return [p for p in paths if p.is_file()] if existing_only else paths


def remember_scenario(path) -> list[Path]:
    """Put ``path`` first in the recent list (at most RECENT_LIMIT); the new list.

    A folder that cannot be written is not an error: the list is returned
    as it would have been.
    """
    path = Path(path).expanduser().resolve()
    paths = [path] + [p for p in recent_scenarios(existing_only=False) if p != path]
    paths = paths[:RECENT_LIMIT]
    try:
        write_text_atomic(config_folder() / RECENT_FILE,
                          json.dumps([str(p) for p in paths], indent=1) + "\n")
    except OSError:
        pass
    return paths
