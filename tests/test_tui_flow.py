"""The terminal UI driven by a Pilot: setup, parameters, run, measures, views.

Every test runs on a tiny generated scene (seeded) in tmp_path.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest
import pytest_asyncio

from ladartui.cmf import read_cmf
from ladartui.flight import FlightPlan
from ladartui.measures import Measures
from ladartui.scenario import load_scenario
from ladartui.scene.voxels import load_voxels
from ladartui.sensor import Sensor
from ladartui.tui.app import CONTROLS, LadarApp
from ladartui.tui.canvas import ProjectionWidget, TopViewWidget
from ladartui.tui.fields import NumberField
from ladartui.tui.file_dialogs import SetupScreen
from ladartui.tui.host import AppHost
from ladartui.tui.measures_screens import CompareScreen
from ladartui.tui.measures_view import compact_rows, level_rows
from ladartui.tui.screens import AngleScreen, FormScreen, HelpScreen
from ladartui.tui.status import BUSY, NOT_READY, READY, StatusBar
from tui_support import make_scenario, wait_until


class LadarApp(LadarApp):
    """The app without the child-process warm-up (the fixture compiled the kernels)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("compile_in_child", False)
        super().__init__(*args, **kwargs)


SIZE = (100, 32)


@pytest_asyncio.fixture(loop_scope="module", scope="module")
async def shared(tmp_path_factory, scene_files):
    """One app for the tests that do not run a simulation (each starts from ``fresh``)."""
    scenario = make_scenario(tmp_path_factory.mktemp("shared"), scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        yield pilot, scenario


async def fresh(shared):
    """The shared app back at its starting state: scenario, views, no dialogs."""
    pilot, scenario = shared
    app = pilot.app
    while len(app.screen_stack) > 1:
        app.pop_screen()
    app.set_scenario(scenario, modified=False)
    app.threshold = None
    app.output_voxels = None
    app.show_output()
    app.action_layout(1)
    app.query_one("#sidebar").display = True
    app.query_one("#scene3d").set_camera(app.query_one("#scene3d").camera.__class__())
    app.messages.clear()
    app.clear_notifications()  # a toast left by an earlier test could catch a click
    await pilot.pause()
    return pilot, app


def loaded(app):
    return app.scene is not None and app.busy is None


async def open_app(pilot):
    await wait_until(pilot, lambda: loaded(pilot.app))


def field(app, key) -> NumberField:
    return app.query_one("#f-" + key.replace(".", "-").replace("_", "-"), NumberField)


async def type_into(pilot, widget, text, commit="enter"):
    widget.focus()
    await pilot.pause()
    widget.value = ""
    await pilot.press(*list(text))
    if commit:
        await pilot.press(commit)
    await pilot.pause()


def status(app) -> StatusBar:
    return app.query_one(StatusBar)


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


async def test_setup_parameters_run_and_measures(tmp_path, scene_files, monkeypatch):
    monkeypatch.chdir(tmp_path)
    first = make_scenario(tmp_path, scene_files, name="first")
    app = LadarApp(first.path)
    async with app.run_test(size=SIZE) as pilot:
        await open_app(pilot)
        # file setup: a new scenario for the scene model
        await pilot.press("f2")
        await pilot.pause()
        setup = app.screen
        assert isinstance(setup, SetupScreen)
        setup.query_one("#scenario-file").value = "trial.toml"
        setup.query_one("#scene-file").value = str(scene_files[0])
        setup.query_one("#voxel-size").value = "0.25"
        await pilot.pause()
        derived = str(setup.query_one("#derived").render())
        for name in ("forest_Target.txt", "trial_Scene.txt", "trial_Target.txt", "trial.cmf"):
            assert name in derived
        await pilot.click("#setup-ok")
        await wait_until(pilot, lambda: loaded(app) and app.scenario.name == "trial")
        assert (tmp_path / "trial.toml").is_file()
        assert load_scenario(tmp_path / "trial.toml").voxel_size == 0.25
        # parameters: a small sensor so the run is quick
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "6")
        await type_into(pilot, field(app, "sensor.ray_grid"), "1")
        assert app.scenario.sensor.grid == 6
        await wait_until(pilot, lambda: status(app).state == READY)
        # run
        await pilot.press("f5")
        await wait_until(pilot, lambda: app.busy is None and app.result is not None)
        assert "Comparison measures" in app.screen.query_one(".dialog").border_title
        await pilot.press("escape")
        scenario = app.scenario
        for path in (scenario.scene_output, scenario.target_output, scenario.measures_file):
            assert path.is_file()
        # the run panel names every file the run wrote, not the measures alone
        said = str(app.query_one("#run-info").render())
        assert said.endswith("; wrote trial_Scene.txt, trial_Target.txt, trial.cmf, trial_Run.toml"), said
        written = read_cmf(scenario.measures_file)
        table = app.query_one("#measures")
        shown = [tuple(str(c) for c in table.get_row_at(i)) for i in range(table.row_count)]
        assert shown == compact_rows(written) + level_rows(written, short=True)
        assert [label for label, _ in shown[-3:]] == ["Detect", "Recognise", "Identify"]
        # fusion: the obscured view sees a subset of what the unobscured view sees
        assert written.obscured_voxels <= written.unobscured_voxels <= written.visible_voxels
        assert written.scans == len(scenario.poses())
        fused = load_voxels(scenario.scene_output)
        assert len(fused) == len(app.result.scene_output)
        assert status(app).state == READY
        # opening another scenario clears the run line: that run was trial's
        app.load(first.path)
        await wait_until(pilot, lambda: loaded(app) and app.scenario.name == "first")
        assert str(app.query_one("#run-info").render()) == ""


