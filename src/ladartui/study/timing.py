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


# A call that compiled is run again at most this many times. A call compiles only what the
# calls before it did not reach (a scan's other tracing order), so one more call is normally
# enough; but the order is learned from the calls' own times, so the next call may still
# reach a kernel none did before: two spare, and the last timed whatever it did, so a
# compiler that goes on compiling cannot hold the study.
RETRIES_AFTER_COMPILING = 3


def timed_without_compiling(call: Callable[[], object], clock=time.perf_counter):
    """``timed``, where a call during which numba compiled or loaded kernels (a kernel's
    first call in the process, which a warm-up need not reach: the exact trace takes
    turns between its two orders) is run again: its time was the compiler's. Returns
    (the result, seconds of the call that compiled nothing) after at most
    ``RETRIES_AFTER_COMPILING`` calls again, the last one timed whatever it did."""
    from ladartui.tracing.order_choice import compile_time

    for retry in range(RETRIES_AFTER_COMPILING + 1):
        with compile_time(clock) as compiling:
            result, seconds = timed(call, clock)
        if compiling.seconds == 0 or retry == RETRIES_AFTER_COMPILING:
            break
    return result, seconds


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
