"""The CLI's cancellable runner: a Ctrl-C is a cancel wherever the main thread is when it lands."""

from __future__ import annotations

import _thread
import re
import sys
import threading

import pytest

from cli_support import ctrl_c
from ladartui.cli.progress import run_cancellable
from ladartui.errors import Cancelled


def test_a_ctrl_c_that_lands_while_the_worker_starts_is_a_cancel():
    # A long switch interval keeps the GIL with the worker until it blocks, so the
    # interrupt is always pending when the main thread resumes inside Thread.start().
    previous = sys.getswitchinterval()
    sys.setswitchinterval(30.0)
    cancel = threading.Event()
    stopped_by_cancel = []

    def work():
        stopped_by_cancel.append(ctrl_c(cancel))  # as Ctrl-C would, on the main thread
        raise Cancelled("stopped")

    try:
        with pytest.raises(Cancelled, match="nothing written"):
            run_cancellable(work, cancel, "test-worker", Cancelled("nothing written"))
    finally:
        sys.setswitchinterval(previous)
    assert stopped_by_cancel == [True]


def test_work_that_stops_between_long_steps_says_it_is_stopping():
    """generate stops at the end of a stage, up to a minute later: a Ctrl-C was met
    with silence."""
    cancel, said = threading.Event(), []
    started = threading.Event()

    def work():
        started.set()
        cancel.wait(10)
        raise Cancelled("stopped")

    def interrupt():
        started.wait(10)
        ctrl_c(cancel)

    threading.Thread(target=interrupt).start()
    with pytest.raises(Cancelled, match="nothing written"):
        run_cancellable(work, cancel, "test-worker", Cancelled("nothing written"), lambda: said.append(1))
    assert said == [1]
    assert run_cancellable(lambda: 42, threading.Event(), "w", Cancelled("no"), lambda: said.append(2)) == 42
    assert said == [1]  # nothing to say without a Ctrl-C


def test_a_second_ctrl_c_waits_for_the_work_it_would_cut_short():
    """Two Ctrl-C's (or timeout's SIGINT to the whole group) let the command exit while
    the writer still renamed files: 'interrupted', and yet a new set in place."""
    cancel, seen = threading.Event(), []
    started = threading.Event()

    def work():  # a write that, once begun, finishes whatever the cancel says
        started.set()
        cancel.wait(10)
        _thread.interrupt_main()  # the second Ctrl-C, while it finishes
        seen.append(cancel.is_set())
        import time

        time.sleep(0.3)
        return "written"

    def interrupt():
        started.wait(10)
        ctrl_c(cancel)

    threading.Thread(target=interrupt).start()
    assert run_cancellable(work, cancel, "test-worker", Cancelled("nothing written")) == "written"
    assert seen == [True]


def test_a_third_ctrl_c_leaves_work_that_never_stops(capsys):
    """A step that never checks the cancel (a compile, a cluster closing) held the
    command however often Ctrl-C or SIGTERM came."""
    cancel, started = threading.Event(), threading.Event()
    never = threading.Event()

    def work():
        started.set()
        never.wait(30)

    def interrupt():
        import os
        import signal
        import time

        started.wait(10)
        for _ in range(3):
            os.kill(os.getpid(), signal.SIGINT)  # as the terminal sends it
            time.sleep(0.3)

    threading.Thread(target=interrupt).start()
    with pytest.raises(KeyboardInterrupt):
        run_cancellable(work, cancel, "test-worker", Cancelled("nothing written"))
    never.set()
    assert "still stopping" in capsys.readouterr().err and cancel.is_set()


def test_a_result_that_arrives_before_the_cancel_is_kept():
    cancel = threading.Event()
    assert run_cancellable(lambda: 42, cancel, "test-worker", Cancelled("no")) == 42
    assert not cancel.is_set()


def test_the_run_progress_keeps_its_figures_whole_in_80_columns():
    """A long run's progress line in an 80-column terminal: scan, share, rays and both
    times whole, the bar taking the room left."""
    import io

    from rich.console import Console

    from ladartui.cli.run import run_progress

    out = io.StringIO()
    console = Console(file=out, width=80, force_terminal=True, color_system=None)
    with run_progress(console, transient=False, auto_refresh=False) as bar:
        task = bar.add_task("scan 240/240", total=1.0, rays="12,582,912/25,165,824 rays")
        bar.update(task, completed=0.5)
        bar.refresh()
    shown = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", out.getvalue())  # cursor controls
    line = [line for line in shown.replace("\r", "\n").splitlines() if "scan" in line][-1]
    assert len(line) <= 80
    assert "\u2026" not in line
    for figure in ("scan 240/240", "50.0 %", "12,582,912/25,165,824 rays", "0:00:0", "-:--:--"):
        assert figure in line
    assert "\u2501" in line  # the bar is still there


