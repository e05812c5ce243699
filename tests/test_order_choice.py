"""The order choice: which order traces a block, learned from the blocks' own times
(tracing/order_choice.py). Scripted clocks: the answers must not hang on how busy
the machine is."""

import math
import threading
import time

import numba
import numpy as np
import pytest
from numba.core import event as numba_event

from ladartui.tracing.config import MIN_SCAN_RAYS, SCAN_BLOCK
from ladartui.tracing.order_choice import RAY_RUN_BLOCKS, OrderChoice, trace_in_blocks


def run(choice, calls, seconds):
    """``calls`` picks of ``choice``, each recorded as taking ``seconds[pick]`` for 1,000
    rays; the picks' first letters."""
    picks = ""
    for _ in range(calls):
        pick = choice.pick()
        picks += pick[0]
        choice.record(pick, seconds[pick], 1000)
    return picks


def test_order_choice_learns_the_faster_order():
    def calls_of(picks, letter, first_call):
        return [first_call + k for k, p in enumerate(picks) if p == letter]

    assert (OrderChoice.RETRY, OrderChoice.MAX_RETRY) == (16, 64)
    choice = OrderChoice()
    # Turns until each order is timed twice; a slow first call (compiling) is forgiven.
    choice.record("object", 0.5, 1000)
    choice.samples["object"].clear()
    picks = run(choice, 250, {"object": 0.040, "ray": 0.010})
    assert picks[:4] == "oror"
    # Ray order leads from call 2 on. Object order is tried again 16 calls later, and
    # after each retry it loses, twice as long after: 32, then 64 at most.
    assert calls_of(picks[4:], "o", 5) == [18, 18 + 32, 18 + 32 + 64, 18 + 32 + 2 * 64, 18 + 32 + 3 * 64]
    assert choice.retry_every == 64
    # The views change: ray order turns slow. Its own next two times show it, object
    # order leads again, and ray order is retried 16 calls later, then 32, 64 later.
    picks = run(choice, 150, {"object": 0.040, "ray": 0.200})
    assert picks[:3] == "rro"
    assert calls_of(picks[2:], "r", 253) == [252 + 16, 252 + 16 + 32, 252 + 16 + 32 + 64]
    first = OrderChoice()
    first.record("object", 0.9, 1000)  # compiling
    assert run(first, 3, {"object": 0.040, "ray": 0.060}) == "ror"
    assert run(first, 5, {"object": 0.040, "ray": 0.060}) == "ooooo"


def test_order_choice_reads_the_given_clock():
    # A block that waits (as when other processes hold the cores) costs no CPU time:
    # on the process's CPU clock the order that computes less wins even though it
    # took longer by the wall clock; on the wall clock the other one does. The blocks
    # advance scripted clocks rather than sleep and spin: real clocks made the answer
    # hang on how busy the machine was (10 ms of CPU took over 30 ms of wall time on
    # loaded cores, so the wall clock picked object order too).
    elapsed = {"cpu": 0.0, "wall": 0.0}

    def waits(a, b, max_voxels):  # object order: 30 ms of wall time, no CPU
        elapsed["wall"] += 0.03
        return True

    def computes(a, b):  # ray order: 10 ms of CPU, as long by the wall clock
        elapsed["cpu"] += 0.01
        elapsed["wall"] += 0.01

    picks = {}
    for name in ("cpu", "wall"):
        choice = OrderChoice()
        for _ in range(6):
            trace_in_blocks(
                MIN_SCAN_RAYS, "auto", choice, waits, computes, clock=lambda name=name: elapsed[name]
            )
        picks[name] = choice.pick()
    assert picks == {"cpu": "object", "wall": "ray"}


