"""Kill tests: a ``run`` killed at points of its write leaves the old set or the new one.

Each trial runs ``ladartui run`` in a subprocess whose write pauses at one step
(a hook in ``ladartui.outputset``), sends a signal there, and compares the
files by checksum with the old set and with the set an uninterrupted run
writes. The next run over the set then leaves no hidden temporaries.
"""

import errno
import hashlib
import shutil
import signal
import subprocess
import sys
import textwrap

import pytest

from ladartui.cli import main
from ladartui.simulation import _output_set
from test_output_set import hidden, make_scenario, outputs_of, write_old_set

PAUSING_RUN = textwrap.dedent("""
    import sys, time
    import ladartui.outputset as outputset
    step, occurrence = sys.argv[1], int(sys.argv[2])
    seen = []
    def pause(name):
        if name == step:
            seen.append(name)
            if len(seen) == occurrence:
                print("paused", flush=True)
                time.sleep(0.5)
    outputset._step_hook = pause
    from ladartui.cli import main
    sys.exit(main(["run", sys.argv[3]]))
""")


def digest(scenario):
    return [hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else None for p in outputs_of(scenario)]


@pytest.fixture(scope="module")
def new_set(tmp_path_factory):
    scenario = make_scenario(tmp_path_factory.mktemp("reference"))
    assert main(["run", str(scenario.path)]) == 0
    return digest(scenario)


# (step, occurrence): temporaries written; between the renames (first file new,
# second in its backup); after the commit point, backups not yet removed.
POINTS = [("temporaries", 1), ("swap", 2), ("backups", 1)]


@pytest.mark.parametrize(
    "sig",
    [signal.SIGKILL, signal.SIGINT, signal.SIGTERM, signal.SIGHUP],
    ids=["SIGKILL", "SIGINT", "SIGTERM", "SIGHUP"],  # SIGHUP: the SSH connection dropped
)
@pytest.mark.parametrize("step, occurrence", POINTS, ids=[p[0] for p in POINTS])
def test_killed_run_leaves_one_set(tmp_path, new_set, sig, step, occurrence):
    scenario = make_scenario(tmp_path / "s")
    write_old_set(scenario)
    old_set = digest(scenario)
    process = subprocess.Popen(
        [sys.executable, "-c", PAUSING_RUN, step, str(occurrence), str(scenario.path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert process.stdout.readline().strip() == "paused"
    process.send_signal(sig)
    out, err = process.communicate(timeout=60)
    with _output_set(scenario, las=False):  # what the next run does first
        after = digest(scenario)
    assert after in (old_set, new_set)
    if sig == signal.SIGKILL:
        # Before the commit point the old set comes back; after it the new one stays.
        assert after == (new_set if step == "backups" else old_set)
    else:
        # A stop before the swap writes nothing; once the swap began it finishes.
        assert after == (old_set if step == "temporaries" else new_set)
        if after == old_set:
            # 128 + the signal, as a shell reports it: 130 for Ctrl-C, 143 for SIGTERM,
            # 129 for a hangup
            assert process.returncode == 128 + sig and "nothing was written" in err
        else:
            assert process.returncode == 0 and "wrote measures" in out + err
    assert hidden(scenario.path.parent) == []
    shutil.rmtree(tmp_path / "s")


def test_a_run_under_nohup_finishes_through_a_hangup(tmp_path, new_set):
    """nohup (SIGHUP ignored) keeps a run going when the SSH connection drops: the
    handler that stops a run on a hangup is not put in place of the ignore."""
    scenario = make_scenario(tmp_path / "s")
    write_old_set(scenario)
    process = subprocess.Popen(
        [sys.executable, "-c", PAUSING_RUN, "temporaries", "1", str(scenario.path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN),
    )
    assert process.stdout.readline().strip() == "paused"
    process.send_signal(signal.SIGHUP)
    out, err = process.communicate(timeout=60)
    assert process.returncode == 0 and "wrote measures" in out + err
    assert digest(scenario) == new_set


class _GoneTerminal:
    """A terminal the SSH connection took with it: every write fails with EIO."""

    def write(self, text):
        raise OSError(errno.EIO, "Input/output error")

    def flush(self):
        raise OSError(errno.EIO, "Input/output error")

    def isatty(self):
        return True

    def fileno(self):
        import io

        raise io.UnsupportedOperation("fileno")  # (no descriptor here to point at /dev/null)


@pytest.mark.parametrize("bar_drawn_on_the_way_out", [True, False])
def test_a_hangup_whose_terminal_is_gone_ends_with_129_not_a_traceback(monkeypatch, bar_drawn_on_the_way_out):
    """An SSH connection dropping stops a run (SIGHUP) and takes its terminal: the
    progress bar's last draw, then the message, failed with EIO; the command ended in
    an OSError traceback with status 1, as if it had failed, not been stopped."""
    import ladartui.cli.progress as progress
    import ladartui.cli.run as run_command
    from ladartui.errors import Cancelled

    def stopped_run(args):
        progress._stopped_by["signal"] = int(signal.SIGHUP)
        try:
            raise Cancelled("run cancelled; nothing was written, earlier outputs are unchanged")
        finally:
            if bar_drawn_on_the_way_out:
                sys.stderr.write("scan 3/24\n")

    monkeypatch.setattr(run_command, "run", stopped_run)
    monkeypatch.setattr(sys, "stderr", _GoneTerminal())
    monkeypatch.setattr(sys, "stdout", _GoneTerminal())
    assert main(["run", "default"]) == 128 + signal.SIGHUP