def test_progress_written_to_a_file_is_never_cut_short(monkeypatch):
    """stderr sent to a log file: no terminal width to fit, so the last progress line is
    whole (it was cut at 80 columns, ending in an ellipsis)."""
    import io

    from rich.console import Console
    from rich.progress import MofNCompleteColumn, TextColumn, TimeElapsedColumn

    from ladartui.cli.progress import progress_display

    monkeypatch.delenv("COLUMNS", raising=False)
    out = io.StringIO()
    console = Console(file=out, color_system=None)
    assert not console.is_terminal
    note = "96 resumed, 12 failed, 3 impossible, 328.9/min"
    after = (MofNCompleteColumn(), TextColumn("{task.fields[note]}"), TimeElapsedColumn())
    with progress_display(console, after, transient=False) as bar:
        task = bar.add_task("sweep on local cluster", total=960, note="starting")
        bar.update(task, completed=960, note=note)
    line = out.getvalue().strip().splitlines()[-1]
    assert "\u2026" not in line
    assert line.startswith("sweep on local cluster") and f"960/960 {note} 0:00:0" in line


def test_the_sweep_progress_keeps_its_figures_whole_in_80_columns():
    """Counts, rate and the times were cut ('0:00:…') in an 80-column terminal."""
    import io
    from types import SimpleNamespace

    from rich.console import Console

    from ladartui.cli.sweep import progress_note, sweep_progress

    out = io.StringIO()
    console = Console(file=out, width=80, force_terminal=True, color_system=None)
    worst = SimpleNamespace(done=960, total=960, resumed=96, failed=12, impossible=3, elapsed=157.0)
    note = progress_note(worst)
    assert note == "96 resumed, 12 failed, 3 impossible, 330.2/min"
    assert progress_note(SimpleNamespace(done=4, resumed=0, failed=0, impossible=0, elapsed=2.0)) == (
        "120.0/min"
    )
    # before the first variant is done: the wait is the workers' start (and first compile)
    starting = SimpleNamespace(done=12, total=48, resumed=12, failed=0, impossible=0, elapsed=3.0)
    assert progress_note(starting) == "12 resumed, starting; a first run compiles kernels"
    with sweep_progress(console, auto_refresh=False) as bar:
        task = bar.add_task("sweep", total=960, note="starting")
        bar.update(task, completed=480, note=note)
        bar.refresh()
    shown = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", out.getvalue())
    line = [line for line in shown.replace("\r", "\n").splitlines() if "sweep" in line][-1]
    assert len(line) <= 80 and "\u2026" not in line
    assert re.search(f"480/960 {re.escape(note)} (-:--:--|\\d:\\d\\d:\\d\\d)$", line.rstrip())
    assert "\u2501" in line


@pytest.mark.parametrize("where", ["log", "dumb"])
def test_progress_into_a_log_or_a_dumb_terminal_says_how_far_now_and_then(monkeypatch, where):
    """'ladartui run S.toml > run.log 2>&1' (a batch job, nohup) or TERM=dumb (an editor's
    shell): rich redraws nothing there and wrote the progress once, at the end; an
    hour's run said nothing for an hour ('tail -f run.log' stayed empty). A line now
    comes every LOG_EVERY_SECONDS, and the last one at the end as before."""
    import io

    from rich.console import Console

    import ladartui.cli.progress as progress
    from ladartui.cli.run import run_progress

    monkeypatch.delenv("COLUMNS", raising=False)
    monkeypatch.setattr(progress, "LOG_EVERY_SECONDS", 0.0)
    out = io.StringIO()
    if where == "dumb":
        monkeypatch.setenv("TERM", "dumb")
        console = Console(file=out, force_terminal=True, color_system=None)
        assert console.is_dumb_terminal
    else:
        console = Console(file=out, color_system=None)
    assert not console.is_interactive
    with run_progress(console, transient=False) as bar:
        task = bar.add_task("scan 1", total=1.0, rays="")
        for scan in (1, 2, 3):
            bar.update(task, completed=scan / 4, description=f"scan {scan}/4", rays=f"{scan},000/4,000 rays")
            assert f"scan {scan}/4" in out.getvalue()  # said as it happens, not at the end
        bar.update(task, completed=1.0, description="scan 4/4", rays="4,000/4,000 rays")
    lines = [line for line in out.getvalue().splitlines() if line.strip()]
    assert [line.split()[1] for line in lines] == ["1/4", "2/4", "3/4", "4/4", "4/4"], lines
    assert "\x1b" not in out.getvalue()


def test_progress_on_a_terminal_is_not_logged_line_by_line(monkeypatch):
    import io

    from rich.console import Console

    import ladartui.cli.progress as progress
    from ladartui.cli.run import run_progress

    monkeypatch.setattr(progress, "LOG_EVERY_SECONDS", 0.0)
    monkeypatch.setenv("TERM", "xterm")
    out = io.StringIO()
    console = Console(file=out, width=80, force_terminal=True, color_system=None)
    with run_progress(console, transient=True, auto_refresh=False) as bar:
        task = bar.add_task("scan 1", total=1.0, rays="")
        bar.update(task, completed=0.5, description="scan 2/4")
        assert "scan 2/4" not in out.getvalue()  # redrawn in place (at refresh), never a line
