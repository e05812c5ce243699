"""``ladartui study``: speed against accuracy of every backend, method and setting."""

from __future__ import annotations

import argparse
import os
import threading

from rich.markup import escape

from ladartui.cli.flags import MAX_RUNS, check_file_names, check_scenario_name, run_count
from ladartui.cli.progress import progress_display, run_cancellable, sigterm_as_interrupt
from ladartui.errors import Cancelled, FieldError
from ladartui.textsafe import single_line, visible

DEFAULT_OUT = "study-results"
DEFAULT_WARMUP = 1
CHART_WIDTH, CHART_HEIGHT = 120, 34


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "study",
        help="time and score every tracing backend x method x setting; chart and verdict",
        description="Trace a scenario's scans with every backend, method, march step, "
        "precision and ray grid; time them (median after warm-up), compare each ray's first "
        "hit with exact float64 numba, score obscured target coverage against exact m=8, and "
        "chart speed against accuracy with the Pareto front. Without a scenario, uses the "
        "generated 'reference' scene (cached under LADARTUI_HOME). Ctrl-C cancels.",
    )
    parser.add_argument(
        "scenario",
        nargs="?",
        help="scenario file (.toml), or a bundled one by name: default, convoy (default: a generated scene)",
    )
    parser.add_argument(
        "--quick", action="store_true", help="small scene, few settings and scans: a fast check"
    )
    parser.add_argument(
        "--out",
        default=DEFAULT_OUT,
        help=f"folder for study.csv, study.json, speed-accuracy.svg/.png/.txt (default: {DEFAULT_OUT})",
    )
    parser.add_argument(
        "--runs",
        type=int,
        default=None,
        help=f"timed runs per setting, 1 to {MAX_RUNS}, median quoted (default 5; 3 with --quick)",
    )
    parser.add_argument(
        "--warmup",
        type=int,
        default=None,
        help=f"untimed calls first, 0 to {MAX_RUNS} (default {DEFAULT_WARMUP})",
    )
    parser.add_argument(
        "--chart-from",
        metavar="JSON",
        default=None,
        help="redraw the chart, table and verdict from a study.json; no tracing",
    )
    parser.add_argument(
        "--scans",
        type=int,
        default=None,
        help="scans traced, evenly spread over the flight (around it, for a full orbit); "
        "no more than it has "
        "(default 3, or all when it has fewer; 2 with --quick)",
    )
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from ladartui.cli.console import CliConsole as Console
    from ladartui.errors import LadarError
    from ladartui.outputset import check_writable_folder
    from ladartui.study import full_settings, quick_settings
    from ladartui.study.inputs import generated_inputs, scenario_inputs
    from ladartui.study.run import check_outputs

    if args.scenario is not None:  # "" is not the generated scene
        check_scenario_name(args.scenario)
    check_file_names({"--chart-from": args.chart_from}, "a study.json written by 'ladartui study'")
    if args.chart_from is not None:  # a study already run: what would shape a new one does not apply
        # every flag here defaults to None (or False), so one given at its default value is refused too
        given = [
            flag
            for flag, value in (
                ("SCENARIO", args.scenario),
                ("--quick", args.quick or None),
                ("--runs", args.runs),
                ("--scans", args.scans),
                ("--warmup", args.warmup),
            )
            if value is not None
        ]
        if given:
            raise LadarError(
                f"--chart-from redraws a study already run: {', '.join(given)} would shape a new one; drop "
                + ("it" if len(given) == 1 else "them")
            )
    check_file_names({"--out": args.out}, f"a folder name, such as {DEFAULT_OUT}")
    check_writable_folder(args.out)  # before the study, not after it
    check_outputs(args.out)
    if args.chart_from:
        return _report(_load_result(args.chart_from), args.out)
    runs = run_count("--runs", args.runs if args.runs is not None else (3 if args.quick else 5))
    scans = _positive("--scans", args.scans if args.scans is not None else (2 if args.quick else 3))
    warmup = run_count("--warmup", args.warmup if args.warmup is not None else DEFAULT_WARMUP, low=0)
    console = Console(stderr=True)
    # --scans above the flight's count is refused; the default (3) takes what there is
    refuse_as = "--scans" if args.scans is not None else None
    try:
        with sigterm_as_interrupt():
            if args.scenario:
                from ladartui.user_data import bundled_or_path

                inputs = scenario_inputs(bundled_or_path(args.scenario), scans, refuse_as=refuse_as)
            else:
                preset = "small" if args.quick else "reference"
                with console.status(f"loading the {preset!r} scene ..."):
                    inputs = generated_inputs(preset, scans, progress=console.print, refuse_as=refuse_as)
            settings = quick_settings() if args.quick else full_settings()
            result = _run_with_progress(console, inputs, settings, runs, warmup)
    except (Cancelled, KeyboardInterrupt):  # the latter: before the study's worker started
        raise Cancelled(_nothing_written(args.out)) from None
    return _report(result, args.out)