def test_blocks_picked_for_ray_order_go_together(monkeypatch):
    """Once ray order has won, the blocks picked for it one after another go to
    ray_block as one run (up to RAY_RUN_BLOCKS), broken where the choice retries
    object order; a short last block joins the run before it. Every ray is traced
    once, and each run is learned from as one sample."""

    def traced(n, retry):
        monkeypatch.setattr(OrderChoice, "RETRY", retry)
        choice = OrderChoice()
        choice.samples = {"object": [1e-6, 1e-6], "ray": [1e-7, 1e-7]}
        calls = []
        now = [0.0]  # seconds: object order costs ten times what ray order does

        def object_block(a, b, limit):
            calls.append(("object", a // SCAN_BLOCK, b / SCAN_BLOCK))
            now[0] += (b - a) * 1e-6
            return True

        def ray_block(a, b):
            calls.append(("ray", a // SCAN_BLOCK, b / SCAN_BLOCK))
            now[0] += (b - a) * 1e-7

        trace_in_blocks(n, "auto", choice, object_block, ray_block, clock=lambda: now[0])
        covered = sorted((a, b) for _, a, b in calls)
        assert covered[0][0] == 0 and covered[-1][1] == n / SCAN_BLOCK
        assert all(x[1] == y[0] for x, y in zip(covered, covered[1:]))  # no gap, no overlap
        return calls, choice

    calls, choice = traced(20 * SCAN_BLOCK, OrderChoice.RETRY)  # the 16th pick retries object order
    assert calls == [("ray", 0, 15), ("object", 15, 16), ("ray", 16, 20)]
    assert choice.calls == 20 and len(choice.samples["ray"]) == 2
    tail = MIN_SCAN_RAYS // 2
    calls, _ = traced(2 * RAY_RUN_BLOCKS * SCAN_BLOCK + 8 * SCAN_BLOCK + tail, 1000)
    last = 2 * RAY_RUN_BLOCKS + 8 + tail / SCAN_BLOCK
    assert calls == [
        ("ray", 0, RAY_RUN_BLOCKS),
        ("ray", RAY_RUN_BLOCKS, 2 * RAY_RUN_BLOCKS),
        ("ray", 2 * RAY_RUN_BLOCKS, last),
    ]


def test_an_order_far_slower_than_a_settled_one_is_timed_once():
    slow_ray = {"object": 0.010, "ray": 0.040}
    # Object order is timed twice (settled); ray order's one time is four times its
    # best, so ray order waits for its retry, 16 calls after the lead was first known.
    picks = run(OrderChoice(), 40, slow_ray)
    assert picks[:3] == "oro"
    assert [k + 1 for k, p in enumerate(picks) if p == "r"] == [2, 18]
    # Within the gap, or against an order timed once, ray order is timed again.
    assert run(OrderChoice(), 4, {"object": 0.010, "ray": 0.019}) == "oror"
    first = OrderChoice()
    first.record("object", 0.9, 1000)  # its first call, slow as a cold start is
    assert run(first, 3, slow_ray) == "roo"  # object's best is what counts
    # With no gap (the wgpu backend's, whose first calls build pipelines) both are timed twice.
    assert run(OrderChoice(settled_gap=math.inf), 4, slow_ray) == "oror"


def test_compiling_is_not_charged_to_the_order():
    """numba compiling (or loading from its cache) in a block, on the block's own
    thread, is taken off the block's time; another thread's compiling is not."""
    now = [0.0]
    samples = []

    class Choice(OrderChoice):
        def record(self, order, seconds, rays):
            samples.append((order, round(seconds, 9)))
            super().record(order, seconds, rays)

    def compiles_here(a, b, max_voxels):  # 2 s of compiling, nested as numba's lock can be
        with numba_event.trigger_event("numba:compiler_lock"):
            now[0] += 1.0
            with numba_event.trigger_event("numba:compiler_lock"):
                now[0] += 1.0
        now[0] += 0.010
        return True

    def compiles_elsewhere(a, b):
        def other():
            with numba_event.trigger_event("numba:compiler_lock"):
                now[0] += 1.0

        thread = threading.Thread(target=other)
        thread.start()
        thread.join()
        now[0] += 0.040

    choice = Choice()
    for _ in range(2):
        trace_in_blocks(
            MIN_SCAN_RAYS, "auto", choice, compiles_here, compiles_elsewhere, clock=lambda: now[0]
        )
    assert samples == [("object", 0.010), ("ray", 1.040)]


def test_a_real_compile_is_not_charged():
    # numba's own events, on the real clock: a block that compiles a new function
    # (tens of milliseconds) is charged only its own few microseconds.
    elapsed = []

    class Choice(OrderChoice):
        def record(self, order, seconds, rays):
            elapsed.append(seconds)

    def compiles(a, b, max_voxels):
        numba.njit(lambda x: x * 3 + 1)(2.0)
        return True

    started = time.perf_counter()
    trace_in_blocks(MIN_SCAN_RAYS, "auto", Choice(), compiles, None)
    whole = time.perf_counter() - started
    assert len(elapsed) == 1 and whole > 0.02 and elapsed[0] < 0.25 * whole


def test_sample_spans_spread_a_share_of_the_rays_over_the_block():
    from ladartui.tracing.order_choice import sample_spans

    spans = sample_spans(1000, 1000 + 262_144, 1 / 16)
    assert len(spans) == 4 and sum(end - first for first, end in spans) == 262_144 // 16
    centres = [(first + end) / 2 - 1000 for first, end in spans]
    assert np.allclose(centres, [32_768, 98_304, 163_840, 229_376], atol=1)
    for n in (1, 3, 10, 100):  # small blocks: runs inside the block, none empty
        spans = sample_spans(5, 5 + n, 1 / 16)
        assert all(5 <= first < end <= 5 + n for first, end in spans)
        assert spans == sorted(spans) and all(x[1] <= y[0] for x, y in zip(spans, spans[1:]))


def test_ray_order_is_timed_on_a_sample_while_it_does_not_lead():
    """With ``ray_sample``, a pick of ray order while object order leads (or nothing
    does yet) traces about that share of the block in ray order, spread over it, for
    its time per ray; object order answers the whole block and is timed too. Once ray
    order leads it takes whole blocks. A block object order cannot take goes to ray
    order whole, and teaches nothing."""
    from ladartui.tracing.order_choice import sample_spans

    n = 4 * MIN_SCAN_RAYS
    now = [0.0]
    calls = []
    per_ray = {"ray": 4e-6}
    scan_seconds = {"object": 0.010}
    is_scan = [True]

    def object_block(a, b, limit):
        calls.append(("object", a, b))
        if is_scan[0]:
            now[0] += scan_seconds["object"]
        return is_scan[0]

    def ray_block(a, b):
        calls.append(("ray", a, b))
        now[0] += (b - a) * per_ray["ray"]

    def trace_once(choice):
        calls.clear()
        return trace_in_blocks(n, "auto", choice, object_block, ray_block, clock=lambda: now[0])

    choice = OrderChoice(ray_sample=1 / 16)
    assert trace_once(choice) == {"object"} and calls == [("object", 0, n)]
    # Ray order's turn: a sixteenth in four runs, then object order for the answers.
    assert trace_once(choice) == {"object"}
    assert calls == [("ray", a, b) for a, b in sample_spans(0, n, 1 / 16)] + [("object", 0, n)]
    assert choice.samples["ray"] == [pytest.approx(4e-6)] and len(choice.samples["object"]) == 2
    # Ray order costs 6.5x object order's per ray here: object order goes on, and
    # ray order's retry 16 calls after the lead was set is a sample again.
    picks = []
    for _ in range(16):
        trace_once(choice)
        picks.append("".join(kind[0] for kind, _, _ in calls))
    assert picks[:-1] == ["o"] * 15 and picks[-1] == "rrrro"
    # The scene changes: ray order turns cheap. Its next sample shows it, and from
    # then on it traces whole blocks.
    per_ray["ray"] = 1e-8
    picks = []
    while not picks or "r" not in picks[-1]:  # the lost retry doubled the wait: 32 calls
        trace_once(choice)
        picks.append("".join(kind[0] for kind, _, _ in calls))
    assert len(picks) == 32 and picks[-1] == "rrrro" and choice.pick() == "ray"
    assert trace_once(choice) == {"ray"} and calls == [("ray", 0, n)]
    # Not a scan: ray order traces the block whole on a sampled pick, and nothing is learned.
    fresh = OrderChoice(ray_sample=1 / 16)
    fresh.record("object", 0.010, n)
    is_scan[0] = False
    recorded = {order: list(times) for order, times in fresh.samples.items()}
    assert trace_once(fresh) == {"ray"}
    assert [kind for kind, _, _ in calls] == ["ray"] * 4 + ["object", "ray"] and calls[-1] == ("ray", 0, n)
    assert fresh.samples == recorded
