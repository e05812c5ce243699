"""How the views reach the terminal: real pixels, half-block or plain characters.

Modes: ``kitty`` (Kitty graphics protocol), ``sixel``, ``iterm`` (iTerm2 inline
images), all drawn by ``textual-image``; else ``halfblocks`` (two pixels a
cell), in 24-bit colour where the terminal says it has it (``COLORTERM``), else
in the xterm 256-colour palette; else ``characters``: plain spaces on a
coloured background, one square pixel every two cells, for terminals without
block glyphs. ``auto`` (the default) chooses at start-up, before the app
takes the terminal's input:

- not a terminal, or inside tmux or screen (they pass no graphics by default):
  half-blocks, without asking the terminal anything;
- a terminal without block glyphs (``TERM`` dumb, vt100, vt102 or vt220):
  plain characters;
- iTerm2 (``TERM_PROGRAM``, or ``LC_TERMINAL``, which ssh forwards): iterm;
- kitty (``KITTY_WINDOW_ID``, or ``TERM=xterm-kitty``, which ssh forwards): kitty;
- otherwise the terminal is asked (textual-image's own queries: Sixel in the
  device attributes, then a Kitty graphics query), which works over ssh too;
  no answer within its time-out means half-blocks.

The mode can be forced in the settings file, ``settings.toml`` in the config
folder::

    [display]
    graphics = "sixel"   # auto, halfblocks, characters, sixel, kitty or iterm

or for one session by ``ladartui tui --graphics MODE``.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from ladartui.textsafe import one_line
from ladartui.toml_lines import read_config_table
from ladartui.user_data import config_folder

MODES = ("auto", "halfblocks", "characters", "sixel", "kitty", "iterm")
IMAGE_MODES = ("sixel", "kitty", "iterm")
NO_BLOCK_GLYPHS = ("dumb", "vt100", "vt102", "vt220")
SETTINGS_FILE = "settings.toml"
SETTING = "display.graphics"


@dataclass(frozen=True)
class Graphics:
    """The chosen way to draw the views, and why."""

    mode: str = "halfblocks"  # one of MODES but "auto"
    truecolor: bool = True  # else the 256-colour palette (half-blocks and characters)
    reason: str = ""
    seconds: float = 0.0  # time taken to choose (asking the terminal)

    @property
    def image(self) -> bool:
        return self.mode in IMAGE_MODES

    def describe(self) -> str:
        colours = "24-bit colour" if self.truecolor else "256 colours"
        if self.mode == "halfblocks":
            what = "half-blocks, " + colours
        elif self.mode == "characters":
            what = "plain characters, " + colours
        else:
            what = f"{self.mode} images"
        return f"{what}: {self.reason}"


def has_truecolor(env: Mapping[str, str]) -> bool:
    """Whether the terminal says it shows 24-bit colour (as rich, and so Textual, reads it)."""
    return env.get("COLORTERM", "").strip().lower() in ("truecolor", "24bit")


def in_multiplexer(env: Mapping[str, str]) -> bool:
    term = env.get("TERM", "").lower()
    return bool(env.get("TMUX")) or bool(env.get("STY")) or term.startswith(("tmux", "screen"))


def choose(
    setting: str,
    env: Mapping[str, str],
    is_tty: bool,
    probe: Callable[[], str | None],
) -> Graphics:
    """The mode for ``setting`` (one of MODES) in a terminal described by ``env``.

    ``probe`` asks the terminal and returns "sixel", "kitty" or None; it is
    called only when ``auto`` cannot decide from the environment.
    """
    truecolor = has_truecolor(env)
    if setting != "auto":
        return Graphics(setting, truecolor or setting in IMAGE_MODES, f"set to {setting}")
    if not is_tty:
        return Graphics("halfblocks", truecolor, "not a terminal")
    if in_multiplexer(env):
        return Graphics(
            "halfblocks",
            truecolor,
            "inside tmux or screen, which pass no graphics by default "
            '(graphics = "sixel" suits tmux 3.4+ built with Sixel)',
        )
    if env.get("TERM", "").lower() in NO_BLOCK_GLYPHS:
        return Graphics("characters", truecolor, f"TERM={env['TERM']} has no block glyphs")
    if env.get("TERM", "").lower() == "linux":
        return Graphics("halfblocks", truecolor, f"TERM={env['TERM']} shows no graphics")
    if env.get("TERM_PROGRAM") == "iTerm.app" or env.get("LC_TERMINAL") == "iTerm2":
        return Graphics("iterm", True, "iTerm2")
    if env.get("KITTY_WINDOW_ID") or env.get("TERM", "").lower() == "xterm-kitty":
        return Graphics("kitty", True, "kitty")
    found = probe()
    if found in IMAGE_MODES:
        return Graphics(found, True, f"the terminal answered that it shows {found} graphics")
    return Graphics("halfblocks", truecolor, "the terminal reported neither Sixel nor Kitty graphics")


def probe_terminal() -> str | None:
    """Ask the terminal what it shows, with textual-image's own queries ("sixel",
    "kitty" or None). Only before the app starts: the app reads the answers as keys."""
    from textual_image import renderable

    if renderable.Image is renderable.SixelImage:
        return "sixel"
    if renderable.Image is renderable.TGPImage:
        return "kitty"
    return None


def read_setting(folder: Path | None = None) -> tuple[str, list[str]]:
    """The ``[display] graphics`` setting ("auto" when absent) and one line per problem."""
    config = read_config_table((folder or config_folder()) / SETTINGS_FILE, "display", "graphics = mode")
    display, problems, at = config.table, config.problems, config.at
    where = at(SETTING)
    problems += [
        one_line(f"{at(f'display.{name}')}: display.{name}: no such setting; expected graphics")
        for name in display
        if name != "graphics"
    ]
    value = display.get("graphics", "auto")
    if not isinstance(value, str) or value.strip().lower() not in MODES:
        return "auto", [
            *problems,
            one_line(f"{where}: {SETTING} = {value!r}: expected one of {', '.join(MODES)}; using auto"),
        ]
    return value.strip().lower(), problems


def detect(forced: str | None = None, folder: Path | None = None) -> tuple[Graphics, list[str]]:
    """The start-up choice: ``forced`` (a command-line flag) over the settings file over
    ``auto``; returns it (timed) and the settings file's problems."""
    setting, problems = read_setting(folder)
    if forced is not None:
        setting = forced
    started = time.perf_counter()
    stdout = sys.__stdout__
    is_tty = bool(stdout and stdout.isatty())
    graphics = choose(setting, os.environ, is_tty, probe_terminal)
    if graphics.image:
        from textual_image import widget  # noqa: F401  (reads the cell size in pixels, once)
    seconds = time.perf_counter() - started
    return Graphics(graphics.mode, graphics.truecolor, graphics.reason, seconds), problems
