"""``ladartui tui [SCENARIO.toml]``: the terminal UI (also ``ladartui`` alone)."""

from __future__ import annotations

from pathlib import Path

from ladartui.errors import InputFileError


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "tui",
        help="open the terminal UI (the default when no command is given)",
        description="Open the terminal UI on SCENARIO.toml, or on the default scenario "
        "(created with its scene on first use).",
    )
    parser.add_argument("scenario", nargs="?", type=Path, help="a scenario file (.toml)")
    parser.set_defaults(handler=run)


def run(args) -> int:
    path = args.scenario
    if path is not None and not path.is_file():
        raise InputFileError(path, "scenario file not found")
    from ladartui.tui import run_app

    return run_app(path)
