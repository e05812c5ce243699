"""Pareto front of settings where every objective is to be minimised."""

from __future__ import annotations

import math
from typing import Sequence


def dominates(a: Sequence[float], b: Sequence[float]) -> bool:
    """True when ``a`` is no worse than ``b`` in every objective and better in one."""
    return all(x <= y for x, y in zip(a, b)) and any(x < y for x, y in zip(a, b))


def _usable(point) -> bool:
    return point is not None and all(v is not None and not math.isnan(v) for v in point)


def pareto_front(points: Sequence[Sequence[float] | None]) -> list[bool]:
    """For each point, whether no other point dominates it.

    Points that are None or hold a None/NaN objective (a skipped setting) are
    never on the front and never dominate. Identical points are all on the front.
    """
    usable = [_usable(p) for p in points]
    front = []
    for i, p in enumerate(points):
        if not usable[i]:
            front.append(False)
            continue
        front.append(not any(usable[j] and dominates(points[j], p) for j in range(len(points)) if j != i))
    return front


def dominator(points: Sequence[Sequence[float] | None], index: int) -> int | None:
    """A front point that dominates point ``index`` (the fastest such, objective 0), or None."""
    p = points[index]
    if not _usable(p):
        return None
    front = pareto_front(points)
    best = None
    for j, q in enumerate(points):
        if j != index and front[j] and dominates(q, p):
            if best is None or q[0] < points[best][0]:
                best = j
    return best
