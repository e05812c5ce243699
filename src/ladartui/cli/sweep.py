"""``ladartui sweep SPEC``: simulate many flight-path variants on Dask and rank them.

The sweep runs on a worker thread so Ctrl-C on the main thread can set the
cancel event; rows finished so far stay in the result table and the same
command resumes. Progress goes to stderr, the ranking to stdout.
"""

from __future__ import annotations

import json
import os
import threading
from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING

from ladartui.cli.flags import as_flags, check_file_names
from ladartui.cli.progress import progress_display, run_cancellable, sigterm_as_interrupt, stop_status
from ladartui.errors import Cancelled, FieldError, LadarError
from ladartui.number_text import plural
from ladartui.textsafe import single_line

if TYPE_CHECKING:
    from ladartui.sweep.spec import SweepSpec

DEFAULT_TOP = 10
DEFAULT_CONNECT_TIMEOUT = 30.0
MAX_CONNECT_TIMEOUT = 86400  # seconds: a day
# Flags that only shape a run (its cluster and workers): --show starts none.
RUN_ONLY_FLAGS = {
    "workers": "--workers",
    "serial": "--serial",
    "scheduler": "--scheduler",
    "tls_ca_file": "--tls-ca-file",
    "tls_cert": "--tls-cert",
    "tls_key": "--tls-key",
    "insecure": "--insecure",
    "connect_timeout": "--connect-timeout",
}


def add_parser(subparsers):
    from ladartui.sweep.ranking import OBJECTIVES

    parser = subparsers.add_parser(
        "sweep",
        help="simulate variants of a scenario's flight path and rank them",
        description="Run every variant of a sweep spec (TOML: a base scenario and the "
        "parameters to vary) on a Dask cluster, append one row per variant to "
        "OUT/results.csv, rank the variants and save the best flight path as a scenario. "
        "An interrupted sweep resumes where it stopped. See docs/sweeps.md.",
    )
    parser.add_argument("spec", metavar="SPEC", help="sweep spec file (.toml)")
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="address of a running Dask scheduler: tls://HOST:PORT with the --tls flags, "
        "or tcp://HOST:PORT on this machine (see --insecure); default: a local cluster on this machine",
    )
    parser.add_argument(
        "--tls-ca-file", metavar="PEM", help="certificate authority of a TLS scheduler (ladartui certs DIR)"
    )
    parser.add_argument("--tls-cert", metavar="PEM", help="this client's TLS certificate")
    parser.add_argument("--tls-key", metavar="PEM", help="this client's TLS private key")
    parser.add_argument(
        "--insecure",
        action="store_true",
        help="allow a plain tcp:// scheduler that is not on loopback (any "
        "peer that reaches it can run code on the cluster and here)",
    )
    parser.add_argument(
        "--connect-timeout",
        metavar="SECONDS",
        type=float,
        help="with --scheduler: how long to wait for the scheduler and a first worker "
        f"(default {DEFAULT_CONNECT_TIMEOUT:g})",
    )
    parser.add_argument(
        "--workers",
        metavar="N",
        type=int,
        help="worker processes of the local cluster (default: one per core; at most 4 per core)",
    )
    parser.add_argument(
        "--serial", action="store_true", help="run the variants one by one in this process, without Dask"
    )
    parser.add_argument(
        "--out",
        metavar="DIR",
        help="folder for results.csv, ranking.csv, pareto.svg/.png and the best "
        "scenario "
        "(default: SPEC's folder/SPEC-results)",
    )
    parser.add_argument(
        "--objective",
        metavar="NAME",
        help="ranking objective: " + ", ".join(OBJECTIVES) + " (default: the spec's)",
    )
    parser.add_argument(
        "--budget",
        metavar="SECONDS",
        type=float,
        help="flight-time budget in seconds for coverage-within-budget and "
        "identified-within-budget (default: the spec's)",
    )
    parser.add_argument(
        "--cost", metavar="NAME", help="cost axis of the Pareto front: flight-time or distance"
    )
    parser.add_argument(
        "--top",
        metavar="N",
        type=int,
        default=DEFAULT_TOP,
        help=f"ranked variants to show (default {DEFAULT_TOP})",
    )
    parser.add_argument(
        "--show", action="store_true", help="rank the results already in OUT without running anything"
    )
    parser.add_argument("--json", action="store_true", help="print the ranking as JSON on stdout")
    parser.set_defaults(handler=run)
    return parser


