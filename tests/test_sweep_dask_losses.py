"""Sweeps on Dask that lose part of the cluster: the only worker killed."""

import os
import signal
import threading
import time

import pytest

from ladartui.sweep import local_client, run_sweep
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
