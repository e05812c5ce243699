"""The scenario on screen is the scenario that runs and is saved; file text is never markup.

Pilot tests on a tiny generated scene: a value typed but not confirmed with
Enter is committed by Run and Save (or stops them when invalid), an invalid
value goes back to the scenario's value, and names or lines read from files
are shown literally. Also what is typed in dialogs is kept (poses, points,
partial paths), the palette waits under a prompt, unsaved edits are asked
about (the user's keys.toml: test_tui_keys.py; outputs changed on disk:
test_tui_outputs_on_disk.py; the status line fitting its name:
test_tui_text_fit.py).
"""

from __future__ import annotations

import shutil

from ladartui.scenario import load_scenario, target_file_for
from ladartui.tui.status import StatusBar
from tui_support import LadarApp, field, loaded, make_scenario, screen_after, type_into, wait_until

SIZE = (100, 32)


def copy_scene(source, scene) -> None:
    """Copy a scene model and its target model (``X.txt`` and ``X_Target.txt``)."""
    shutil.copy(source, scene)
    shutil.copy(target_file_for(source), target_file_for(scene))


def capture_runs(app) -> list:
    """Replace the run worker by a recorder of the scenario it would run."""
    runs = []
    app._run_worker = lambda scenario, scene, fast: runs.append(scenario)
    return runs


async def test_a_value_typed_without_enter_is_used_by_run(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        runs = capture_runs(app)
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "12", commit=None)
        await pilot.press("f5")
        await pilot.pause()
        assert [run.sensor.grid for run in runs] == [12]


async def test_a_run_after_a_voxel_size_edit_still_reads_and_records_the_model_files(tmp_path, scene_files):
    """A run's record fingerprints the models it read, so that a later change to them
    puts its outputs out of date; a new voxel size rescales the scene, not its files."""
    from ladartui.run_record import run_inputs

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        runs = []
        app._run_worker = lambda scenario, scene, fast: runs.append((scenario, scene))
        app.action_show_tab("run")
        await type_into(pilot, field(app, "scenario.voxel_size"), "0.3")
        await pilot.press("f5")
        await pilot.pause()
        [(ran, scene)] = runs
        assert ran.voxel_size == scene.voxel_size == 0.3
        assert sorted(entry.role for entry in run_inputs(ran, scene)) == ["scene model", "target model"]


async def test_a_value_typed_without_enter_is_what_ctrl_s_saves(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "12", commit=None)
        await pilot.press("ctrl+s")
        await pilot.pause()
        assert load_scenario(scenario.path).sensor.grid == 12
        assert field(app, "sensor.grid").value == "12"
        assert "(modified)" not in app.query_one(StatusBar).message
        await type_into(pilot, field(app, "sensor.grid"), "16")
        assert "(modified)" in app.query_one(StatusBar).message


