"""Long commands: the work runs on a worker thread while the main thread draws progress.

Python delivers Ctrl-C (and the signals turned into it) only to the main
thread, so the main thread waits in short joins and, when interrupted, sets
the work's cancel event and waits for the worker to stop between chunks.
"""

from __future__ import annotations

import contextlib
import functools
import os
import signal
import sys
import threading
from collections.abc import Callable
from typing import Any, TypeVar

from ladartui.errors import Cancelled, LadarError, ResourceLimitError
from ladartui.stop_signals import stop_signals_to_catch

T = TypeVar("T")

POLL_SECONDS = 0.1  # how soon a Ctrl-C is noticed while waiting
# Shown until the first scan is done when numba's cache lacks the kernels: a first run
# compiles them (minutes on two cores).
FIRST_SCAN = "scan 1 (compiling kernels on a first run)"


def first_scan(scenario) -> str:
    """What the bar says until a run of ``scenario`` finishes its first scan: compiling
    is named only when the cache lacks its kernels (``precompile.kernels_cached``)."""
    from ladartui.precompile import kernels_cached

    return "scan 1" if kernels_cached(scenario) else FIRST_SCAN


LOG_WIDTH = 200  # progress written to a file or pipe: wide enough for every line
# Where nothing is redrawn (a file or pipe, TERM=dumb), a progress line this often.
LOG_EVERY_SECONDS = 30.0


def _logging_progress(columns, console, **options):
    """rich's Progress that, where nothing is redrawn in place (a log, a pipe, a dumb
    terminal: rich writes the display once, as it ends), prints the progress as a line
    every ``LOG_EVERY_SECONDS``, so that a long run in a log says how far it is."""
    return _logging_progress_class()(*columns, console=console, **options)


@functools.cache
def _logging_progress_class():
    """The class, made on first use: rich stays off the commands' start-up path."""
    import time

    from rich.progress import Progress

    class LoggingProgress(Progress):
        def __init__(self, *args, **kwargs) -> None:
            super().__init__(*args, **kwargs)
            self.logged_at = time.monotonic()

        def update(self, task_id, **fields) -> None:
            super().update(task_id, **fields)
            if self.disable or self.console.is_interactive or not self.live.is_started:
                return
            now = time.monotonic()
            if now - self.logged_at >= LOG_EVERY_SECONDS:
                self.logged_at = now
                self.console.print(self.make_tasks_table(self.tasks))

    return LoggingProgress


def progress_display(console, after, description=None, **options):
    """rich's Progress across the console's width: the ``description`` column (the
    task's description by default), a bar taking the room the texts leave, then the
    columns ``after`` (a fixed 40-cell bar cut the texts and times short in an
    80-column terminal)."""
    from rich.progress import BarColumn, TextColumn

    description = description or TextColumn("{task.description}")
    if not console.is_terminal and "COLUMNS" not in os.environ:
        # A file or pipe (a log): no width to fit, so a short bar and nothing cut short.
        console.width = max(console.width, LOG_WIDTH)
        return _logging_progress((description, BarColumn(bar_width=20), *after), console, **options)
    return _logging_progress(
        (description, BarColumn(bar_width=None), *after), console, expand=True, **options
    )


def voxelize_display(console):
    """``progress_display`` for voxelising a file: its stage or path (not markup), the bar,
    the count done and the time taken; drawn on a terminal only (a log or a pipe gets the
    summary alone)."""
    from rich.progress import TextColumn, TimeElapsedColumn

    description = TextColumn("{task.description}", markup=False)  # paths are not markup
    after = (TextColumn("{task.fields[done]}", markup=False), TimeElapsedColumn())
    return progress_display(console, after, description, transient=True, disable=not console.is_terminal)


