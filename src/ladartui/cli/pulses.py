"""``ladartui pulses``: coverage and false alarms against Geiger-mode pulses per look.

The study runs on a worker thread (``run_cancellable``) while a rich progress
bar is drawn on stderr; Ctrl-C stops it between scans. It writes no files:
the table and the plotext chart go to stdout, or with ``--json`` the rows as
data (``rows``: one object per pulse count), ready for any charting tool.
"""

from __future__ import annotations

import dataclasses
import json
import shutil
import sys
import threading

from ladartui.cli.flags import as_flags, check_scenario_name
from ladartui.cli.progress import stop_status
from ladartui.errors import Cancelled, FieldError
from ladartui.number_text import plural

CHART_WIDTH = 78
CHART_MIN_WIDTH = 52  # the legend's longest entry still fits inside the axes
CHART_HEIGHT = 20
TITLE = "Geiger-mode: coverage and false alarms against pulses per look"
SHORT_TITLE = "coverage and false alarms against pulses per look"
LEGEND_HEADROOM = 1.5


def add_parser(sub):
    p = sub.add_parser(
        "pulses",
        help="obscured coverage and false alarms against pulses per look "
        "(Geiger-mode detection; see docs/detection.md)",
        description="Trace each scan once, then fire M pulses per look for each "
        "M and declare points where at least k fired (k keeps the scenario's "
        "coincidence share). Prints the ideal model's obscured coverage, a row "
        "per M and a chart. The scenario's [detection] numbers are used where "
        "set. Writes no files.",
    )
    p.add_argument(
        "scenario",
        nargs="?",
        help="scenario file (.toml), or a bundled one by name: default, convoy "
        "(default: the default scenario)",
    )
    p.add_argument(
        "--pulses",
        default="1,10,100",
        help="comma-separated pulses per look, each 1 to 100000 (default 1,10,100); "
        "each is studied once, in increasing order",
    )
    p.add_argument(
        "--n-ref",
        type=float,
        default=None,
        help="mean photoelectrons of a full-footprint return at the reference range "
        "(default: the scenario's, else 5)",
    )
    p.add_argument("--seed", type=int, default=None, help="random stream (default: the scenario's, else 0)")
    p.add_argument(
        "--backend", default=None, help="tracing backend: auto, numba or wgpu (default: the scenario's)"
    )
    p.add_argument("--json", action="store_true", help="print the results as JSON, no chart")
    p.add_argument("--no-chart", dest="chart", action="store_false", help="table only")
    p.set_defaults(handler=run)


def _pulse_counts(text):
    from ladartui.detection.settings import MAX_PULSES

    try:
        pulses = [int(v) for v in text.split(",")]
    except ValueError:
        raise FieldError("--pulses", text, "comma-separated whole numbers") from None
    if any(p < 1 or p > MAX_PULSES for p in pulses):
        raise FieldError("--pulses", text, f"pulse counts in 1..{MAX_PULSES}")
    return sorted(set(pulses))  # each count once, in the order the chart's line is drawn


def _settings(scenario, args):
    from ladartui.detection.settings import DetectionSettings

    settings = scenario.detection or DetectionSettings()
    changes = {"model": "geiger"}
    for flag, name in (("n_ref", "n_ref"), ("seed", "seed")):
        value = getattr(args, flag)
        if value is not None:
            changes[name] = value
    with as_flags({"n_ref": args.n_ref, "seed": args.seed}):
        return dataclasses.replace(settings, **changes)


def run(args) -> int:
    from ladartui.cli.console import CliConsole as Console
    from ladartui.detection.pulses import check_study_rays
    from ladartui.scenario import load_scenario
    from ladartui.user_data import bundled_or_path, default_scenario_path

    if args.scenario is not None:  # "" is not the default scenario
        check_scenario_name(args.scenario)
    pulses = _pulse_counts(args.pulses)
    scenario = load_scenario(
        default_scenario_path() if args.scenario is None else bundled_or_path(args.scenario)
    )
    settings = _settings(scenario, args)
    if args.backend is not None:  # before any tracing, as run does
        with as_flags({"backend": args.backend}):
            scenario.with_changes(backend=args.backend)
    check_study_rays(scenario)  # before the kernels compile and the bar is drawn
    errors = Console(stderr=True)
    state = {"last": None}
    try:
        ideal, rows = _study_with_progress(scenario, pulses, settings, args.backend, errors, state)
    except (Cancelled, KeyboardInterrupt):  # the latter: Ctrl-C before the worker started
        last = state["last"]
        finished = () if last is None or args.json else last.rows
        if finished:  # what a cancelled study has to show: the rows it finished
            _print_table(last.ideal, finished)
        shown = f"; the {plural(len(finished), 'row')} finished {'is' if len(finished) == 1 else 'are'} above"
        print(
            f"ladartui: pulse study cancelled {_where(last)}"
            + (shown if finished else "; no results")
            + ", and this command writes no files",
            file=sys.stderr,
        )
        return stop_status()
    if args.json:
        print(json.dumps(result_dict(scenario, settings, ideal, rows), indent=2, allow_nan=False))
        return 0
    _print_table(ideal, rows)
    if args.chart:
        columns = shutil.get_terminal_size((CHART_WIDTH, CHART_HEIGHT)).columns  # COLUMNS first
        width = max(CHART_MIN_WIDTH, min(columns, CHART_WIDTH))
        print(chart_text(ideal, rows, width=width, color=_colours_shown()))
    return 0