async def test_an_invalid_value_typed_stops_run_and_save_and_focuses_the_field(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    before = scenario.path.read_bytes()
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        runs = capture_runs(app)
        app.action_show_tab("sensor")
        grid = field(app, "sensor.grid")
        await type_into(pilot, grid, "0", commit=None)
        for key in ("f5", "ctrl+s"):
            app.messages.clear()
            await pilot.press(key)
            await pilot.pause()
            assert app.focused is grid
            assert "grid" in app.messages[-1] and "0" in app.messages[-1]
        assert runs == []
        assert scenario.path.read_bytes() == before
        assert grid.value == "0"  # the typed text stays for the analyst to correct


async def test_run_stopped_by_a_typed_value_names_the_field_as_the_form_does(tmp_path, scene_files):
    """F5 over a value typed without Enter says what Enter would: the form's label, the text
    typed and the limits in the field's unit, not the file's key in metres."""
    app = LadarApp(make_scenario(tmp_path, scene_files).path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.pixel_pitch"), "50000", commit=None)
        await pilot.press("f5")
        await pilot.pause()
        assert app.messages[-1] == (
            "Not done: invalid value: Pixel pitch um: 50000 is not allowed; expected a number "
            "from 0.1 to 10000 um. Correct the value and try again."
        )


async def test_an_invalid_value_goes_back_to_the_scenarios_value(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files, grid=8, ray_grid=2)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("sensor")
        grid = field(app, "sensor.grid")
        await type_into(pilot, grid, "0")
        assert grid.value == "8" and app.scenario.sensor.grid == 8  # not the default 128
        assert not app.modified
        assert "8" in app.messages[-1]
        ray_grid = field(app, "sensor.ray_grid")
        await type_into(pilot, ray_grid, "x", commit="tab")
        assert ray_grid.value == "2" and app.scenario.sensor.ray_grid == 2


async def test_a_voxel_line_that_looks_like_markup_is_shown_not_parsed(tmp_path, scene_files):
    scene = tmp_path / "odd.txt"
    copy_scene(scene_files[0], scene)
    with scene.open("a") as out:
        out.write("[/oops],1,2\n")
    scenario = make_scenario(tmp_path, (scene, *scene_files[1:]))
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: any("[/oops]" in m for m in app.messages))
        await pilot.pause()
        assert "[/oops]" in str(app.query_one("#run-info").render())


async def test_a_file_name_that_looks_like_markup_is_shown_literally(tmp_path, scene_files):
    scene = tmp_path / "[@click=app.quit]x.txt"
    copy_scene(scene_files[0], scene)
    scenario = make_scenario(tmp_path, (scene, *scene_files[1:]))
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        info = app.query_one("#file-info")
        assert "[@click=app.quit]x.txt" in str(info.render())
        await pilot.click("#file-info", offset=(20, 2))
        await pilot.pause()
        assert app.is_running


async def test_quit_new_and_open_with_unsaved_edits_ask_first(tmp_path, scene_files):
    from ladartui.tui.file_dialogs import SetupScreen
    from ladartui.tui.unsaved import UnsavedScreen

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "12")
        for key in ("ctrl+q", "f2", "f3"):
            await pilot.press(key)
            await pilot.pause()
            assert isinstance(app.screen, UnsavedScreen), key
            await pilot.click("#unsaved-cancel")
            await pilot.pause()
            assert app.is_running and not isinstance(app.screen, UnsavedScreen)
        # the sweep screen's "open best path" asks too, and cancelling keeps the edit
        from ladartui.tui.sweep_screen import SweepScreen

        other = make_scenario(tmp_path, scene_files, name="best")
        app.post_message(SweepScreen.OpenScenario(other.path))
        await pilot.pause()
        assert isinstance(app.screen, UnsavedScreen)
        await pilot.click("#unsaved-cancel")
        await pilot.pause()
        assert app.scenario.path == scenario.path and app.scenario.sensor.grid == 12
        # from the sweep screen itself: Cancel goes back to it, not to the main screen
        sweep = await screen_after(pilot, "f12", SweepScreen)
        await screen_after(
            pilot, lambda: sweep.post_message(SweepScreen.OpenScenario(other.path)), UnsavedScreen
        )
        await pilot.click("#unsaved-cancel")
        await pilot.pause()
        assert app.screen is sweep and app.tool_screen is sweep
        await pilot.press("escape")
        await pilot.pause()
        await pilot.press("f3")
        await pilot.pause()
        await pilot.click("#unsaved-discard")
        await pilot.pause()
        assert isinstance(app.screen, SetupScreen)
        await pilot.press("escape")
        await pilot.pause()
        await pilot.press("ctrl+q")
        await pilot.pause()
        await pilot.click("#unsaved-save")
        await pilot.pause()
        assert not app.is_running
    assert load_scenario(scenario.path).sensor.grid == 12


