"""Sweeps on Dask that lose part of the cluster: the only worker killed, the scheduler gone."""

import logging
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from ladartui.errors import LadarError
from ladartui.sweep import local_client, read_table, run_sweep
from ladartui.sweep.cluster import close_client
from tiny_sweep import write_spec, write_tiny_scenario

pytestmark = pytest.mark.slow


@pytest.fixture()
def spec(tmp_path):
    write_tiny_scenario(tmp_path)
    return write_spec(tmp_path, "[grid]\nradius = [10.0, 20.0]\nscans = [2, 3]\n")


def _when_variants_wait(client, then):
    """Call ``then`` once the sweep's variants are submitted (they wait behind a task
    that holds the worker's one thread), from a thread of its own."""

    def watch():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            if any(str(key).startswith("ladartui-variant-") for key in list(client.futures)):
                then()
                return
            time.sleep(0.02)

    watcher = threading.Thread(target=watch, daemon=True)
    watcher.start()
    return watcher


def test_the_only_worker_killed_mid_sweep_costs_no_variant(spec, tmp_path):
    """The scene scattered to the one worker died with it: every variant still to run
    was recorded 'failed' with the error 'NoneType: None'."""
    client = local_client(1)
    try:
        (pid,) = client.run(os.getpid).values()
        holder = client.submit(time.sleep, 5, pure=False)  # the variants queue behind it

        def kill():
            os.kill(pid, signal.SIGKILL)
            holder.cancel()

        watcher = _when_variants_wait(client, kill)
        result = run_sweep(spec, client=client, out=tmp_path / "out")
        watcher.join()
        client.wait_for_workers(1, timeout=60)
        (restarted,) = client.run(os.getpid).values()
    finally:
        close_client(client)
    assert restarted != pid  # the worker was killed, and its nanny started another
    assert [(r["status"], r["error"]) for r in result.rows] == [("ok", None)] * 4
    assert result.failures == []


def test_the_scheduler_gone_mid_sweep_is_told_in_one_line(spec, tmp_path, caplog):
    """The scheduler gone printed a traceback (ClosedClientError) after 30 s, and
    recorded every variant in flight as failed with 'NoneType: None'; closing the
    client then logged its cancelled reconnection with three more tracebacks."""
    client = local_client(1)
    cluster = client.cluster
    closing = threading.Thread(target=cluster.close)
    try:
        client.submit(time.sleep, 5, pure=False)
        _when_variants_wait(client, closing.start)
        started = time.monotonic()
        with pytest.raises(LadarError) as caught:
            run_sweep(spec, client=client, out=tmp_path / "out")
        took = time.monotonic() - started
    finally:
        if closing.is_alive():
            closing.join()
        with caplog.at_level(logging.ERROR, logger="distributed.client"):
            close_client(client)
    message = str(caught.value)
    assert "\n" not in message and "NoneType" not in message
    assert message.startswith(f"lost the connection to the Dask scheduler {cluster.scheduler_address}")
    assert message.endswith("no variant had finished; run the sweep again to start it")
    assert took < 20  # not the client's 30 s of trying to reconnect first
    rows, _ = read_table(tmp_path / "out" / "results.csv")
    assert all(r["status"] != "failed" for r in rows)
    assert [r.getMessage() for r in caplog.records if r.name == "distributed.client"] == []