def run(args) -> int:
    from ladartui.cli.console import CliConsole as Console
    from ladartui.sweep import default_out_dir, load_sweep_results, load_sweep_spec
    from ladartui.sweep.ranking import BUDGET_OBJECTIVES, normal_cost, normal_objective

    check_file_names({"SPEC": args.spec}, "a sweep spec (.toml)")
    check_file_names({"--out": args.out}, f"a folder name, such as {Path(args.spec).stem}-results")
    given = [flag for name, flag in RUN_ONLY_FLAGS.items() if getattr(args, name) not in (None, False)]
    if args.show and given:
        raise LadarError(
            f"{', '.join(given)}: only a run uses {'it' if len(given) == 1 else 'them'}; "
            "--show ranks the results in OUT and runs nothing"
        )
    if args.connect_timeout is not None and not args.scheduler:
        raise FieldError(
            "--scheduler",
            None,
            "an address with --connect-timeout (only a connection to a scheduler waits for it)",
        )
    if args.connect_timeout is None:
        args.connect_timeout = DEFAULT_CONNECT_TIMEOUT
    if args.workers is not None and args.workers < 1:
        raise FieldError("--workers", args.workers, "an integer >= 1")
    if args.serial and args.workers is not None:
        raise FieldError(
            "--workers", args.workers, "no --workers with --serial (one process runs every variant)"
        )
    from ladartui.sweep.cluster import check_local_workers

    check_local_workers(args.workers, "--workers")
    if not 0 < args.connect_timeout <= MAX_CONNECT_TIMEOUT:  # inf: a traceback in dask; 1e300: for ever
        raise FieldError(
            "--connect-timeout",
            args.connect_timeout,
            f"a number of seconds greater than 0 and at most {MAX_CONNECT_TIMEOUT}",
        )
    if args.top < 0:
        raise FieldError("--top", args.top, "an integer >= 0")
    if args.scheduler and (args.workers is not None or args.serial):
        raise FieldError(
            "--scheduler",
            args.scheduler,
            "no --workers or --serial with it (the cluster's workers run the sweep)",
        )
    security = None
    if args.scheduler:
        from ladartui.sweep.security import cluster_security

        security = cluster_security(
            args.scheduler, args.tls_ca_file, args.tls_cert, args.tls_key, args.insecure
        )
    elif args.tls_ca_file or args.tls_cert or args.tls_key or args.insecure:
        raise FieldError(
            "--scheduler",
            None,
            "an address with the TLS or --insecure flags (the local cluster listens on 127.0.0.1 only)",
        )
    args.security = security
    spec = load_sweep_spec(args.spec)
    with as_flags({"objective": args.objective, "cost": args.cost}):
        objective = normal_objective(args.objective or spec.objective)
        normal_cost(args.cost or spec.cost)
    if args.budget is not None:
        from ladartui.sweep.execute import checked_budget

        checked_budget(args.budget, "--budget")
        if objective not in BUDGET_OBJECTIVES:  # it would be taken and never used
            raise FieldError(
                "--budget",
                args.budget,
                f"no --budget with objective '{objective}' (only "
                f"{' and '.join(sorted(BUDGET_OBJECTIVES))} use a budget)",
            )
    if objective in BUDGET_OBJECTIVES and args.budget is None and spec.budget is None:
        raise FieldError(
            "--budget",
            None,
            f"a flight-time budget in seconds (or sweep.budget in the spec) for objective '{objective}'",
        )
    errors = Console(stderr=True)
    if args.show:
        from ladartui.errors import InputFileError
        from ladartui.sweep.base import base_scenario_path

        out = args.out or default_out_dir(spec)
        if Path(out).is_file():  # read as a table, it said "not a sweep result table"
            raise FieldError("--out", str(out), "a sweep's results folder; it is a file")
        own: SweepSpec | None = spec  # rank its variants from its base as it is now
        try:
            base_scenario_path(spec)
        except InputFileError as error:  # gone: nothing to tell this base's rows by
            errors.print(
                single_line(
                    f"ladartui: the base scenario is not there ({error}); every row of the table is ranked"
                ),
                highlight=False,
                markup=False,
                soft_wrap=True,
            )
            own = None
        result = load_sweep_results(
            out,
            objective=args.objective or spec.objective,
            budget=args.budget if args.budget is not None else spec.budget,
            cost=args.cost or spec.cost,
            spec=own,
        )
        result.parameter_names = spec.parameter_names
        # it ranks as asked, and writes nothing: the folder stays one set
        _say_folder_unchanged(errors, result.results_path.parent, spec.name)
    else:
        from ladartui.outputset import check_writable_folder
        from ladartui.sweep.base import checked_base
        from ladartui.sweep.execute import check_sweep_files

        checked = checked_base(spec)  # a bad base or spec is reported before any cluster starts
        check_writable_folder(args.out or default_out_dir(spec))
        check_sweep_files(Path(args.out or default_out_dir(spec)), spec.name)
        result = _sweep_with_progress(checked, args, errors)
        if result is None:
            return stop_status()
    from ladartui.cli.sweep_report import result_dict, show_result

    if args.json:
        print(json.dumps(result_dict(result, args.top), indent=2, allow_nan=False))
    else:
        console = Console()
        if not console.is_terminal and "COLUMNS" not in os.environ:
            console = Console(width=160)  # a file or pipe: do not squeeze the table into 80 columns
        show_result(console, result, args.top)
    if not any(row.get("status") == "ok" for row in result.rows):
        counts = Counter(str(row.get("status")) for row in result.rows)
        said = ", ".join(
            f"{n} {'impossible' if status == 'error' else status}" for status, n in counts.items()
        )
        said = f"({said})" if said else "(no row of this spec's variants from its base as it is now)"
        errors.print(f"ladartui: no variant finished {said}", highlight=False, markup=False, soft_wrap=True)
        return 1  # a script must not take an empty ranking for a result
    return 0