def _nothing_written(out_dir) -> str:
    """What a study stopped before its outputs were written says of them."""
    from ladartui.study.run import output_paths

    if any(path.exists() for path in output_paths(out_dir).values()):
        return f"study cancelled; nothing was written, the earlier study in {out_dir} is unchanged"
    return f"study cancelled; nothing was written to {out_dir}"


def _load_result(path):
    from ladartui.study.results import read_study

    return read_study(path)


def _positive(flag, value):
    if value < 1:
        raise FieldError(flag, value, "1 or more")
    return value


def _run_with_progress(console, inputs, settings, runs, warmup):
    from rich.progress import TextColumn, TimeElapsedColumn

    from ladartui.number_text import plural
    from ladartui.study.run import backend_reasons, run_study

    for name, reason in backend_reasons(s.backend for s in settings).items():
        if reason:
            console.print(f"[yellow]skipping backend {name}:[/] {escape(reason)}")
    scene = inputs.scene
    console.print(
        f"study on {inputs.name}: {len(scene.voxels):,} voxels, shape {scene.shape}, "
        f"{plural(len(inputs.poses), 'scan')}, sensor {inputs.sensor.grid}x{inputs.sensor.grid}, "
        f"{len(settings)} settings, median of {plural(runs, 'run')}"
    )
    cancel = threading.Event()
    progress_bar = progress_display(
        console, (TextColumn("{task.completed}/{task.total} traces"), TimeElapsedColumn()), transient=True
    )
    task = progress_bar.add_task("starting", total=None)

    plain = not console.is_terminal  # a log file gets one line per setting instead of a bar
    last: dict[str, str] = {}

    def report(p):
        progress_bar.update(
            task, completed=p.done, total=p.total, description=f"{p.label} scan {p.scan}/{p.scans}"
        )
        # a line as each setting starts, and the last one at the end: N/N
        if plain and ((last.get("label") != p.label and p.scan == 1) or p.done == p.total):
            last["label"] = p.label
            console.print(f"[{p.done}/{p.total} traces] {p.label}", highlight=False, markup=False)

    with progress_bar:
        return run_cancellable(
            lambda: run_study(inputs, settings, runs=runs, warmup=warmup, progress=report, cancel=cancel),
            cancel,
            "ladartui-study",
            Cancelled("study cancelled"),
        )


def _report(result, out_dir) -> int:
    """Show the study and write its files: a Ctrl-C or SIGTERM on the way says whether
    they were written (130 or 143 either way)."""
    # matplotlib first: a SIGTERM taken as Ctrl-C inside its extension modules' start
    # fails the import and then the interpreter as it ends, where it would end quietly
    import ladartui.charts  # noqa: F401
    import ladartui.study.figure  # noqa: F401
    from ladartui.study.run import interrupted_after_writing, write_outputs

    paths: dict | None = None  # once in place (write_outputs tells an interrupt as it puts them)
    try:
        with sigterm_as_interrupt():
            console = _show(result)
            paths = write_outputs(result, out_dir, width=CHART_WIDTH, height=CHART_HEIGHT)
            console.print(
                single_line("wrote " + ", ".join(str(p) for p in paths.values())),
                highlight=False,
                markup=False,
            )
            return 0
    except KeyboardInterrupt:
        if paths is not None:
            raise Cancelled(interrupted_after_writing(paths)) from None
        raise Cancelled(_nothing_written(out_dir)) from None


def _show(result):
    """The study's chart, table and verdict on the terminal; the console they went to."""
    from rich.table import Table
    from rich.text import Text

    from ladartui.cli.console import CliConsole as Console
    from ladartui.study.chart import TABLE_COLUMNS, chart_text, table_rows

    console = Console()
    if not console.is_terminal and "COLUMNS" not in os.environ:
        console = Console(width=CHART_WIDTH + 20)  # a log file: no need to wrap at 80
    width = max(60, min(console.width, CHART_WIDTH))
    console.print(Text.from_ansi(chart_text(result, width, CHART_HEIGHT, color=console.is_terminal)))
    label = Text(single_line(f"Settings (coverage error against {result.reference_label or '-'})"))
    table = Table(title=label)  # the label is read from a file: never markup
    for column in TABLE_COLUMNS:
        table.add_column(
            column, justify="right" if column in ("s/scan", "rays/s", "differ", "cov. error") else "left"
        )
    for row in table_rows(result):
        table.add_row(*(Text(single_line(cell)) for cell in row))  # a reason read from a file: never markup
    console.print(table)
    console.print(visible(result.verdict()), highlight=False, markup=False)
    return console
