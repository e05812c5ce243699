"""Sweeps on Dask: a 2-worker LocalCluster, and a scheduler and worker started as processes."""

import json
import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from ladartui.errors import Cancelled
from ladartui.sweep import local_client, read_table, run_sweep
from tiny_sweep import write_tiny_scenario

VOLATILE = {"run_time_s", "worker"}
SWEEP = """
[grid]
radius = [10.0, 20.0]
scans = [2, 3]
fov = [20.0, -1.0]
"""


def write_tiny_spec(folder):
    """The shared tiny base scenario and a spec of 8 variants over it."""
    write_tiny_scenario(folder)
    spec = folder / "spec.toml"
    spec.write_text('[sweep]\nscenario = "base.toml"\n' + SWEEP, encoding="utf-8")
    return spec


def comparable(rows):
    return {r["variant"]: {k: v for k, v in r.items() if k not in VOLATILE} for r in rows}


@pytest.fixture(scope="module")
def spec(tmp_path_factory):
    return write_tiny_spec(tmp_path_factory.mktemp("dask"))


@pytest.fixture(scope="module")
def serial_rows(spec, tmp_path_factory):
    result = run_sweep(spec, serial=True, out=tmp_path_factory.mktemp("serial"))
    assert sum(r["status"] == "ok" for r in result.rows) == 4
    return result.rows


@pytest.fixture(scope="module")
def client():
    client = local_client(2)
    yield client
    cluster = client.cluster
    client.close()
    cluster.close()


def _sigint_handler():
    import signal

    return signal.getsignal(signal.SIGINT)


def test_local_workers_ignore_ctrl_c_which_this_process_handles(client):
    import signal

    # A Ctrl-C reaches the terminal's whole process group: a worker that took it
    # printed a traceback as it died.
    assert set(client.run(_sigint_handler).values()) == {signal.SIG_IGN}


def _worker_errors_logged():
    """In a worker: which of a failed heartbeat and another error its log lets through."""
    import logging

    from ladartui.sweep.cluster import HEARTBEAT_FAILED

    log, seen = logging.getLogger("distributed.worker"), []

    class Keep(logging.Handler):
        def emit(self, record):
            seen.append(record.getMessage())

    keep = Keep()
    log.addHandler(keep)
    try:
        log.error(HEARTBEAT_FAILED + ".")
        log.error("another worker error")
    finally:
        log.removeHandler(keep)
    return tuple(seen)


def test_local_workers_never_log_a_failed_heartbeat(client):
    """A sweep killed (kill -9, the kernel's out-of-memory killer) took the scheduler
    with it: its running workers printed 'Failed to communicate with scheduler during
    heartbeat' with two tracebacks each under the command's last line, in two kills of
    three. A local worker's scheduler is the sweep's own process."""
    assert set(client.run(_worker_errors_logged).values()) == {("another worker error",)}


def test_a_local_schedulers_lost_scattered_data_is_not_logged(client, caplog):
    """SIGTERM to the process group reaches the workers too: every stop printed the
    scheduler's 'caused the cluster to lose scattered data' ERROR line."""
    import logging

    log = logging.getLogger("distributed.scheduler")
    with caplog.at_level(logging.ERROR, logger="distributed.scheduler"):
        log.error(
            "Removing worker 'tcp://127.0.0.1:1' caused the cluster to lose scattered data, "
            "which can't be recovered: {'ScenePayload-1'} (stimulus_id='x')"
        )
        log.error("another scheduler error")
    assert [r.getMessage() for r in caplog.records] == ["another scheduler error"]


def test_two_workers_give_the_same_rows_as_serial_runs(spec, serial_rows, client, tmp_path):
    result = run_sweep(spec, client=client, out=tmp_path)
    assert result.workers == 2
    assert comparable(result.rows) == comparable(serial_rows)
    bad = [r for r in result.rows if r["status"] != "ok"]
    assert len(bad) == 4 and all("fov = -1.0" in r["error"] for r in bad)
    # Both workers took part, and each rebuilt the scene from the broadcast once.
    assert len({r["worker"] for r in result.rows}) == 2

    def scenes_built():
        from ladartui.sweep.variant import _WORKER_SCENES

        return len(_WORKER_SCENES)

    assert set(client.run(scenes_built).values()) == {1}


