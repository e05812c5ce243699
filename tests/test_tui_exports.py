"""What the app writes and draws from a scenario and its outputs: LAS point clouds
after a run (said when made from outputs out of date), the view commands reaching every
view and a view saved as PNG beside an earlier one, the top view's footprints as they
fall with attitude.

Each test drives a real app on a tiny generated scene with Pilot.
"""

from __future__ import annotations

from tui_support import SIZE, LadarApp, loaded, make_scenario, wait_until


async def test_the_outputs_export_as_las_point_clouds_after_a_run(tmp_path, scene_files):
    import laspy

    from ladartui.scene.voxels import load_voxels

    scenario = make_scenario(tmp_path, scene_files, scans=2)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        await app.run_action("export_las")  # nothing to export yet: said, nothing written
        await wait_until(pilot, lambda: any("Nothing exported" in m for m in app.messages))
        assert not list(tmp_path.glob("*.las"))
        await pilot.press("f5")
        await wait_until(pilot, lambda: app.result is not None and not app.running)
        await pilot.press("escape")
        app.action_show_tab("results")
        await pilot.pause()
        await pilot.click("#btn-export-las")
        await wait_until(pilot, lambda: app.messages[-1].startswith("Wrote"))
        for output in (scenario.scene_output, scenario.target_output):
            cloud = laspy.read(output.with_suffix(".las"))
            assert len(cloud.points) == len(load_voxels(output)) > 0


async def test_las_exported_from_outputs_out_of_date_says_so(tmp_path, scene_files):
    """Outputs made with other settings were exported with no more than 'Wrote ...': the
    point clouds read as the scenario's while the status bar called them out of date."""
    from ladartui.sensor import Sensor
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files, scans=2)
    simulate(scenario.with_changes(sensor=Sensor(grid=12, ray_grid=1, fov=8.0)))  # not this file's grid
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app) and app.measures is not None)
        assert app.outputs_stale()
        await app.run_action("export_las")
        await wait_until(pilot, lambda: any(m.startswith("Wrote") for m in app.messages))
        said = next(m for m in app.messages if m.startswith("Wrote"))
        assert said.startswith(f"Wrote {scenario.scene_output.with_suffix('.las')}")
        assert "from outputs out of date: made from other settings" in said and "sensor.grid" in said
        # as they are made again: the export says nothing more
        await pilot.press("f5")
        await wait_until(pilot, lambda: app.result is not None and not app.running)
        await pilot.press("escape")
        app.messages.clear()
        await app.run_action("export_las")
        await wait_until(pilot, lambda: any(m.startswith("Wrote") for m in app.messages))
        assert "out of date" not in next(m for m in app.messages if m.startswith("Wrote"))


async def test_view_commands_reach_every_view_and_a_view_saves_as_png(tmp_path, scene_files):
    from PIL import Image

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        scene3d = app.query_one("#scene3d")
        before = scene3d.camera
        app.set_focus(None)
        await pilot.press("z")  # zoom to target, from anywhere (not only a focused view)
        await pilot.pause()
        assert scene3d.camera != before and scene3d.camera.zoom > before.zoom
        # F7 keeps the target framing (zoom and centre), changing only the angle
        framed = scene3d.camera
        await app.run_action("view_angle")
        await pilot.pause()
        app.screen.query_one("#f-azimuth").value = "45"
        app.screen.query_one("#form-ok").press()
        await pilot.pause()
        assert scene3d.camera.azimuth == 45.0 and scene3d.camera.zoom == framed.zoom
        assert scene3d.camera.centre == framed.centre
        await app.run_action("save_png")
        await pilot.pause()
        app.screen.query_one("#f-width").value = "320"
        app.screen.query_one("#f-height").value = "200"
        app.screen.query_one("#form-ok").press()
        await wait_until(pilot, lambda: any(m.startswith("Wrote") for m in app.messages))
        written = tmp_path / "demo-scene3d.png"
        assert Image.open(written).size == (320, 200)
        # a second picture of the view goes beside the first: it replaced it without a word
        first = written.read_bytes()
        app.messages.clear()
        await app.run_action("save_png")
        await pilot.pause()
        assert "3D scene" in str(app.screen.query_one(".dialog").border_title)  # the view's name alone
        assert " az " not in str(app.screen.query_one(".dialog").border_title)
        app.screen.query_one("#f-width").value = "160"
        app.screen.query_one("#f-height").value = "100"
        app.screen.query_one("#form-ok").press()
        await wait_until(pilot, lambda: any(m.startswith("Wrote") for m in app.messages))
        assert written.read_bytes() == first
        assert Image.open(tmp_path / "demo-scene3d-2.png").size == (160, 100)


