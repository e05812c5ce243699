"""The flight tab's tables in the sidebar: the scans table fitting at 120 columns and
showing whole columns only, naming those left out; the segments table wrapping a long
detail whole, each unit kept beside its number; both drawn to their new cells at once.

Each test drives a real app on a tiny generated scene with Pilot.
"""

from __future__ import annotations

from rich.cells import cell_len

from ladartui.flight import FlightPlan
from tui_support import LadarApp, loaded, make_scenario, opened, wait_until


async def test_the_scans_table_fits_the_sidebar_at_120_columns(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files, scans=24)
    async with opened(scenario, size=(120, 40)) as (app, pilot):
        app.action_show_tab("flight")
        await pilot.pause()
        scans = app.query_one("#scans")
        # no column shown cut: a depression of 44.6 cut to "4" read as a value
        assert scans.max_scroll_x == 0
        assert scans.row_count == 24 and scans.size.height > 10
        assert not any(str(cell) == "-0" for i in range(scans.row_count) for cell in scans.get_row_at(i))


async def test_a_path_of_thousands_of_scans_lists_the_first_thousand_and_says_so(tmp_path, scene_files):
    """A 9,000-scan fly-past froze the screen for seconds as its rows went into the
    table (Textual measures every cell of a new row); the table lists the first scans
    and its heading says how many of all."""
    from ladartui.flight import FlyPast
    from ladartui.tui.panels.flight import MOST_SCAN_ROWS

    scenario = make_scenario(tmp_path, scene_files)
    long = FlyPast(target=(30.0, 30.0, 1.0), standoff=40.0, altitude=30.0, length=600.0, scans=2500)
    scenario = scenario.with_changes(flight=FlightPlan(None, (*scenario.flight.segments, long))).save()
    async with opened(scenario, size=(120, 40)) as (app, pilot):
        app.action_show_tab("flight")
        await pilot.pause()
        scans = app.query_one("#scans")
        assert scans.row_count == MOST_SCAN_ROWS == 1000
        assert [str(cell) for cell in scans.get_row_at(999)][0] == "1000"
        assert str(app.query_one("#scans-heading").render()) == "Scans (the first 1,000 of 2,506)"
    async with opened(scenario, size=(80, 24)) as (app, pilot):  # the narrow sidebar
        app.action_show_tab("flight")
        await pilot.pause()
        heading = app.query_one("#scans-heading")
        said = str(heading.render())
        assert said.startswith("Scans (the first 1,000 of 2,506; no room for ")
        # whole, over more lines: cut at the sidebar's edge, it lost the columns left out
        assert heading.size.height * heading.size.width >= cell_len(said) > heading.size.width


async def test_the_segments_table_fits_the_sidebar_and_wraps_a_long_detail(tmp_path, scene_files):
    import shutil
    from pathlib import Path

    from ladartui.flight import FlightPlan, Manual, ScanPose, Standoff
    from ladartui.trajectory import LogSegment

    log = tmp_path / "飛行記録.csv"  # wide characters: two cells each
    shutil.copy(Path(__file__).parent.parent / "scenarios" / "flight-log.csv", log)
    scenario = make_scenario(tmp_path, scene_files)
    far = Standoff(target=(30.0, 30.0, 1.0), standoffs=(40.0, 55.0, 70.0, 85.0, 100.0), altitude=50.0)
    poses = Manual((ScanPose(0.0, 0.0, 40.0),))
    segments = (*scenario.flight.segments, far, poses, LogSegment(str(log), rate=2.0))
    scenario = scenario.with_changes(flight=FlightPlan(None, segments)).save()
    whole = ["r 30 m at 30 m", "40, 55, 70, 85, 100 m", "1 pose", "飛行記録.csv, 2 Hz"]
    for size in ((80, 24), (120, 40)):
        async with opened(scenario, size=size) as (app, pilot):
            app.action_show_tab("flight")
            await pilot.pause()
            table = app.query_one("#segments")
            # no sideways scrolling (a detail cut at the edge read "at 6" for "at 60"):
            # a detail too long for the sidebar goes on over more lines, whole. The table
            # is drawn again when a resize reaches it (the sidebar's scrollbar coming or
            # going): on a busy machine one pause may end before that
            await wait_until(pilot, lambda table=table: table.max_scroll_x == 0, timeout=10.0)
            rows = [[str(cell) for cell in table.get_row_at(i)] for i in range(table.row_count)]
            assert ["".join(row[3].split()) for row in rows] == ["".join(d.split()) for d in whole]
            assert [row[1] for row in rows] == ["Orbit", "Standoff", "Poses", "Log"]
            room = list(table.columns.values())[3].width
            heights = [table.rows[row.key].height for row in table.ordered_rows]
            for detail, height, row in zip(whole, heights, rows):
                assert (height > 1) == (cell_len(detail) > room), (size, detail)
                assert height == len(row[3].split("\n"))
            assert heights[3] > 1 or size == (120, 40)


