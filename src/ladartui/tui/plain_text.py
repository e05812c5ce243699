"""Text from files and fields shown as written: put into Textual markup (``literal``),
or in a Static that reads none (``PlainStatic``), its controls written out either way.

Textual reads ``\\[`` as a bracket and nothing else as an escape, so every ``[`` is
escaped: ``rich.markup.escape`` (and Textual's own) escape only what looks like a
tag, so "x[b [c].toml" showed as "x[b \\[c].toml", a path holding "[/run [final]"
raised a MarkupError, and a backslash before a bracket or at the end was doubled.
"""

from __future__ import annotations

from typing import Any

from rich.text import Text
from textual.visual import VisualType
from textual.widgets import Input, Static

from ladartui.textsafe import CONTROL_CODES, visible


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


# Each control character as one printable one (ESC as the picture of ESC), so that a
# field's cursor keeps its place over the value it shows.
# (the controls messages write out; those without a picture of their own as U+FFFD)
_PICTURES = {code: 0x2400 + code if code < 0x20 else 0xFFFD for code in CONTROL_CODES} | {0x7F: 0x2421}


class PathInput(Input):
    """A field of file paths: a name holding controls (picked in a tree, or offered
    filled in) shows them as their pictures, never raw to the terminal; its value stays
    the name on disk."""

    @property
    def _value(self) -> Text:
        text = super()._value
        shown = text.plain.translate(_PICTURES)
        if shown == text.plain:
            return text
        pictured = Text(shown, no_wrap=True, overflow="ignore", end="")
        for span in text.spans:
            pictured.stylize(span.style, span.start, span.end)
        return pictured
