"""Helpers shared by the CLI tests."""

import _thread
import contextlib
import resource
import signal
import threading
import time


def ctrl_c(until: threading.Event, timeout: float = 10.0, signum: int = signal.SIGINT) -> bool:
    """Ctrl-C as the key gives it (KeyboardInterrupt on the main thread), again each
    second until ``until`` is set; whether it was. Python drops an interrupt that lands
    while the main thread runs a finalizer (a GPU object's, freed by the garbage
    collector), and a user would press the key again. (A second, the main thread
    polls ten times as often: one that arrived has been seen by then.) ``signum``: the
    signal it stands for (SIGTERM as ``kill`` sends it)."""
    deadline = time.monotonic() + timeout
    while True:
        _thread.interrupt_main(signum)
        if until.wait(1.0):
            return True
        if time.monotonic() > deadline:
            return False


def one_error_line(capsys) -> str:
    """The one line a CLI run wrote to stderr: ``ladartui: error: ...``, no traceback."""
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("ladartui: error:") and "Traceback" not in err, err
    return err


@contextlib.contextmanager
def file_size_limit(most: int):
    """Files of this process held to ``most`` bytes, as ``ulimit -f`` holds them: a write
    past it fails with "File too large" (Python ignores SIGXFSZ), a real failed write."""
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (most, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