async def test_the_top_view_draws_footprints_as_they_fall_with_attitude(tmp_path, scene_files):
    import dataclasses

    import numpy as np

    from ladartui.attitude import scan_footprints
    from ladartui.tui.canvas import TopViewWidget

    scenario = make_scenario(tmp_path, scene_files)
    banked = scenario.with_changes(sensor=dataclasses.replace(scenario.sensor, mount="body-fixed")).save()
    app = LadarApp(banked.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        drawn = app.query_one(TopViewWidget).footprints
        expected = [f[:, :2] for f in scan_footprints(banked)]
        level = [f[:, :2] for f in scan_footprints(scenario)]
        assert len(drawn) == len(expected)
        assert all(np.allclose(d, e) for d, e in zip(drawn, expected))
        assert not all(np.allclose(d, e) for d, e in zip(drawn, level))  # the bank shows


async def test_an_export_that_fails_leaves_the_earlier_pair_and_says_so(tmp_path, scene_files):
    """The scene's cloud was written before the target's failed: a new S_Scene.las beside
    the earlier S_Target.las (here a folder), while the note said 'Nothing exported'."""
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files, scans=2)
    simulate(scenario)
    scene_las = scenario.scene_output.with_suffix(".las")
    scene_las.write_bytes(b"the earlier export")
    scenario.target_output.with_suffix(".las").mkdir()  # cannot be written: a folder
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app) and app.measures is not None)
        await app.run_action("export_las")
        await wait_until(pilot, lambda: any("Nothing exported" in m for m in app.messages))
        said = next(m for m in app.messages if "Nothing exported" in m)
        assert f"{scenario.target_output.with_suffix('.las')}: is a folder, expected a file name" in said
        assert scene_las.read_bytes() == b"the earlier export"
        assert not list(tmp_path.glob(".*.las.*"))  # no temporaries left beside them


async def test_the_palette_screenshot_goes_beside_the_scenario(tmp_path, scene_files, monkeypatch):
    """Textual's Screenshot command wrote to ~/Downloads, which a server reached over SSH
    seldom has: it failed there with no reason given. The picture now goes beside the
    scenario, as a saved view does, never over an earlier one, and a failure says why."""
    home = tmp_path / "home"
    home.mkdir()  # no Downloads folder in it
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.delenv("XDG_DOWNLOAD_DIR", raising=False)
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        # as the palette runs it (Textual's own command, not the screenshot action)
        palette = next(c for c in app.get_system_commands(app.screen) if c.title == "Screenshot")
        palette.callback()
        await wait_until(pilot, lambda: any(m.startswith("Wrote") for m in app.messages))
        written = tmp_path / "demo-screen.svg"
        assert app.messages[-1] == f"Wrote {written}"
        assert written.read_text(encoding="utf-8").lstrip().startswith("<svg")
        await app.run_action("screenshot")
        await wait_until(pilot, lambda: app.messages[-1] == f"Wrote {tmp_path / 'demo-screen-2.svg'}")
        assert (tmp_path / "demo-screen-2.svg").stat().st_size > 0

        def full_disk(target, text, durable=False):
            raise OSError(28, "No space left on device")

        monkeypatch.setattr("ladartui.tui.file_actions.write_text_atomic", full_disk)
        await app.run_action("screenshot")
        await wait_until(pilot, lambda: "Screenshot not saved" in app.messages[-1])
        assert str(tmp_path / "demo-screen-3.svg") in app.messages[-1]
        assert "no space left on device" in app.messages[-1].lower()
        assert not (tmp_path / "demo-screen-3.svg").exists()
