"""Safe one-line text for messages: control characters escaped, length capped.

Text from files, file names and scenario fields can hold terminal escapes, line
breaks or megabytes; a message shows it as one readable line. Core module (no UI
imports) so the CLI and the TUI both use it.
"""

MAX_MESSAGE_CHARS = 400


# The code points written out: C0 and C1 controls, DEL, the line and paragraph
# separators, and lone surrogates (a file name's byte that is not UTF-8, which a strict
# stdout refuses). The TUI's path fields show the same ones as pictures.
CONTROL_CODES = frozenset((*range(0x20), *range(0x7F, 0xA0), 0x2028, 0x2029, *range(0xD800, 0xE000)))


def _visible(char: str) -> str:
    code = ord(char)
    if code in CONTROL_CODES:
        return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"
    return char


def one_line(text: object, limit: int = MAX_MESSAGE_CHARS) -> str:
    """``text`` as one line: control characters written as ``\\xNN``, at most ``limit`` characters."""
    safe = single_line(text)
    if len(safe) <= limit:
        return safe
    dropped = len(safe) - limit
    return f"{safe[:limit]}... ({dropped} more characters)"


def single_line(text: object) -> str:
    """``text`` for a terminal as one line, nothing cut: control characters, line breaks
    included, written as ``\\xNN`` (a file name's newline must not start a line of its own)."""
    return "".join(_visible(char) for char in str(text))


def visible(text: object) -> str:
    """``text`` for a terminal, its lines kept: control characters in each line (a file
    name's terminal escapes) written as ``\\xNN``, nothing cut."""
    return "\n".join(single_line(line) for line in str(text).split("\n"))