def test_only_a_few_variants_wait_submitted_ahead_of_the_workers(
    spec, serial_rows, client, tmp_path, monkeypatch
):
    """Every variant was submitted at once: 100,000 futures held 800 MB and a Ctrl-C
    waited while the scheduler cancelled them all."""
    import ladartui.sweep.dask_runs as dask_runs

    monkeypatch.setattr(dask_runs, "tasks_ahead", lambda client: 3)
    held = []

    def count_futures(progress):
        variants = [key for key in client.futures if str(key).startswith("ladartui-variant-")]
        held.append(len(variants))

    result = run_sweep(spec, client=client, out=tmp_path, progress=count_futures)
    assert len(held) == 9 and max(held) <= 3  # the first report, then one per variant
    assert comparable(result.rows) == comparable(serial_rows)


def test_cluster_sweep_resumes_after_an_interruption(spec, serial_rows, client, tmp_path):
    cancel = threading.Event()

    def stop_after_two(progress):
        if progress.done >= 2:
            cancel.set()

    with pytest.raises(Cancelled):
        run_sweep(spec, client=client, out=tmp_path, progress=stop_after_two, cancel=cancel)
    before, _ = read_table(tmp_path / "results.csv")
    assert 2 <= len(before) < 8
    result = run_sweep(spec, client=client, out=tmp_path)
    assert (result.resumed, result.ran) == (len(before), 8 - len(before))
    by_id = {r["variant"]: r for r in result.rows}
    for row in before:  # kept as they were (same worker, same run time), not run again
        # (Columns added by later rows read back as None in earlier ones.)
        assert {k: v for k, v in by_id[row["variant"]].items() if v is not None} == {
            k: v for k, v in row.items() if v is not None
        }
    assert comparable(result.rows) == comparable(serial_rows)


def test_ranking_by_time_to_identify_is_the_same_on_dask_and_serially(client, tmp_path):
    from ladartui.levels import LevelThresholds
    from ladartui.scenario import load_scenario
    from ladartui.sweep.ranking import levels_text

    base = write_tiny_scenario(tmp_path)
    # Identify at 55 % of the visible voxels: the 30 m orbits (half the target seen) never do.
    load_scenario(base.path).with_changes(levels=LevelThresholds(0.1, 0.3, 0.55, 0.1, 0.5, 0.75)).save()
    spec = tmp_path / "identify.toml"
    spec.write_text(
        '[sweep]\nscenario = "base.toml"\nobjective = "time-to-identify"\n'
        "[grid]\nradius = [10.0, 20.0, 30.0]\nheading_offset = [0.0, 90.0]\n",
        encoding="utf-8",
    )
    serial = run_sweep(spec, serial=True, out=tmp_path / "serial")
    on_dask = run_sweep(spec, client=client, out=tmp_path / "dask")

    assert ranking(on_dask) == ranking(serial)
    ranked = [r for r in serial.ranking if r.rank is not None]
    values = [r.value for r in ranked]
    assert values == sorted(values) and len(set(values)) >= 3  # a real order, not all ties
    unranked = [r for r in serial.ranking if r.rank is None]
    assert unranked and all(r.row["radius"] == 30.0 for r in unranked)
    assert all(r.row["levels.identify.reached"] is False for r in unranked)
    best = on_dask.best.row
    assert levels_text(best) == levels_text(serial.best.row)
    assert levels_text(best).startswith("reaches identify at scan ")


def test_two_target_ranking_by_time_to_identify_all_is_the_same_on_dask_and_serially(client, tmp_path):
    from tiny_sweep import write_two_target_spec

    spec = write_two_target_spec(tmp_path, "time-to-identify")
    serial = run_sweep(spec, serial=True, out=tmp_path / "serial")
    on_dask = run_sweep(spec, client=client, out=tmp_path / "dask")

    assert ranking(on_dask) == ranking(serial)
    assert comparable(on_dask.rows) == comparable(serial.rows)
    assert all(r["targets.ids"] == [1, 2] for r in on_dask.rows)  # the workers saw both targets
    ranked = [r for r in on_dask.ranking if r.rank is not None]
    # Looking down (altitude 40) never sees the roofed target: only the low paths rank.
    assert {r.row["altitude"] for r in ranked} == {2.0}


def ranking(result):
    return [(r.row["variant"], r.rank, r.value) for r in result.ranking]


