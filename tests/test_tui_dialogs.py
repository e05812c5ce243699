"""The app's dialogs as an analyst meets them: what a refused value says and where
(earlier outputs and run records: test_tui_earlier_outputs.py; the flight tab's tables:
test_tui_flight_tables.py).

Each test drives a real app on a tiny generated scene with Pilot.
"""

from __future__ import annotations

import shlex

from ladartui.tui.file_dialogs import SaveAsScreen
from ladartui.tui.measures_screens import CompareScreen, MeasuresScreen
from ladartui.tui.poses_screen import PosesScreen
from ladartui.tui.screens import FormScreen
from tui_support import make_scenario, opened, screen_after, type_into, wait_until


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


async def test_compare_notes_a_scenario_edited_since_its_run(tmp_path, scene_files):
    """A scenario's path typed in Compare stood for its last run's measures without a word
    when the file had been changed since, as ``ladartui compare`` did."""
    scenario = make_scenario(tmp_path, scene_files, name="orbit")
    async with opened(scenario) as (app, pilot):
        await app.run_action("run")
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen) and app.screen.is_mounted)
        await pilot.press("escape")
        await pilot.pause()
        other = tmp_path / "other.cmf"
        other.write_bytes(scenario.measures_file.read_bytes())
        compare = await screen_after(pilot, app.action_compare, CompareScreen)
        compare.query_one("#cmf-files").value = f"orbit.toml {other}"
        await pilot.press("enter")
        await pilot.pause()
        assert message(compare, "#compare-message") == ""  # as it ran: nothing to say
        text = scenario.path.read_text()
        scenario.path.write_text(text.replace("radius = 30.0", "radius = 45.0"))
        await pilot.press("enter")
        await pilot.pause()
        assert message(compare, "#compare-message") == (
            f"Note: {scenario.path}: its measures are its last run's, made with other settings than "
            "this file: flight.segments[0].radius 30 (here 45); run it again to compare these"
        )
        assert len(compare.query_one("#compare-table").columns) == 3  # compared all the same


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


def test_new_on_a_survey_s_point_cloud_gives_the_command_that_makes_a_scene_of_it(tmp_path):
    """New's form given a survey's .las as the scene model said only 'expected a scene
    model (.txt)', where the scenario check gives the voxelize command."""
    import pytest

    from ladartui.errors import InputFileError
    from ladartui.tui import bridge

    cloud = tmp_path / "survey.las"
    cloud.write_bytes(b"LASF")
    with pytest.raises(InputFileError) as caught:
        bridge.new_scenario(tmp_path / "new.toml", cloud, 0.5)
    assert str(caught.value) == (
        f"{cloud}: scene model file is a LAS point cloud (.las); expected a scene model (.txt): make one "
        f"from it with 'ladartui voxelize {cloud} {tmp_path / 'survey'} --voxel-size 0.5'"
    )


async def test_the_unsaved_question_keeps_a_file_names_newline_on_its_line():
    """What was being done named a file whose name holds a newline: the question broke
    in two there. Both the name and what is being done are written out on one line."""
    from textual.app import App

    from ladartui.tui.unsaved import QuitRunScreen, UnsavedScreen

    app = App()
    async with app.run_test(size=(200, 24)) as pilot:
        app.push_screen(UnsavedScreen("a\nb.toml", "open /tmp/c\nd.toml"))
        await pilot.pause()
        said = str(app.screen.query_one("Static").render())
        assert said == "a\\x0ab.toml has unsaved edits. Save them before you open /tmp/c\\x0ad.toml?", said
        app.pop_screen()
        app.push_screen(QuitRunScreen("a\x1b[31mb.toml", None))
        await pilot.pause()
        said = str(app.screen.query_one("#quit-run-question").render())
        assert said.startswith("A run of a\\x1b[31mb.toml is going on. Quit"), said
