"""The Pareto front, one function for every caller, each objective's sense stated.

``sense`` gives, per objective, "min" (less is better) or "max" (more is
better): the study minimises (seconds, error), sweeps take (cost, coverage)
as ("min", "max"). One rule: a point is dominated when another point is no
worse in every objective and strictly better in at least one. Identical points
therefore do not dominate each other and are all on the front together.
A point that is None, or holds a None or NaN objective (a skipped setting, a
failed variant), is never on the front and never dominates.

Two objectives take an O(n log n) sort (a sweep may have thousands of
variants); more take the O(n^2) pairwise check.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

Point = Sequence[float]
Objectives = Sequence[float | None]
Sense = Literal["min", "max"]
SENSES = ("min", "max")


def dominates(a: Point, b: Point) -> bool:
    """True when ``a`` is no worse than ``b`` in every objective and better in one
    (every objective minimised: ``oriented`` turns a point into that form)."""
    return all(x <= y for x, y in zip(a, b)) and any(x < y for x, y in zip(a, b))


def oriented(point: Objectives | None, sense: Sequence[Sense]) -> Point | None:
    """``point`` with every "max" objective negated, so that less is better in each;
    None for a missing point or one with a None or NaN objective (never usable)."""
    if len(sense) == 0 or any(s not in SENSES for s in sense):
        raise ValueError(f"sense must be a sequence of 'min' or 'max', not {sense!r}")
    if point is None:
        return None
    values = [v for v in point if v is not None and not math.isnan(v)]
    if len(values) != len(point):
        return None
    if len(point) != len(sense):
        raise ValueError(f"a point of {len(point)} objectives against {len(sense)} senses")
    return tuple(v if s == "min" else -v for v, s in zip(values, sense))


def pareto_front(points: Sequence[Objectives | None], sense: Sequence[Sense]) -> list[bool]:
    """For each point, whether no other usable point dominates it, each objective taken
    in its ``sense`` ("min" or "max")."""
    return _front([oriented(p, sense) for p in points])


def _front(points: Sequence[Point | None]) -> list[bool]:
    pairs = [(i, p) for i, p in enumerate(points) if p is not None]
    if pairs and all(len(p) == 2 for _, p in pairs):
        return _front_of_pairs(len(points), pairs)
    front = [False] * len(points)
    for i, p in pairs:
        front[i] = not any(j != i and dominates(q, p) for j, q in pairs)
    return front


def _front_of_pairs(n: int, pairs: list[tuple[int, Point]]) -> list[bool]:
    # Sorted by (x, y), a point is dominated exactly when a point with smaller x
    # has y <= its y, or a point with equal x has a strictly smaller y.
    order = sorted(pairs, key=lambda pair: (pair[1][0], pair[1][1]))
    front = [False] * n
    best_before = math.inf  # least y among points with strictly smaller x
    group_x, group_best = None, math.inf  # the current equal-x group and its least y
    for i, (x, y) in order:
        if x != group_x:
            best_before = min(best_before, group_best)
            group_x, group_best = x, y
        front[i] = not (best_before <= y or group_best < y)
    return front


def dominator(points: Sequence[Objectives | None], index: int, sense: Sequence[Sense]) -> int | None:
    """A front point that dominates point ``index`` (best in objective 0 among such), or None."""
    oriented_points = [oriented(p, sense) for p in points]
    p = oriented_points[index]
    if p is None:
        return None
    front = _front(oriented_points)
    best, best_first = None, math.inf
    for j, q in enumerate(oriented_points):
        if j != index and front[j] and q is not None and dominates(q, p) and q[0] < best_first:
            best, best_first = j, q[0]
    return best
