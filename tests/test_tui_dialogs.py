"""The app's dialogs as an analyst meets them: what a refused value says and where.

Each test drives a real app on a tiny generated scene with Pilot.
"""

from __future__ import annotations

import shlex
from contextlib import asynccontextmanager

from rich.cells import cell_len

from ladartui.tui.file_dialogs import SaveAsScreen
from ladartui.tui.measures_screens import CompareScreen, MeasuresScreen
from ladartui.tui.poses_screen import PosesScreen
from ladartui.tui.screens import FormScreen
from tui_support import LadarApp, loaded, make_scenario, screen_after, type_into, wait_until

SIZE = (100, 32)


@asynccontextmanager
async def opened(scenario, size=SIZE, notifications=False):
    """The app on ``scenario``, loaded: (app, pilot); ``notifications``: its notes drawn."""
    app = LadarApp(scenario.path)
    async with app.run_test(size=size, notifications=notifications) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        yield app, pilot


def message(screen, selector="#form-message") -> str:
    return str(screen.query_one(selector).render())


async def test_a_segment_form_names_the_point_field_that_is_wrong(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        app.action_show_tab("flight")
        app.action_add_segment("orbit")
        await pilot.pause()
        form = app.screen
        assert isinstance(form, FormScreen)
        centre, radius = form.query_one("#f-centre"), form.query_one("#f-radius")
        await type_into(pilot, centre, "a,b,c", commit="tab")
        form.query_one("#form-ok").press()
        await pilot.pause()
        # refused, naming the centre and what was typed there; the radius is not blamed
        assert app.screen is form and app.focused is centre
        said = message(form)
        assert said.startswith("Centre x,y,z m: a,b,c is not allowed; expected ") and "Radius" not in said
        assert not radius.has_class("-bad") and centre.has_class("-bad")
        await type_into(pilot, centre, "1,2,3,4", commit=None)
        form.query_one("#form-ok").press()
        await pilot.pause()
        assert message(form) == (
            "Centre x,y,z m: 1,2,3,4 is not allowed; expected x, y, z in metres (z 0 if left out)"
        )
        # 'x y' without commas said 'expected a number': spaces part the numbers too
        await type_into(pilot, centre, "10 20", commit=None)
        assert form.values()["centre"] == (10.0, 20.0, 0.0)
        await type_into(pilot, centre, "10, 20, 0", commit=None)
        # a limit is said in the field's unit, as the main form says it ("at most 1000 m/s")
        await type_into(pilot, radius, "-7", commit=None)
        form.query_one("#form-ok").press()
        await pilot.pause()
        assert message(form) == (
            "Radius m: -7 is not allowed; expected a number greater than 0 and at most 1000000 m"
        )
        await type_into(pilot, radius, "50", commit=None)
        # whole numbers are called so in every form, whatever the check's own words
        scans = form.query_one("#f-scans")
        for typed in ("x", "2.5", "0"):
            await type_into(pilot, scans, typed, commit=None)
            form.query_one("#form-ok").press()
            await pilot.pause()
            # with its range, letters too (they said only "a whole number")
            assert message(form) == f"Scans: {typed} is not allowed; expected a whole number from 1 to 10000"
        await type_into(pilot, scans, "6", commit=None)
        form.query_one("#form-ok").press()
        await pilot.pause()
        assert app.screen is not form
        assert app.scenario.flight.segments[-1].centre == (10.0, 20.0, 0.0)


async def test_an_empty_list_field_says_empty(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        app.action_show_tab("flight")
        app.action_add_segment("standoff")
        await pilot.pause()
        form = app.screen
        await type_into(pilot, form.query_one("#f-standoffs"), "", commit=None)
        form.query_one("#form-ok").press()
        await pilot.pause()
        assert app.screen is form
        assert message(form).startswith("Standoffs m: empty is not allowed; expected ")


async def test_the_poses_dialog_keeps_a_refused_value_and_ok_applies_the_row(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        app.action_manual_poses()
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, PosesScreen)
        x = screen.query_one("#p-x")
        await type_into(pilot, x, "xyz", commit="tab")
        # left marked with the text kept, and OK refuses, saying why
        assert x.value == "xyz" and x.has_class("-bad")
        screen.query_one("#poses-ok").press()
        await pilot.pause()
        assert app.screen is screen and app.focused is x
        assert (
            message(screen, "#poses-message")
            == "x m: xyz is not allowed; expected a number from -1000000 to 1000000 m"
        )
        screen.query_one("#pose-apply").press()
        await pilot.pause()
        assert app.screen is screen and x.value == "xyz"
        # a good value typed and not applied is not lost: OK applies the row first
        await type_into(pilot, x, "12.5", commit=None)
        screen.query_one("#poses-ok").press()
        await pilot.pause()
        assert app.screen is not screen
        assert app.scenario.flight.segments[-1].kind == "manual"
        assert app.scenario.flight.segments[-1].poses[0].x == 12.5


async def test_save_as_refuses_a_folder_and_clears_the_last_run_line(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    folder = tmp_path / "kept"
    folder.mkdir()
    async with opened(scenario) as (app, pilot):
        app.run_panel.say("Last run cancelled; nothing was written.")
        await app.run_action("save_as")
        await pilot.pause()
        dialog = app.screen
        assert isinstance(dialog, SaveAsScreen)
        for typed in (str(folder), "kept", "kept/"):
            dialog.query_one("#save-as-file").value = typed
            await pilot.press("enter")
            await pilot.pause()
            assert app.screen is dialog, typed
            said = message(dialog, "#save-as-message")
            assert said == f"{folder}: is a folder; expected a scenario file name", typed
        assert list(folder.iterdir()) == [] and not (tmp_path / "kept.toml").exists()
        # a place that cannot be written keeps the dialog open, the error naming the file
        dialog.query_one("#save-as-file").value = "/proc/a.toml"
        await pilot.press("enter")
        await pilot.pause()
        assert app.screen is dialog
        assert message(dialog, "#save-as-message").startswith("/proc/a.toml: cannot be written")
        dialog.query_one("#save-as-file").value = "kept/copy"
        await pilot.press("enter")
        await pilot.pause()
        assert app.scenario.path == folder / "copy.toml" and (folder / "copy.toml").is_file()
        # the run line was the old file's: the new one has not been run
        assert str(app.query_one("#run-info").render()) == ""


async def test_save_as_onto_a_name_with_outputs_shows_them_as_opening_it_would(tmp_path, scene_files):
    from ladartui.sensor import Sensor
    from ladartui.simulation import simulate
    from ladartui.tui.status import NOT_READY, StatusBar

    scenario = make_scenario(tmp_path, scene_files)
    other = make_scenario(tmp_path, scene_files, name="other")
    simulate(other.with_changes(sensor=Sensor(grid=12, ray_grid=1, fov=8.0)))  # other's outputs: 12 x 12
    async with opened(scenario) as (app, pilot):
        assert app.measures is None
        await app.run_action("save_as")
        await pilot.pause()
        app.screen.query_one("#save-as-file").value = "other"
        await pilot.press("enter")  # it exists: a second OK replaces it
        await pilot.pause()
        await pilot.press("enter")
        await wait_until(pilot, lambda: app.measures is not None)
        assert app.scenario.path == other.path and app.output_voxels is not None
        bar = app.query_one(StatusBar)
        assert bar.state == NOT_READY and bar.message == "other.toml: outputs out of date; F5 reruns."


async def test_markup_in_names_shows_as_typed_and_compare_reads_spaced_paths(tmp_path, scene_files):
    from rich.text import Text

    scenario = make_scenario(tmp_path, scene_files, name="[bold red]x y")
    async with opened(scenario) as (app, pilot):
        await app.run_action("run")
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen) and app.screen.is_mounted)
        title = app.screen.query_one(".dialog").border_title
        assert Text.from_markup(title).plain == "Comparison measures: [bold red]x y"
        await pilot.press("escape")
        await pilot.pause()
        # Compare offers this run's measures file, whose name has a space, and reads it
        compare = await screen_after(pilot, app.action_compare, CompareScreen)
        assert message(compare, "#compare-message") in ("", "Give two or more .cmf files to compare.")
        other = tmp_path / "other run.cmf"
        other.write_bytes(scenario.measures_file.read_bytes())
        field = compare.query_one("#cmf-files")
        field.value += " " + shlex.quote(str(other))
        await pilot.press("enter")
        await pilot.pause()
        assert message(compare, "#compare-message") == ""
        table = compare.query_one("#compare-table")
        assert [str(c.label) for c in table.columns.values()] == ["Measure", "[bold red]x y", "other run"]
        field.value = "'unclosed " + str(other)
        await pilot.press("enter")
        await pilot.pause()
        assert message(compare, "#compare-message").startswith(".cmf files: ")


def test_segment_words_read_as_english():
    from ladartui.flight import Manual, ScanPose
    from ladartui.tui import bridge
    from ladartui.tui.actions import palette_entries

    helps = {title: text for title, text, _ in palette_entries()}
    assert helps["Add orbit segment"].startswith("Append an orbit to")
    assert helps["Add straight segment"].startswith("Append a straight to")
    assert bridge.segment_summary(Manual((ScanPose(0.0, 0.0, 50.0),))) == "1 pose"
    assert bridge.segment_summary(Manual((ScanPose(0.0, 0.0, 50.0),) * 2)) == "2 poses"


async def test_the_help_fits_the_terminal_without_sideways_scrolling(tmp_path, scene_files):
    from ladartui.tui.screens import HelpScreen

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        for size in ((80, 24), (120, 40)):
            await pilot.resize_terminal(*size)
            await pilot.press("f1")
            await pilot.pause()
            assert isinstance(app.screen, HelpScreen)
            table = app.screen.query_one("DataTable")
            assert table.max_scroll_x == 0, size  # every action wraps within the view
            longest = max(app.screen.rows, key=lambda row: len(row[2]))
            index = [tuple(map(str, table.get_row_at(i))) for i in range(table.row_count)].index(longest)
            assert table.rows[table.ordered_rows[index].key].height > 1 or size == (120, 40)
            await pilot.press("end")
            await pilot.pause()
            assert table.scroll_x == 0
            await pilot.press("escape")
            await pilot.pause()


async def test_outputs_from_other_settings_are_said_to_be_out_of_date(tmp_path, scene_files):
    from ladartui.tui.status import NOT_READY, READY, StatusBar
    from tui_support import field

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        bar = app.query_one(StatusBar)
        await app.run_action("run")
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen) and app.screen.is_mounted)
        await pilot.press("escape")
        await pilot.pause()
        assert bar.state == READY and "before" not in bar.message
        info = app.query_one("#results-info")
        assert str(info.render()) == f"Measures of {scenario.name}:"
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "12")
        # the outputs and measures shown are the 8 x 8 run's: said in the bar and the tab
        assert bar.state == NOT_READY
        assert bar.message == f"{scenario.path.name} (modified): outputs out of date; F5 reruns."
        assert str(info.render()) == (
            f"Measures of {scenario.name}, from other settings: sensor.grid 8 (here 12). "
            f"The run's settings are in {scenario.name}_Run.toml."
        )
        # back to the settings that ran (undo): up to date again, though not yet saved
        await pilot.press("ctrl+z")
        await pilot.pause()
        assert bar.state == READY and "out of date" not in bar.message
        assert str(info.render()) == f"Measures of {scenario.name}:"
        # the backend and fast mode change nothing that a run writes
        app.set_scenario(app.scenario.with_changes(fast_mode=not app.scenario.fast_mode))
        await pilot.pause()
        assert bar.state == READY


