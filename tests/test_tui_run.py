"""A run in the app from setup to measures: a new scenario made in the setup dialog, its
parameters, F5, and the measures shown and written; a run's controls held, its progress
and Cancel keeping the earlier outputs; the output drawn as it grows unless fast mode.

Every test runs its own app on a tiny generated scene (seeded) in tmp_path.
"""

from __future__ import annotations

import dataclasses
import re

from ladartui.cmf import read_cmf
from ladartui.flight import FlightPlan
from ladartui.scenario import load_scenario
from ladartui.scene.voxels import load_voxels
from ladartui.sensor import Sensor
from ladartui.tui.app import CONTROLS
from ladartui.tui.canvas import ProjectionWidget
from ladartui.tui.file_dialogs import SetupScreen
from ladartui.tui.measures_view import compact_rows, level_rows
from ladartui.tui.status import BUSY, NOT_READY, READY
from tui_support import SIZE, LadarApp, field, loaded, make_scenario, status, type_into, wait_until


async def open_app(pilot):
    await wait_until(pilot, lambda: loaded(pilot.app))


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
        # Ctrl+C, the reflex to stop it, copies in a terminal app: it says how to cancel
        # and quit, where it had said nothing while the run went on
        await pilot.press("ctrl+c")
        assert app.run_in_progress()
        assert app.messages[-1] == "Ctrl+C does not stop the run: Esc cancels it; Ctrl+Q quits."
        # a click on a dimmed key in the footer says why, as the key does (it rang the bell)
        from textual.widgets._footer import FooterKey

        (compare,) = [k for k in app.query(FooterKey) if k.key == "f10"]
        assert compare.has_class("-disabled")
        # at its place on the screen, as a terminal's click comes (not addressed to it)
        await pilot.click(offset=compare.region.offset + (1, 0))
        assert app.run_in_progress() and not app.screen_stack[1:]
        assert app.messages[-1] == "Compare is off while the run goes on; Esc cancels the run."
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
