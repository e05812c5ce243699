"""Which of two ways of doing the same work is faster, learned from the calls themselves.

``TwoWayChoice`` is the learning both choices of the tracer share: which order
traces an occupancy's scans (tracing/order_choice.py) and, where a GPU could
trace them too, which backend traces a size of call (tracing/backend_choice.py).
It never changes an answer: it is used only where both ways give the same one.
"""

from __future__ import annotations

import threading


class TwoWayChoice:
    """Which of ``ways`` is faster per unit of work, from the recorded times.

    The ways take turns until each has been timed ``SAMPLES`` times, except that
    a way timed at over ``settled_gap`` times the best of a way timed that often
    is not timed again then. Then the faster by its better recent time per unit
    goes on (a slow first call, which compiles or opens a device, is forgiven),
    and the other is tried again in case the work has changed: RETRY picks after
    the lead last changed, then twice as long after each retry that loses, up to
    MAX_RETRY picks. The less timed way goes first while learning, ``ways[0]``
    on a tie. Thread-safe.
    """

    RETRY = 16
    MAX_RETRY = 64
    SAMPLES = 2

    def __init__(self, ways: tuple[str, str], settled_gap: float = 2.0):
        self.ways = ways
        self.settled_gap = settled_gap
        self.samples: dict[str, list[float]] = {way: [] for way in ways}  # recent seconds per unit
        self.calls = 0
        self.retry_every = self.RETRY
        self._next_retry = self.RETRY  # the call that retries the other way
        self._retrying: str | None = None  # the way a retry picked, until it is timed
        self._leader: str | None = None  # the faster way by the samples so far
        self._lock = threading.Lock()

    def other(self, way: str) -> str:
        return self.ways[1] if way == self.ways[0] else self.ways[0]

    def leader(self) -> str | None:
        """The way that leads, None until both have been timed."""
        with self._lock:
            return self._leader

    def _best(self) -> str:
        return min(self.samples, key=lambda way: min(self.samples[way]))

    def _needs_sample(self, way: str) -> bool:
        mine, other = self.samples[way], self.samples[self.other(way)]
        if len(mine) >= self.SAMPLES:
            return False
        settled_far_ahead = (
            len(other) >= self.SAMPLES and bool(mine) and min(mine) > self.settled_gap * min(other)
        )
        return not settled_far_ahead

    def pick(self) -> str:
        with self._lock:
            self.calls += 1
            learning = [way for way in self.ways if self._needs_sample(way)]
            if learning:  # the less timed first, ways[0] on a tie
                return min(learning, key=lambda way: len(self.samples[way]))
            best = self._best()
            if self.calls >= self._next_retry:
                self._next_retry = self.calls + self.retry_every
                self._retrying = self.other(best)
                return self._retrying
            return best

    def record(self, way: str, seconds: float, units: int) -> None:
        with self._lock:
            recent = self.samples[way]
            recent.append(seconds / max(1, units))
            del recent[: -self.SAMPLES]
            leader = self._best() if all(self.samples.values()) else None
            if leader != self._leader:  # the work changed (or a first lead): look again soon
                self.retry_every = self.RETRY
                self._next_retry = self.calls + self.RETRY
            elif way == self._retrying:  # a retry lost: wait twice as long for the next
                self.retry_every = min(self.MAX_RETRY, 2 * self.retry_every)
                self._next_retry = self.calls + self.retry_every
            if way == self._retrying:
                self._retrying = None
            self._leader = leader
