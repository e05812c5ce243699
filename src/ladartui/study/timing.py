"""Timing harness: warm-up calls, then the median of timed runs."""

from __future__ import annotations

import statistics
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from ladartui.errors import check_cancelled


@dataclass
class Timing:
    """Wall-clock seconds of each timed run; ``median`` is the figure quoted."""

    seconds: list[float] = field(default_factory=list)

    def add(self, seconds: float) -> None:
        self.seconds.append(float(seconds))

    @property
    def median(self) -> float | None:
        return statistics.median(self.seconds) if self.seconds else None

    @property
    def runs(self) -> int:
        return len(self.seconds)


def timed(call: Callable[[], object], clock=time.perf_counter):
    """Run ``call`` once: (its result, seconds taken)."""
    start = clock()
    result = call()
    return result, clock() - start


def measure(
    call: Callable[[], object],
    runs: int = 5,
    warmup: int = 1,
    cancel: threading.Event | None = None,
    clock=time.perf_counter,
):
    """Call ``call`` ``warmup`` times untimed, then ``runs`` times timed.

    Returns (the last result, Timing). Warm-up absorbs one-off costs (numba
    compilation, shader compilation, buffer upload). ``cancel`` is checked
    before every call.
    """
    if runs < 1:
        raise ValueError("runs must be at least 1")
    result = None
    for _ in range(warmup):
        check_cancelled(cancel, "study cancelled")
        result = call()
    timing = Timing()
    for _ in range(runs):
        check_cancelled(cancel, "study cancelled")
        result, seconds = timed(call, clock)
        timing.add(seconds)
    return result, timing
