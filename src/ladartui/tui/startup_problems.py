"""Problems found at start-up (keys.toml, settings.toml) told in one notice.

A notice each stacked up at 80 x 24 and the first ran off the top of the screen,
so several come as one: a line each, the config folder named once in the title,
and the command ids the unknown ones could be told once at the end, where the
notice still fits the screen (else where to find them).
"""

from __future__ import annotations

from pathlib import Path

from rich.cells import cell_len

from ladartui.tui.actions import BY_ID

TOAST_WIDTH = 60  # Textual's notice: 60 cells, at most half the screen,
TOAST_FRAME = 3  # less its padding and edge
TOAST_ROOM = 5  # lines the screen keeps: the status bar, the footer, the notice's frame


def command_ids() -> str:
    return ", ".join(sorted(BY_ID))


def startup_notice(problems: list[tuple[str, str]], folder: Path, size: tuple[int, int]) -> tuple[str, str]:
    """The (title, message) of one notice for ``problems``, each (title, problem);
    ``folder``: the config folder; ``size``: the screen's (width, height)."""
    if len(problems) == 1:
        return problems[0]
    unknown_tail = f"; expected one of {command_ids()}"
    prefix = f"{folder}/"
    lines, unknown = [], False
    for _title, problem in problems:
        if problem.endswith(unknown_tail):  # the ids are told once, below
            problem, unknown = problem.removesuffix(unknown_tail), True
        lines.append(problem.removeprefix(prefix))
    title = f"{len(problems)} problems at start-up, in {folder}"
    if unknown:
        ids = f"Command ids: {command_ids()}"
        width, height = size
        across = max(min(TOAST_WIDTH, width // 2) - TOAST_FRAME, 1)
        tall = sum(-(-cell_len(line) // across) + 1 for line in [title, *lines, ids])  # +1: wrapping
        fits = tall <= height - TOAST_ROOM
        lines.append(ids if fits else "Command ids: see docs/tui.md, Keys (no room to list them here)")
    return title, "\n".join(lines)
