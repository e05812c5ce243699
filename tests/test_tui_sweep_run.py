"""Running a sweep from the sweep screen: a missing spec, a spec mistake and an
unreachable or remote plain scheduler refused in one line before anything starts or is
written; a running sweep cancelled, keeping its rows and taking keys; a finished sweep
run again showing its stored rows first and its whole 100%; a local cluster starting
while the interface captures stderr; the ETA counting only the variants run here.

Every sweep here runs serially in this process on a hand-made 24 x 24 scene
with an 8 x 8 detector sensor, so each variant takes milliseconds.
"""

from __future__ import annotations

import math
import subprocess
import sys

import pytest
from textual.widgets import DataTable

from ladartui.sweep import read_table
from ladartui.tui.status import BUSY, NOT_READY, READY, format_eta
from ladartui.tui.sweep_screen import SweepScreen
from ladartui.tui.sweep_view import eta_seconds
from sweep_screen_support import (
    SIZE,
    SweepHost,
    assert_clear_of_the_palette_key,
    footer_keys,
    opened,
    status_of,
    wait_for,
    write_base,
    write_spec,
)


async def test_a_missing_spec_gives_one_line_and_starts_nothing(tmp_path):
    missing = tmp_path / "nowhere.toml"
    screen = SweepScreen(missing, serial=True)
    app = SweepHost(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        await pilot.pause()
        assert status_of(screen).state == NOT_READY
        assert (
            str(missing) in screen.last_message
            and "no such file; expected a sweep spec" in screen.last_message
        )
        assert not screen.running and not list(screen.workers)
        assert not (tmp_path / "nowhere-results").exists()


async def test_an_empty_spec_field_is_named_as_the_form_names_it(tmp_path, monkeypatch):
    """F5 or F3 with the Spec field empty said "spec = '': expected ...", a name the
    screen shows nowhere, where its other fields say "Budget s: ... is not allowed"."""
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))  # no last sweep to reopen
    screen = SweepScreen(serial=True)
    app = SweepHost(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        await pilot.pause()
        assert screen.last_message == (
            "Spec: empty is not allowed; expected the path of a sweep spec (.toml)"
        )
        assert not screen.running and status_of(screen).state == NOT_READY
        await pilot.press("f3")
        await opened(pilot)
        assert screen.last_message == (
            "Spec: empty is not allowed; expected a sweep spec, a results.csv or a results folder"
        )


async def test_a_spec_mistake_names_its_line_and_starts_nothing(tmp_path):
    write_base(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [10.0]\nscans = [2, 2.5]\n")
    screen = SweepScreen(spec, serial=True)
    app = SweepHost(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        await pilot.pause()
        message = screen.last_message
        assert status_of(screen).state == NOT_READY
        assert message.startswith(f"{spec}:6: grid.scans") and "2.5" in message
        assert "\n" not in message
        assert not screen.running and not list(screen.workers)
        assert not (tmp_path / "spec-results").exists()


async def test_a_running_sweep_cancels_keeps_its_rows_and_stays_responsive(tmp_path, finished):
    # ``finished`` ran a sweep in this process already, so the kernels are compiled.
    write_base(tmp_path)
    # 7,200 variants: far more than run while the test waits (a few hundred a second
    # here), so only Cancel can end it early.
    spec = write_spec(
        tmp_path, "[grid]\nheading_offset = { start = 0, stop = 359.95, step = 0.05 }\nscans = [1]\n"
    )
    results = tmp_path / "spec-results" / "results.csv"
    screen = SweepScreen(spec, serial=True)
    app = SweepHost(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        assert screen.running and status_of(screen).state == BUSY
        await wait_for(pilot, lambda: screen.progress is not None and screen.progress.done >= 2)
        # At 80 columns the keys that act while it runs are all readable: Ctrl+X, F8, F9
        # and Esc were under the palette's key or past the edge.
        await wait_for(pilot, lambda: "cancel" in footer_keys(screen))
        await pilot.pause()
        shown = footer_keys(screen)
        assert {"cancel", "objective", "cost", "best", "view", "close"} <= shown.keys()
        assert_clear_of_the_palette_key(shown)
        # F5 and F3, off the footer while it runs, still say why they do nothing
        # (the notes as they are given: one shown earlier may expire as a new one comes)
        said: list[str] = []
        notify = screen.notify
        screen.notify = lambda message, **kwargs: said.append(message) or notify(message, **kwargs)
        for key in ("f5", "f3"):
            await pilot.press(key)
            await wait_for(pilot, lambda key=key: len(said) == ("f5", "f3").index(key) + 1)  # a busy machine
        assert screen.running and said == ["A sweep is running: Ctrl+X cancels it first."] * 2
        screen.notify = notify
        # Keys still act while the worker runs.
        await pilot.press("f9")
        assert screen.running and screen.query_one("#sweep-body").has_class("-table")
        await pilot.press("ctrl+x")
        await wait_for(pilot, lambda: not screen.running)
        # F5 resumes it: ready, not the yellow of a sweep that cannot run
        assert "cancelled" in screen.last_message and status_of(screen).state == READY
        # the status line is short enough for 80 columns; a note names the folder
        assert screen.last_message.endswith("kept; F5 resumes") and str(screen.out) not in screen.last_message
        assert any(f"rows are kept in {screen.out}" in n.message for n in screen.app._notifications)
        done = screen.progress.done
        assert 2 <= done < 7200
        kept, _ = read_table(results)
        assert len(kept) == done and all(r["status"] == "ok" for r in kept)
        assert screen.query_one("#sweep-table", DataTable).row_count == done
        counts = str(screen.query_one("#sweep-counts").render())
        assert counts.startswith(f"{done}/7200, 0 failed, 0 resumed") and "ETA" in counts
        await pilot.press("f6")
        assert screen.objective == "coverage-per-km"
        # Run again and leave at once: Escape closes the screen and cancels the run.
        await pilot.press("f5", "escape")
        await pilot.pause()
        assert app.screen is not screen
        # said where the analyst goes, not only on the screen left behind
        said = f"sweep cancelled on leaving its screen; the rows so far are kept in {screen.out}; F5 resumes"
        assert screen.last_message == said and said in [n.message for n in app._notifications]
        await wait_for(pilot, lambda: not any(w.is_running for w in app.workers))
        rows, _ = read_table(results)
        assert done <= len(rows) < 7200
        # The kept variants were resumed, not run again: their rows are as they were.
        again = {r["variant"]: r for r in rows}
        assert len(again) == len(rows)
        assert all(again[r["variant"]] == r for r in kept)


async def test_an_unreachable_scheduler_gives_one_line_and_writes_nothing(tmp_path):
    write_base(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [10.0, 20.0]\n")
    screen = SweepScreen(spec, scheduler="tcp://127.0.0.1:9", connect_timeout=0.5)
    app = SweepHost(screen)
    notes: list[str] = []  # recorded as made: a note in the app expires by the wall clock
    notify = app.notify
    app.notify = lambda message, **options: (notes.append(message), notify(message, **options))[1]
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        # A refused connection may end the run before the key press returns: wait for
        # its end, whether or not it is still running here.
        await wait_for(pilot, lambda: not screen.running, timeout=60)
        message = screen.last_message
        assert status_of(screen).state == NOT_READY
        # in the form's words, as its other fields say theirs: not the command's --scheduler
        assert "Scheduler: tcp://127.0.0.1:9 is not allowed; expected" in message and "\n" not in message
        assert not (tmp_path / "spec-results" / "results.csv").exists()
        # too long for the status line: cut there, so the whole of it comes as a note too
        room = screen.query_one("#sweep-status #status-text").content_size.width
        assert len(message) > room and message in notes


TRACKER_SCRIPT = """
import asyncio, multiprocessing, sys
from textual.app import App
from ladartui.tui.sweep_jobs import start_resource_tracker

async def main():
    async with App().run_test():
        assert sys.stderr.fileno() == -1, "the app no longer captures stderr"
        start_resource_tracker()
        multiprocessing.get_context("spawn").Lock()  # registers with the tracker
        print("lock made")

asyncio.run(main())
"""


def test_a_local_cluster_can_start_while_the_interface_captures_stderr():
    # Without the tracker started first, making the lock fails: bad value(s) in fds_to_keep.
    done = subprocess.run([sys.executable, "-c", TRACKER_SCRIPT], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "lock made" in done.stdout


def test_eta_counts_only_the_variants_run_here():
    from ladartui.sweep import SweepProgress

    progress = SweepProgress(total=10, done=6, resumed=2, failed=0, elapsed=8.0)
    assert eta_seconds(progress) == pytest.approx(8.0 / 4 * 4)
    assert eta_seconds(SweepProgress(10, 2, 2, 0, 1.0)) is None
    assert format_eta(125) == "2m05s" and format_eta(3725) == "1h02m" and format_eta(None) == "--"
    assert format_eta(math.inf) == "--"
    # the last half second of a run read "about 0s left"
    assert [format_eta(s) for s in (0.0, 0.49, 0.5, 59.6)] == ["<1s", "<1s", "1s", "1m00s"]


async def test_a_plain_scheduler_off_this_machine_is_refused_as_the_cli_refuses_it(tmp_path):
    write_base(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [10.0, 20.0]\n")
    screen = SweepScreen(spec, scheduler="tcp://192.0.2.10:8786", connect_timeout=0.5)
    app = SweepHost(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        await pilot.pause()
        assert not screen.running and not list(screen.workers)
        assert "run code on it" in screen.last_message  # says why, in the form's words
        assert screen.last_message.startswith("Scheduler: tcp://192.0.2.10:8786 is not allowed; expected")
        # a tls:// scheduler needs the certificates folder, named when incomplete
        screen.query_one("#sweep-scheduler").value = "tls://192.0.2.10:8786"
        screen.query_one("#sweep-certs").value = str(tmp_path)
        await pilot.press("f5")
        await pilot.pause()
        assert not screen.running
        assert screen.last_message.startswith(f"Certificates: {tmp_path} is not allowed; expected a folder")
        assert "ca.pem" in screen.last_message


def _copy_of_finished(finished, folder):
    """The finished sweep's spec, copied with its results into ``folder`` (running again
    rewrites the table)."""
    import shutil

    spec, _ = finished
    for path in spec.parent.iterdir():
        copy = shutil.copytree if path.is_dir() else shutil.copy
        copy(path, folder / path.name)
    return folder / spec.name


async def test_a_sweep_run_again_shows_its_stored_rows_first(finished, tmp_path):
    """Run again over a finished folder, the stored rows come from the job before any
    variant (none left to run here: all resume)."""
    screen = SweepScreen(_copy_of_finished(finished, tmp_path), serial=True)
    app = SweepHost(screen)
    seen: list[int] = []
    show = screen._show_stored_rows
    screen._show_stored_rows = lambda rows: (seen.append(len(rows)), show(rows))[1]
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        await wait_for(pilot, lambda: not screen.running)
        assert seen == [12], screen.last_message
        assert screen.query_one("#sweep-table", DataTable).row_count == 12
        assert "12 resumed" in screen.last_message


async def test_a_finished_sweep_shows_its_whole_100_percent(finished, tmp_path):
    """At 80x24 the progress reads "100%", not "100" cut by the row's label padding."""
    screen = SweepScreen(_copy_of_finished(finished, tmp_path), serial=True)
    app = SweepHost(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        await wait_for(pilot, lambda: not screen.running)
        await pilot.pause()
        percent = screen.query_one("#sweep-progress PercentageStatus")
        assert str(percent.render()) == "100%"
        assert percent.content_region.width >= len("100%")


async def test_a_sweep_from_the_screen_draws_its_charts_with_its_ranking(finished, tmp_path):
    """The screen's sweep replaced the ranking and best path but left an earlier sweep's
    pareto.svg and .png beside them, charts of another ranking; it draws them as the
    command does, in one set with the ranking."""
    spec = _copy_of_finished(finished, tmp_path)
    out = tmp_path / finished[1].name
    (out / "pareto.svg").write_text("an earlier sweep's chart")
    screen = SweepScreen(spec, serial=True)
    app = SweepHost(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        await wait_for(pilot, lambda: not screen.running)
    assert (out / "pareto.svg").read_text().lstrip().startswith("<?xml"), screen.last_message
    assert (out / "pareto.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
