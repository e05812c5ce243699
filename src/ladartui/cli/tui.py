"""``ladartui tui [SCENARIO.toml]``: the terminal UI (also ``ladartui`` alone)."""

from __future__ import annotations

from ladartui.fileprobe import require_file
from ladartui.tui.graphics import MODES  # no textual: the mode is chosen before the app loads


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "tui",
        help="open the terminal UI (the default when no command is given)",
        description="Open the terminal UI on SCENARIO.toml, or on the default scenario "
        "(created with its scene on first use).",
    )
    parser.add_argument(
        "scenario",
        nargs="?",  # a str: as a Path, "" would be the current folder
        help="a scenario file (.toml), or a bundled one by name (default, convoy)",
    )
    parser.add_argument(
        "--graphics",
        choices=MODES,
        help="how the views are drawn: real pixels (sixel, kitty, iterm), half-block characters "
        "(halfblocks), plain coloured characters (characters) or auto (chosen at start-up; "
        "the default, or [display] graphics in settings.toml)",
    )
    parser.set_defaults(handler=run)


def _terminals(*streams) -> bool:
    return all(stream is not None and stream.isatty() for stream in streams)


def on_a_terminal() -> bool:
    """Whether the process reads keys from, and draws on, a terminal: standard input and
    output, and standard error, the stream Textual's driver draws every screen on."""
    import sys

    return _terminals(sys.__stdin__, sys.__stdout__, sys.__stderr__)


def run(args) -> int:
    path = args.scenario
    if path is not None:
        from ladartui.cli.flags import check_scenario_name
        from ladartui.user_data import bundled_or_path

        check_scenario_name(path)
        path = bundled_or_path(path)  # "convoy": the bundled scenario, made on first use
    if path is not None:
        require_file(path, "expected a scenario file (.toml)")
    if not on_a_terminal():  # the app would draw into a file or pipe and wait for keys for ever
        import sys

        from ladartui.errors import LadarError

        if _terminals(sys.__stdin__, sys.__stdout__):  # 2>errors.log: a blank terminal
            raise LadarError(
                "the terminal UI draws on standard error, and it is a file or pipe (2>FILE); "
                "run it with standard error on the terminal, or for a run without one: "
                "ladartui run SCENARIO"
            )
        raise LadarError(
            "the terminal UI needs a terminal, and its input or output is a file or pipe; "
            "for a run without one: ladartui run SCENARIO"
        )
    from ladartui.tui import run_app

    return run_app(path, args.graphics)
