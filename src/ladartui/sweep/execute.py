"""Running a sweep: resume, Dask (a local cluster or a scheduler address), the result files.

Every variant runs the same function, ``run_variant``, whether in this process
(``serial=True``) or on a Dask worker (``dask_runs``), so both give the same
rows. The base scene is loaded once here and scattered to every worker once
(broadcast); each task gets a reference to the worker's copy, never the arrays
themselves, and the occupancy built by the first variant on a worker is reused
by the rest.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import numbers
import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ladartui.checks import switch_field
from ladartui.errors import (
    FieldError,
    InputFileError,
    LadarError,
    OutputFileError,
    OutputSetBusy,
    check_callbacks,
    check_cancelled,
)
from ladartui.fileprobe import path_field
from ladartui.number_text import plural
from ladartui.precompile import compile_ahead
from ladartui.sweep.base import CheckedBase, checked_base, earlier_base_rows, own_rows, spec_digest
from ladartui.sweep.cluster import check_local_workers, close_client, local_client
from ladartui.sweep.dask_runs import ClusterLost, run_on_dask
from ladartui.sweep.ranked_set import CHART_NAMES, RANKING_NAME, set_lock, write_ranked_set
from ladartui.sweep.ranking import (
    BUDGET_OBJECTIVES,
    COSTS,
    Ranked,
    normal_cost,
    normal_objective,
    rank_rows,
)
from ladartui.sweep.spec import SweepSpec, load_sweep_spec
from ladartui.sweep.table import TableWriter, read_table
from ladartui.sweep.variant import run_variant

RESULTS_NAME = "results.csv"
LOCK_NAME = ".lock"  # held while a sweep writes the folder's tables
# Rows with these statuses are final; "failed" rows (a crash, a lost worker) run again.
FINAL_STATUSES = ("ok", "error")


@dataclass
class SweepProgress:
    """Where a sweep stands: variants done (resumed ones included) of total, those that
    failed (run again on resume) and those with impossible values (status "error",
    final), and the last row."""

    total: int
    done: int
    resumed: int
    failed: int
    elapsed: float
    row: dict | None = None
    impossible: int = 0

    @property
    def fraction(self) -> float:
        return self.done / self.total if self.total else 1.0


@dataclass
class SweepResult:
    """The rows of a sweep (spec order), their ranking and the files written."""

    rows: list[dict]
    ranking: list[Ranked]
    objective: str
    cost: str
    budget: float | None
    parameter_names: list[str]
    results_path: Path
    ranking_path: Path | None = None
    best_scenario_path: Path | None = None
    best_kept: Path | None = None  # an edited best-path file the sweep wrote beside
    best_kept_why: str = ""  # why it was not replaced
    best_earlier: Path | None = None  # none ranked now: the best-path file an earlier ranking wrote
    left_out: int = 0  # rows of the table not ranked: other variants, or an earlier base
    left_out_earlier_base: int = 0  # of those, the rows made from an earlier base
    unreadable_lines: list[int] = field(default_factory=list)  # of rows the table could not read
    unreadable_removed: bool = False  # the table rewritten since: those lines are gone from it
    ran: int = 0
    resumed: int = 0
    workers: int = 0
    elapsed: float = 0.0
    scheduler: str = ""
    notes: list[str] = field(default_factory=list)
    charts: dict[str, Path] = field(default_factory=dict)  # format -> chart file (pareto.svg, .png)

    @property
    def best(self) -> Ranked | None:
        """The top-ranked row, or None when no variant could be ranked."""
        return self.ranking[0] if self.ranking and self.ranking[0].rank == 1 else None

    @property
    def failures(self) -> list[dict]:
        """Rows that are not ok: failed (run again on resume) or impossible."""
        return [row for row in self.rows if row.get("status") != "ok"]

    @property
    def failed(self) -> list[dict]:
        """Rows that failed (a crash, a lost worker): run again when the sweep resumes."""
        return [row for row in self.rows if row.get("status") not in FINAL_STATUSES]

    @property
    def impossible(self) -> list[dict]:
        """Rows whose values are impossible (status "error"): final, never run again."""
        return [row for row in self.rows if row.get("status") == "error"]

    @property
    def pareto(self) -> list[Ranked]:
        """Rows on the Pareto front of coverage against cost, cheapest first."""
        return sorted((r for r in self.ranking if r.pareto), key=_cheapest_first)


def _refuse_in_worker_start() -> None:
    """A local cluster starts each worker process by importing the caller's script: a
    script that calls run_sweep outside ``if __name__ == "__main__":`` would start the
    sweep again in every worker (each refused by the folder lock, the cluster failing)."""
    import sys
    import types

    frame: types.FrameType | None = sys._getframe(1)
    while frame is not None:  # the script's top level runs as "__mp_main__" while a worker imports it
        if frame.f_globals.get("__name__") == "__mp_main__" and frame.f_code.co_name == "<module>":
            raise LadarError(
                "run_sweep was called while a worker process imported the script "
                f"{frame.f_globals.get('__file__', '')!r}: put the sweep under "
                "'if __name__ == \"__main__\":' (a local cluster's workers import the main script)"
            )
        frame = frame.f_back


def checked_budget(budget, name: str = "budget") -> float:
    """``budget`` as seconds; FieldError naming ``name`` unless it is a finite number > 0
    (numpy's numbers too)."""
    ok = isinstance(budget, numbers.Real) and not isinstance(budget, bool)
    if not (ok and math.isfinite(budget) and budget > 0):
        raise FieldError(name, budget, "a flight-time budget in seconds, > 0")
    return float(budget)


def default_out_dir(spec: SweepSpec) -> Path:
    return spec.path.parent / f"{spec.path.stem}-results"


class _LazyScene:
    """Loads the base scene on first use, once."""

    def __init__(self, base):
        self.base, self.scene = base, None

    def __call__(self):
        if self.scene is None:
            self.scene = self.base.load_scene()
        return self.scene


def run_sweep(
    spec,
    client=None,
    progress: Callable[[SweepProgress], None] | None = None,
    cancel=None,
    *,
    out=None,
    workers: int | None = None,
    objective: str | None = None,
    budget: float | None = None,
    cost: str | None = None,
    serial: bool = False,
    simulate_options: dict | None = None,
    charts: bool = False,
    checked: CheckedBase | None = None,
) -> SweepResult:
    """Run every variant of ``spec`` not already in the result table, then rank them all.

    ``spec`` is a SweepSpec or a spec file path. ``client`` is a
    ``distributed.Client``; without one a ``LocalCluster`` of ``workers``
    processes (default: one per core) runs the sweep and is closed at the
    end; ``serial=True`` runs the variants one by one in this process.
    ``progress(SweepProgress)`` is called after each variant; ``cancel``
    (a ``threading.Event``) stops the sweep with ``Cancelled``, keeping the rows
    written so far for a later resume. Writes ``out/results.csv`` (row by row),
    ``out/ranking.csv`` and the best scenario ``out/<name>-best.toml``.
    ``simulate_options`` (``backend``, ``method``, ``step``, ``precision``) go to
    every variant's ``simulate``; they are checked before any variant runs.
    ``charts=True`` also draws the Pareto charts ``out/pareto.svg`` and ``.png``;
    the ranking, the best scenario and the charts are replaced together or not at all.
    ``checked`` is ``checked_base(spec)`` where the caller refused a bad base or
    spec before this call; without it (or for another spec) this call makes it.
    """
    started = time.perf_counter()
    _refuse_in_worker_start()
    check_callbacks(progress, cancel)
    spec = spec_argument(spec)
    objective = normal_objective(objective or spec.objective)
    cost = normal_cost(cost or spec.cost)
    if budget is not None:
        budget = checked_budget(budget)
    else:
        budget = spec.budget
    if objective in BUDGET_OBJECTIVES and budget is None:
        raise FieldError(
            "budget",
            None,
            f"a flight-time budget in seconds (sweep.budget or --budget) for objective '{objective}'",
        )
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise FieldError("workers", workers, "an integer >= 1")
    switch_field("serial", serial)
    switch_field("charts", charts)
    if client is not None:
        _check_client(client)
    if client is None and not serial:
        check_local_workers(workers)
    out = path_field("out", out, "a results folder's path") if out is not None else default_out_dir(spec)
    if out.exists() and not out.is_dir():
        raise OutputFileError(out, "is a file, expected a folder")
    check_sweep_files(out, spec.name)
    if checked is None or checked.spec is not spec:
        checked = checked_base(spec)
    base = checked.scenario
    simulate_options = _checked_simulate_options(simulate_options, base)
    scene = _LazyScene(base)
    with _exclusive(out):
        return _run_locked(
            spec,
            checked.digest,
            base,
            scene,
            client,
            progress,
            cancel,
            out,
            workers,
            objective,
            budget,
            cost,
            serial,
            simulate_options,
            charts,
            started,
        )


def _check_client(client) -> None:
    """FieldError unless ``client`` is a ``distributed.Client``: a scheduler's address given
    in its place failed with AttributeError only once the variants were due to run."""
    from distributed import Client

    if not isinstance(client, Client):
        raise FieldError("client", client, "a distributed.Client (or None)")


def check_sweep_files(out: Path, name: str) -> None:
    """``OutputFileError`` naming a file the sweep keeps in ``out`` that it could not
    write (a folder, a pipe or a device there, say), before any variant runs: a pipe
    would be waited on for ever when read, or replaced by a file when written; and
    ``OutputSetBusy`` when another sweep holds the folder now."""
    from ladartui.outputset import check_lock, check_writable

    check_writable(
        *(out / file for file in (LOCK_NAME, RESULTS_NAME, RANKING_NAME, f"{name}-best.toml", *CHART_NAMES))
    )
    check_lock(set_lock(out))
    if (out / LOCK_NAME).is_file():  # held now: said before a bar or a cluster starts
        with _exclusive(out):
            pass


SIMULATE_OPTIONS = ("backend", "method", "step", "precision")


def _checked_simulate_options(options, base) -> dict:
    """``simulate_options`` checked before any variant runs: a bad one made every
    variant an ``error`` row, which a later sweep with good options skipped."""
    if options is None:
        return {}
    if not isinstance(options, Mapping) or not set(options) <= set(SIMULATE_OPTIONS):
        raise FieldError("simulate_options", options, "a dict of " + ", ".join(SIMULATE_OPTIONS))
    _with_options(base, options)
    return dict(options)


def _with_options(base, options: Mapping):
    """The base scenario as its variants run it: with the options that are set."""
    return base.with_changes(**{key: value for key, value in options.items() if value is not None})


@contextlib.contextmanager
def _exclusive(out: Path):
    """Hold ``out/.lock`` so two sweeps never write the same result table at once (POSIX)."""
    out.mkdir(parents=True, exist_ok=True)
    try:
        import fcntl
    except ImportError:  # not POSIX: nothing to lock with
        yield
        return
    with open(out / LOCK_NAME, "a+b") as handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise OutputSetBusy(
                out, "another sweep is writing its results here; wait for it or choose another --out"
            ) from None
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _run_locked(
    spec,
    digest,
    base,
    scene,
    client,
    progress,
    cancel,
    out,
    workers,
    objective,
    budget,
    cost,
    serial,
    simulate_options,
    charts,
    started,
) -> SweepResult:
    variants = spec.variants
    results_path = out / RESULTS_NAME
    unreadable: list[int] = []  # read once: a rewrite leaves such lines out of the file
    table_rows, _ = read_table(results_path, unreadable)
    table = TableWriter(results_path, table_rows, spec.parameter_names)
    todo = [
        v
        for v in variants
        if (row := table.held(v.id, digest)) is None or row.get("status") not in FINAL_STATUSES
    ]
    resumed = len(variants) - len(todo)
    state = SweepProgress(total=len(variants), done=resumed, resumed=resumed, failed=0, elapsed=0.0)

    def record(row):
        state.done += 1  # (before the row is put: a put that fails counts it as unwritten)
        table.put(row)
        state.failed += row.get("status") not in FINAL_STATUSES
        state.impossible += row.get("status") == "error"
        state.elapsed = time.perf_counter() - started
        state.row = row
        if progress is not None:
            progress(dataclasses.replace(state))  # a snapshot: the caller may keep it

    if progress is not None:
        progress(dataclasses.replace(state))
    try:
        result_workers, scheduler = _run_todo(
            todo, digest, base, scene, client, cancel, workers, serial, simulate_options, record
        )
    except BaseException as error:  # the rows held back are written: finished variants are kept
        try:
            table.flush()
        except LadarError as also:  # the first error is the one to tell
            error.add_note(f"and the results table could not be written: {also}")
        else:
            if isinstance(error, ClusterLost):  # what is kept, and how to go on
                raise ClusterLost(f"{error}; {_kept(state, results_path)}") from None
        if isinstance(error, OutputFileError) and error.path == str(results_path):  # a full disk
            kept = state.done - table.unwritten
            raise OutputFileError(
                error.path,
                f"{error.reason}; it keeps {kept:,} of {plural(state.total, 'variant')}, as last written: "
                "run the sweep again to resume once it can be written",
            ) from None
        raise
    table.flush()

    # The rows as the file holds them (every column present), so this result
    # and load_sweep_results of the same folder agree.
    table_rows, _ = read_table(results_path)
    rows = own_rows(table_rows, variants, digest)
    left_out = len(table_rows) - len(rows)
    earlier = earlier_base_rows(table_rows, digest)
    ranking = rank_rows(rows, objective, budget, cost)
    result = SweepResult(
        rows=rows,
        ranking=ranking,
        objective=objective,
        cost=cost,
        budget=budget,
        parameter_names=spec.parameter_names,
        results_path=results_path,
        ran=len(todo),
        resumed=resumed,
        workers=result_workers,
        scheduler=scheduler,
        left_out=left_out,
        left_out_earlier_base=earlier,
        unreadable_lines=unreadable,
        unreadable_removed=table.written,
    )
    write_ranked_set(result, spec.name, base, scene, charts)
    result.elapsed = time.perf_counter() - started
    return result


def _kept(state: SweepProgress, results_path: Path) -> str:
    if not state.done:
        return "no variant had finished; run the sweep again to start it"
    return (
        f"{state.done:,} of {state.total:,} variants are kept in {results_path}; "
        "run the sweep again to resume"
    )


def _run_todo(todo, digest, base, scene, client, cancel, workers, serial, simulate_options, record):
    """Run the variants not yet in the table; the number of workers and the scheduler that ran them."""
    if not todo:
        return 0, "serial"
    options = dict(simulate_options or {})
    if serial or client is None:  # here or on this machine's workers: its cache
        scene()  # read first: a mistake in its model is told before any compiling
        compile_ahead(_with_options(base, options), cancel)
    if serial:
        _run_serial(todo, base, digest, scene(), options, record, cancel)
        return 1, "serial"
    owned = client is None
    if owned:
        client = local_client(workers)
    try:
        ran_on = len(client.scheduler_info(n_workers=-1).get("workers", {}))
        run_on_dask(client, todo, base, digest, scene(), options, record, cancel)
        return ran_on, client.scheduler.address
    finally:
        if owned:
            close_client(client)


def _run_serial(todo, base, digest, scene, options, record, cancel):
    for variant in todo:
        check_cancelled(cancel, "sweep cancelled")
        run_options = dict(options)
        if cancel is not None:
            run_options["cancel"] = cancel
        record(run_variant(base, variant.params, variant.id, digest, scene, run_options))


def spec_argument(spec) -> SweepSpec:
    """A ``spec`` argument: a SweepSpec as given, a spec file's path read; anything
    else a FieldError naming ``spec``."""
    if isinstance(spec, SweepSpec):
        return spec
    return load_sweep_spec(path_field("spec", spec, "a SweepSpec or a sweep spec file's path"))


def load_sweep_results(
    path,
    objective: str = "obscured-coverage",
    budget: float | None = None,
    cost: str = "flight-time",
    spec: SweepSpec | str | os.PathLike | None = None,
) -> SweepResult:
    """Read a sweep's result table (a results.csv or the folder holding it) and rank its rows.

    With ``spec`` (a SweepSpec or its file's path), the rows are its variants made from its base as it is now
    (``sweep.base.spec_rows``), as the sweep itself ranks them. Without, every
    row in the file is included; when a variant appears more than once
    (several base scenarios) each row is kept.
    """
    path = path_field("path", path, "a sweep's results folder or its results.csv")
    if path.is_dir():
        path = path / RESULTS_NAME
    if not path.exists():
        raise InputFileError(path, "no sweep results here")
    unreadable: list[int] = []
    rows, header = read_table(path, unreadable)
    every, earlier = len(rows), 0
    if spec is not None:
        spec = spec_argument(spec)
        digest = spec_digest(spec)
        earlier = earlier_base_rows(rows, digest)
        rows = own_rows(rows, spec.variants, digest)
    objective, cost = normal_objective(objective), normal_cost(cost)
    if budget is not None:
        budget = checked_budget(budget)
    if objective in BUDGET_OBJECTIVES and budget is None:
        raise FieldError("budget", None, "a flight-time budget in seconds")
    known = {
        "variant",
        "status",
        "base",
        "error",
        "worker",
        "backend",
        "method",
        "run_time_s",
        "scan_count",
        *COSTS.values(),
    }
    from ladartui.sweep.spec import PARAMETERS

    parameter_names = [c for c in header if c in PARAMETERS and c not in known]
    return SweepResult(
        rows=rows,
        ranking=rank_rows(rows, objective, budget, cost),
        objective=objective,
        cost=cost,
        budget=budget,
        parameter_names=parameter_names,
        results_path=path,
        left_out=every - len(rows),
        left_out_earlier_base=earlier,
        unreadable_lines=unreadable,
    )


def _cheapest_first(entry: Ranked) -> tuple[float, float]:
    # a Pareto row has both its cost and its coverage (an unmeasured one would sort last)
    cost = math.inf if entry.cost is None else entry.cost
    coverage = -math.inf if entry.coverage is None else entry.coverage
    return cost, -coverage
