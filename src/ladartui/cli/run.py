"""``ladartui run SCENARIO``: simulate a scenario, write its outputs, show the measures.

The run happens on a worker thread so that Ctrl-C (or SIGTERM) on the main
thread can set the cancel event; the run then stops between chunks and writes
nothing, or, when the outputs were already being swapped in, finishes the swap
and reports the files written.
Progress goes to stderr, the measures to stdout (a table, or JSON with --json), and
the files written after them (with --json, the chart's line goes to stderr).
"""

from __future__ import annotations

import contextlib
import json
import os
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from ladartui.cli.flags import as_flags, check_scenario_name, refuse_step_without_march
from ladartui.cli.progress import (
    bar_hidden_if_refused,
    first_scan,
    progress_display,
    run_cancellable,
    sigterm_as_interrupt,
)
from ladartui.errors import Cancelled, LadarError, OutputFileError
from ladartui.textsafe import single_line

if TYPE_CHECKING:
    from ladartui.simulation import SimulationResult


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "run",
        help="simulate a scenario's collection and score it",
        description="Trace every scan of the scenario against the scene (obscured) and the "
        "target alone (unobscured), fuse the returns, write S_Scene.txt, S_Target.txt, "
        "S.cmf and S_Run.toml (the settings the run went with, flags included) beside the "
        "scenario, and show the measures of effectiveness.",
    )
    parser.add_argument(
        "scenario",
        metavar="SCENARIO",
        help="scenario file (.toml), or a bundled one by name: default, convoy (made on first use)",
    )
    parser.add_argument(
        "--backend", metavar="B", help="tracing backend: auto, numba or wgpu (default: the scenario's)"
    )
    parser.add_argument("--method", metavar="M", help="tracing method: exact or march")
    parser.add_argument(
        "--step", metavar="S", type=float, help="march step in voxels (needs a march: --method march)"
    )
    parser.add_argument("--precision", metavar="P", help="tracing precision: f32 or f64")
    parser.add_argument("--las", action="store_true", help="also write the outputs as LAS point clouds")
    parser.add_argument(
        "--no-write", dest="write", action="store_false", help="do not write outputs or measures"
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON on stdout")
    parser.add_argument(
        "--max-rays",
        metavar="N",
        type=float,
        help="refuse a run tracing more rays than this (default 2e9; also LADARTUI_MAX_RAYS)",
    )
    parser.add_argument(
        "--chart", metavar="FILE", help="also write the coverage after each scan as a chart (.svg or .png)"
    )
    parser.set_defaults(handler=run)
    return parser


def run(args) -> int:
    from ladartui.cli.console import CliConsole as Console
    from ladartui.errors import FieldError
    from ladartui.scenario import check_work, load_scenario

    if args.max_rays is not None:
        from ladartui.resources import set_max_rays

        if not (args.max_rays >= 1 and float(args.max_rays).is_integer()):
            given = int(args.max_rays) if float(args.max_rays).is_integer() else args.max_rays
            raise FieldError("--max-rays", given, "a whole number of rays >= 1")  # "-1", not "-1.0"
        set_max_rays(int(args.max_rays))
    if args.las and not args.write:
        raise LadarError("--las: it copies the outputs as LAS files, which --no-write does not write")
    from ladartui.user_data import bundled_or_path

    check_scenario_name(args.scenario)
    scenario = load_scenario(bundled_or_path(args.scenario))
    # Check the overrides like scenario fields, before any progress is drawn.
    overrides = {name: getattr(args, name) for name in ("backend", "method", "step", "precision")}
    overrides = {name: value for name, value in overrides.items() if value is not None}
    with as_flags(overrides):
        scenario = scenario.with_changes(**overrides)
    check_work(scenario)  # before the kernels compile and the bar is drawn
    how = (
        f"--method {args.method}" if args.method else f"{scenario.method} (the scenario's simulation.method)"
    )
    refuse_step_without_march(args.step, scenario.method, f"this run is {how}")
    if args.write:  # before any progress is drawn; the run checks again under its lock
        from ladartui.outputset import check_not_held, check_writable
        from ladartui.simulation import check_outputs_spare_inputs, output_lock, output_paths

        check_outputs_spare_inputs(scenario, args.las)
        check_writable(*output_paths(scenario, args.las).values())
        check_not_held(output_lock(scenario))  # not after minutes of compiling
    if args.chart is not None:
        from ladartui.outputset import output_problem

        # the suffix, as the chart's writer reads it: ".svg" alone is a name with none
        if Path(args.chart).suffix.lower() not in (".svg", ".png"):
            raise FieldError("--chart", args.chart, "a file name ending in .svg or .png, a name before it")
        if not os.path.exists(os.path.dirname(args.chart) or "."):  # a mistyped folder is not made
            raise FieldError("--chart", args.chart, "a file in an existing folder")
        problem = output_problem(args.chart)  # before the run, not after its outputs
        if problem:
            raise FieldError("--chart", args.chart, f"a writable path; it {problem}")
    errors = Console(stderr=True)
    finished: list[SimulationResult] = []  # the result, once there is one
    with _told_if_finished(finished):  # a Ctrl-C from then on says what the run wrote
        notes: list[str] = []
        result = _simulate_with_progress(scenario, args, errors, finished, notes)
        chart_error = chart_line = chart_path = undrawn_line = None
        if args.chart is not None:
            from ladartui import charts
            from ladartui.charts.coverage import coverage_figure

            try:
                with charts.undrawn_characters() as undrawn:
                    chart_path = charts.save_figure(coverage_figure(result.measures), args.chart)
                chart_line = single_line(f"wrote chart: {chart_path}")
                undrawn_line = _undrawn_note(undrawn)
            except OSError as error:  # the run's outputs are written: say so, and show them
                reason = (error.strerror or str(error)).lower()
                written = (
                    ", ".join(str(p) for p in result.outputs.values()) or "no scenario outputs (--no-write)"
                )
                chart_error = OutputFileError(
                    args.chart, f"the chart was not written ({reason}); the run wrote {written}"
                )
        # The chart's line follows the run's own "wrote" lines; --json keeps stdout JSON.
        said = errors if args.json else Console()
        if args.json:
            print(json.dumps(result_dict(scenario, result, chart_path, notes), indent=2, allow_nan=False))
        else:
            show_result(said, result, asked_precision=scenario.precision)
        for line in (chart_line, undrawn_line):
            if line is not None:
                said.print(line, highlight=False, markup=False, soft_wrap=True)
        if result.outputs and not args.las:
            _note_earlier_las(said, scenario)
        if chart_error is not None:
            raise chart_error
    return 0


def _undrawn_note(characters: list[str]) -> str | None:
    """A line saying which characters of the chart's names no font here has, if any."""
    if not characters:
        return None
    return single_line(
        f"note: the chart draws a box for each of {', '.join(characters)}: no font here has them"
    )


def _note_earlier_las(console, scenario) -> None:
    """Name the LAS copies an earlier ``run --las`` left beside the outputs just written."""
    from ladartui.run_record import earlier_las

    left = earlier_las(scenario)
    if left:
        names = " and ".join(path.name for path in left)
        verb = "are" if len(left) > 1 else "is"
        console.print(
            single_line(
                f"note: {names} {verb} from an earlier run, not this one (run --las writes them again)"
            ),
            highlight=False,
            markup=False,
            soft_wrap=True,
        )


def run_progress(console, **options):
    """The run's progress display: scan, bar, share done, rays of both runs, times."""
    from rich.progress import TextColumn, TimeElapsedColumn, TimeRemainingColumn

    after = (
        TextColumn("{task.percentage:>5.1f} %"),
        TextColumn("{task.fields[rays]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
    )
    return progress_display(console, after, **options)


def _simulate_with_progress(scenario, args, console, finished: list, notes: list):
    """The run's result, also appended to ``finished`` as soon as there is one; ``notes``
    gets the sentences for scans that never look at the scene or a target (view_reach)."""
    from ladartui.precompile import compile_ahead
    from ladartui.simulation import NOTHING_WRITTEN, simulate

    cancel = threading.Event()
    with run_progress(console, transient=False) as bar:
        task = bar.add_task(first_scan(scenario), total=1.0, rays="")
        traced = threading.Event()  # a scan's progress came

        def report(p):
            traced.set()
            bar.update(
                task,
                completed=p.fraction,
                description=f"scan {p.scan}/{p.scans}",
                rays=f"{p.rays_done:,}/{p.rays_total:,} rays",  # both runs: scene and target
            )

        # A stop during the write lets the swap finish (or roll back): the files on
        # disk belong to one run and the result says which.
        def work():
            from ladartui.view_reach import reach_notes

            scene = scenario.load_scene()  # a mistake in a model file told before any compiling
            compile_ahead(scenario, cancel)
            notes[:] = reach_notes(scenario, scene)  # told before the tracing: Ctrl-C saves it
            for note in notes:
                bar.console.print(single_line(f"note: {note}"), markup=False, highlight=False, soft_wrap=True)
            return simulate(
                scenario, progress=report, cancel=cancel, write=args.write, las=args.las, scene=scene
            )

        with sigterm_as_interrupt(), bar_hidden_if_refused(bar, task, traced.is_set):
            finished.append(run_cancellable(work, cancel, "ladartui-run", Cancelled(NOTHING_WRITTEN)))
    return finished[0]


@contextlib.contextmanager
def _told_if_finished(finished: list):
    """A Ctrl-C once the run has a result (as the progress display closes, or while the
    chart and the measures are written out) names the files it wrote, not just
    "interrupted"."""
    try:
        yield
    except KeyboardInterrupt:
        if not finished:
            raise
        written = ", ".join(str(path) for path in finished[0].outputs.values())
        raise Cancelled(
            "interrupted after the run had finished; "
            + (f"it wrote {written}" if written else "no scenario outputs were written (--no-write)")
        ) from None


def result_dict(scenario, result, chart=None, notes=()) -> dict:
    """The run as a JSON-safe dict: backend, outputs, the chart written (None: none),
    the ``notes`` on scans that never look at the scene or a target, timings and measures."""
    return {
        "scenario": str(getattr(scenario, "path", "")),
        "backend": result.backend,
        "method": result.method,
        "precision": result.precision,
        "scans": result.scans,
        "rays_per_scan": result.rays_per_scan,
        "scene_output_voxels": int(len(result.scene_output)),
        "target_output_voxels": int(len(result.target_output)),
        "outputs": dict(result.outputs),
        "chart": None if chart is None else str(chart),
        "notes": list(notes),
        "timings_s": {k: round(v, 4) for k, v in result.timings.items()},
        "measures": result.measures.to_dict(),
    }


def show_result(console, result, asked_precision=None) -> None:
    """The measures as tables in the layout of the report's figure 10; the summary names
    the precision traced where it is not ``asked_precision`` (a backend without it)."""
    from rich.table import Table

    from ladartui.measures_table import comparison_rows, view_rows
    from ladartui.number_text import plural

    views = Table(title="Measures of effectiveness")
    views.add_column("")
    for name in ("3D target model", "Unobscured output", "Obscured output"):
        views.add_column(name, justify="right")
    for row in view_rows(result.measures):
        views.add_row(*row)
    console.print(views)
    comparison = Table(show_header=False)
    comparison.add_column("")
    comparison.add_column("", justify="right")
    for row in comparison_rows(result.measures):
        comparison.add_row(*row)
    console.print(comparison)
    targets = result.measures.targets
    if targets is not None and len(targets.targets) > 1:  # one target: the tables above are its own
        for table in target_tables(targets):
            console.print(table)
    if result.measures.detection is not None:
        console.print(detection_table(result.measures.detection))
    if result.measures.levels is not None:
        several = targets is not None and len(targets.targets) > 1
        console.print(
            levels_table(result.measures.levels, "Levels of all targets together" if several else "Levels")
        )
        if several:  # the levels each target reached on its own, as --json holds them
            console.print(target_levels_table(targets))
    total = result.timings.get("total", 0.0)
    how = f"{result.method}, {result.precision}" if result.precision else result.method
    if asked_precision and result.precision and result.precision != asked_precision:
        how += f", not the {asked_precision} asked for"
    console.print(
        f"backend: {result.backend} ({how}); {plural(result.scans, 'scan')} x "
        f"{result.rays_per_scan:,} rays, two runs, in {total:.2f} s"
    )
    if result.outputs:
        for name, path in result.outputs.items():
            shown = name.replace("_las", " LAS")  # "scene_las": the scene as a LAS point cloud
            console.print(
                single_line(f"wrote {shown}: {path}"), highlight=False, markup=False, soft_wrap=True
            )
    else:
        console.print("no scenario outputs written (--no-write)")


def target_tables(per_target):
    """Each target's measures with the worst and mean, and each one's coverage after each scan."""
    from rich.markup import escape
    from rich.table import Table

    from ladartui.number_text import plural
    from ladartui.target_measures import TABLE_HEADER, TABLE_NOTE, after_scan_rows, table_rows

    count = len(per_target.targets)
    table = Table(title=f"Measures per target ({plural(count, 'target')})", caption=TABLE_NOTE)
    for index, name in enumerate(TABLE_HEADER):
        table.add_column(name, justify="left" if index == 0 else "right")
    rows = table_rows(per_target)
    for index, row in enumerate(rows):
        # Names come from the scenario file: shown as text, never as markup.
        table.add_row(escape(row[0]), *row[1:], end_section=index == count - 1)
    curves = Table(title="Obscured coverage after each scan, per target (%)", show_header=False)
    curves.add_column("")
    curves.add_column("")
    for index, (name, curve) in enumerate(after_scan_rows(per_target)):
        curves.add_row(escape(name), curve, end_section=index == count - 1)
    return [table, curves]


def detection_table(detection):
    """The Geiger-mode measures (``[detection] model = "geiger"``) as a table."""
    from rich.table import Table

    from ladartui.measures_table import format_share
    from ladartui.number_text import fixed_or_tiny, plural

    def number(value, digits=1):
        return "undefined" if value is None else fixed_or_tiny(value, digits, grouped=True)

    table = Table(
        title=f"Geiger-mode detection: {plural(detection.pulses, 'pulse')} per look, "
        f"k = {detection.coincidence}, seed {detection.seed}",
        show_header=False,
    )
    table.add_column("")
    table.add_column("", justify="right")
    for name, value in (
        (
            "declared points (per look)",
            f"{detection.declared_points:,} ({number(detection.declared_per_look)})",
        ),
        (
            "false alarms (per look)",
            f"{detection.false_alarms:,} ({number(detection.false_alarms_per_look)})",
        ),
        ("false-alarm probability per noise bin", number(detection.false_alarm_probability, 6)),
        ("P_d of target voxels", format_share(detection.target_detection)),
        ("ideal sensor: obscured coverage", format_share(detection.ideal_obscured_coverage)),
        ("ideal sensor: unobscured coverage", format_share(detection.ideal_unobscured_coverage)),
    ):
        table.add_row(name, value)
    return table


def levels_table(levels, title="Levels"):
    """Detect / recognise / identify: each level's thresholds and the scan that reached it."""
    from rich.table import Table

    from ladartui.measures_table import format_share

    table = Table(
        title=f"{title}: {format_share(levels.visible_share)} of {levels.visible_voxels or 0:,} "
        f"visible voxels, {format_share(levels.footprint_share)} of {levels.footprint_cells or 0:,} "
        "footprint cells seen"
    )
    table.add_column("level")
    table.add_column("needs voxels / footprint", justify="right")
    table.add_column("reached at")
    for row in levels.rows():
        table.add_row(*row)
    return table


def target_levels_table(per_target):
    """Each target's detect / recognise / identify: the scan and flight time that reached it."""
    from rich.markup import escape
    from rich.table import Table

    from ladartui.levels import LEVELS, NOT_REACHED

    table = Table(title="Levels per target")
    table.add_column("Target")
    for level in LEVELS:
        table.add_column(level.capitalize())
    for target in per_target.targets:
        levels = target.measures.levels
        if levels is None:
            continue
        cells = [
            f"scan {item.scan} ({item.flight_time_s:.1f} s)" if item.reached else NOT_REACHED
            for item in levels.levels
        ]
        table.add_row(escape(f"{target.target_id} {target.name}"), *cells)  # a name is text, not markup
    return table