@contextlib.contextmanager
def bar_hidden_if_refused(bar, task, started: Callable[[], bool]):
    """A refusal before the work reported progress (a model file's bad line, memory),
    or work refused for its size once traced (Geiger-mode firing), hides the bar: no
    "scan 1  0.0 %" line is left above the one-line error, nor, where stderr is a log
    or a pipe, the blank line rich ends a display there with."""
    try:
        yield
    except LadarError as error:
        if not started() or isinstance(error, ResourceLimitError):  # refused, not stopped
            bar.update(task, visible=False)
            bar.live.transient = True  # cleared from a terminal, never written to a file
            bar.live.stop()  # (Progress.stop would end it with a blank line in a log)
            bar.disable = True  # and leaving the display adds nothing after it
        raise


def run_cancellable(
    work: Callable[[], T],
    cancel: threading.Event,
    name: str,
    cancelled: Cancelled,
    stopping: Callable[[], None] | None = None,
) -> T:
    """``work()`` on a worker thread named ``name``; its result, or its error raised here.

    On Ctrl-C the ``cancel`` event is set, ``stopping()`` called (work that stops
    only between long steps says so) and the worker awaited; if it had not
    finished by then, ``cancelled`` is raised (a result that arrived first is
    returned).
    """
    outcome: dict[str, Any] = {}  # "result" or "error"
    # Waited on instead of join(): a join interrupted by Ctrl-C can report the
    # thread finished while it still runs, and the process would exit mid-write.
    finished = threading.Event()

    def target():
        try:
            outcome["result"] = work()
        except BaseException as error:  # handed to the main thread
            outcome["error"] = error
        finally:
            finished.set()

    worker = threading.Thread(target=target, name=name, daemon=True)
    try:
        # Started inside the try: a Ctrl-C can land while start() waits for the
        # worker (a busy machine may run the worker far before this thread resumes).
        worker.start()
        while not finished.wait(POLL_SECONDS):
            pass
    except KeyboardInterrupt:
        cancel.set()
        if worker.ident is not None:  # else it never ran a line: with cancel set, it writes nothing
            _wait_out_interrupts(finished, stopping)
        if "result" not in outcome:  # else it finished before it saw the cancel
            raise cancelled from None
    if "error" in outcome:
        raise outcome["error"]
    return outcome["result"]


STILL_STOPPING = "ladartui: still stopping (a step under way finishes first); Ctrl-C again to leave at once\n"


def _wait_out_interrupts(finished: threading.Event, stopping: Callable[[], None] | None) -> None:
    """Wait for cancelled work to stop. A second Ctrl-C (or timeout's SIGINT to the whole
    group) is answered and waited out: leaving while the work writes would cut a set's
    renames short, and the message would not say what was written. A third leaves at
    once (a step that never checks for the cancel must not hold the terminal; a set
    cut short in its renames is rolled back by the next run from its journal)."""
    presses = 1
    while True:
        try:
            if stopping is not None and not finished.is_set():
                say, stopping = stopping, None
                say()
            while not finished.wait(POLL_SECONDS):  # short waits: a Ctrl-C is seen at once
                pass
            return
        except KeyboardInterrupt:
            presses += 1
            if presses > 2:
                raise
            sys.stderr.write(STILL_STOPPING)
            sys.stderr.flush()


# The signal that stopped the command (SIGINT unless SIGTERM or SIGHUP did): its exit status is
# 128 + its number, as a shell reports a process that signal killed.
_stopped_by = {"signal": int(signal.SIGINT)}


def reset_stop() -> None:
    _stopped_by["signal"] = int(signal.SIGINT)


def stop_status() -> int:
    """The exit status of a command stopped by a signal: 130 for Ctrl-C, 143 for SIGTERM,
    129 for SIGHUP."""
    return 128 + _stopped_by["signal"]


def _interrupt(signum, frame):
    _stopped_by["signal"] = int(signum)
    raise KeyboardInterrupt


@contextlib.contextmanager
def sigterm_as_interrupt():
    """Treat SIGTERM and SIGHUP like Ctrl-C while inside: the work stops where it may, a
    set being swapped in finishes, and the message says what was written. A signal the
    command started with ignored (``nohup`` ignores SIGHUP) stays ignored."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {number: signal.signal(number, _interrupt) for number in stop_signals_to_catch()}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