async def test_outputs_a_run_made_from_unsaved_settings_are_out_of_date_on_opening(tmp_path, scene_files):
    from ladartui.sensor import Sensor
    from ladartui.simulation import simulate
    from ladartui.tui.status import NOT_READY, READY, StatusBar
    from tui_support import field

    scenario = make_scenario(tmp_path, scene_files)  # saved with an 8 x 8 grid
    simulate(scenario.with_changes(sensor=Sensor(grid=12, ray_grid=1, fov=8.0)))  # never saved
    async with opened(scenario) as (app, pilot):
        bar = app.query_one(StatusBar)
        assert bar.state == NOT_READY
        assert bar.message == f"{scenario.path.name}: outputs out of date; F5 reruns."
        info = app.query_one("#results-info")
        assert str(info.render()) == (
            f"Measures of {scenario.name}, from other settings: sensor.grid 12 (here 8). "
            f"The run's settings are in {scenario.name}_Run.toml."
        )
        files = str(app.query_one("#file-info").render())
        assert f"Run record    {scenario.name}_Run.toml" in files
        # typing the settings that ran makes them current again
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "12")
        assert bar.state == READY and "out of date" not in bar.message
        assert str(info.render()) == f"Measures of {scenario.name}:"


async def test_outputs_whose_scene_model_changed_since_their_run_are_out_of_date(tmp_path, scene_files):
    import shutil

    from ladartui.simulation import simulate
    from ladartui.tui.status import NOT_READY, READY, StatusBar

    scene_path, centre, voxel_size = scene_files
    for model in (scene_path, scene_path.with_name(f"{scene_path.stem}_Target.txt")):
        shutil.copy(model, tmp_path)  # the module's files stay as they are
    scenario = make_scenario(tmp_path, (tmp_path / scene_path.name, centre, voxel_size))
    simulate(scenario)
    with open(scenario.scene_file, "a", encoding="utf-8") as model:
        model.write("0,0,0\n")
    async with opened(scenario) as (app, pilot):
        said = f"Earlier outputs: the scene model {scene_path.name} changed since the run."
        assert said in app.messages
        # the settings are those that ran, the model is not: yellow until a rerun
        bar = app.query_one(StatusBar)
        assert bar.state == NOT_READY
        assert bar.message == f"{scenario.path.name}: outputs out of date; F5 reruns."
        assert str(app.query_one("#results-info").render()) == (
            f"Measures of {scenario.name}, from other inputs: the scene model {scene_path.name} "
            f"changed since the run. The run's settings are in {scenario.name}_Run.toml."
        )
        await app.run_action("run")
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen) and app.screen.is_mounted)
        assert bar.state == READY