def test_the_cli_tells_a_killed_scheduler_in_one_line_and_no_traceback(spec, tmp_path):
    """Closing the client that lost its scheduler cancelled its attempts to reconnect,
    which distributed logged with three tracebacks under the sweep's message."""
    from distributed import Client

    from test_sweep_dask import _stop, start_scheduler_and_worker

    def variants_held(dask_scheduler):  # nested: sent by value to a scheduler that lacks this file
        return [key for key in dask_scheduler.tasks if str(key).startswith("ladartui-variant-")]

    bin_dir = Path(sys.executable).parent
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    started = []
    try:
        address = start_scheduler_and_worker(tmp_path, env, started)
        holder = Client(address, timeout="30s")
        holder.wait_for_workers(1, timeout=60)
        holder.submit(time.sleep, 60, pure=False)  # the sweep's variants wait behind it
        sweep = subprocess.Popen(
            [
                str(bin_dir / "ladartui"),
                "sweep",
                str(spec),
                "--scheduler",
                address,
                "--out",
                str(tmp_path / "out"),
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        deadline = time.monotonic() + 120
        while not holder.run_on_scheduler(variants_held) and time.monotonic() < deadline:
            time.sleep(0.1)
        holder.close()
        started[0][0].kill()  # the scheduler
        _, stderr = sweep.communicate(timeout=60)
    finally:
        for process, handle in reversed(started):
            _stop(process)
            handle.close()
    assert sweep.returncode == 2
    assert "Traceback" not in stderr and "ERROR" not in stderr
    assert stderr.splitlines()[-1] == (
        f"ladartui: error: lost the connection to the Dask scheduler {address}; no variant had "
        "finished; run the sweep again to start it"
    )


def _left_without_workers(client, then=lambda: None):
    """Every worker leaves once the sweep's variants wait (the scene goes with them)."""

    def leave():
        client.cluster.scale(0)
        then()

    client.submit(time.sleep, 5, pure=False)
    _when_variants_wait(client, leave)


def test_a_cluster_left_without_workers_stops_the_sweep_in_one_line(spec, tmp_path, monkeypatch):
    import ladartui.sweep.dask_runs as dask_runs

    monkeypatch.setattr(dask_runs, "_WORKER_WAIT_SECONDS", 3.0)
    client = local_client(1)
    try:
        _left_without_workers(client)
        started = time.monotonic()
        with pytest.raises(LadarError) as caught:
            run_sweep(spec, client=client, out=tmp_path)
        took = time.monotonic() - started
    finally:
        close_client(client)
    assert took < 30
    assert str(caught.value) == (
        "the Dask cluster lost every worker and none came back within 3 s; no variant had "
        "finished; run the sweep again to start it"
    )


def test_waiting_for_a_worker_to_come_back_heeds_a_cancel(spec, tmp_path, monkeypatch):
    """Once the scene was lost with every worker, the sweep waited for one to come back
    without looking at a Ctrl-C."""
    import ladartui.sweep.dask_runs as dask_runs
    from ladartui.errors import Cancelled

    monkeypatch.setattr(dask_runs, "_WORKER_WAIT_SECONDS", 600.0)
    client = local_client(1)
    cancel = threading.Event()
    try:
        _left_without_workers(client, threading.Timer(3.0, cancel.set).start)
        started = time.monotonic()
        with pytest.raises(Cancelled):
            run_sweep(spec, client=client, out=tmp_path, cancel=cancel)
        took = time.monotonic() - started
    finally:
        close_client(client)
    assert took < 30  # not the 600 s allowed for a worker to come back


class _ClosingScheduler:
    """A client whose scheduler is closing: a call to it hangs (as an RPC to a closing
    scheduler does, until the 30 s connect timeout) unless the call bounds its wait, and
    the client sees the connection gone only after a few calls."""

    def __init__(self):
        self.calls = 0
        self.address = "tcp://127.0.0.1:1"

    @property
    def status(self):
        return "running" if self.calls < 3 else "closing"

    def _hang(self, callback_timeout=None):
        self.calls += 1
        if callback_timeout is None or callback_timeout > 1:
            raise AssertionError("a call to a closing scheduler with no bound on its wait")
        raise TimeoutError(f"timed out after {callback_timeout} s.")

    def wait_for_workers(self, n_workers, timeout=None):
        self._hang()  # the cluster's wait asks the scheduler with no bound of its own

    def nthreads(self, workers=None, callback_timeout=None):
        return self._hang(callback_timeout)

    def scatter(self, *args, **kwargs):
        raise AssertionError("scattered to a closing scheduler")


def test_waiting_for_a_worker_never_hangs_on_a_closing_scheduler(monkeypatch):
    """The scheduler gone as the scene was lost with it took 30 s and more to be told
    (1 in 10 runs of the test above): waiting for a worker to scatter the scene to asked
    the closing scheduler with no bound, until the connection timed out."""
    from ladartui.sweep import dask_runs
    from ladartui.sweep.dask_runs import ClusterLost, _scatter_again

    monkeypatch.setattr(dask_runs, "_PROBE_SECONDS", 0.01)
    client = _ClosingScheduler()
    with pytest.raises(ClusterLost, match="lost the connection to the Dask scheduler tcp://127.0.0.1:1"):
        _scatter_again(client, client.address, payload=None, cancel=None)
    assert client.calls == 3


class _ClosingWorkerOnly(_ClosingScheduler):
    """A closing scheduler whose one worker is closing too: the worker is still counted
    among the cluster's threads, but a scatter finds no running worker to take the scene
    and waits for one as long as it is let (30 s unless told)."""

    def nthreads(self, workers=None, callback_timeout=None):
        self.calls += 1
        if callback_timeout is None or callback_timeout > 1:
            raise AssertionError("a call to a closing scheduler with no bound on its wait")
        return {"tcp://127.0.0.1:2": 1}  # the closing worker

    def scatter(self, data, workers=None, broadcast=False, hash=True, timeout=None):
        return self._hang(timeout)


def test_waiting_for_a_worker_never_hangs_on_a_scatter_with_only_a_closing_worker(monkeypatch):
    """A closing worker is counted among the threads, so the scene was scattered to the
    cluster, which waited with no bound of the sweep's for a running worker, the sweep's
    cancel unheeded meanwhile."""
    from ladartui.sweep import dask_runs
    from ladartui.sweep.dask_runs import ClusterLost, _scatter_again

    monkeypatch.setattr(dask_runs, "_PROBE_SECONDS", 0.01)
    client = _ClosingWorkerOnly()
    with pytest.raises(ClusterLost, match="lost the connection to the Dask scheduler tcp://127.0.0.1:1"):
        _scatter_again(client, client.address, payload=None, cancel=None)
    assert client.calls == 4  # asked twice each: the threads, then the scatter
