"""A folder tree that shows only the files a dialog can take."""

from __future__ import annotations

from pathlib import Path

from rich.text import Text
from textual.widgets import DirectoryTree

from ladartui.run_record import is_record
from ladartui.textsafe import single_line

# A scenario file has a [files] table (scenario.py); other .toml files (pyproject.toml,
# sweep specs) are not scenarios, nor are run records (outputs, though they have one).
SCENARIO_TABLE = "[files]"
HEAD_BYTES = 65536  # how much of a .toml is read to find the table


class FileTree(DirectoryTree):
    """Folders, and the files with one of ``suffixes``; hidden entries left out.
    ``toml_table``: a .toml file is shown only when a line opens that table."""

    DEFAULT_CSS = "FileTree { height: 1fr; min-height: 3; border: round $panel-lighten-2; }"

    def __init__(self, path: Path, suffixes: tuple[str, ...], toml_table: str | None = None, **kwargs):
        super().__init__(path, **kwargs)
        self.suffixes = suffixes
        self.toml_table = toml_table

    def process_label(self, label) -> Text:
        """A file's name, whole on its line, its controls (an escape, a newline) written out:
        raw, they reached the terminal, and the name was cut at a newline."""
        return Text(single_line(label)) if isinstance(label, str) else super().process_label(label)

    def filter_paths(self, paths):
        return [p for p in paths if not p.name.startswith(".") and (p.is_dir() or self._takes(p))]

    def _takes(self, path: Path) -> bool:
        suffix = path.suffix.lower()
        if suffix not in self.suffixes:
            return False
        if suffix != ".toml" or self.toml_table is None:
            return True
        if not opens_table(path, self.toml_table):
            return False
        return self.toml_table != SCENARIO_TABLE or not is_record(path)


def opens_table(path: Path, table: str) -> bool:
    """Whether a line near the start of ``path`` opens TOML table ``table`` ("[files]")."""
    if not path.is_file():  # a pipe would wait for ever
        return False
    try:
        with open(path, encoding="utf-8-sig", errors="replace") as handle:
            head = handle.read(HEAD_BYTES)
    except OSError:
        return False
    return any(line.strip().startswith(table) for line in head.splitlines())
