"""``ladartui compare A.cmf B.cmf ...``: several runs' measures side by side, as the TUI's Compare."""

from __future__ import annotations

import json


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "compare",
        help="put two or more runs' measures side by side",
        description="Read the measures files (.cmf) two or more runs wrote, or the scenarios "
        "(.toml) whose last runs wrote them, and print their figures side by side (the "
        "coverage after each scan, a list, is left to run and the .cmf): where the "
        "runs differ the row is yellow, and for a measure with a better direction the best "
        "value is green and the worst red (the TUI's Compare, F10, shows the same). A scenario "
        "edited since its last run is compared by that run's measures, with a note on standard "
        "error naming the settings that differ.",
    )
    parser.add_argument(
        "files",
        metavar="FILE",
        nargs="+",
        help="measures file (.cmf) or scenario (.toml), or a bundled scenario's name (default, "
        "convoy); two or more",
    )
    parser.add_argument(
        "--json",
        action="store_true",
        help="print JSON instead: the columns and files, and per measure its values, their "
        "text, whether they differ and the best and worst columns",
    )
    parser.set_defaults(handler=run)
    return parser


def run(args) -> int:
    from ladartui.cli.flags import check_file_names
    from ladartui.errors import FieldError
    from ladartui.measures_compare import column_names, read_compared, side_by_side
    from ladartui.user_data import bundled_run

    for file in args.files:
        check_file_names({"FILE": file}, "a measures file (.cmf) or a scenario (.toml)")
    if len(args.files) < 2:
        raise FieldError("FILE", args.files[0], "two or more files to compare")
    paths = [bundled_run(file) for file in args.files]  # "convoy", as run takes it
    measures, notes = read_compared(paths)  # a folder is refused before it is named
    rows = side_by_side(measures)
    names = column_names(paths)
    _note_earlier_settings(notes)
    if args.json:
        print(json.dumps(as_json(names, paths, rows), indent=2, allow_nan=False))
    else:
        show(names, rows)
    return 0


def _note_earlier_settings(notes) -> None:
    """A note on standard error for each scenario whose last run (its measures compared)
    went with other settings than the file has now (a file given twice: said once)."""
    from ladartui.cli.console import CliConsole
    from ladartui.textsafe import one_line

    console = CliConsole(stderr=True)
    for note in notes:
        console.print(one_line(f"note: {note}"), highlight=False, markup=False, soft_wrap=True)


def as_json(names, paths, rows) -> dict:
    return {
        "columns": names,
        "files": [str(path) for path in paths],
        "measures": [
            {
                "measure": row.label,
                "values": [_plain(value) for value in row.values],
                "text": list(row.texts),
                "differ": row.differ,
                "best": [names[i] for i in row.best],
                "worst": [names[i] for i in row.worst],
            }
            for row in rows
        ],
    }


def _plain(value):
    """A value as JSON holds it: vectors as lists, a non-finite number as None."""
    import math

    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def show(names, rows) -> None:
    from rich.table import Table
    from rich.text import Text

    from ladartui.cli.console import CliConsole
    from ladartui.measures_compare import styled

    table = Table(title="Measures side by side")
    table.add_column("Measure")
    for name in names:
        table.add_column(Text(name), justify="right")  # names from files: never markup
    for row in rows:
        table.add_row(*styled(row))
    CliConsole().print(table)