async def test_quit_without_edits_does_not_ask(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        await pilot.press("ctrl+q")
        await pilot.pause()
        assert not app.is_running


def test_a_value_typed_in_other_units_is_saved_as_typed():
    """A pitch of 50 um typed in the form was saved as 49.99999999999999: 50 * 1e-6 is
    not the double nearest 50 um, so the file could not write it back as 50."""
    from ladartui.scenario_writer import _to_micrometres
    from ladartui.tui.fields import format_number, parse_number

    for typed in ("50", "57", "0.3", "12.3", "100", "9999"):
        metres = parse_number("pixel_pitch", typed, scale=1e-6)
        assert _to_micrometres(metres) == float(typed), typed
        assert format_number(metres, scale=1e-6) == f"{float(typed):g}"


async def test_the_palette_over_a_prompt_offers_none_of_the_apps_commands(tmp_path, scene_files):
    """With the Save/Discard prompt open, the palette still offered Run, Open, New..."""
    from ladartui.tui.app import palette_entries
    from ladartui.tui.unsaved import UnsavedScreen

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        ours = {title for title, _, _ in palette_entries(app)}
        offered = {command.title for command in app.get_system_commands(app.screen)}
        assert ours <= offered  # the main screen offers every command
        await type_into(pilot, field(app, "sensor.grid"), "12")
        await pilot.press("f3")
        await pilot.pause()
        assert isinstance(app.screen, UnsavedScreen)
        offered = {command.title for command in app.get_system_commands(app.screen)}
        assert not ours & offered and "Screenshot" in offered  # Textual's own stay
        assert "Quit" not in offered  # it would ask the same question again


async def test_a_palette_command_that_is_off_says_why(tmp_path, scene_files):
    """Save from the palette during a run did nothing and said nothing, where its key
    says it is off while the run goes on."""
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        commands = {command.title: command for command in app.get_system_commands(app.screen)}
        app.set_busy("Working...")
        await pilot.pause()
        commands["Save scenario"].callback()
        await pilot.pause()
        assert app.messages[-1] == "Save scenario is off while busy: Working..."
        app.set_busy(None)
        await pilot.pause()


def test_the_new_scenario_preview_takes_any_partial_path():
    """Typing '/' as the scene model ended the app: Path('/') has an empty name."""
    from pathlib import Path

    from ladartui.tui import bridge

    for scenario, scene in [(None, Path("/")), (Path("/"), Path("x.txt")), (Path("/"), Path("/"))]:
        names = dict(bridge.derived_names(scenario, scene))
        assert len(names) == 5
        if scene == Path("/"):
            assert names["3D target model"] == "(from the scene model)"
        if scenario == Path("/"):
            assert names["Comparison measures"] == "(from the scenario file)"
    names = dict(bridge.derived_names(Path("/tmp/a.toml"), Path("/tmp/x.txt")))
    assert names["3D target model"] == "x_Target.txt" and names["Comparison measures"] == "a.cmf"


def test_a_point_or_list_with_an_empty_part_is_refused_not_shortened():
    """'29.881,,0.926' was taken as (29.881, 0.926, 0): every scan moved."""
    import pytest

    from ladartui.errors import FieldError
    from ladartui.tui.screens import _parse_points

    for kind, text in [("point", "29.881,,0.926"), ("points", "50,,100"), ("points", ",50")]:
        with pytest.raises(FieldError) as caught:
            _parse_points("centre", text, kind)
        assert "empty" in caught.value.expected
    assert _parse_points("centre", "1, 2, 3,", "point") == (1.0, 2.0, 3.0)  # a trailing comma
    assert _parse_points("centre", "1; 2", "point") == (1.0, 2.0, 0.0)
    assert _parse_points("standoffs", "50, 100", "points") == (50.0, 100.0)


def test_the_app_ending_on_an_error_exits_non_zero(monkeypatch, tmp_path, scene_files, capsys):
    """A crash in the interface (the traceback screen) exited 0, as if all went well.
    The real app runs (headless) on a scenario; once mounted, a callback raises, as a
    handler with a bug would, or the app quits as the user would."""
    from ladartui import tui
    from ladartui.tui.app import LadarApp

    scenario = make_scenario(tmp_path, scene_files)
    real_run, real_mount = LadarApp.run, LadarApp.on_mount
    monkeypatch.setattr(LadarApp, "run", lambda self: real_run(self, headless=True, size=SIZE))

    def ends_by(then):
        def on_mount(self):
            real_mount(self)
            self.call_after_refresh(then, self)

        monkeypatch.setattr(LadarApp, "on_mount", on_mount)
        code = tui.run_app(scenario.path, "characters")  # (no terminal to ask)
        return code, capsys.readouterr().err

    def handler_with_a_bug(app):
        raise RuntimeError("a bug in a handler")

    code, said = ends_by(handler_with_a_bug)
    assert code == 1 and "a bug in a handler" in said
    assert ends_by(lambda app: app.exit()) == (0, "")


async def test_the_poses_dialog_keeps_what_is_typed_across_add_and_rows(tmp_path, scene_files):
    """z typed and then Add: the new row copied the old z and the typed one was lost; so
    was an edit when another row was clicked. A fixed value's error stayed on screen, and
    OK with every pose deleted closed the dialog, changing nothing."""
    from ladartui.tui.poses_screen import PosesScreen

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_manual_poses()
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, PosesScreen)
        z = screen.query_one("#p-z")
        await type_into(pilot, z, "99", commit=None)
        screen.query_one("#pose-add").press()
        await pilot.pause()
        assert [p.z for p in screen.poses] == [99.0, 99.0]
        table = screen.query_one("#poses-table")
        await type_into(pilot, z, "70", commit=None)  # row 2, then row 1 chosen
        table.move_cursor(row=0)
        await pilot.pause()
        assert [p.z for p in screen.poses] == [99.0, 70.0] and z.value == "99"
        message = screen.query_one("#poses-message")
        await type_into(pilot, z, "", commit="tab")
        assert "empty" in str(message.render())
        await type_into(pilot, z, "80", commit=None)
        assert str(message.render()) == ""  # fixed: the error goes
        for _ in range(2):
            screen.query_one("#pose-delete").press()
            await pilot.pause()
        assert screen.poses == []
        screen.query_one("#poses-ok").press()
        await pilot.pause()
        assert app.screen is screen and "at least one pose" in str(message.render())
        # with none left, what is typed makes the one row: Add does not copy it again
        await type_into(pilot, z, "42", commit=None)
        screen.query_one("#pose-add").press()
        await pilot.pause()
        assert [p.z for p in screen.poses] == [42.0]
        screen.query_one("#pose-delete").press()
        await pilot.pause()
        await type_into(pilot, z, "43", commit=None)
        screen.query_one("#poses-ok").press()  # OK keeps it too
        await pilot.pause()
        assert app.screen is not screen and app.scenario.flight.segments[-1].poses[0].z == 43.0


