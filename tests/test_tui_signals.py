"""The terminal UI stopped by a signal from outside (``kill PID`` from another login,
``timeout``): the terminal is given back as it was, not left in the app's modes."""

from __future__ import annotations

import os
import pty
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parent.parent / "src"
LEAVE_ALTERNATE_SCREEN = b"\x1b[?1049l"


def read_until(fd, wanted: bytes, seen: bytearray, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while wanted not in seen and time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 0.2)
        if ready:
            try:
                chunk = os.read(fd, 65536)
            except OSError:  # the other end closed
                return wanted in seen
            if not chunk:
                break
            seen += chunk
    return wanted in seen


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP], ids=["SIGTERM", "SIGHUP"])
def test_a_stop_signal_gives_the_terminal_back(tmp_path, sig):
    """SIGTERM killed the app where it stood: the terminal stayed on the alternate
    screen with mouse reports on, the cursor hidden and nothing echoed, until 'reset'
    was typed blind. SIGHUP (an SSH connection dropping) killed it too, a run's swap of
    its outputs cut short; both now quit as Quit does."""
    primary, secondary = pty.openpty()
    env = dict(os.environ, PYTHONPATH=str(SRC), LADARTUI_HOME=str(tmp_path / "home"), TERM="xterm")
    env.pop("TMUX", None)
    process = subprocess.Popen(
        [sys.executable, "-m", "ladartui", "--graphics", "halfblocks"],
        stdin=secondary,
        stdout=secondary,
        stderr=secondary,
        env=env,
        cwd=tmp_path,
        start_new_session=True,
    )
    os.close(secondary)
    seen = bytearray()
    try:
        assert read_until(primary, b"F5 runs", seen, timeout=300), bytes(seen[-400:])
        process.send_signal(sig)
        assert process.wait(timeout=60) == 128 + sig
        read_until(primary, LEAVE_ALTERNATE_SCREEN, seen, timeout=5)
        assert LEAVE_ALTERNATE_SCREEN in seen, bytes(seen[-400:])
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        os.close(primary)