async def test_outputs_replaced_since_their_run_are_said_to_be_so_on_opening(tmp_path, scene_files):
    """A scene output overwritten after its run was shown as the run's, without a word."""
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files)
    simulate(scenario)
    scenario.scene_output.write_text("1,1,1\n", encoding="utf-8")
    async with opened(scenario) as (app, pilot):
        said = (
            f"Earlier outputs: {scenario.scene_output.name} changed since the run wrote it: "
            "it is not the run's output."
        )
        assert said in app.messages


async def test_a_damaged_run_record_is_reported_and_the_outputs_still_shown(tmp_path, scene_files):
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files)
    simulate(scenario)
    record = scenario.path.with_name(f"{scenario.name}_Run.toml")
    record.write_text(record.read_text(encoding="utf-8") + "\n[sensor\n", encoding="utf-8")
    async with opened(scenario) as (app, pilot):
        assert app.measures is not None and app.output_voxels is not None
        said = [m for m in app.messages if record.name in m]
        assert said and "settings of the earlier run not read" in said[-1]


async def test_run_says_why_it_is_off_when_pressed(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        await wait_until(pilot, lambda: app.backend_rows is not None)
        panel = app.run_panel  # the backend the scenario names is not there
        panel.backend_rows = [
            (n, note, ok and n != app.scenario.backend) for n, note, ok in panel.backend_rows
        ]
        app.refresh_status()
        await pilot.press("f5")
        await pilot.pause()
        assert app.check_action("run", ()) is None and not app.run_in_progress()
        assert app.messages[-1] == f"Run is off: backend {app.scenario.backend} unavailable."


async def test_a_run_bound_to_be_refused_is_not_ready(tmp_path, scene_files):
    from ladartui.tui.status import NOT_READY, StatusBar

    scenario = make_scenario(tmp_path, scene_files)
    theirs = scenario.path.with_name(f"{scenario.name}_Run.toml")
    theirs.write_text("# my own notes\n", encoding="utf-8")
    async with opened(scenario) as (app, pilot):
        bar = app.query_one(StatusBar)
        assert bar.state == NOT_READY and "is not a run record" in bar.message
        await pilot.press("f5")
        await pilot.pause()
        assert not app.run_in_progress() and app.messages[-1].startswith("Run is off: ")
    assert theirs.read_text(encoding="utf-8") == "# my own notes\n"


async def test_opening_a_run_record_says_what_it_is_and_save_keeps_it(tmp_path, scene_files):
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files)
    simulate(scenario)
    record = scenario.path.with_name(f"{scenario.name}_Run.toml")
    before = record.read_bytes()
    async with opened(scenario.with_changes(path=record)) as (app, pilot):
        assert any("is a run record" in m and "Save As" in m for m in app.messages)
        await pilot.press("ctrl+s")
        await pilot.pause()
        assert "Not saved" in app.messages[-1] and "run record" in app.messages[-1]
    assert record.read_bytes() == before


