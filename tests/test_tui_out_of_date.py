"""Outputs out of date are said so wherever their measures are shown, and why in the
truest words: the Measures dialog (F9) as the Results tab and the status bar do."""

from __future__ import annotations

from ladartui.sensor import Sensor
from ladartui.simulation import simulate
from ladartui.tui.measures_screens import MeasuresScreen
from tui_support import make_scenario, opened, wait_until


def stale_note(screen) -> str:
    notes = screen.query("#measures-stale")
    return str(notes.first().render()) if notes and notes.first().display else ""


async def test_the_measures_dialog_says_when_its_measures_are_out_of_date(tmp_path, scene_files):
    """F9 showed the measures of a run with other settings with no word of it, while
    the status bar was yellow and the Results tab named the setting."""
    scenario = make_scenario(tmp_path, scene_files)  # saved with an 8 x 8 grid
    simulate(scenario.with_changes(sensor=Sensor(grid=12, ray_grid=1, fov=8.0)))  # never saved
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        await pilot.press("f9")
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen), timeout=10.0)
        screen = app.screen
        assert str(screen.query_one(".dialog").border_title) == "Comparison measures (out of date)"
        assert stale_note(screen) == (
            "Out of date: made from other settings: sensor.grid 12 (here 8). "
            f"The run's settings are in {scenario.name}_Run.toml. F5 reruns."
        )
        await pilot.press("escape")
        await app.run_action("run")  # up to date: nothing more is said
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen) and app.screen.is_mounted)
        await pilot.pause()
        assert "out of date" not in str(app.screen.query_one(".dialog").border_title)
        assert stale_note(app.screen) == ""


async def test_a_model_changed_on_disk_since_opening_is_said_so_not_changed_since_the_run(
    tmp_path, scene_files
):
    """The scene model edited while the app had it open, then run by the CLI: reading that
    run's outputs, the app called them out of date, 'the scene model changed since the
    run', and offered F5, which would have run its old copy of the model."""
    import shutil

    from ladartui.scenario import load_scenario
    from ladartui.tui.status import NOT_READY, StatusBar

    scene_path, centre, voxel_size = scene_files
    for model in (scene_path, scene_path.with_name(f"{scene_path.stem}_Target.txt")):
        shutil.copy(model, tmp_path)  # the module's files stay as they are
    scenario = make_scenario(tmp_path, (tmp_path / scene_path.name, centre, voxel_size))
    async with opened(scenario) as (app, pilot):
        with open(scenario.scene_file, "a", encoding="utf-8") as model:
            model.write("0,0,0\n")
        simulate(load_scenario(scenario.path))  # the CLI's run, of the model as it is now
        app.check_outputs_on_disk()
        said = f"the scene model {scene_path.name} changed on disk since it was opened"
        await wait_until(pilot, lambda: any(said in m for m in app.messages), timeout=60.0)
        await pilot.pause()
        assert not any("changed since the run" in m for m in app.messages), app.messages
        bar = app.query_one(StatusBar)
        assert bar.state == NOT_READY
        assert bar.message == f"{scenario.path.name}: {scene_path.name} changed on disk; reopen to read it."
        info = str(app.query_one("#results-info").render())
        assert f"other inputs: {said} (reopen to read it)." in info, info
        await pilot.press("f9")  # the measures dialog says the same, and offers no rerun
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen), timeout=10.0)
        note = stale_note(app.screen)
        assert f"{said} (reopen to read it)." in note and "F5" not in note, note
        # F5 runs the app's own copy: the model on disk is still not the one run
        await pilot.press("escape")
        await app.run_action("run")
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen), timeout=120.0)
        await pilot.press("escape")
        await pilot.pause()
        assert bar.state == NOT_READY
        assert bar.message == f"{scenario.path.name}: {scene_path.name} changed on disk; reopen to read it."


async def test_a_model_edited_on_disk_while_open_is_said_so_before_any_other_run(tmp_path, scene_files):
    """The scene model edited while the app had it open, and no other run since: the bar
    stayed green, and F5 ran the app's old copy, recorded it as the run's model and still
    said ready, while validate called those fresh outputs out of date."""
    import shutil

    from ladartui.tui.status import NOT_READY, READY, StatusBar

    scene_path, centre, voxel_size = scene_files
    for model in (scene_path, scene_path.with_name(f"{scene_path.stem}_Target.txt")):
        shutil.copy(model, tmp_path)  # the module's files stay as they are
    scenario = make_scenario(tmp_path, (tmp_path / scene_path.name, centre, voxel_size))
    simulate(scenario)  # outputs of the model as opened
    async with opened(scenario) as (app, pilot):
        bar = app.query_one(StatusBar)
        await look_at_disk(app, pilot)
        assert bar.state == READY, bar.message
        text = scenario.scene_file.read_bytes()
        with open(scenario.scene_file, "a", encoding="utf-8") as model:
            model.write("0,0,0\n")
        await look_at_disk(app, pilot)
        said = f"{scenario.path.name}: {scene_path.name} changed on disk; reopen to read it."
        assert (bar.state, bar.message) == (NOT_READY, said)
        assert any(f"{scene_path.name} changed on disk" in m for m in app.messages), app.messages
        info = str(app.query_one("#results-info").render())
        assert f"the scene model {scene_path.name} changed on disk since it was opened" in info, info
        await app.run_action("run")  # runs the app's copy: the model on disk is still another
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen), timeout=120.0)
        await pilot.press("escape")
        await look_at_disk(app, pilot)
        assert (bar.state, bar.message) == (NOT_READY, said)
        scenario.scene_file.write_bytes(text)  # put back as it was opened
        await look_at_disk(app, pilot)
        assert bar.state == READY, bar.message


async def look_at_disk(app, pilot) -> None:
    """The app's timed look at the files on disk, now, its hashing job done."""
    from ladartui.tui.work import running

    app.check_outputs_on_disk()
    await wait_until(pilot, lambda: not running(app.inputs_worker))
    await pilot.pause()
