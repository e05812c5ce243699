"""Earlier outputs and run records as the app opens and shows them: out of date for
other settings (typed, saved over or never saved) or a scene model changed since their
run, replaced since their run, a damaged or foreign run record, a run record opened;
and Run off saying why.

Each test drives a real app on a tiny generated scene with Pilot.
"""

from __future__ import annotations

from ladartui.tui.measures_screens import MeasuresScreen
from tui_support import make_scenario, opened, type_into, wait_until


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


def test_the_settings_that_made_the_outputs_are_named_in_a_sentence():
    from ladartui.tui.app import named_changes

    # a third change read "...; ...." before the next sentence
    assert named_changes(["a 1 (here 2)", "b 3 (here 4)", "c 5 (here 6)"]) == (
        ": a 1 (here 2); b 3 (here 4); and 1 more"
    )
    assert named_changes(["a 1 (here 2)"]) == ": a 1 (here 2)"
    assert named_changes([]) == ""


async def test_the_bar_warns_of_a_path_whose_scans_never_look_at_the_target(tmp_path, scene_files):
    """Aimed past the target, a path ran to 0 % with the bar green; validate said why."""
    from ladartui.flight import FlightPlan, Orbit
    from ladartui.tui.status import NOT_READY, READY, StatusBar
    from ladartui.view_reach import reach_notes

    scenario = make_scenario(tmp_path, scene_files)
    orbit = Orbit(centre=(0.5, 15.5, 0.0), radius=20.0, altitude=30.0, scans=6, aim_at=(15.5, 15.5, 0.0))
    away = scenario.with_changes(flight=FlightPlan(None, (orbit,))).save()
    (note,) = reach_notes(away, away.load_scene())
    assert note.startswith("none of the 6 scans looks at the target")
    async with opened(away) as (app, pilot):
        bar = app.query_one(StatusBar)
        await wait_until(pilot, lambda: app.scene is not None and app.busy is None and note in bar.message)
        assert bar.state == NOT_READY and bar.message == f"demo.toml: {note}; F5 runs anyway."
        app.set_scenario(scenario)  # aimed at it: ready
        await pilot.pause()
        assert bar.state == READY and bar.message.startswith("demo.toml (modified): 6 scans")
        app.set_scenario(away)
        await wait_until(pilot, lambda: note in bar.message)
        assert bar.state == NOT_READY
        await app.run_action("run")  # a warning, not a refusal
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen) and app.screen.is_mounted)


async def test_an_edit_the_reach_notes_do_not_read_keeps_the_bar_note_without_a_new_search(
    tmp_path, scene_files, monkeypatch
):
    """The note is found again for a new path, sensor, speed, target names or scene, not
    for an edit of a field it does not read (the step): no second search in a thread."""
    from ladartui import view_reach
    from ladartui.flight import FlightPlan, Orbit
    from ladartui.tui.status import NOT_READY, StatusBar

    scenario = make_scenario(tmp_path, scene_files)
    orbit = Orbit(centre=(0.5, 15.5, 0.0), radius=20.0, altitude=30.0, scans=6, aim_at=(15.5, 15.5, 0.0))
    away = scenario.with_changes(flight=FlightPlan(None, (orbit,))).save()
    searches = []
    reach_notes = view_reach.reach_notes
    monkeypatch.setattr(
        view_reach, "reach_notes", lambda *args, **kw: searches.append(args) or reach_notes(*args, **kw)
    )
    async with opened(away) as (app, pilot):
        bar = app.query_one(StatusBar)
        await wait_until(
            pilot, lambda: app.scene is not None and app.busy is None and "looks at" in bar.message
        )
        assert len(searches) == 1
        note = bar.message.split(": ", 1)[1]
        app.set_scenario(away.with_changes(step=away.step * 2))
        await pilot.pause()
        await pilot.pause()
        assert bar.state == NOT_READY and note in bar.message
        assert len(searches) == 1
        app.set_scenario(away.with_changes(speed=away.speed * 2))  # read by the notes: found again
        await wait_until(pilot, lambda: len(searches) == 2)
