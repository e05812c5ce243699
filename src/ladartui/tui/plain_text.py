"""Text from files and fields put into Textual markup so that it shows as written.

Textual reads ``\\[`` as a bracket and nothing else as an escape, so every ``[`` is
escaped: ``rich.markup.escape`` (and Textual's own) escape only what looks like a
tag, so "x[b [c].toml" showed as "x[b \\[c].toml", a path holding "[/run [final]"
raised a MarkupError, and a backslash before a bracket or at the end was doubled.
"""

from __future__ import annotations

from ladartui.textsafe import visible


def literal(text: object) -> str:
    """``text`` for Textual markup: shown as it is, never read as tags, its lines kept and
    any other control character (a file name's terminal escape) written out."""
    return visible(text).replace("[", "\\[")
