"""A sweep's variants on a Dask cluster: the base scene scattered to every worker once,
the variants submitted a few tasks ahead of the workers, each row recorded as its
task ends (a lost task as a ``failed`` row, run again on resume).

The scene lost with the workers that held it (the only worker killed and restarted by
its nanny) is scattered again and the variants it took with it run again, each once:
one that kills its worker every time is then recorded ``failed``."""

from __future__ import annotations

import math
import time
import uuid

from ladartui.errors import LadarError, check_cancelled
from ladartui.sweep.variant import ScenePayload, run_variant

_POLL_SECONDS = 0.05
_AHEAD_SECONDS = 1.0  # how often the cluster's threads are counted again
_WORKER_WAIT_SECONDS = 60.0  # for a worker to come back once the scene is lost with them all
_PROBE_SECONDS = 1.0  # the longest a question to the scheduler is waited for


class ClusterLost(LadarError):
    """The sweep cannot go on on this cluster: its scheduler gone, or every worker."""


def _check_connected(client, address) -> None:
    """ClusterLost once ``client`` has lost its scheduler: it then cancels every task it
    holds (and a scheduler started again knows none of them nor the scene)."""
    if client.status != "running":
        raise ClusterLost(f"lost the connection to the Dask scheduler {address}")


def _lost_row(variant, digest, future) -> dict:
    if future.status == "error":
        try:
            error = future.exception(timeout=5)
            message = f"{type(error).__name__}: {error}"
        except Exception as reason:  # noqa: BLE001 - the future itself may be gone
            message = f"task {future.status}: {reason}"
    else:  # cancelled: its exception is None
        message = f"task {future.status} by the cluster (its worker lost, or its data)"
    return {"variant": variant.id, "status": "failed", "base": digest, **variant.params, "error": message}


def run_on_dask(client, todo, base, digest, scene, options, record, cancel):
    """Run ``todo`` on ``client``'s workers, a few tasks ahead of them: submitting
    every variant at once held 100,000 futures (800 MB here) and made a Ctrl-C wait
    while the scheduler cancelled them all."""
    from distributed import as_completed

    # Plain arrays once to every worker; each rebuilds the Scene once per token.
    address = client.scheduler.address
    payload = ScenePayload.of(scene, uuid.uuid4().hex)
    scene_future = client.scatter(payload, broadcast=True, hash=False)
    tag = uuid.uuid4().hex[:8]
    waiting = list(reversed(todo))  # popped from the end: the first variant first
    retried: set[str] = set()  # variants run again once after the scene was lost
    pending: dict = {}
    completed = as_completed(loop=client.loop)  # this client's, not the default one's
    ahead, asked = 0, -math.inf

    def submit_more():
        nonlocal ahead, asked
        if not waiting:  # all submitted: no more asking the scheduler
            return
        if time.monotonic() - asked >= _AHEAD_SECONDS:  # a round trip: not every batch
            ahead, asked = tasks_ahead(client), time.monotonic()
        while len(pending) < ahead and waiting:
            _check_connected(client, address)
            variant = waiting.pop()
            future = client.submit(
                run_variant,
                base,
                variant.params,
                variant.id,
                digest,
                scene_future,
                options,
                pure=False,
                key=f"ladartui-variant-{variant.id}-{tag}{'-again' if variant.id in retried else ''}",
            )
            pending[future] = variant
            completed.add(future)

    try:
        submit_more()
        while pending:
            check_cancelled(cancel, "sweep cancelled")
            batch = completed.next_batch(block=False)
            if not batch:
                time.sleep(_POLL_SECONDS)
                continue
            for future in batch:
                # A batch may hold many finished variants: honour a cancel set
                # while recording them (they run again on resume).
                check_cancelled(cancel, "sweep cancelled")
                variant = pending.pop(future)
                if future.status == "finished":
                    record(future.result())
                    continue
                _check_connected(client, address)  # not the variant's failure: stop here
                if scene_future.status != "finished" and variant.id not in retried:
                    retried.add(variant.id)  # lost with the scene, not by its own fault
                    waiting.append(variant)
                    continue
                record(_lost_row(variant, digest, future))
            if scene_future.status != "finished":
                scene_future.release()
                scene_future = _scatter_again(client, address, payload, cancel)
            submit_more()
    except Exception:
        if client.status != "running":  # a call that failed for it (ClosedClientError, ...)
            pending.clear()  # cancelled with the connection
            raise ClusterLost(f"lost the connection to the Dask scheduler {address}") from None
        raise
    finally:
        if pending:
            client.cancel(list(pending))
        scene_future.release()


def _scatter_again(client, address, payload, cancel):
    """The scene scattered anew, once a worker is there to take it (a nanny restarts a
    killed worker in seconds): asked for a second at a time, heeding ``cancel``.

    Each question to the scheduler is bounded: one that is closing answers none, and an
    unbounded call (the cluster's own ``wait_for_workers``) hung until the connection
    timed out, 30 s, before the sweep could say the scheduler was gone."""
    deadline = time.monotonic() + _WORKER_WAIT_SECONDS
    while True:
        _check_connected(client, address)
        check_cancelled(cancel, "sweep cancelled")
        asked = time.monotonic()
        try:
            if client.nthreads(callback_timeout=_PROBE_SECONDS):
                # (a worker still closing counts here; the scatter then waits for a
                # running one, so its wait is bounded too: TimeoutError, asked again)
                return client.scatter(payload, broadcast=True, hash=False, timeout=_PROBE_SECONDS)
        except (TimeoutError, OSError):  # no answer, or the connection closing under it
            pass
        if time.monotonic() >= deadline:
            raise ClusterLost(
                f"the Dask cluster lost every worker and none came back within {_WORKER_WAIT_SECONDS:g} s"
            )
        time.sleep(max(0.0, _PROBE_SECONDS - (time.monotonic() - asked)))


def tasks_ahead(client) -> int:
    """Tasks kept submitted: four per worker thread the cluster has now (workers that
    join later get theirs as tasks finish), at least 16."""
    workers = client.scheduler_info(n_workers=-1).get("workers", {})
    return max(16, 4 * sum(int(w.get("nthreads", 1)) for w in workers.values()))