async def test_reopening_the_file_being_edited_offers_no_save_that_would_be_lost(tmp_path, scene_files):
    # the sweep's F8 writes the best path over best.toml, then opens it: saving the
    # edits of best.toml there would replace the best path it had just written
    from ladartui.tui.unsaved import UnsavedScreen
    from tui_support import field

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "12")
        saved = scenario.path.read_bytes()
        app.open_path(scenario.path)
        await pilot.pause()
        dialog = app.screen
        assert isinstance(dialog, UnsavedScreen)
        assert not dialog.query("#unsaved-save") and dialog.query("#unsaved-discard")
        said = str(dialog.query_one("Static").render())
        assert said.startswith(f"{scenario.path.name} has unsaved edits, and opening it reads the file again")
        await pilot.press("escape")
        await pilot.pause()
        assert app.scenario.sensor.grid == 12 and scenario.path.read_bytes() == saved


async def test_a_committed_value_is_shown_and_named_as_a_number(tmp_path, scene_files):
    from tui_support import field

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        app.action_show_tab("sensor")
        grid = field(app, "sensor.grid")
        await type_into(pilot, grid, "1.2e1")
        assert app.scenario.sensor.grid == 12 and grid.value == "12"
        await pilot.press("ctrl+z")
        await pilot.pause()
        assert app.messages[-1].endswith("Sensor grid n 8 -> 12")


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


