"""Core field errors named as the flags the user typed; the limits of run counts.

The core names a field as the scenario file does (``simulation.backend``,
``detection.n_ref``, ``at``); a command that passed a flag's value on says
``--backend``, ``--n-ref``, ``--at`` instead, with the value as typed; a
positional argument is named as its usage line names it (``PRESET``).
``run_count`` bounds the timed runs and warm-up calls of bench and study;
``voxel_size_flag`` holds a ``--voxel-size`` to what a scenario takes;
``check_file_names`` refuses empty file names; ``check_scene_stem`` a scene to write
named as a target model.
"""

from __future__ import annotations

import contextlib
import math

from ladartui.errors import FieldError, LadarError


@contextlib.contextmanager
def as_flags(typed: dict, labels: dict | None = None):
    """Re-raise a FieldError whose field ends in one of ``typed``'s names (``n_ref``) as
    that flag (``--n-ref``), or as ``labels[name]`` where given (``PRESET``), with the
    value typed, and the file it was checked against where the error names one; names whose
    value is None were not typed and pass the error on as it is."""
    try:
        yield
    except FieldError as error:
        name = error.field.rpartition(".")[2]
        if typed.get(name) is None:
            raise
        label = (labels or {}).get(name) or "--" + name.replace("_", "-")
        raise FieldError(label, typed[name], error.expected, source=error.source) from None


MAX_RUNS = 1000  # timed runs or warm-up calls: more would take hours and tell no more


def run_count(flag: str, value: int, low: int = 1, high: int = MAX_RUNS) -> int:
    """``value`` when it is from ``low`` to ``high``; else a FieldError naming ``flag``."""
    if not low <= value <= high:
        raise FieldError(flag, value, f"a whole number from {low} to {high}")
    return value


def voxel_size_flag(value: float, flag: str = "--voxel-size") -> float:
    """A voxel size typed as a flag, held to what a scenario's ``files.voxel_size`` takes:
    finite, MIN_VOXEL_SIZE to MAX_VOXEL_SIZE metres; else FieldError naming the flag."""
    from ladartui.checks import range_text
    from ladartui.scenario import MAX_VOXEL_SIZE, MIN_VOXEL_SIZE

    if not (math.isfinite(value) and MIN_VOXEL_SIZE <= value <= MAX_VOXEL_SIZE):
        raise FieldError(
            flag, value, range_text("a number of metres", MIN_VOXEL_SIZE, MAX_VOXEL_SIZE, False, False)
        )
    return value


def check_file_names(given: dict, expected: str = "a file name") -> None:
    """FieldError for the first of ``given`` (flag or argument as the usage line names
    it: value typed, None if not given) that is empty or blank: "" names no file, and
    as a Path it is the current folder."""
    for name, value in given.items():
        if value is not None and not value.strip():
            raise FieldError(name, value, expected)


def check_scenario_name(value) -> None:
    """FieldError for an empty or blank SCENARIO: as a path it is the current folder, and
    where a command has a default scenario "" must not quietly mean it."""
    from ladartui.user_data import BUNDLED

    check_file_names(
        {"SCENARIO": value}, "a scenario file (.toml) or a bundled scenario: " + ", ".join(BUNDLED)
    )


def refuse_step_without_march(step: float | None, method: str, what: str) -> None:
    """A ``--step`` given where the tracing is not a march (``method``) would be ignored:
    refused in one line, saying what the trace is (``what``: "this run is exact (...)")."""
    if step is not None and method != "march":
        raise LadarError(
            f"--step {step:g} sets the march's step, and {what}: add --method march, or drop --step"
        )


def check_scene_stem(flag: str, value: str, scene_file) -> None:
    """Refuse a scene to write named as a target model (``forest_Target.txt``): it would go
    over ``forest.txt``'s target model, with its own target beside it as ``..._Target_Target``."""
    from pathlib import Path

    stem = Path(scene_file).stem
    if stem.endswith("_Target"):
        name = stem.removesuffix("_Target")
        raise FieldError(
            flag,
            value,
            f"the scene's stem, such as {name} (it writes {name}.txt and {name}_Target.txt), "
            "not a target model's name",
        )
