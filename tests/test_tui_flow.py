"""The terminal UI driven by a Pilot on one shared app: a scenario opened with every
field filled, values refused and kept, a missing model or outputs, flight segments and
manual poses, Compare, help and the palette, and the study and sweep screens' keys
(a run from setup: test_tui_run.py; the views: test_tui_view_controls.py).

Every test runs on a tiny generated scene (seeded) in tmp_path.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import pytest_asyncio

from ladartui.measures import Measures
from ladartui.scenario import load_scenario
from ladartui.tui.canvas import TopViewWidget
from ladartui.tui.file_dialogs import SetupScreen
from ladartui.tui.host import AppHost
from ladartui.tui.measures_screens import CompareScreen
from ladartui.tui.screens import FormScreen, HelpScreen
from ladartui.tui.status import NOT_READY, READY
from tui_support import (
    LadarApp,
    field,
    fresh,
    loaded,
    make_scenario,
    shared_app,
    status,
    type_into,
    wait_until,
)


@pytest_asyncio.fixture(loop_scope="module", scope="module")
async def shared(tmp_path_factory, scene_files):
    """One app for the tests that do not run a simulation (each starts from ``fresh``)."""
    async with shared_app(tmp_path_factory.mktemp("shared"), scene_files) as pilot_and_scenario:
        yield pilot_and_scenario


@pytest.mark.asyncio(loop_scope="module")
async def test_opens_a_scenario_ready_and_fills_every_field(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    assert status(app).state == READY
    assert field(app, "sensor.grid").value == "8"
    assert field(app, "sensor.fov").value == "8"
    assert field(app, "scenario.voxel_size").value == "0.25"
    assert field(app, "sensor.pixel_pitch").value == "100"  # micrometres
    assert app.query_one("#scans").row_count == 6
    assert app.query_one(TopViewWidget).top is not None


@pytest.mark.asyncio(loop_scope="module")
async def test_the_app_has_everything_its_parts_are_declared_to_use(shared):
    # tui/host.py declares what the mixins and panels use of the app: the type
    # checker holds the app's methods to it, this holds its attributes
    pilot, app = await fresh(shared)
    declared = list(vars(AppHost)["__annotations__"])
    assert "scene" in declared and "view_area" in declared
    assert [name for name in declared if not hasattr(app, name)] == []
    assert AppHost not in type(app).__mro__  # a declaration only: no App between the mixins


@pytest.mark.asyncio(loop_scope="module")
async def test_invalid_values_go_back_to_the_scenarios_value_with_a_message(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    app.action_show_tab("sensor")
    grid = field(app, "sensor.grid")
    await type_into(pilot, grid, "0")
    # the scenario's 8, not Sensor's default 128
    assert grid.value == "8" and app.scenario.sensor.grid == 8
    assert "grid" in app.messages[-1] and "expected" in app.messages[-1]
    fov = field(app, "sensor.fov")
    await type_into(pilot, fov, "abc", commit="tab")  # leaving the field commits too
    assert fov.value == "8" and app.scenario.sensor.fov == 8.0
    # the message speaks the form's words: the label, its unit and the range in that unit
    assert "Field of view deg: abc is not allowed" in app.messages[-1]
    pitch = field(app, "sensor.pixel_pitch")
    await type_into(pilot, pitch, "50000")
    assert "Pixel pitch um: 50000 is not allowed" in app.messages[-1]
    assert "from 0.1 to 10000 um" in app.messages[-1]  # micrometres, as typed, not metres
    # a good value is kept
    await type_into(pilot, field(app, "sensor.ray_grid"), "3")
    assert app.scenario.sensor.ray_grid == 3
    assert status(app).state == READY


@pytest.mark.asyncio(loop_scope="module")
async def test_a_bad_value_being_typed_turns_the_status_yellow_and_names_it(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    app.action_show_tab("sensor")
    fov = field(app, "sensor.fov")
    await type_into(pilot, fov, "95", commit=None)
    assert status(app).state == NOT_READY
    assert "Field of view deg" in status(app).message
    # F5 stays offered: it refuses the typed value itself, naming it (tests/test_tui_edits.py)
    await pilot.press("enter")
    await pilot.pause()
    assert status(app).state == READY


@pytest.mark.asyncio(loop_scope="module")
async def test_a_missing_model_is_refused_but_missing_outputs_open(shared, tmp_path, scene_files):
    good = make_scenario(tmp_path, scene_files, name="good")
    broken = tmp_path / "broken.toml"
    broken.write_text(
        good.path.read_text()
        .replace(str(Path(scene_files[0]).name), "nowhere.txt")
        .replace(str(scene_files[0]), str(tmp_path / "nowhere.txt"))
    )
    partial = make_scenario(tmp_path, scene_files, name="partial")
    partial.scene_output.write_text("1,2,3\n")
    partial.measures_file.write_text("")
    pilot, app = await fresh(shared)
    # a missing scene model: named, and nothing is loaded
    await pilot.press("f3")
    await pilot.pause()
    assert isinstance(app.screen, SetupScreen) and app.screen.mode == "load"
    app.screen.query_one("#scenario-file").value = str(broken)
    app.screen.query_one("#setup-ok").press()
    await pilot.pause()
    await pilot.pause()
    assert "nowhere.txt" in str(app.screen.query_one("#setup-message").render())
    await pilot.press("escape")
    await pilot.pause()
    assert app.scenario.path == shared[1].path
    # missing outputs: it opens, says which are missing (yellow) and can still be run
    await pilot.press("f3")
    await pilot.pause()
    app.screen.query_one("#scenario-file").value = str(partial.path)
    app.screen.query_one("#setup-ok").press()
    await wait_until(pilot, lambda: app.scenario.path == partial.path and app.busy is None)
    await pilot.pause()
    assert status(app).state == NOT_READY
    assert "partial_Target.txt" in status(app).message
    assert "partial_Target.txt" in str(app.query_one("#file-info").render())
    assert app.check_action("run", ()) is True
    app.set_scenario(shared[1], modified=False)  # leave the shared app as it was


@pytest.mark.asyncio(loop_scope="module")
async def test_flight_segments_are_added_edited_and_checked(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    app.action_show_tab("flight")
    await pilot.pause()
    app.action_add_segment("straight")
    await pilot.pause()
    form = app.screen
    assert isinstance(form, FormScreen)
    distance = form.query_one("#f-distance")
    await type_into(pilot, distance, "-5", commit="tab")
    # the value stays for correcting, marked, with why in the form's words
    assert distance.value == "-5" and distance.has_class("-bad")
    assert "Distance m: -5 is not allowed" in str(form.query_one("#form-message").render())
    form.query_one("#f-scans").value = "3"
    form.query_one("#form-ok").press()  # OK refuses: nothing is replaced unseen
    await pilot.pause()
    assert app.screen is form and app.focused is distance
    assert [s.kind for s in app.scenario.flight.segments] == ["orbit"]
    assert "Distance m: -5 is not allowed" in str(form.query_one("#form-message").render())
    distance.value = "100"
    form.query_one("#form-ok").press()
    await pilot.pause()
    await pilot.pause()
    kinds = [s.kind for s in app.scenario.flight.segments]
    assert kinds == ["orbit", "straight"]
    # an edit's form names the segment it edits (two alike read the same)
    app.query_one("#segments").move_cursor(row=1)
    app.action_edit_segment()
    await pilot.pause()
    assert isinstance(app.screen, FormScreen) and app.screen.title_text == "Straight (segment 2 of 2)"
    await pilot.press("escape")
    await pilot.pause()
    assert len(app.scenario.poses()) == 6 + 3
    assert app.query_one("#scans").row_count == 9
    # aim every scan at the target centre: the central ray passes through it (to the
    # millimetre: the aim point is written as a person would write it)
    app.action_aim_all()
    await pilot.pause()
    centre = np.array(scene_files[1])
    for pose in app.scenario.poses():
        origin, direction = app.scenario.sensor.central_ray(pose)
        miss = np.cross(np.asarray(direction), centre - np.asarray(origin))  # metres off the ray
        assert np.linalg.norm(miss) <= 0.5e-3 * np.sqrt(3) + 1e-9
    # save writes the edited plan
    await pilot.press("ctrl+s")
    await pilot.pause()
    assert [s.kind for s in load_scenario(app.scenario.path).flight.segments] == kinds


@pytest.mark.asyncio(loop_scope="module")
async def test_manual_poses_are_edited_in_a_table(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    app.action_manual_poses()
    await pilot.pause()
    screen = app.screen
    screen.query_one("#p-x").value = "12.5"
    screen.query_one("#p-z").value = "0"  # not allowed: must be above the ground
    screen.query_one("#pose-apply").press()
    await pilot.pause()
    await pilot.pause()
    assert str(screen.query_one("#poses-message").render()).startswith("z m: 0 is not allowed; expected ")
    await pilot.pause()
    assert screen.query_one("#p-z").value == "0"  # kept for correcting, and nothing applied
    assert app.screen is screen and screen.poses[0].x != 12.5
    screen.query_one("#p-z").value = "40"
    screen.query_one("#pose-apply").press()
    await pilot.pause()
    screen.query_one("#pose-add").press()
    await pilot.pause()
    screen.query_one("#poses-ok").press()
    await pilot.pause()
    manual = app.scenario.flight.segments[-1]
    assert manual.kind == "manual" and len(manual.poses) == 2
    assert manual.poses[0].x == 12.5 and manual.poses[0].z == 40.0


@pytest.mark.asyncio(loop_scope="module")
async def test_compare_shows_scenarios_side_by_side_with_differences_marked(shared, tmp_path, scene_files):
    a, b = tmp_path / "a.cmf", tmp_path / "b.cmf"
    Measures(target_voxels=100, obscured_coverage=0.2, unobscured_coverage=0.5, scans=10).write_cmf(a)
    Measures(target_voxels=100, obscured_coverage=0.3, unobscured_coverage=0.5, scans=12).write_cmf(b)
    pilot, app = await fresh(shared)
    app.push_screen(CompareScreen([a, b]))
    await pilot.pause()
    table = app.screen.query_one("#compare-table")
    assert table.row_count > 10 and len(table.columns) == 3
    rows = {str(table.get_row_at(i)[0]): table.get_row_at(i) for i in range(table.row_count)}
    obscured = rows["Obscured target coverage"]
    assert [str(c) for c in obscured[1:]] == ["20.0%", "30.0%"]
    assert "red" in str(obscured[1].style) and "green" in str(obscured[2].style)
    same = rows["Unobscured target coverage"]
    assert str(same[0].style) == "" and str(same[1].style) == ""
    await pilot.press("escape")
    # a missing file is named
    app.push_screen(CompareScreen([a, tmp_path / "gone.cmf"]))
    await pilot.pause()
    assert "gone.cmf" in str(app.screen.query_one("#compare-message").render())


@pytest.mark.asyncio(loop_scope="module")
async def test_help_lists_the_keys_and_the_palette_offers_every_action(shared, tmp_path, scene_files):
    from ladartui.tui.app import palette_entries

    pilot, app = await fresh(shared)
    await pilot.press("f1")
    await pilot.pause()
    assert isinstance(app.screen, HelpScreen)
    table = app.screen.query_one("DataTable")
    keys = {str(table.get_row_at(i)[1]) for i in range(table.row_count)}
    assert {"F1 / ?", "F2", "F3", "F5", "F6", "F8", "Ctrl+S", "Esc"} <= keys
    await pilot.press("escape")
    actions = {a.split("(")[0] for _, _, a in palette_entries()}
    bound = {b.action.split("(")[0] for b in LadarApp.BINDINGS}
    assert bound <= actions
    for action in actions:
        assert callable(getattr(app, f"action_{action}", None)), action
    # found by the words of its button: 'Aim all' matched no palette command
    names = {name: action for name, _, action in palette_entries()}
    assert names.get("Aim all scans at the target") == "aim_all"


def shown_keys(app) -> set[str]:
    """Keys the footer shows (enabled or greyed out) on the current screen."""
    return {b.binding.key for b in app.active_bindings.values() if b.binding.show}


@pytest.mark.asyncio(loop_scope="module")
async def test_study_key_opens_the_study_of_the_open_scenario_and_esc_returns(shared, tmp_path, scene_files):
    from ladartui.tui.app import help_rows, palette_entries
    from ladartui.tui.study_screen import StudyScreen

    pilot, app = await fresh(shared)
    assert {"f11", "f12"} <= shown_keys(app)
    assert {
        ("Anywhere", "F11", "Speed-against-accuracy study"),
        ("Anywhere", "F12", "Flight-path sweep"),
    } <= set(help_rows(app))
    assert {"study", "sweep"} <= {action for _, _, action in palette_entries()}
    await pilot.press("f11")
    await pilot.pause()
    screen = app.screen
    assert isinstance(screen, StudyScreen)
    assert screen.scenario_path == app.scenario.path
    bar = screen.query_one("#study-progress")
    assert bar.total == 1 and bar.progress == 0  # idle reads 0 %, not an animation of work
    # the study screen's keys only: the app's F5 must not start a run underneath
    assert app.check_action("run", ()) is False and "f5" not in shown_keys(app)
    # one Help in its footer, which shows one key per action (it showed 'f1 Help' and '? Help')
    helps = {
        b.binding.action
        for b in app.active_bindings.values()
        if b.binding.show and "help" in b.binding.action
    }
    assert helps == {"app.help"}
    await pilot.press("f5")
    await pilot.pause()
    assert not app.running and app.screen is screen
    await pilot.press("escape")
    await pilot.pause()
    assert not isinstance(app.screen, StudyScreen) and app.tool_screen is None
    assert app.check_action("study", ()) is True


@pytest.mark.asyncio(loop_scope="module")
async def test_sweep_key_opens_the_sweep_screen_and_its_best_path_loads_in_the_app(
    shared, tmp_path, scene_files
):
    from ladartui.tui.sweep_screen import SweepScreen

    pilot, app = await fresh(shared)
    await pilot.press("f12")
    await pilot.pause()
    assert isinstance(app.screen, SweepScreen)
    await pilot.press("escape")
    await pilot.pause()
    assert not isinstance(app.screen, SweepScreen) and app.tool_screen is None
    # the sweep asks to open its best path: the app loads that scenario and shows it
    best = make_scenario(tmp_path, scene_files, name="tiny-best", scans=3)
    await pilot.press("f12")
    await pilot.pause()
    screen = app.screen
    screen.post_message(SweepScreen.OpenScenario(best.path))
    await wait_until(pilot, lambda: loaded(app) and app.scenario.path == best.path, timeout=60)
    assert app.screen is not screen and app.tool_screen is None
    assert len(app.scenario.poses()) == 3 and status(app).state == READY
    app.set_scenario(shared[1], modified=False)


@pytest.mark.asyncio(loop_scope="module")
async def test_study_and_sweep_are_not_offered_while_busy(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    app.set_busy("Working...")
    await pilot.pause()
    try:
        assert app.query_one("#btn-study").disabled and app.query_one("#btn-sweep").disabled
        assert app.check_action("study", ()) is None and app.check_action("sweep", ()) is None
        await pilot.press("f11")
        await pilot.press("f12")
        await pilot.pause()
        assert app.tool_screen is None and len(app.screen_stack) == 1
    finally:
        app.set_busy(None)
    await pilot.pause()
    assert not app.query_one("#btn-study").disabled
