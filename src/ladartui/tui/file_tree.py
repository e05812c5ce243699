"""A folder tree that shows only the files a dialog can take."""

from __future__ import annotations

from pathlib import Path

from textual.widgets import DirectoryTree


class FileTree(DirectoryTree):
    """Folders, and the files with one of ``suffixes``; hidden entries left out."""

    DEFAULT_CSS = "FileTree { height: 1fr; min-height: 3; border: round $panel-lighten-2; }"

    def __init__(self, path: Path, suffixes: tuple[str, ...], **kwargs):
        super().__init__(path, **kwargs)
        self.suffixes = suffixes

    def filter_paths(self, paths):
        return [
            p
            for p in paths
            if not p.name.startswith(".") and (p.is_dir() or p.suffix.lower() in self.suffixes)
        ]
