"""Ranking sweep rows by an objective, and the Pareto front of coverage against cost."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ladartui.errors import FieldError
from ladartui.pareto import Sense, pareto_front

# Column of the measure every objective is built on: the share of target
# voxels seen through the foliage over the whole flight.
COVERAGE_COLUMN = "obscured_coverage"

OBJECTIVES = {
    "obscured-coverage": "obscured target coverage (higher is better)",
    "coverage-per-km": "obscured coverage per kilometre flown (higher is better; undefined "
    "for a path of zero length)",
    "coverage-within-budget": "obscured coverage of paths flown within the flight-time budget "
    "(longer paths are not ranked)",
}
COSTS = {"flight-time": "flight_time_s", "distance": "path_length_m"}


@dataclass
class Ranked:
    """One row in the ranking: its objective value, rank (None: not rankable) and Pareto flag."""

    row: dict
    value: float | None
    rank: int | None
    pareto: bool
    cost: float | None
    coverage: float | None


def normal_objective(name: str) -> str:
    normal = name.replace("_", "-") if isinstance(name, str) else name
    if normal not in OBJECTIVES:
        raise FieldError("objective", name, "one of " + ", ".join(OBJECTIVES))
    return normal


def normal_cost(name: str) -> str:
    normal = name.replace("_", "-") if isinstance(name, str) else name
    if normal not in COSTS:
        raise FieldError("cost", name, "one of " + ", ".join(COSTS))
    return normal


def _number(value) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value):
        return None
    return float(value)


def coverage_of(row: dict) -> float | None:
    return _number(row.get(COVERAGE_COLUMN))


def objective_value(row: dict, objective: str, budget: float | None = None) -> float | None:
    """The row's score under ``objective``; None when undefined or out of budget."""
    objective = normal_objective(objective)
    if row.get("status") != "ok":
        return None
    coverage = coverage_of(row)
    if coverage is None:
        return None
    if objective == "obscured-coverage":
        return coverage
    if objective == "coverage-per-km":
        length = _number(row.get("path_length_m"))
        return coverage / (length / 1000.0) if length else None
    if budget is None:
        raise FieldError(
            "budget", None, "a flight-time budget in seconds for objective 'coverage-within-budget'"
        )
    time = _number(row.get("flight_time_s"))
    return coverage if time is not None and time <= budget else None


# (cost, coverage): less cost and more coverage are better (ladartui.pareto).
COST_COVERAGE: tuple[Sense, Sense] = ("min", "max")


def rank_rows(rows, objective="obscured-coverage", budget=None, cost="flight-time") -> list[Ranked]:
    """Rows best first under ``objective``; unrankable rows (failed, undefined) last.

    Ties go to the cheaper path, then to the variant id, so the order is stable.
    """
    objective, cost = normal_objective(objective), normal_cost(cost)
    cost_column = COSTS[cost]
    entries = []
    for row in rows:
        coverage = coverage_of(row) if row.get("status") == "ok" else None
        cost_value = _number(row.get(cost_column)) if coverage is not None else None
        entries.append(
            Ranked(row, objective_value(row, objective, budget), None, False, cost_value, coverage)
        )
    flags = pareto_front(
        [(e.cost, e.coverage) if e.cost is not None else None for e in entries], COST_COVERAGE
    )
    for entry, flag in zip(entries, flags):
        entry.pareto = flag

    def key(entry):
        cost_key = entry.cost if entry.cost is not None else math.inf
        if entry.value is None:
            return (1, 0.0, cost_key, str(entry.row.get("variant")))
        return (0, -entry.value, cost_key, str(entry.row.get("variant")))

    entries.sort(key=key)
    rank = 0
    for entry in entries:
        if entry.value is not None:
            rank += 1
            entry.rank = rank
    return entries
