"""Ranking sweep rows by an objective, and the Pareto front of coverage against cost.

Objectives on coverage score the share of target voxels seen through the
foliage; objectives on levels (``ladartui.levels``) score when the target(s)
reach identification: the flight time or distance until every target is
identified, and how many targets are identified within a flight-time budget.
A row is read per target through ``sweep.columns.target_values`` (one value
per target id; a row without per-target columns reads as one target).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ladartui.errors import FieldError
from ladartui.levels import LEVELS as LEVEL_NAMES
from ladartui.number_text import fixed
from ladartui.pareto import Sense, pareto_front
from ladartui.sweep.columns import LEVEL_FIELDS
from ladartui.sweep.columns import target_names as target_names
from ladartui.sweep.columns import target_values as target_values

# Column of the measure every objective is built on: the share of target
# voxels seen through the foliage over the whole flight.
COVERAGE_COLUMN = "obscured_coverage"
# Columns of the levels (Measures.levels flattened by the sweep's row builder).
LEVEL_COLUMN = "levels.{level}.{field}"

OBJECTIVES = {
    "obscured-coverage": "obscured target coverage (higher is better)",
    "coverage-per-km": "obscured coverage per kilometre flown (higher is better; undefined "
    "for a path of zero length)",
    "coverage-within-budget": "obscured coverage of paths flown within the flight-time budget "
    "(longer paths are not ranked)",
    "time-to-identify": "flight time until every target is identified (lower is better; paths "
    "that do not identify them all are not ranked)",
    "distance-to-identify": "distance flown until every target is identified (lower is better; "
    "paths that do not identify them all are not ranked)",
    "worst-target-coverage": "obscured coverage of the worst-covered target (higher is better)",
    "identified-within-budget": "targets identified within the flight-time budget (higher is "
    "better; ties go to the earlier identification; paths identifying none are not ranked)",
}
# Objectives whose smaller values are better; the rest rank larger values first.
LOWER_IS_BETTER = frozenset({"time-to-identify", "distance-to-identify"})
BUDGET_OBJECTIVES = frozenset({"coverage-within-budget", "identified-within-budget"})
# Objectives whose value is itself a coverage, a share of target voxels (0..1).
COVERAGE_OBJECTIVES = frozenset({"obscured-coverage", "coverage-within-budget", "worst-target-coverage"})
# Short column headers of each objective's value, for the CLI's and the TUI's tables.
OBJECTIVE_HEADERS = {
    "obscured-coverage": "coverage",
    "coverage-per-km": "cov/km",
    "coverage-within-budget": "in budget",
    "time-to-identify": "identify s",
    "distance-to-identify": "identify m",
    "worst-target-coverage": "worst cov.",
    "identified-within-budget": "identified",
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


def level_of(row: dict, level: str) -> list[tuple[bool, int | None, float | None, float | None]]:
    """Per target: (reached, scan, flight time s, distance m) of ``level`` in the row."""
    columns = [LEVEL_COLUMN.format(level=level, field=f) for f in LEVEL_FIELDS]
    values = [target_values(row, c) for c in columns]
    out = []
    for reached, scan, time, distance in zip(*values):
        ok = reached is True
        out.append(
            (ok, scan if ok else None, _number(time) if ok else None, _number(distance) if ok else None)
        )
    return out


def time_to_identify(row: dict) -> float | None:
    """Seconds of flight until every target is identified; None if one never is."""
    return _until_all_identified(row, 2)


def distance_to_identify(row: dict) -> float | None:
    """Metres flown until every target is identified; None if one never is."""
    return _until_all_identified(row, 3)


def _until_all_identified(row: dict, index: int) -> float | None:
    values = [t[index] if t[0] else None for t in level_of(row, "identify")]
    known = [float(v) for v in values if v is not None]
    return max(known) if known and len(known) == len(values) else None


def worst_target_coverage(row: dict) -> float | None:
    """The lowest obscured coverage over the row's targets (None if one is undefined)."""
    values = [_number(v) for v in target_values(row, COVERAGE_COLUMN)]
    known = [v for v in values if v is not None]
    return min(known) if known and len(known) == len(values) else None


def identified_within(row: dict, budget: float) -> tuple[int, float | None]:
    """Targets identified at a flight time within ``budget`` s, and when the last of them was."""
    times = [t[2] for t in level_of(row, "identify") if t[0] and t[2] is not None and t[2] <= budget]
    return len(times), (max(times) if times else None)


def identified_count(row: dict) -> int:
    """How many of the row's targets its path identifies (by its last scan)."""
    return sum(t[0] for t in level_of(row, "identify"))


