"""The sweep screen's work outside the interface thread: the sweep job, writing the
best variant as a scenario, checking a spec to run, and the paths and process
set-up they need. Nothing here draws; tui/sweep_screen.py starts these and shows
what they report."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ladartui.errors import FieldError, InputFileError, LadarError
from ladartui.fileprobe import user_path
from ladartui.tui.fields import refusal

if TYPE_CHECKING:
    from ladartui.sweep.best_file import BestScenario


# The sweep screen's fields, as the refusals of the spec to run or open and the cluster's
# name them (some name the CLI's flags); its Certificates folder holds the three TLS files.
FORM_LABELS = {
    "spec": "Spec",
    "scheduler": "Scheduler",
    "--scheduler": "Scheduler",
    "certificates": "Certificates",
    "--tls-ca-file": "Certificates",
    "--tls-cert": "Certificates",
    "--tls-key": "Certificates",
}


def in_form_words(error: FieldError) -> LadarError:
    """A refusal of the spec, scheduler or certificates as the sweep screen's other fields
    say theirs ("Scheduler: X is not allowed; expected ..."); others as they are."""
    label = FORM_LABELS.get(error.field)
    if label is None:
        return error
    return LadarError(refusal(label, str(error.value), error.expected))


def start_resource_tracker() -> None:
    """Start multiprocessing's resource tracker with the process's real stderr.

    The tracker is handed ``sys.stderr.fileno()``; while the interface runs,
    ``sys.stderr`` is a capture object whose descriptor is -1, so a local
    cluster started then fails ("bad value(s) in fds_to_keep"). Started once
    here, it is reused by every later cluster.
    """
    from multiprocessing import resource_tracker

    captured = sys.stderr
    sys.stderr = sys.__stderr__
    try:
        resource_tracker.ensure_running()
    finally:
        sys.stderr = captured


def sibling_spec(results: Path) -> Path | None:
    """The spec whose default results folder is ``results`` (``S-results`` beside ``S.toml``)."""
    folder = results if results.is_dir() else results.parent
    if not folder.name.endswith("-results"):
        return None
    spec = folder.parent / (folder.name[: -len("-results")] + ".toml")
    return spec if spec.is_file() else None


@dataclass
class StoredRows:
    """The rows a sweep's table already holds for its variants from its base as it is
    now: shown at once when it starts (they resume), read off the UI thread (the
    base's models are hashed)."""

    rows: list[dict]


def sweep_job(
    spec,
    scheduler: str,
    security,
    serial: bool,
    objective: str,
    cost: str,
    budget,
    connect_timeout: float,
    cancel,
    progress,
):
    """The sweep job (worker thread): first the rows already stored (``StoredRows``),
    then every finished variant, each a kept progress report."""
    from ladartui.sweep import connect, default_out_dir, run_sweep
    from ladartui.sweep.base import checked_base, own_rows
    from ladartui.sweep.cluster import close_client
    from ladartui.sweep.table import read_table

    checked = checked_base(spec)  # the base read and hashed once, for these rows and the run
    stored, _ = read_table(default_out_dir(spec) / "results.csv")
    progress(0.0, "", StoredRows(own_rows(stored, spec.variants, checked.digest)), keep=True)
    client = None
    try:
        if scheduler:
            progress(0.0, f"connecting to {scheduler} ...")
            try:
                client = connect(scheduler, connect_timeout, security)
            except FieldError as error:
                raise in_form_words(error) from None
        return run_sweep(
            spec,
            checked=checked,
            client=client,
            cancel=cancel,
            objective=objective,
            cost=cost,
            budget=budget,
            serial=serial,
            charts=True,  # as the command draws them: never an earlier ranking's beside this one
            progress=lambda p: progress(p.fraction, "", p, keep=p.row is not None),
        )
    finally:
        if client is not None:
            close_client(client)


def write_best(spec, row: dict, parameter_names, path: Path) -> BestScenario:
    """The best variant as a scenario file beside the results (worker thread)."""
    from ladartui.sweep.base import load_base
    from ladartui.sweep.best_file import write_best_scenario

    base = load_base(spec)
    return write_best_scenario(path, base, row, parameter_names, base.load_scene)


def spec_to_run(text: str):
    """Load and check the spec at ``text`` and its base scenario; LadarError if unusable."""
    from ladartui.sweep import load_sweep_spec
    from ladartui.sweep.base import load_base
    from ladartui.sweep.spec import bundled_name

    if not text:
        raise FieldError("spec", text, "the path of a sweep spec (.toml)")
    path = user_path(text)
    if path.is_dir() or path.suffix.lower() == ".csv":
        sibling = sibling_spec(path)
        if sibling is None:
            raise InputFileError(path, "expected a sweep spec (.toml) to run; F3 opens results")
        path = sibling
    spec = load_sweep_spec(path)
    if bundled_name(spec.scenario_path) is None:
        load_base(spec)
    return spec


@dataclass
class OpenedSweep:
    """What the sweep screen opened: a spec (with its results, once run) or results."""

    path: Path  # as typed
    spec: Any  # SweepSpec, or None for results without a spec beside them
    out: Path  # the results folder
    result: Any = None  # SweepResult; None: the spec has no results yet
    own: list[dict] | None = None  # opened by its spec: its variants from its base as it is now
    earlier_base: int = 0  # of the rows not its own, those made from an earlier base


def open_sweep(text: str) -> OpenedSweep:
    """Read a sweep spec, a results folder or a results.csv; ``LadarError`` naming what
    is wrong. A spec opened ranks only its own variants from its base as it is now (the
    folder may hold others: another seed, an edited base or model)."""
    from ladartui.sweep import default_out_dir, load_sweep_results, load_sweep_spec
    from ladartui.sweep.base import earlier_base_rows, own_rows, spec_digest

    if not text:
        raise FieldError("spec", text, "a sweep spec, a results.csv or a results folder")
    path = user_path(text)
    by_spec = path.suffix.lower() == ".toml"
    if by_spec:
        spec = load_sweep_spec(path)
        results = default_out_dir(spec)
        if not (results / "results.csv").exists():
            return OpenedSweep(path, spec, results)
    else:
        results = path
        sibling = sibling_spec(path)
        spec = load_sweep_spec(sibling) if sibling is not None else None
    objective = spec.objective if spec else "obscured-coverage"
    budget = spec.budget if spec else None
    cost = spec.cost if spec else "flight-time"
    result = load_sweep_results(results, objective=objective, budget=budget, cost=cost)
    own, earlier = None, 0
    if spec is not None and by_spec:
        digest = spec_digest(spec)
        own, earlier = own_rows(result.rows, spec.variants, digest), earlier_base_rows(result.rows, digest)
    return OpenedSweep(path, spec, result.results_path.parent, result, own, earlier)
