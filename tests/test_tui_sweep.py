"""The sweep screen driven by a Pilot: open results, reject bad specs, run and cancel a sweep.

Every sweep here runs serially in this process on a hand-made 24 x 24 scene
with an 8 x 8 detector sensor, so each variant takes milliseconds.
"""

from __future__ import annotations

import math
import subprocess
import sys
import time

import numpy as np
import pytest
from textual.app import App
from textual.widgets import DataTable

from ladartui.scenario import load_scenario
from ladartui.sweep import read_table, run_sweep
from ladartui.tui.status import BUSY, NOT_READY, READY, StatusBar, format_eta
from ladartui.tui.sweep_screen import SweepScreen
from ladartui.tui.sweep_view import eta_seconds

SIZE = (80, 24)
CENTRE = (11.5, 11.5, 0.5)


class _Host(App):
    """A bare app that shows one SweepScreen and records the scenarios it asks to open."""

    def __init__(self, screen: SweepScreen):
        super().__init__()
        self.sweep_screen = screen
        self.opened = []

    def on_mount(self) -> None:
        self.push_screen(self.sweep_screen)

    def on_sweep_screen_open_scenario(self, message: SweepScreen.OpenScenario) -> None:
        self.opened.append(message.path)


def write_base(folder):
    """A 24 x 24 canopy with gaps over a 4 x 2 x 2 vehicle; a 2-scan orbit, 8 x 8 detectors."""
    from ladartui.flight import FlightPlan, Orbit
    from ladartui.scenario import Scenario
    from ladartui.scene.voxels import save_voxels
    from ladartui.sensor import Sensor

    target = np.array([(i, j, k) for i in range(10, 14) for j in range(11, 13) for k in range(2)], np.int32)
    canopy = np.array([(i, j, 5) for i in range(24) for j in range(24) if (i * 5 + j * 3) % 4 == 0], np.int32)
    save_voxels(folder / "tiny.txt", np.concatenate([target, canopy]))
    save_voxels(folder / "tiny_Target.txt", target)
    flight = FlightPlan(segments=(Orbit(centre=CENTRE, radius=15.0, altitude=15.0, scans=2),))
    Scenario(
        folder / "base.toml", "tiny.txt", 1.0, Sensor(grid=8, ray_grid=1, fov=25.0), flight, backend="numba"
    ).save()


def write_spec(folder, body, name="spec.toml"):
    path = folder / name
    path.write_text(f'[sweep]\nscenario = "base.toml"\nname = "tiny"\n{body}', encoding="utf-8")
    return path


SMALL_GRID = """
[grid]
radius = [8.0, 15.0, 30.0]
scans = [1, 3]
sensor_grid = [8, 0]
"""


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A sweep run to the end by the core (serially): its spec and results folder."""
    folder = tmp_path_factory.mktemp("sweep")
    write_base(folder)
    spec = write_spec(folder, SMALL_GRID)
    result = run_sweep(spec, serial=True)
    return spec, result.results_path.parent


# Generous: a numba kernel recompiled after an edit elsewhere can take minutes on a busy machine.
async def wait_for(pilot, condition, timeout=300.0):
    start = time.monotonic()
    while not condition():
        if time.monotonic() - start > timeout:
            screen = pilot.app.sweep_screen
            raise AssertionError(f"timed out; status: {screen.last_message!r}")
        await pilot.pause(0.05)


async def opened(pilot, screen=None):
    """Wait until the screen's open (read in a worker) is shown."""
    screen = screen or pilot.app.sweep_screen
    await wait_for(pilot, lambda: screen.opening is None or screen.opening.is_finished)
    await pilot.pause()


def table_column(table: DataTable, key: str) -> list[str]:
    return [str(cell) for cell in table.get_column(key)]


def status_of(screen) -> StatusBar:
    return screen.query_one("#sweep-status", StatusBar)


