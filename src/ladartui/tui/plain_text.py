"""Text from files and fields shown as written: put into Textual markup (``literal``),
or in a Static that reads none (``PlainStatic``), its controls written out either way.

Textual reads ``\\[`` as a bracket and nothing else as an escape, so every ``[`` is
escaped: ``rich.markup.escape`` (and Textual's own) escape only what looks like a
tag, so "x[b [c].toml" showed as "x[b \\[c].toml", a path holding "[/run [final]"
raised a MarkupError, and a backslash before a bracket or at the end was doubled.
"""

from __future__ import annotations

from typing import Any

from textual.visual import VisualType
from textual.widgets import Static

from ladartui.textsafe import visible


def literal(text: object) -> str:
    """``text`` for Textual markup: shown as it is, never read as tags, its lines kept and
    any other control character (a file name's terminal escape) written out."""
    return visible(text).replace("[", "\\[")


class PlainStatic(Static):
    """A Static of text from files and fields: never read as markup, its controls (a
    file name's terminal escape, which would reach the terminal raw) written out."""

    def __init__(self, content: VisualType = "", **kwargs: Any) -> None:
        super().__init__(_written_out(content), markup=False, **kwargs)

    def update(self, content: VisualType = "", *, layout: bool = True) -> None:
        super().update(_written_out(content), layout=layout)


def _written_out(content: VisualType) -> VisualType:
    return visible(content) if isinstance(content, str) else content