def test_a_wrapped_detail_keeps_each_unit_beside_its_number():
    from ladartui.tui.fitted_tables import wrap_detail

    # "300 m" wrapped at its space read as two values: "300" and a lone "m"
    assert wrap_detail("40, 55, 70, 85, 300 m", 17) == ["40, 55, 70, 85,", "300 m"]
    assert wrap_detail("r 300 m at 150 m", 9) == ["r 300 m", "at 150 m"]
    assert wrap_detail("left 90 deg r 25 m", 11) == ["left 90 deg", "r 25 m"]
    assert wrap_detail("r 300 m at 150 m", 40) == ["r 300 m at 150 m"]
    # a name wider than the room is cut where it must, in cells (a CJK character takes two)
    assert wrap_detail("飛行記録.csv, 2 Hz", 6) == ["飛行記", "録.", "csv,", "2 Hz"]  # no ", 2 Hz"
    assert all(cell_len(line) <= 6 for line in wrap_detail("飛行記録.csv, 2 Hz", 6))


async def test_the_scans_table_shows_whole_columns_only_and_names_those_left_out(tmp_path, scene_files):
    from ladartui.flight import FlightPlan, Orbit

    scenario = make_scenario(tmp_path, scene_files)
    wide = Orbit(centre=(30.0, 30.0, 1.0), radius=1234.5, altitude=987.6, scans=4)
    scenario = scenario.with_changes(flight=FlightPlan(None, (wide,))).save()
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        app.action_show_tab("flight")
        await pilot.pause()
        scans = app.query_one("#scans")
        # a column cut at the edge read as another value ("9" under "a" for an az of 90)
        assert scans.max_scroll_x == 0
        shown = [str(column.label) for column in scans.columns.values()]
        left_out = [c for c in ("#", "x", "y", "z", "hdg", "az", "dep") if c not in shown]
        assert shown[:3] == ["#", "x", "y"] and left_out
        heading = str(app.query_one("#scans-heading").render())
        assert heading == "Scans (no room for " + ", ".join(left_out) + ")"
    async with opened(make_scenario(tmp_path, scene_files, name="near"), size=(120, 40)) as (app, pilot):
        app.action_show_tab("flight")
        await pilot.pause()
        assert len(app.query_one("#scans").columns) == 7
        assert str(app.query_one("#scans-heading").render()) == "Scans"


async def test_the_flight_tables_are_drawn_to_their_new_cells_at_once(tmp_path, scene_files):
    """After a segment was deleted the scans table showed x -12 as "-" and y 82 as "8"
    until the next change: its columns took their widths from the cells only when
    Textual next measured them, and a frame drawn before that cut every value."""
    from rich.cells import cell_len

    from ladartui.flight import Turn

    scenario = make_scenario(tmp_path, scene_files)
    turn = Turn(radius=100.0, arc=90.0, direction="right", scans=4)
    scenario = scenario.with_changes(flight=FlightPlan(None, (*scenario.flight.segments, turn))).save()
    app = LadarApp(scenario.path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("flight")
        await pilot.pause()
        app.query_one("#segments").move_cursor(row=0)
        app.flight_panel.delete_selected()
        # no pause: the frame drawn next must already have the widths
        for table in (app.query_one("#scans"), app.query_one("#segments")):
            columns = list(table.columns.values())
            rows = [[str(cell) for cell in table.get_row_at(i)] for i in range(table.row_count)]
            for index, column in enumerate(columns[: len(columns) if table.id == "scans" else 3]):
                widest = max(cell_len(str(column.label)), *(cell_len(row[index]) for row in rows))
                assert column.get_render_width(table) == widest + 2 * table.cell_padding, (table.id, index)
