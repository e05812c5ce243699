"""The sweep screen driven by a Pilot: a finished sweep's results opened, ranked by each
objective with its failures and Pareto front, the best path handed to the app; a budget
typed; results picked in a tree, the last sweep reopened, a narrowed spec's own rows;
opening off the UI thread (running a sweep: test_tui_sweep_run.py).

Every sweep here runs serially in this process on a hand-made 24 x 24 scene
with an 8 x 8 detector sensor, so each variant takes milliseconds.
"""

from __future__ import annotations

from textual.widgets import DataTable

from ladartui.scenario import load_scenario
from ladartui.sweep import read_table
from ladartui.tui.status import BUSY, NOT_READY, READY
from ladartui.tui.sweep_screen import SweepScreen
from sweep_screen_support import (
    SIZE,
    SweepHost,
    assert_clear_of_the_palette_key,
    footer_keys,
    opened,
    status_of,
    wait_for,
    write_spec,
)


def table_column(table: DataTable, key: str) -> list[str]:
    return [str(cell) for cell in table.get_column(key)]


async def test_opening_results_shows_the_ranking_failures_and_pareto_front(finished):
    spec, results = finished
    rows, _ = read_table(results / "results.csv")
    ok = [r for r in rows if r["status"] == "ok"]
    failed = [r for r in rows if r["status"] != "ok"]
    assert len(rows) == 12 and len(failed) == 6  # sensor_grid = 0 is impossible
    screen = SweepScreen(results)
    app = SweepHost(screen)
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
        await wait_for(pilot, lambda: "run" in footer_keys(screen))
        await pilot.pause()
        shown_keys = footer_keys(screen)
        for binding in SweepScreen.BINDINGS:
            if binding.action == "cancel":  # shown only while a sweep runs
                assert binding.action not in shown_keys
                continue
            if binding.action == "browse":  # its button names its key
                assert "Browse F2" in str(screen.query_one("#sweep-browse").label)
                continue
            region = shown_keys[binding.action]
            assert region.width > 0 and region.right <= SIZE[0], binding.action
        assert_clear_of_the_palette_key(shown_keys)
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
    app = SweepHost(screen)
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
    app = SweepHost(screen)
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


async def test_browse_picks_a_results_folder_in_a_tree_and_opens_it(finished):
    from ladartui.tui.file_dialogs import PickPathScreen
    from ladartui.tui.file_tree import FileTree

    _spec, results = finished
    screen = SweepScreen(serial=True)
    app = SweepHost(screen)
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
    app = SweepHost(first)
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
    app = SweepHost(screen)
    async with app.run_test(size=SIZE) as pilot:
        await opened(pilot)
        assert screen.query_one("#sweep-table", DataTable).row_count == 1
        assert str(screen.query_one("#sweep-counts").render()) == "1 variant, 1 ok, 0 failed"
        said = "11 rows not ranked: other variants;"  # the base is the one they ran on
        assert status_of(screen).query_one("#status-text").render().plain.startswith(said)  # whole at 80


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
    app = SweepHost(screen)
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


async def test_opening_a_sweep_leaves_no_note_of_the_empty_screen(finished):
    """The screen's first words ('type a sweep spec ...') came as a note, read as cut
    before the status line was laid out, and stayed over the chart of the sweep it had
    opened, then followed onto the main screen."""
    spec, results = finished
    screen = SweepScreen(results)
    app = SweepHost(screen)
    notes: list[str] = []
    notify = app.notify
    app.notify = lambda message, **options: (notes.append(message), notify(message, **options))[1]
    async with app.run_test(size=(120, 40)) as pilot:
        await opened(pilot)
        await pilot.pause(0.3)
        assert screen.last_message.startswith("ranked by")
        assert not [note for note in notes if "type a sweep spec" in note], notes