def never_identified(rows) -> list[str]:
    """Names of the targets no finished row identifies (rows of one sweep share their targets)."""
    done = [r for r in rows if r.get("status") == "ok"]
    if not done:
        return []
    names = target_names(done[0])
    if len(names) < 2:
        return []
    identify = [level_of(r, "identify") for r in done]
    identify = [per_target for per_target in identify if len(per_target) == len(names)]
    seen = [any(per_target[i][0] for per_target in identify) for i in range(len(names))]
    return [name for name, identified in zip(names, seen) if not identified]


def levels_text(row: dict) -> str:
    """Which level the row's path reaches and when, per target, e.g. for the recommended path.

    With several targets it names them and leads with how many are identified,
    e.g. ``identifies 2 of 3 targets: truck reaches identify at scan 3 of 8 (...); ...``.
    """
    texts = []
    per_level = {level: level_of(row, level) for level in LEVEL_NAMES}
    count = len(per_level["identify"])
    names = target_names(row)
    for index in range(count):
        reached = [(level, per_level[level][index]) for level in LEVEL_NAMES if per_level[level][index][0]]
        prefix = f"{names[index]} " if count > 1 else ""
        if not reached:
            known = (
                target_values(row, LEVEL_COLUMN.format(level="detect", field="reached"))[index] is not None
            )
            texts.append(prefix + ("reaches no level (not detected)" if known else "levels unknown"))
            continue
        level, (_, scan, time, distance) = reached[-1]
        scans = target_values(row, "levels.scans")[index]
        of = f" of {scans}" if isinstance(scans, int) and not isinstance(scans, bool) else ""
        text = (
            f"{prefix}reaches {level} at scan {scan}{of} ({_amount(time, 's')}, {_amount(distance, 'm')} "
            "from the first scan)"
        )
        above = LEVEL_NAMES[LEVEL_NAMES.index(level) + 1 :]
        if above:
            text += f"; {', '.join(above)} not reached"
        texts.append(text)
    if count > 1:
        identified = sum(t[0] for t in per_level["identify"])
        lead = (
            f"identifies all {count} targets"
            if identified == count
            else f"identifies {identified} of {count} targets"
        )
        return lead + ": " + "; ".join(texts)
    return "; ".join(texts)


def _amount(value, unit) -> str:
    return "?" if value is None else f"{fixed(value, 1)} {unit}"  # 1e10 s and up: an exponent


def objective_value(row: dict, objective: str, budget: float | None = None) -> float | None:
    """The row's score under ``objective``; None when undefined or out of budget."""
    objective = normal_objective(objective)
    if row.get("status") != "ok":
        return None
    if objective == "time-to-identify":
        return time_to_identify(row)
    if objective == "distance-to-identify":
        return distance_to_identify(row)
    if objective == "worst-target-coverage":
        return worst_target_coverage(row)
    if objective == "identified-within-budget":
        count = identified_within(row, _need_budget(budget, objective))[0]
        return count if count else None  # a count: shown as 2, not 2.000
    coverage = coverage_of(row)
    if coverage is None:
        return None
    if objective == "obscured-coverage":
        return coverage
    if objective == "coverage-per-km":
        length = _number(row.get("path_length_m"))
        return coverage / (length / 1000.0) if length else None
    budget = _need_budget(budget, objective)
    time = _number(row.get("flight_time_s"))
    return coverage if time is not None and time <= budget else None


def _need_budget(budget, objective) -> float:
    if budget is None:
        raise FieldError("budget", None, f"a flight-time budget in seconds for objective '{objective}'")
    return budget


def _tie_break(row: dict, objective: str, budget) -> float:
    """Between equal values: the earlier identification for targets within budget, else nothing."""
    if objective == "identified-within-budget" and budget is not None:
        last = identified_within(row, budget)[1]
        return last if last is not None else math.inf
    return 0.0


# (cost, coverage): less cost and more coverage are better (ladartui.pareto).
COST_COVERAGE: tuple[Sense, Sense] = ("min", "max")


def rank_rows(rows, objective="obscured-coverage", budget=None, cost="flight-time") -> list[Ranked]:
    """Rows best first under ``objective``; unrankable rows (failed, undefined) last.

    Ties go to the cheaper path (for identified-within-budget first to the
    earlier identification), then to the variant id, so the order is stable.
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

    sign = 1.0 if objective in LOWER_IS_BETTER else -1.0

    def key(entry):
        cost_key = entry.cost if entry.cost is not None else math.inf
        if entry.value is None:
            return (1, 0.0, 0.0, cost_key, str(entry.row.get("variant")))
        tie = _tie_break(entry.row, objective, budget)
        return (0, sign * entry.value, tie, cost_key, str(entry.row.get("variant")))

    entries.sort(key=key)
    rank = 0
    for entry in entries:
        if entry.value is not None:
            rank += 1
            entry.rank = rank
    return entries
