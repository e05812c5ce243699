"""Which order traces a block of rays: learned per occupancy from the blocks' own times.

Both backends' ``trace_cells`` run their exact rays through ``trace_in_blocks``:
blocks that are scans may go in object order (tracing.object_order), the rest,
and scans where walking the rays is cheaper, in ray order.
"""

from __future__ import annotations

import threading
import time
from contextlib import contextmanager

import numpy as np
from numba.core import event as numba_event

from ladartui.errors import check_cancelled
from ladartui.tracing.config import MIN_SCAN_RAYS, SCAN_BLOCK, VOXELS_PER_RAY
from ladartui.tracing.learned_choice import TwoWayChoice

RAY_RUN_BLOCKS = 16  # blocks one ray_block call may take: bounds the wait for a cancel
# Share of a block's rays that times ray order while it does not lead (numba, and
# wgpu on a CPU adapter): a retry then costs a sixteenth of a ray-order scan beside
# the object-order one.
RAY_SAMPLE = 1 / 16


class OrderChoice(TwoWayChoice):
    """Which order traces an occupancy's scans faster, learned from the calls themselves
    (``TwoWayChoice`` over "object" and "ray", per ray).

    Neither order wins everywhere: object order costs about the same for any
    scene in view, ray order is cheap where rays stop early (dense cover) and
    dear where they pass many gaps (foliage). So the orders take turns until
    each has been timed twice (a process's first calls also start threads and
    touch new memory; compiling is not counted, ``trace_in_blocks``), object
    order first, except that an order timed at over ``settled_gap`` times the
    best of an order timed twice is not timed again then (a scan in ray order
    at 45 degrees on the reference scene costs four object-order scans; the
    wgpu backend, whose first calls also build pipelines, passes
    ``settled_gap=inf``). On the reference orbit, losing retries every 16 scans
    were a tenth of the numba backend's work.

    Ray order's cost is per ray, so while it does not lead it can be timed on
    ``ray_sample`` of a block's rays (spread over the block), object order
    answering the whole block; object order's cost is per scan, so it is timed
    on whole blocks. None: ray order too takes whole blocks (the wgpu backend on
    a GPU, where each call costs a dispatch).
    """

    def __init__(
        self,
        settled_gap: float = 2.0,
        ray_sample: float | None = None,
        voxels_per_ray: float = VOXELS_PER_RAY,
    ):
        super().__init__(("object", "ray"), settled_gap)
        self.ray_sample = ray_sample
        self.voxels_per_ray = voxels_per_ray  # object order is tried for a scan with at most these in view

    def times_ray_order_on_a_sample(self) -> bool:
        """Whether a pick of ray order is timed on a sample of the block (``ray_sample``)."""
        return self.ray_sample is not None and self.leader() != "ray"


class CompileTime(numba_event.Listener):
    """How far ``clock`` advances while this thread compiles or loads numba kernels
    (holds numba's compiler lock, or waits for it): a process's first call of a
    kernel, not the cost of the order that made it."""

    def __init__(self, clock):
        self.clock = clock
        self.seconds = 0.0
        self._thread = threading.get_ident()
        self._depth = 0  # the lock is re-entrant: time the outermost hold
        self._began = 0.0

    def on_start(self, event):
        if threading.get_ident() == self._thread:
            if self._depth == 0:
                self._began = self.clock()
            self._depth += 1

    def on_end(self, event):
        if threading.get_ident() == self._thread and self._depth > 0:
            self._depth -= 1
            if self._depth == 0:
                self.seconds += self.clock() - self._began


def trace_in_blocks(n, order, choice, object_block, ray_block, cancel=None, clock=time.perf_counter):
    """Trace ``n`` exact rays in blocks of up to SCAN_BLOCK, each in object or ray
    order, as both backends do; returns the set of orders used.

    ``object_block(a, b, max_voxels)`` traces rays a..b in object order and says
    whether it could (a scan with at most ``max_voxels`` voxels in view);
    ``ray_block(a, b)`` traces them in ray order. ``order`` "object" tries object
    order on every block, whatever it costs; "auto" lets ``choice`` (this
    occupancy's OrderChoice) pick for blocks of at least MIN_SCAN_RAYS and learn
    from their times, read from ``clock``: wall time by default (a GPU's work costs
    the host nothing), the process's CPU time for a CPU backend (time.process_time:
    on a shared machine, other processes' work then does not make an order look
    slow, and the choice does not flip with the load). In "auto", blocks picked
    for ray order one after another go to ``ray_block`` together, up to
    RAY_RUN_BLOCKS of them (the wgpu backend overlaps the batches of one call),
    and are timed as one. Time spent compiling numba kernels (``CompileTime``) is
    not counted.
    """
    with compile_time(clock) as compiling:
        return _trace_blocks(n, order, choice, object_block, ray_block, cancel, clock, compiling)


@contextmanager
def compile_time(clock=time.perf_counter):
    """A ``CompileTime`` of this thread, listening while the block runs."""
    compiling = CompileTime(clock)
    with numba_event.install_listener("numba:compiler_lock", compiling):
        yield compiling


def sample_spans(first: int, end: int, share: float, spans: int = 4) -> list[tuple[int, int]]:
    """About ``share`` of rays ``first..end`` as ``spans`` runs, centred on equal parts
    of the range (for a scan, strips across its image: near and far rays alike)."""
    n = end - first
    length = max(1, round(n * share / spans))
    runs = []
    for k in range(spans):
        start = first + min(max(0, (2 * k + 1) * n // (2 * spans) - length // 2), n - length)
        runs.append((start, start + min(length, n)))
    return sorted(set(runs))


def _trace_blocks(n, order, choice, object_block, ray_block, cancel, clock, compiling):
    def spent(started, compiled):  # a block's time, less its compiling
        return clock() - started - (compiling.seconds - compiled)

    orders = set()
    picked = None  # the choice's pick for the block at ``a``, when made ahead
    a = 0
    while a < n:
        b = min(n, a + SCAN_BLOCK)
        check_cancelled(cancel, "trace cancelled")
        learning = choice if order == "auto" and b - a >= MIN_SCAN_RAYS else None
        pick = None if learning is None else picked or learning.pick()
        picked = None
        started, compiled = clock(), compiling.seconds
        sampled = None  # (seconds, rays) of ray order timed on a sample of this block
        if pick == "ray" and learning is not None and learning.times_ray_order_on_a_sample():
            spans = sample_spans(a, b, learning.ray_sample)
            for first, end in spans:
                ray_block(first, end)
            sampled = (spent(started, compiled), sum(end - first for first, end in spans))
            pick = "object"  # which answers the block
            started, compiled = clock(), compiling.seconds
        if order == "object" or pick == "object":
            limit = np.inf if learning is None else learning.voxels_per_ray * (b - a)
            if object_block(a, b, limit):
                orders.add("object")
                if learning is not None:
                    if sampled is not None:
                        learning.record("ray", *sampled)
                    learning.record("object", spent(started, compiled), b - a)
                a = b
                continue
            learning = None  # no scan for object order: nothing to learn from this block
        if learning is not None:  # picked for ray order: so may the blocks after it be
            while b < n and b - a < RAY_RUN_BLOCKS * SCAN_BLOCK:
                after = min(n, b + SCAN_BLOCK)
                if after - b >= MIN_SCAN_RAYS:
                    picked = choice.pick()
                    if picked != "ray":
                        break
                    picked = None
                b = after
        orders.add("ray")
        ray_block(a, b)
        if learning is not None:
            learning.record("ray", spent(started, compiled), b - a)
        a = b
    return orders