def _start(args, log, env):
    handle = open(log, "wb")
    return subprocess.Popen(
        args, stdout=handle, stderr=subprocess.STDOUT, env=env, start_new_session=True
    ), handle


def _wait_for(pattern, log, process, seconds=60.0):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        match = re.search(pattern, Path(log).read_text(errors="replace"))
        if match:
            return match
        if process.poll() is not None:
            break
        time.sleep(0.1)
    raise AssertionError(f"no {pattern!r} in {log}:\n{Path(log).read_text(errors='replace')}")


def start_scheduler_and_worker(tmp_path, env, started) -> str:
    """A Dask scheduler on loopback and one single-thread worker, as processes (each with
    its log appended to ``started``, to stop): the scheduler's address."""
    bin_dir = Path(sys.executable).parent
    scheduler, log = _start(
        [str(bin_dir / "dask"), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard"],
        tmp_path / "scheduler.log",
        env,
    )
    started.append((scheduler, log))
    address = _wait_for(
        r"Scheduler at:\s+(tcp://127\.0\.0\.1:\d+)", tmp_path / "scheduler.log", scheduler
    ).group(1)
    worker, log = _start(
        [str(bin_dir / "dask"), "worker", address, "--nthreads", "1", "--no-dashboard"],
        tmp_path / "worker.log",
        env,
    )
    started.append((worker, log))
    return address


def _stop(process):
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


@pytest.mark.slow
def test_cli_runs_on_a_scheduler_and_worker_started_as_processes(spec, serial_rows, tmp_path):
    bin_dir = Path(sys.executable).parent
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    started = []
    try:
        address = start_scheduler_and_worker(tmp_path, env, started)
        out = tmp_path / "out"
        run = subprocess.run(
            [
                str(bin_dir / "ladartui"),
                "sweep",
                str(spec),
                "--scheduler",
                address,
                "--out",
                str(out),
                "--json",
            ],
            capture_output=True,
            text=True,
            env=env,
            timeout=240,
        )
        assert run.returncode == 0, run.stderr
        report = json.loads(run.stdout)
        assert (report["variants"], report["ran"], report["failed"], report["impossible"]) == (8, 8, 0, 4)
        rows, _ = read_table(out / "results.csv")
        assert comparable(rows) == comparable(serial_rows)
        assert (
            report["top"][0]["variant"]
            == max(
                (r for r in serial_rows if r["status"] == "ok"),
                key=lambda r: (r["obscured_coverage"], -r["flight_time_s"]),
            )["variant"]
        )
    finally:
        for process, handle in reversed(started):
            _stop(process)
            handle.close()
    assert all(process.poll() is not None for process, _ in started)


def test_an_unreachable_scheduler_is_named_in_one_line():
    from ladartui.errors import LadarError
    from ladartui.sweep import connect

    started = time.monotonic()
    with pytest.raises(LadarError) as caught:
        connect("tcp://127.0.0.1:9", timeout=1.0)
    message = str(caught.value)
    assert "--scheduler" in message and "tcp://127.0.0.1:9" in message and "\n" not in message
    assert time.monotonic() - started < 15


def test_a_script_without_a_main_guard_is_told_what_to_change(tmp_path):
    """A local cluster's workers import the main script: one that calls run_sweep at its
    top level started the sweep again in each worker, which the folder lock refused
    ('another sweep is writing its results here'), pointing the user the wrong way."""
    write_tiny_scenario(tmp_path)
    (tmp_path / "spec.toml").write_text('[sweep]\nscenario = "base.toml"\n[grid]\nradius = [10.0]\n')
    script = tmp_path / "script.py"
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parent.parent / "src")}

    def run_script(*lines: str):
        script.write_text("\n".join(lines) + "\n", encoding="utf-8")
        command = [sys.executable, str(script)]
        return subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)

    done = run_script(
        "from ladartui.sweep import run_sweep", "print('ran', run_sweep('spec.toml', workers=1).ran)"
    )
    assert done.returncode != 0 and "ran" not in done.stdout
    assert f"run_sweep was called while a worker process imported the script {str(script)!r}" in done.stderr
    assert 'if __name__ == "__main__":' in done.stderr.splitlines()[-1]
    assert "another sweep" not in done.stderr
    # as the docs show it, under the guard, the same sweep runs
    done = run_script(
        "from ladartui.sweep import run_sweep",
        "if __name__ == '__main__':",
        "    print('ran', run_sweep('spec.toml', workers=1).ran)",
    )
    assert done.returncode == 0 and done.stdout.split() == ["ran", "1"], done.stderr
    # a function of a guarded script, run in a spawned process of a pool, is not that import
    done = run_script(
        "import multiprocessing",
        "from concurrent.futures import ProcessPoolExecutor",
        "from ladartui.sweep import run_sweep",
        "def job():",
        "    return run_sweep('spec.toml', serial=True, out='pooled').ran",
        "if __name__ == '__main__':",
        "    spawn = multiprocessing.get_context('spawn')",
        "    with ProcessPoolExecutor(1, mp_context=spawn) as pool:",
        "        print('ran', pool.submit(job).result())",
    )
    assert done.returncode == 0 and done.stdout.split() == ["ran", "1"], done.stderr