STARTING = "starting; a first run compiles kernels"


def sweep_progress(console, **options):
    """The sweep's progress line: bar, variants done of all, the counts that are not
    zero and the rate, the time left (every figure whole in 80 columns; the summary
    says how long it took)."""
    from rich.progress import MofNCompleteColumn, TextColumn, TimeRemainingColumn

    after = (MofNCompleteColumn(), TextColumn("{task.fields[note]}"), TimeRemainingColumn())
    return progress_display(console, after, transient=False, **options)


def progress_note(p) -> str:
    """'12 resumed, 2 failed, 1 impossible, 86.0/min', leaving out counts of zero."""
    ran = p.done - p.resumed
    counts = ((p.resumed, "resumed"), (p.failed, "failed"), (p.impossible, "impossible"))
    parts = [f"{count} {what}" for count, what in counts if count]
    if ran and p.elapsed > 0:
        parts.append(f"{60 * ran / p.elapsed:.1f}/min")
    elif not ran and p.done < p.total:  # the workers' first variant also compiles the kernels
        parts.append(STARTING)
    return ", ".join(parts)


LATE_INTERRUPT = "the interrupt came after the last variant: the sweep finished"


def _sweep_with_progress(checked, args, console):
    from ladartui.sweep import connect, run_sweep
    from ladartui.sweep.cluster import close_client

    spec = checked.spec

    client = connect(args.scheduler, args.connect_timeout, args.security) if args.scheduler else None
    cancel = threading.Event()
    outcome = {}
    where = (
        f"scheduler {args.scheduler}"
        if args.scheduler
        else ("this process" if args.serial else "local cluster")
    )
    console.print(
        f"sweep of {plural(len(spec.variants), 'variant')} on {where}", highlight=False, markup=False
    )
    try:
        with sweep_progress(console) as bar:
            task = bar.add_task("sweep", total=len(spec.variants), note=STARTING)

            def report(p):
                outcome["progress"] = p
                bar.update(task, completed=p.done, total=p.total, note=progress_note(p))

            def work():
                # The charts are drawn in the set with the ranking and best path: a Ctrl-C
                # once every variant is done waits for the whole set (it left the last
                # run's charts), and a full disk leaves the earlier set whole.
                return run_sweep(
                    spec,
                    client=client,
                    progress=report,
                    cancel=cancel,
                    out=args.out,
                    workers=args.workers,
                    objective=args.objective,
                    budget=args.budget,
                    cost=args.cost,
                    serial=args.serial,
                    charts=True,
                    checked=checked,
                )

            def stopping() -> None:  # a cluster still starting finishes first (seconds)
                bar.update(task, note="stopping; finished variants are kept")

            try:
                with sigterm_as_interrupt():
                    result = run_cancellable(work, cancel, "ladartui-sweep", Cancelled(), stopping)
            except Cancelled:
                pass  # reported below, once the client is closed
            else:
                if cancel.is_set():  # every variant had run: the whole set was written
                    bar.update(task, note=LATE_INTERRUPT)
                return result
    finally:
        if client is not None:
            close_client(client)
    last = outcome.get("progress")
    if last is None or not last.done:
        said = "sweep interrupted before any variant finished; run the same command again to start it"
    else:
        said = (
            f"sweep interrupted; {last.done:,} of {last.total:,} variants are kept in the results "
            "table; run the same command again to resume"
        )
    console.print(f"ladartui: {said}", highlight=False)
    return None


def _say_folder_unchanged(errors, folder: Path, name: str) -> None:
    """What --show leaves: the ranking files the folder holds, as the last sweep wrote
    them (by the terms it ranked by, which --show's may not be)."""
    from ladartui.sweep.best_file import best_files
    from ladartui.sweep.execute import CHART_NAMES, RANKING_NAME

    names = [file for file in (RANKING_NAME, *CHART_NAMES) if (folder / file).exists()]
    names += [path.name for path in best_files(folder, name)]
    if names:
        errors.print(
            single_line(
                f"ladartui: {', '.join(names)} in {folder} stay as the last sweep wrote them "
                "(--show writes nothing; the sweep again redraws them)"
            ),
            highlight=False,
            markup=False,
            soft_wrap=True,
        )