async def test_the_new_scenario_dialog_refuses_in_the_forms_words(tmp_path, scene_files):
    from ladartui.tui.file_dialogs import SetupScreen

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        dialog = await screen_after(pilot, "f2", SetupScreen)
        assert dialog.mode == "new"
        dialog.query_one("#setup-ok").press()
        await pilot.pause()
        assert (
            message(dialog, "#setup-message") == "Scenario file: empty is not allowed; expected a file name"
        )
        dialog.query_one("#scenario-file").value = "fresh.toml"
        dialog.query_one("#scene-file").value = str(scene_files[0])
        dialog.query_one("#voxel-size").value = "0"
        dialog.query_one("#setup-ok").press()
        await pilot.pause()
        assert message(dialog, "#setup-message") == (  # the limit in the label's unit, as in the forms
            "Voxel size m: 0 is not allowed; expected a number from 0.001 to 100 m"
        )


def test_compare_names_files_of_one_stem_apart_by_their_folders():
    from pathlib import Path

    from ladartui.measures_compare import column_names

    paths = [Path("home/default/default.cmf"), Path("w/d2/default.cmf"), Path("w/other.cmf")]
    assert column_names(paths) == ["default/default", "d2/default", "other"]
    assert column_names([Path("a/x.cmf"), Path("b/y.cmf")]) == ["x", "y"]


async def test_every_button_of_the_poses_dialog_is_on_screen(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    for size in ((80, 24), (120, 40)):
        async with opened(scenario, size=size) as (app, pilot):
            app.action_manual_poses()
            await pilot.pause()
            screen = app.screen
            assert isinstance(screen, PosesScreen)
            box = screen.query_one(".dialog").content_region
            for button in screen.query("Button"):
                region = button.region
                # Cancel was drawn past the dialog's right edge, out of sight
                assert region.width >= len(str(button.label)), (size, button.id)
                assert box.contains_region(region), (size, button.id, region, box)


def test_the_settings_that_made_the_outputs_are_named_in_a_sentence():
    from ladartui.tui.app import named_changes

    # a third change read "...; ...." before the next sentence
    assert named_changes(["a 1 (here 2)", "b 3 (here 4)", "c 5 (here 6)"]) == (
        ": a 1 (here 2); b 3 (here 4); and 1 more"
    )
    assert named_changes(["a 1 (here 2)"]) == ": a 1 (here 2)"
    assert named_changes([]) == ""


def test_the_png_and_compare_dialogs_name_what_is_wrong(tmp_path):
    """A width of 0 was 'picture size = ...' (no field of the dialog has that name, so the
    error stood under none); Compare called a folder 'measures file not found'."""
    import pytest

    from ladartui.errors import FieldError, InputFileError
    from ladartui.measures_compare import read_measures_files
    from ladartui.tui import bridge

    with pytest.raises(FieldError) as caught:
        bridge.image_size({"width": "0", "height": "300"})
    assert caught.value.field == "width"
    assert str(caught.value) == "width = 0: expected a whole number of pixels from 16 to 8192"
    with pytest.raises(FieldError) as caught:
        bridge.image_size({"width": "400", "height": "tall"})
    assert caught.value.field == "height" and "'tall'" in str(caught.value)
    with pytest.raises(InputFileError) as caught:
        read_measures_files([tmp_path])
    assert (
        str(caught.value) == f"{tmp_path}: is a folder; expected a .cmf measures file or a scenario (.toml)"
    )
    with pytest.raises(InputFileError) as caught:
        read_measures_files([tmp_path / "gone.cmf"])
    assert str(caught.value) == f"{tmp_path / 'gone.cmf'}: measures file not found"
    import os

    os.mkfifo(tmp_path / "pipe.cmf")  # it exists: not 'not found'
    with pytest.raises(InputFileError) as caught:
        read_measures_files([tmp_path / "pipe.cmf"])
    assert (
        str(caught.value)
        == f"{tmp_path / 'pipe.cmf'}: measures file is not a regular file (a pipe or device)"
    )
    with pytest.raises(InputFileError) as caught:
        bridge.new_scenario(tmp_path / "new.toml", tmp_path / "pipe.cmf")
    assert (
        str(caught.value)
        == f"{tmp_path / 'pipe.cmf'}: scene model file is not a regular file (a pipe or device)"
    )
