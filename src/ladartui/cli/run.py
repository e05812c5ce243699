"""``ladartui run SCENARIO``: simulate a scenario, write its outputs, show the measures.

The run happens on a worker thread so that Ctrl-C on the main thread can set
the cancel event; the run then stops between chunks and writes nothing.
Progress goes to stderr, the measures to stdout (a table, or JSON with --json).
"""

from __future__ import annotations

import json
import threading

from ladartui.cli.progress import run_cancellable
from ladartui.errors import Cancelled


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "run",
        help="simulate a scenario's collection and score it",
        description="Trace every scan of the scenario against the scene (obscured) and the "
        "target alone (unobscured), fuse the returns, write S_Scene.txt, S_Target.txt and "
        "S.cmf beside the scenario, and show the measures of effectiveness.",
    )
    parser.add_argument("scenario", metavar="SCENARIO", help="scenario file (.toml)")
    parser.add_argument("--backend", metavar="B", help="tracing backend: auto, numba or wgpu "
                        "(default: the scenario's)")
    parser.add_argument("--method", metavar="M", help="tracing method: exact or march")
    parser.add_argument("--step", metavar="S", type=float, help="march step in voxels")
    parser.add_argument("--precision", metavar="P", help="tracing precision: f32 or f64")
    parser.add_argument("--las", action="store_true", help="also write the outputs as LAS point clouds")
    parser.add_argument("--no-write", dest="write", action="store_false",
                        help="do not write outputs or measures")
    parser.add_argument("--json", action="store_true", help="print the result as JSON on stdout")
    parser.add_argument("--chart", metavar="FILE",
                        help="also write the coverage after each scan as a chart (.svg or .png)")
    parser.set_defaults(handler=run)
    return parser


def run(args) -> int:
    from rich.console import Console

    from ladartui.errors import FieldError
    from ladartui.scenario import load_scenario

    scenario = load_scenario(args.scenario)
    # Check the overrides like scenario fields, before any progress is drawn.
    for name in ("backend", "method", "step", "precision"):
        value = getattr(args, name)
        if value is None:
            continue
        try:
            scenario = scenario.with_changes(**{name: value})
        except FieldError as error:  # name the flag the user typed, not the TOML field
            raise FieldError(f"--{name}", value, error.expected) from None
    if args.chart is not None and not args.chart.lower().endswith((".svg", ".png")):
        raise FieldError("--chart", args.chart, "a file name ending in .svg or .png")
    errors = Console(stderr=True)
    result = _simulate_with_progress(scenario, args, errors)
    if args.chart is not None:
        from ladartui.charts import save_figure
        from ladartui.charts.coverage import coverage_figure

        try:
            path = save_figure(coverage_figure(result.measures), args.chart)
        except OSError as error:
            raise FieldError("--chart", args.chart, f"a writable path ({error.strerror})") from None
        errors.print(f"wrote chart: {path}", highlight=False, markup=False, soft_wrap=True)
    if args.json:
        print(json.dumps(result_dict(scenario, result), indent=2, allow_nan=False))
    else:
        show_result(Console(), result)
    return 0


def _simulate_with_progress(scenario, args, console):
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

    from ladartui.simulation import simulate

    cancel = threading.Event()
    columns = (
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.percentage:>5.1f} %"),
        TextColumn("{task.fields[rays]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
    )
    with Progress(*columns, console=console, transient=False) as bar:
        task = bar.add_task("starting", total=1.0, rays="")

        def report(p):
            bar.update(task, completed=p.fraction,
                       description=f"scan {p.scan}/{p.scans} (scene and target runs)",
                       rays=f"{p.rays_done:,}/{p.rays_total:,} rays")

        return run_cancellable(
            lambda: simulate(scenario, progress=report, cancel=cancel, write=args.write,
                             las=args.las),
            cancel, "ladartui-run", Cancelled("run cancelled; nothing was written"))


def result_dict(scenario, result) -> dict:
    """The run as a JSON-safe dict: backend, outputs, timings and measures."""
    return {
        "scenario": str(getattr(scenario, "path", "")),
        "backend": result.backend,
        "method": result.method,
        "scans": result.scans,
        "rays_per_scan": result.rays_per_scan,
        "scene_output_voxels": int(len(result.scene_output)),
        "target_output_voxels": int(len(result.target_output)),
        "outputs": dict(result.outputs),
        "timings_s": {k: round(v, 4) for k, v in result.timings.items()},
        "measures": result.measures.to_dict(),
    }


def show_result(console, result) -> None:
    """The measures as tables in the layout of the report's figure 10."""
    from rich.table import Table

    from ladartui.measures import comparison_rows, view_rows

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
    total = result.timings.get("total", 0.0)
    console.print(f"backend: {result.backend} ({result.method}); {result.scans} scans x "
                  f"{result.rays_per_scan:,} rays, two runs, in {total:.2f} s")
    if result.outputs:
        for name, path in result.outputs.items():
            console.print(f"wrote {name}: {path}", highlight=False, soft_wrap=True)
    else:
        console.print("nothing written (--no-write)")