async def test_switching_the_setup_dialogs_mode_clears_the_other_modes_error(tmp_path, scene_files):
    from ladartui.tui.file_dialogs import SetupScreen

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        await pilot.press("f3")
        await pilot.pause()
        dialog = app.screen
        assert isinstance(dialog, SetupScreen) and dialog.mode == "load"
        dialog.query_one("#scenario-file").value = "missing.toml"
        dialog.query_one("#setup-ok").press()
        await pilot.pause()
        message = dialog.query_one("#setup-message")
        assert "missing.toml" in str(message.render())
        dialog.query_one("#mode-new").value = True
        await pilot.pause()
        assert dialog.mode == "new" and str(message.render()) == ""


async def test_the_palette_on_the_sweep_and_study_screens_finds_their_actions(tmp_path, scene_files):
    """Ctrl+P on the sweep screen found no sweep action ("rank", "run": no matches), where
    the help screen says Ctrl+P finds any action; the study screen's were missing too."""
    from ladartui.tui.study_screen import StudyScreen
    from ladartui.tui.sweep_screen import SweepScreen

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        sweep = await screen_after(pilot, "f12", SweepScreen)
        commands = {command.title: command for command in app.get_system_commands(sweep)}
        for title in ("Sweep: Run", "Sweep: Rank by", "Sweep: Cost", "Sweep: View", "Sweep: Back"):
            assert title in commands, sorted(commands)
        assert "Run simulation" not in commands and "Sweep: Cancel" not in commands  # nothing runs
        assert commands["Sweep: Rank by"].help == "F6"  # the key it has here
        objective = sweep.objective
        commands["Sweep: Rank by"].callback()
        await pilot.pause()
        assert sweep.objective != objective  # what F6 does
        commands["Sweep: View"].callback()
        await pilot.pause()
        assert sweep.view == "table"
        commands["Sweep: Back"].callback()
        await pilot.pause()
        assert app.screen is not sweep
        study = await screen_after(pilot, "f11", StudyScreen)
        titles = {command.title for command in app.get_system_commands(study)}
        assert {"Study: Quick study", "Study: Full study", "Study: Back"} <= titles
        await pilot.press("escape")
        await pilot.pause()