def _colours_shown() -> bool:
    """Whether standard output takes the chart's ANSI colours, as rich decides for the
    tables: a terminal, not dumb (TERM=dumb shows escapes as text), and no NO_COLOR."""
    from ladartui.cli.console import CliConsole

    console = CliConsole()
    return console.is_terminal and console.color_system is not None and not console.no_color


def _print_table(ideal, rows) -> None:
    if ideal is None:
        print("ideal model: obscured coverage undefined (the target model holds no voxels)")
    else:
        print(f"ideal model: obscured coverage {ideal:.4f}")
    print(f"{'pulses':>7} {'k':>5} {'coverage':>9} {'declared':>11} {'false':>10} {'P_d(target)':>11}")
    for r in rows:
        detection = "undefined" if r.target_detection is None else f"{r.target_detection:.3f}"
        coverage = "undefined" if r.obscured_coverage is None else f"{r.obscured_coverage:.4f}"
        print(
            f"{r.pulses:>7,} {r.threshold:>5,} {coverage:>9} {r.declared_points:>11,} "
            f"{r.false_alarms:>10,} {detection:>11}"
        )


def _where(progress) -> str:
    if progress is None:
        return "before the first scan was traced"
    if progress.stage == "trace":
        return f"after tracing {progress.done} of {progress.total} scans"
    return f"after tracing every scan, during pulse count {progress.done} of {progress.total}"


def _study_with_progress(scenario, pulses, settings, backend, console, state):
    from rich.progress import TextColumn, TimeElapsedColumn, TimeRemainingColumn

    from ladartui.cli.progress import (
        bar_hidden_if_refused,
        first_scan,
        progress_display,
        run_cancellable,
        sigterm_as_interrupt,
    )
    from ladartui.detection.pulses import pulse_study
    from ladartui.precompile import compile_ahead

    cancel = threading.Event()
    after = (TextColumn("{task.percentage:>5.1f} %"), TimeElapsedColumn(), TimeRemainingColumn())
    with progress_display(console, after, transient=False) as bar:
        chosen = scenario.with_changes(detection=settings)  # Geiger-mode looks
        chosen = chosen if backend is None else chosen.with_changes(backend=backend)
        task = bar.add_task(first_scan(chosen), total=1.0)

        def report(p):
            state["last"] = p
            what = (
                f"tracing scan {p.done}/{p.total}"
                if p.stage == "trace"
                else f"pulse count {p.done}/{p.total} ({plural(pulses[p.done - 1], 'pulse')})"
            )
            bar.update(task, completed=p.units_done / p.units_total, description=what)

        def work():
            scene = compile_ahead(chosen, cancel, load_scene=True)
            return pulse_study(
                scenario, pulses, settings, scene=scene, backend=backend, progress=report, cancel=cancel
            )

        # as run does: the work (and any compiling children) ends
        with sigterm_as_interrupt(), bar_hidden_if_refused(bar, task, lambda: state["last"] is not None):
            return run_cancellable(
                work,
                cancel,
                "ladartui-pulses",
                Cancelled("pulse study cancelled"),
            )


def result_dict(scenario, settings, ideal, rows) -> dict:
    """The study as JSON-safe data: settings, the ideal coverage and one row per pulse count."""
    return {
        "scenario": str(scenario.path),
        "settings": settings.to_dict(),
        "ideal_obscured_coverage": ideal,
        "rows": [r.to_dict() for r in rows],
    }


def chart_text(ideal, rows, width=CHART_WIDTH, height=CHART_HEIGHT, color=True) -> str:
    """Coverage (%, left axis) and false alarms (right axis) against pulses per look (log)."""
    import plotext

    from ladartui.study.chart import _PLOTEXT_LOCK

    xs = [r.pulses for r in rows]
    with _PLOTEXT_LOCK:
        plotext.clear_figure()
        plotext.limit_size(False, False)
        plotext.plotsize(width, height)
        plotext.theme("pro" if color else "clear")
        # plotext drops a title wider than the chart: a shorter one where the full one is
        plotext.title(TITLE if len(TITLE) <= width else SHORT_TITLE)
        if ideal is not None:  # else no target voxels: coverage is undefined, not drawn
            # The ideal line first: where the Geiger points fall on its row they are drawn over it.
            plotext.plot(xs, [100.0 * ideal] * len(xs), color="cyan", label="obscured coverage % (ideal)")
            plotext.plot(
                xs,
                [100.0 * (r.obscured_coverage or 0.0) for r in rows],
                marker="o",
                color="green",
                label="obscured coverage % (Geiger)",
            )
        plotext.plot(
            xs,
            [r.false_alarms for r in rows],
            marker="x",
            color="red",
            yside="right",
            label="false alarms (right)",
        )
        # Head room above the data for the legend, which plotext puts top left.
        top = max([100.0 * (ideal or 0.0), *(100.0 * (r.obscured_coverage or 0.0) for r in rows)])
        plotext.ylim(0.0, (top or 1.0) * LEGEND_HEADROOM)
        plotext.ylim(0.0, (max(r.false_alarms for r in rows) or 1.0) * LEGEND_HEADROOM, yside="right")
        if len(xs) > 1 and min(xs) > 0:
            plotext.xscale("log")
        plotext.xlabel("pulses per look")
        text = plotext.build()
        plotext.clear_figure()
    return text if color else plotext.uncolorize(text)
