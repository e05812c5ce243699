"""The signals that stop long work as Ctrl-C does, for the commands and the app alike.

SIGTERM: a batch system's or kill's stop; SIGHUP: the terminal went away (an SSH
connection dropped), which sends it to the jobs the shell started.
"""

from __future__ import annotations

import signal

STOP_SIGNALS = (signal.SIGTERM, signal.SIGHUP)


def stop_signals_to_catch() -> list[signal.Signals]:
    """``STOP_SIGNALS`` but those ignored now: a signal the process started with ignored
    (``nohup`` ignores SIGHUP) stays ignored."""
    return [number for number in STOP_SIGNALS if signal.getsignal(number) is not signal.SIG_IGN]
