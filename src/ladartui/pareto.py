"""Pareto front of points whose every objective is to be minimised.

One rule for every caller: a point is dominated when another point is no worse
in every objective and strictly better in at least one. Identical points
therefore do not dominate each other and are all on the front together.
A point that is None, or holds a None or NaN objective (a skipped setting, a
failed variant), is never on the front and never dominates.

Two objectives take an O(n log n) sort (a sweep may have thousands of
variants); more take the O(n^2) pairwise check.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TypeGuard

Point = Sequence[float]


def dominates(a: Point, b: Point) -> bool:
    """True when ``a`` is no worse than ``b`` in every objective and better in one."""
    return all(x <= y for x, y in zip(a, b)) and any(x < y for x, y in zip(a, b))


def usable(point: Point | None) -> TypeGuard[Point]:
    """True when the point exists and none of its objectives is None or NaN."""
    return point is not None and all(v is not None and not math.isnan(v) for v in point)


def pareto_front(points: Sequence[Point | None]) -> list[bool]:
    """For each point, whether no other usable point dominates it (all objectives minimised)."""
    kept = {i: p for i, p in enumerate(points) if usable(p)}
    if kept and all(len(p) == 2 for p in kept.values()):
        return _front_of_pairs(len(points), kept)
    front = [False] * len(points)
    for i, p in kept.items():
        front[i] = not any(j != i and dominates(q, p) for j, q in kept.items())
    return front


def _front_of_pairs(count: int, kept: dict[int, Point]) -> list[bool]:
    # Sorted by (x, y), a point is dominated exactly when a point with smaller x
    # has y <= its y, or a point with equal x has a strictly smaller y.
    order = sorted(kept, key=lambda i: (kept[i][0], kept[i][1]))
    front = [False] * count
    best_before = math.inf  # least y among points with strictly smaller x
    group_x, group_best = None, math.inf  # the current equal-x group and its least y
    for i in order:
        x, y = kept[i]
        if x != group_x:
            best_before = min(best_before, group_best)
            group_x, group_best = x, y
        front[i] = not (best_before <= y or group_best < y)
    return front


def dominator(points: Sequence[Point | None], index: int) -> int | None:
    """A front point that dominates point ``index`` (least objective 0 among such), or None."""
    p = points[index]
    if not usable(p):
        return None
    front = pareto_front(points)
    best, best_x = None, math.inf
    for j, q in enumerate(points):
        if j != index and front[j] and usable(q) and dominates(q, p):
            if best is None or q[0] < best_x:
                best, best_x = j, q[0]
    return best