async def test_a_run_disables_controls_and_cancel_keeps_earlier_outputs(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await open_app(pilot)
        await pilot.press("f5")
        await wait_until(pilot, lambda: app.busy is None and app.result is not None)
        await pilot.press("escape")  # close the measures dialog
        outputs = [scenario.scene_output, scenario.target_output, scenario.measures_file]
        before = [p.read_bytes() for p in outputs]
        saved = scenario.path.read_bytes()
        # a long run: many scans with a bigger sensor
        slow = dataclasses.replace(app.scenario.flight.segments[0], scans=4000)
        app.update_scenario(
            app.scenario.with_changes(
                sensor=Sensor(grid=32, ray_grid=2, fov=8.0), flight=FlightPlan(None, (slow,))
            )
        )
        await pilot.press("f5")
        await wait_until(pilot, lambda: app.busy is not None and app.run_in_progress())
        await wait_until(pilot, lambda: (app.progress or 0) > 0)
        # once two scans have given a pace, the busy bar says how long is left
        await wait_until(pilot, lambda: re.search(r"about \S+ left", status(app).message))
        assert status(app).state == BUSY and "%" in str(status(app).query_one("#status-word").render())
        enabled = [w.id for w in app.query(CONTROLS) if not w.disabled]
        assert enabled == ["btn-cancel-run"]
        assert not app.query_one("#status #cancel").disabled
        assert app.check_action("save", ()) is None and app.check_action("run", ()) is None
        await pilot.press("ctrl+s")  # does nothing while busy, and says why
        assert scenario.path.read_bytes() == saved
        assert app.messages[-1] == "Save scenario is off while the run goes on; Esc cancels the run."
        await pilot.press("escape")
        await wait_until(pilot, lambda: app.busy is None, timeout=30)
        assert "cancelled" in app.messages[-1].lower()
        assert [p.read_bytes() for p in outputs] == before
        # enabled again, except the march step (exact method) and the start pose (an orbit
        # starts at its own first scan)
        assert all(
            not w.disabled
            for w in app.query("#sidebar Input")
            if w.id != "f-scenario-step" and not w.id.startswith("f-start")
        )
        assert all(w.disabled for w in app.query("#sidebar Input") if w.id.startswith("f-start"))
        # the outputs kept are the first run's, with the settings before the edits
        assert status(app).state == NOT_READY
        assert "outputs out of date; F5 reruns" in status(app).message


async def test_progressive_output_during_a_run_unless_fast_mode(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files, scans=3000, grid=32, ray_grid=2)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await open_app(pilot)
        output = app.query_one("#output3d", ProjectionWidget)
        assert output.points is None  # never run
        await pilot.press("f5")
        await wait_until(pilot, lambda: output.points is not None and len(output.points))
        assert app.busy is not None  # drawn while the run goes on
        await pilot.press("escape")
        await wait_until(pilot, lambda: app.busy is None)
        assert output.points is None  # cancelled: back to the (absent) earlier output

        app.update_scenario(app.scenario.with_changes(fast_mode=True))
        await pilot.press("f5")
        await wait_until(pilot, lambda: (app.progress or 0) > 0)
        await pilot.pause(1.0)  # two progressive redraw intervals
        assert app.busy is not None and output.points is None
        await pilot.press("escape")
        await wait_until(pilot, lambda: app.busy is None)


@pytest.mark.asyncio(loop_scope="module")
async def test_layout_keys_switch_between_the_five_layouts(shared, tmp_path, scene_files):
    expected = {
        1: {"scene3d", "topview"},
        2: {"scene3d", "output3d"},
        3: {"scene3d"},
        4: {"output3d"},
        5: {"scene3d", "output3d", "topview"},
    }
    pilot, app = await fresh(shared)
    app.query_one("#scene3d").focus()
    for number, shown in expected.items():
        await pilot.press(str(number))
        await pilot.pause()
        visible = {w.id for w in app.query("#views > *") if w.display}
        assert visible == shown
        assert all(app.query_one(f"#{w}").size.width > 0 for w in shown)
    await pilot.press("f6")  # cycles back to the first
    await pilot.pause()
    assert app.layout_number == 1
    await pilot.press("f4")  # hide the panel: the views get the whole width
    await pilot.pause()
    assert not app.query_one("#sidebar").display


@pytest.mark.asyncio(loop_scope="module")
async def test_height_threshold_limits_the_output_view(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    column = np.array([[3, 4, z] for z in range(21)])
    app.output_voxels = column
    app.show_output()
    output = app.query_one("#output3d", ProjectionWidget)
    assert len(output.points) == 21
    await pilot.press("f8")
    await pilot.pause()
    assert isinstance(app.screen, FormScreen)
    await pilot.press("2", "enter")
    await pilot.pause()
    # voxel size 0.25 m: centres at z * 0.25 <= 2.0 m are layers 0..8
    assert sorted(output.points[:, 2].tolist()) == list(range(9))
    assert "2 m" in output.border_title
    await pilot.press("f8")
    await pilot.pause()
    app.screen.query_one("#f-threshold").value = ""
    await pilot.press("enter")
    await pilot.pause()
    assert len(output.points) == 21 and app.threshold is None


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
async def test_3d_view_rotates_zooms_and_takes_an_exact_angle(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    scene3d = app.query_one("#scene3d", ProjectionWidget)
    output3d = app.query_one("#output3d", ProjectionWidget)
    scene3d.focus()
    az = scene3d.camera.azimuth
    await pilot.press("right", "up", "plus", "d")
    assert scene3d.camera.azimuth == pytest.approx((az + 15) % 360)
    assert scene3d.camera.zoom == pytest.approx(1.25)
    assert scene3d.camera.pan_x > 0
    assert output3d.camera == scene3d.camera  # the views turn together
    await pilot.press("f7")
    await pilot.pause()
    app.screen.query_one("#f-azimuth").value = "45"
    app.screen.query_one("#f-elevation").value = "60"
    app.screen.query_one("#form-ok").press()
    await pilot.pause()
    await pilot.pause()
    assert (scene3d.camera.azimuth, scene3d.camera.elevation) == (45.0, 60.0)
    await pilot.press("f7")
    await pilot.pause()
    app.screen.query_one("#f-elevation").value = "120"
    app.screen.query_one("#form-ok").press()
    await pilot.pause()
    await pilot.pause()
    # refused in the form's words; the dialog stays open with the value to correct
    assert "Elevation (deg): 120 is not allowed" in str(app.screen.query_one("#form-message").render())
    assert isinstance(app.screen, AngleScreen)
    assert app.screen.query_one("#f-elevation").value == "120"
    await pilot.press("escape")


@pytest.mark.asyncio(loop_scope="module")
async def test_top_view_overlay_follows_parameters_without_redrawing_the_scene(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    top = app.query_one(TopViewWidget)
    await pilot.pause()
    renders = top.top.renders
    before = [f.copy() for f in top.footprints]
    app.action_show_tab("sensor")
    await type_into(pilot, field(app, "sensor.fov"), "20")

    # a wider field of view gives larger footprints (drawn once the commit is through:
    # on a busy machine that takes more than one pause)
    def area(p):
        x, y = p[:, 0], p[:, 1]
        return abs(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1))) / 2

    await wait_until(pilot, lambda: area(top.footprints[0]) > 4 * area(before[0]), timeout=60)
    assert top.top.renders == renders


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


def test_pictures_use_24_bit_colour_or_the_256_colour_palette():
    from ladartui import views
    from ladartui.tui.canvas import UPPER, picture_strips

    picture = views.Picture.blank(2, 2)
    picture.rgb[0, 0] = (255, 0, 0)
    picture.rgb[1, 0] = (0, 0, 255)
    picture.mask[:, 0] = True
    (strip,) = picture_strips(picture)
    first = list(strip)[0]
    assert first.text.startswith(UPPER)
    assert first.style.color.triplet == (255, 0, 0) and first.style.bgcolor.triplet == (0, 0, 255)
    (strip,) = picture_strips(picture, use_256=True)
    first = list(strip)[0]
    assert (first.style.color.number, first.style.bgcolor.number) == (196, 21)  # xterm red, blue


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