async def test_opening_results_shows_the_ranking_failures_and_pareto_front(finished):
    spec, results = finished
    rows, _ = read_table(results / "results.csv")
    ok = [r for r in rows if r["status"] == "ok"]
    failed = [r for r in rows if r["status"] != "ok"]
    assert len(rows) == 12 and len(failed) == 6  # sensor_grid = 0 is impossible
    screen = SweepScreen(results)
    app = _Host(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        # impossible values are final, not failures (which run again on resume)
        assert str(screen.query_one("#sweep-counts").render()) == "12 variants, 6 ok, 0 failed, 6 impossible"
        # a gap between the table and the chart: a value at the table's edge never runs
        # into the chart's axis numbers ("2958528.9" was variant 29585... and 28.9)
        table_box, chart_box = (
            screen.query_one("#sweep-table").region,
            screen.query_one("#sweep-chart").region,
        )
        assert chart_box.x >= table_box.right + 1
        table = screen.query_one("#sweep-table", DataTable)
        assert status_of(screen).state == READY
        assert table.row_count == 12
        # a column's numbers share their decimals ('4', '8.029', '10.04' did not line up)
        costs = [str(cell) for cell in table.get_column("cost") if str(cell) != "-"]
        assert costs and len({len(c.partition(".")[2]) for c in costs}) == 1, costs
        # At 80 x 24 every key is in the footer, and the table and chart share the body.
        from textual.widgets._footer import FooterKey

        # The footer composes its keys after the screen's bindings settle: on a busy
        # machine that can take more than one pause (CI once saw none yet).
        await wait_for(pilot, lambda: any(key.action == "run" for key in screen.query(FooterKey)))
        await pilot.pause()
        shown_keys = {key.action: key.region for key in screen.query(FooterKey)}
        for binding in SweepScreen.BINDINGS:
            if binding.action == "cancel":  # shown only while a sweep runs
                assert binding.action not in shown_keys
                continue
            region = shown_keys[binding.action]
            assert region.width > 0 and region.right <= SIZE[0], binding.action
        assert table.region.height >= 12 and screen.query_one("#sweep-chart").region.width >= 28
        # Ranked by the spec's objective (obscured coverage): best first, ties to the cheaper.
        # Said first: after the folder and the counts it was cut at the screen's edge.
        assert screen.last_message.startswith("ranked by obscured-coverage: ")
        expected = sorted(ok, key=lambda r: (-r["obscured_coverage"], r["flight_time_s"]))
        shown = table_column(table, "variant")
        assert shown[: len(ok)] == [r["variant"] for r in expected]
        assert table_column(table, "rank")[: len(ok)] == [str(i + 1) for i in range(len(ok))]
        # Failed variants come last, unranked, with their error.
        assert set(shown[len(ok) :]) == {r["variant"] for r in failed}
        assert table_column(table, "rank")[len(ok) :] == ["-"] * len(failed)
        assert all("sensor_grid" in e for e in table_column(table, "error")[len(ok) :])
        # Pareto marks: no other ok variant is at least as cheap and as good, one strictly.
        points = {r["variant"]: (r["flight_time_s"], r["obscured_coverage"]) for r in ok}

        def dominated(v):
            c, g = points[v]
            return any(c2 <= c and g2 >= g and (c2 < c or g2 > g) for w, (c2, g2) in points.items() if w != v)

        marks = dict(zip(shown, table_column(table, "pareto")))
        assert {v for v in points if marks[v]} == {v for v in points if not dominated(v)}
        assert not any(marks[r["variant"]] for r in failed)

        # Another objective re-ranks: coverage per kilometre flown.
        table.move_cursor(row=2)
        await pilot.pause()
        highlighted = shown[2]
        await pilot.press("f6")
        assert screen.objective == "coverage-per-km"
        # The cursor stays on the variant it was on.
        assert table_column(table, "variant")[table.cursor_row] == highlighted
        # A one-scan orbit flies no distance: no coverage per km, so it is not ranked.
        flown = [r for r in ok if r["path_length_m"] > 0]
        assert 0 < len(flown) < len(ok)
        per_km = sorted(
            flown, key=lambda r: (-r["obscured_coverage"] / (r["path_length_m"] / 1000), r["flight_time_s"])
        )
        assert table_column(table, "variant")[: len(flown)] == [r["variant"] for r in per_km]
        assert table_column(table, "rank")[len(flown) :] == ["-"] * (12 - len(flown))

        # The best path is saved as a scenario with its parameters and handed to the app.
        await pilot.press("f8")
        await wait_for(pilot, lambda: app.opened)
        best = load_scenario(app.opened[0])
        assert app.opened[0].parent == results
        orbit = best.flight.segments[0]
        assert orbit.radius == per_km[0]["radius"] and orbit.scans == per_km[0]["scans"]
        assert str(app.opened[0]) in screen.last_message
        # Saved with edits, that file is kept: F8 writes the best path beside it and says so.
        edited = best.with_changes(speed=best.speed + 1).save()
        mine = edited.path.read_bytes()
        await pilot.press("f8")
        await wait_for(pilot, lambda: len(app.opened) == 2)
        assert edited.path.read_bytes() == mine
        assert app.opened[1] == edited.path.with_name(f"{edited.path.stem}-2.toml")
        assert f"{edited.path.name} kept: edited since a sweep wrote it" in screen.last_message
        # said where the analyst goes next too: the app opens the best path over this screen
        notes = [n.message for n in app._notifications]
        assert any(f"{edited.path.name} kept: edited since a sweep wrote it" in n for n in notes)

        # The detail line shows a failed variant's whole error.
        table.move_cursor(row=table.row_count - 1)
        await pilot.pause()
        detail = str(screen.query_one("#sweep-detail").render())
        assert "error: sensor_grid = 0" in detail

        # No budget in the spec or the field: the budget objective is skipped, with the reason.
        await pilot.press("f6")
        assert screen.objective == "time-to-identify"
        # what is ranked now comes first (a status line is cut at the screen's edge)
        assert screen.last_message == (
            "ranking by time-to-identify; coverage-within-budget skipped: "
            "it needs a budget (type one in Budget s)"
        )
        # cut at the screen's edge (the reason is the part cut): told whole as a note too
        assert screen.last_message in [n.message for n in app._notifications]
        # then the objectives on identification, each with its own column
        assert "identify s" in [c.label.plain for c in table.ordered_columns]
        for expected in ("distance-to-identify", "worst-target-coverage"):
            await pilot.press("f6")
            assert screen.objective == expected
        await pilot.press("f6")  # identified within a budget: no budget, skipped again
        assert screen.objective == "obscured-coverage"
        assert screen.last_message.startswith(
            "ranking by obscured-coverage; identified-within-budget skipped"
        )


async def test_budget_objective_ranks_only_paths_within_the_typed_budget(finished):
    spec, results = finished
    rows, _ = read_table(results / "results.csv")
    ok = [r for r in rows if r["status"] == "ok"]
    times = sorted({r["flight_time_s"] for r in ok})
    budget = (times[0] + times[1]) / 2  # between the two shortest flight times
    screen = SweepScreen(spec)
    app = _Host(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        screen.query_one("#sweep-budget").value = f"{budget}"
        await pilot.press("f6", "f6")
        assert screen.objective == "coverage-within-budget"
        table = screen.query_one("#sweep-table", DataTable)
        ranks = table_column(table, "rank")
        within = [r for r in ok if r["flight_time_s"] <= budget]
        assert 0 < len(within) < len(ok)
        assert sum(rank != "-" for rank in ranks) == len(within)
        assert (
            table_column(table, "variant")[0] == max(within, key=lambda r: r["obscured_coverage"])["variant"]
        )


async def test_a_bad_budget_is_one_line_whatever_the_ranking(finished):
    """With a ranking that reads no budget, -5 in Budget s ended the app with a traceback
    (the status line read the budget outside the check). Then the refusal came on a green
    READY bar, in the spec's words (budget = '-5'), and 1e400 was said not to be > 0."""
    spec, _ = finished
    screen = SweepScreen(spec)
    app = _Host(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        budget = screen.query_one("#sweep-budget")
        for typed in ("-5", "0", "abc", "1e400"):
            budget.value = typed
            budget.focus()
            await pilot.press("enter")
            await pilot.pause()
            assert app.is_running
            assert screen.last_message == (
                f"Budget s: {typed} is not allowed; expected a flight time in seconds, greater than 0 "
                "and finite (empty: the spec's budget)"
            )
            assert status_of(screen).state == NOT_READY


async def test_a_missing_spec_gives_one_line_and_starts_nothing(tmp_path):
    missing = tmp_path / "nowhere.toml"
    screen = SweepScreen(missing, serial=True)
    app = _Host(screen)
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


async def test_a_spec_mistake_names_its_line_and_starts_nothing(tmp_path):
    write_base(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [10.0]\nscans = [2, 2.5]\n")
    screen = SweepScreen(spec, serial=True)
    app = _Host(screen)
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
    app = _Host(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        assert screen.running and status_of(screen).state == BUSY
        await wait_for(pilot, lambda: screen.progress is not None and screen.progress.done >= 2)
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
    app = _Host(screen)
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


async def test_browse_picks_a_results_folder_in_a_tree_and_opens_it(finished):
    from ladartui.tui.file_dialogs import PickPathScreen
    from ladartui.tui.file_tree import FileTree

    _spec, results = finished
    screen = SweepScreen(serial=True)
    app = _Host(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        screen.query_one("#sweep-path").value = str(results.parent) + "/"
        await pilot.press("f2")
        await pilot.pause()
        picker = app.screen
        assert isinstance(picker, PickPathScreen)
        tree = picker.query_one(FileTree)
        await wait_for(pilot, lambda: len(tree.root.children) > 0)
        names = [node.data.path.name for node in tree.root.children]
        assert results.name in names
        tree.focus()
        tree.move_cursor(tree.root.children[names.index(results.name)])
        await pilot.press("enter")  # a folder: chosen, as results folders are
        await pilot.pause()
        assert picker.query_one("#pick-path").value == str(results)
        picker.query_one("#pick-ok").press()
        await pilot.pause()
        await opened(pilot)
        assert app.screen is screen
        assert screen.query_one("#sweep-table", DataTable).row_count == 12


async def test_the_screen_reopens_the_last_sweep_opened(finished, tmp_path, monkeypatch):
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    _spec, results = finished
    first = SweepScreen(results)
    app = _Host(first)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        assert first.query_one("#sweep-table", DataTable).row_count == 12
        app.pop_screen()
        again = SweepScreen()  # no path: the last sweep opened comes back
        app.push_screen(again)
        await pilot.pause()
        await opened(pilot, again)
        assert again.query_one("#sweep-path").value == str(results.resolve())
        assert again.query_one("#sweep-table", DataTable).row_count == 12


async def test_a_spec_opened_shows_only_its_own_variants_from_the_folder(finished, tmp_path):
    import shutil

    spec, results = finished
    for path in spec.parent.iterdir():  # a copy: the spec is edited below
        copy = shutil.copytree if path.is_dir() else shutil.copy
        copy(path, tmp_path / path.name)
    # the spec narrowed after its sweep ran: one of its twelve stored variants is still its own
    narrowed = write_spec(tmp_path, "[grid]\nradius = [8.0]\nscans = [1]\nsensor_grid = [8]\n")
    screen = SweepScreen(narrowed)
    app = _Host(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        assert screen.query_one("#sweep-table", DataTable).row_count == 1
        assert str(screen.query_one("#sweep-counts").render()) == "1 variants, 1 ok, 0 failed"
        said = "11 rows not ranked: other variants or an earlier base;"
        assert status_of(screen).query_one("#status-text").render().plain.startswith(said)  # whole at 80


async def test_a_plain_scheduler_off_this_machine_is_refused_as_the_cli_refuses_it(tmp_path):
    write_base(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [10.0, 20.0]\n")
    screen = SweepScreen(spec, scheduler="tcp://192.0.2.10:8786", connect_timeout=0.5)
    app = _Host(screen)
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


async def test_opening_reads_off_the_ui_thread_and_keeps_only_the_last_asked(finished, monkeypatch, tmp_path):
    """open_sweep (the table read, the base's models hashed) runs in a worker: the
    screen says it is opening and takes keys meanwhile. Of two opens, a slow first
    one finishing after the second is not shown over it."""
    import shutil
    import threading

    from ladartui.tui import sweep_opening

    spec, results = finished
    real = sweep_opening.open_sweep
    threads, release = [], threading.Event()

    def slow_open(text):
        threads.append(threading.current_thread())
        if text == "slow":
            release.wait(30)
            return real(str(results))  # (would show the whole folder)
        return real(text)

    monkeypatch.setattr(sweep_opening, "open_sweep", slow_open)
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))  # no sweep opened before
    for path in spec.parent.iterdir():  # a copy: the spec is narrowed below
        copy = shutil.copytree if path.is_dir() else shutil.copy
        copy(path, tmp_path / path.name)
    narrowed = write_spec(tmp_path, "[grid]\nradius = [8.0]\nscans = [1]\nsensor_grid = [8]\n")
    screen = SweepScreen(serial=True)
    app = _Host(screen)
    try:
        async with app.run_test(size=SIZE) as pilot:
            await opened(pilot)
            answers: list[int] = []
            shown = screen._opened
            screen._opened = lambda answer: (answers.append(answer[0]), shown(answer))[1]
            screen._open("slow")
            await pilot.pause()
            assert status_of(screen).state == BUSY and screen.last_message == "opening slow ..."
            budget = screen.query_one("#sweep-budget")
            budget.focus()
            await pilot.press("4", "2")  # keys are taken while it reads
            assert budget.value.endswith("42")
            screen._open(str(narrowed))
            await wait_for(pilot, lambda: screen.query_one("#sweep-table", DataTable).row_count == 1)
            release.set()
            await wait_for(pilot, lambda: len(answers) == 2)
            await pilot.pause()
            assert answers[0] > answers[1]  # the slow one answered last, and was dropped
            assert screen.query_one("#sweep-table", DataTable).row_count == 1
            assert threading.main_thread() not in threads and len(threads) == 2
    finally:
        release.set()


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
    app = _Host(screen)
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
    app = _Host(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        await wait_for(pilot, lambda: not screen.running)
        await pilot.pause()
        percent = screen.query_one("#sweep-progress PercentageStatus")
        assert str(percent.render()) == "100%"
        assert percent.content_region.width >= len("100%")


async def test_opening_a_sweep_leaves_no_note_of_the_empty_screen(finished):
    """The screen's first words ('type a sweep spec ...') came as a note, read as cut
    before the status line was laid out, and stayed over the chart of the sweep it had
    opened, then followed onto the main screen."""
    spec, results = finished
    screen = SweepScreen(results)
    app = _Host(screen)
    notes: list[str] = []
    notify = app.notify
    app.notify = lambda message, **options: (notes.append(message), notify(message, **options))[1]
    async with app.run_test(size=(120, 40)) as pilot:
        await opened(pilot)
        await pilot.pause(0.3)
        assert screen.last_message.startswith("ranked by")
        assert not [note for note in notes if "type a sweep spec" in note], notes