def test_workers_started_for_a_local_cluster_never_see_a_ctrl_c_at_start_up(tmp_path):
    """The key reaches the terminal's whole process group: workers still starting
    printed KeyboardInterrupt tracebacks and died. A script (its own process group)
    starts a real 2-worker local cluster on a thread, as the CLI does, while its main
    thread sends SIGINT to the whole group every 20 ms."""
    script = tmp_path / "start.py"
    script.write_text(
        "\n".join(
            (
                "import os, signal, threading, time",
                "from ladartui.sweep import local_client",
                "if __name__ == '__main__':",
                "    signal.signal(signal.SIGINT, lambda *a: None)  # this process takes the key",
                "    started = {}",
                "    starting = threading.Thread(target=lambda: started.update(client=local_client(2)))",
                "    starting.start()",
                "    sent = 0",
                "    while starting.is_alive():",
                "        os.killpg(0, signal.SIGINT)",
                "        sent += 1",
                "        time.sleep(0.02)",
                "    client = started['client']",
                "    print('workers', len(client.scheduler_info()['workers']), 'sent', sent)",
                "    cluster = client.cluster",
                "    client.close()",
                "    cluster.close()",
            )
        ),
        encoding="utf-8",
    )
    done = subprocess.run(
        [sys.executable, str(script)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        start_new_session=True,
    )
    assert done.returncode == 0, done.stderr
    words = done.stdout.split()
    assert words[:2] == ["workers", "2"] and int(words[3]) > 10, done.stdout
    assert "KeyboardInterrupt" not in done.stderr and "Traceback" not in done.stderr, done.stderr


def test_ctrl_c_early_in_a_local_sweep_says_it_is_stopping(tmp_path):
    """As a terminal sends it, to the whole process group, half a second after the
    sweep starts (its cluster then starts for a few seconds on two cores; the start
    itself is covered above): the command says it is stopping, the workers print
    nothing, and the interruption is reported."""
    import signal

    spec = write_tiny_spec(tmp_path)
    ladartui = Path(sys.executable).parent / "ladartui"
    log = tmp_path / "sweep.log"
    command = [str(ladartui), "sweep", str(spec), "--workers", "2", "--out", str(tmp_path / "out")]
    process, handle = _start(command, log, dict(os.environ))
    try:
        _wait_for("sweep of 8 variants on local cluster", log, process)
        time.sleep(0.5)  # the cluster is starting (a few seconds)
        os.killpg(process.pid, signal.SIGINT)
        assert process.wait(timeout=120) == 130
    finally:
        _stop(process)
        handle.close()
    said = log.read_text(errors="replace")
    assert "stopping; finished variants are kept" in said
    assert "sweep interrupted before any variant finished; run the same command again to start it" in said
    assert "Traceback" not in said and "KeyboardInterrupt" not in said, said


def test_a_second_local_cluster_starts_quietly_and_serves_http_on_loopback_alone(client):
    """Each local cluster's scheduler served HTTP on port 8787 of every interface: a
    second sweep at once (another terminal, the sweep screen) printed distributed's
    'Port 8787 is already in use' warning."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        second = local_client(1)
    try:
        assert not [w for w in caught if "already in use" in str(w.message)]
        for cluster in (client.cluster, second.cluster):
            http = cluster.scheduler.services["dashboard"]
            assert http.address == "127.0.0.1" and http.port != 8787
    finally:
        cluster = second.cluster
        second.close()
        cluster.close()
