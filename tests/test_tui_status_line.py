"""What the status line and the File tab say, and quitting during a run: a short name
kept whole, a reason the line cuts told whole, the run's key in force, and Ctrl+Q
asking before it cancels a run."""

from __future__ import annotations

from ladartui.tui.actions import palette_entries
from ladartui.tui.status import StatusBar
from test_tui_edits import SIZE, capture_runs, copy_scene
from tui_support import LadarApp, loaded, make_scenario, wait_until


async def test_quit_while_a_run_goes_on_asks_first(tmp_path, scene_files):
    """Ctrl+Q in the middle of a run quit at once, with no edits to ask about: a run of
    many minutes was gone on one key."""
    from ladartui.tui.unsaved import QuitRunScreen

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(80, 24)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        capture_runs(app)  # the run never reports back: it goes on
        await pilot.press("f5")
        await pilot.pause()
        assert app.run_in_progress()
        await pilot.press("ctrl+q")
        await pilot.pause()
        assert isinstance(app.screen, QuitRunScreen)
        said = str(app.screen.query_one("#quit-run-question").render())
        assert said == (
            "A run of demo.toml is going on (0%). Quit and cancel it? The outputs on disk stay as they were."
        )
        await pilot.press("escape")  # keeps it running
        await pilot.pause()
        assert app.is_running and app.run_in_progress() and not isinstance(app.screen, QuitRunScreen)
        await pilot.press("ctrl+q")
        await pilot.pause()
        await pilot.click("#quit-run-quit")
        await pilot.pause()
        assert not app.is_running


def test_a_short_name_is_not_cut_for_a_line_whose_end_is_cut_anyway():
    """At 80 columns the status line read 'def…lt.toml (modified): 24 scans x 1,048,576
    rays. F5 ru…': the name cut for one cell while the end was cut all the same."""
    from ladartui.tui.status import fitted

    said = "default.toml (modified): 24 scans x 1,048,576 rays. F5 runs."
    assert fitted(said, 57, "default.toml") == said[:56] + "\u2026"
    said = "default.toml (modified): 24 scans x 16,384 rays. F5 runs."  # 57: the name gives way
    assert fitted(said, 56, "default.toml") == "def\u2026lt.toml (modified): 24 scans x 16,384 rays. F5 runs."


async def test_a_reason_the_status_line_cuts_is_told_whole_once(tmp_path, scene_files):
    """At 80 columns the bar read 'NOT READY  /tmp/…/forest.toml:5: files.scene =
    'forest.t…': why Run was off was cut away, and said nowhere until F5 was pressed."""
    from ladartui.tui.status import NOT_READY
    from tui_support import opened

    scene = tmp_path / "forest.txt"
    copy_scene(scene_files[0], scene)
    scenario = make_scenario(tmp_path, (scene, scene_files[1], scene_files[2]), name="forest")
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        await pilot.pause()
        message = app.query_one(StatusBar).message
        assert app.query_one(StatusBar).state == NOT_READY and "would overwrite a model file" in message
        assert message.endswith("would overwrite a model file")
        told = [m for m in app.messages if message in m]
        assert len(told) == 1
        app.refresh_status()
        await pilot.pause()
        assert len([m for m in app.messages if message in m]) == 1  # once, not at each refresh


async def test_the_file_tab_says_which_key_writes_missing_outputs_only_when_it_would(
    tmp_path, scene_files, monkeypatch
):
    """'Not on disk yet: ... (F5 writes them)': F5 even where keys.toml had moved the run
    to Ctrl+R, and where the run was off (its outputs would overwrite a model file)."""
    home = tmp_path / "home"
    (home / "config").mkdir(parents=True)
    (home / "config" / "keys.toml").write_text('[keys]\nrun = "ctrl+r"\n')
    monkeypatch.setenv("LADARTUI_HOME", str(home))
    scenario = make_scenario(tmp_path, scene_files)
    scenario.scene_output.write_text("1,2,3\n")  # a partial set: the rest is missing
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        info = str(app.query_one("#file-info").render())
        assert "(Ctrl+R writes them)" in info and "F5" not in info
    scene = tmp_path / "forest.txt"
    copy_scene(scene_files[0], scene)
    refused = make_scenario(tmp_path, (scene, scene_files[1], scene_files[2]), name="forest")
    refused.measures_file.write_text("")
    app = LadarApp(refused.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        info = str(app.query_one("#file-info").render())
        assert "Not on disk yet: forest_Scene.txt" in info and "writes them" not in info, info


async def test_quit_during_a_run_saves_the_edits_when_asked(tmp_path, scene_files):
    """Quit during a run, then Save for the unsaved edits: Save was refused while the
    run was busy, so nothing was saved, the app stayed, and nothing said why."""
    from ladartui.scenario import load_scenario
    from ladartui.tui.unsaved import QuitRunScreen, UnsavedScreen
    from tui_support import field, type_into

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        capture_runs(app)  # the run never reports back: it goes on
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "12")
        await pilot.press("f5")
        await pilot.pause()
        assert app.run_in_progress() and app.unsaved()
        await pilot.press("ctrl+q")
        await pilot.pause()
        assert isinstance(app.screen, QuitRunScreen)
        await pilot.click("#quit-run-quit")
        await pilot.pause()
        assert isinstance(app.screen, UnsavedScreen)
        await pilot.click("#unsaved-save")
        await pilot.pause()
        assert not app.is_running
    assert load_scenario(scenario.path).sensor.grid == 12


async def test_a_scenario_changed_on_disk_is_told_once_where_the_line_cuts_it(tmp_path, scene_files):
    """With a long file name at 80 columns the change was told twice: by the check that
    found it, then again by the status bar, which tells a reason it cuts."""
    from tui_support import opened

    scenario = make_scenario(tmp_path, scene_files)
    longer = scenario.with_changes(path=tmp_path / ("a-rather-long-scenario-name-" * 2 + ".toml")).save()
    async with opened(longer, size=(80, 24)) as (app, pilot):
        text = longer.path.read_text(encoding="utf-8")
        longer.path.write_text(text.replace("speed_mps = ", "speed_mps = 1"), encoding="utf-8")
        app.check_outputs_on_disk()
        for _ in range(10):
            await pilot.pause()
        told = [m for m in app.messages if "changed on disk" in m]
        assert len(told) == 1, told


async def test_a_scenario_over_the_ray_limit_opens_not_ready_and_runs_once_cut_down(
    tmp_path, scene_files, monkeypatch
):
    """It was refused as it loaded ('Could not load ...: about 7.86e+05 rays to trace'),
    so it could not be opened to fly a smaller sensor or fewer scans."""
    from ladartui.tui.status import NOT_READY
    from tui_support import field, type_into

    scenario = make_scenario(tmp_path, scene_files, scans=6)  # 8 x 8 rays a scan, two runs: 768
    monkeypatch.setenv("LADARTUI_MAX_RAYS", "700")
    app = LadarApp(scenario.path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        runs = capture_runs(app)
        bar = app.query_one(StatusBar)
        assert bar.state == NOT_READY
        # both runs' rays: '6 scans: about 768' read as a miscount of the 6 x 64 the bar shows
        assert bar.message.endswith(
            "6 scans x 2 runs (the scene run and the target-alone run): about 768 rays to trace, "
            "more than the limit of 700 "
            "(raise it with "
            "LADARTUI_MAX_RAYS, set before ladartui starts, if this is meant)"
        )
        await pilot.press("f5")
        await pilot.pause()
        assert runs == [] and "about 768 rays to trace" in app.messages[-1]
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "7")  # 49 rays a scan: 588
        assert "rays to trace" not in bar.message
        await pilot.press("f5")
        await pilot.pause()
        assert [run.sensor.grid for run in runs] == [7]


async def test_an_output_name_a_folder_holds_turns_the_bar_yellow(tmp_path, scene_files):
    """A folder of the scene output's name left the bar green, 'F5 runs.', and F5 failed
    at once (``ladartui validate`` refused that run before it traced). The outputs are
    looked at as before, no more often: at opening, after a failed run, and every 2 s
    while one is held."""
    from ladartui.tui.status import NOT_READY, READY
    from tui_support import opened

    scenario = make_scenario(tmp_path, scene_files)
    folder = scenario.scene_output
    folder.mkdir()
    async with opened(scenario, size=(100, 30)) as (app, pilot):
        await pilot.pause()
        bar = app.query_one(StatusBar)
        assert bar.state == NOT_READY
        assert bar.message == f"output {folder.name} is a folder, expected a file name", bar.message
        await pilot.press("f5")
        await pilot.pause()
        assert not app.run_in_progress()
        assert app.messages[-1] == f"Run is off: output {folder.name} is a folder, expected a file name."
        folder.rmdir()  # cleared: the next look finds it gone
        await wait_until(pilot, lambda: bar.state == READY, timeout=10)
        folder.mkdir()  # made again while the app shows the bar green: F5 finds it
        await pilot.press("f5")
        await wait_until(pilot, lambda: not app.run_in_progress() and bar.state == NOT_READY, timeout=60)
        assert bar.message == f"output {folder.name} is a folder, expected a file name", bar.message


async def test_a_view_keeps_the_keys_while_a_run_goes_on(tmp_path, scene_files):
    """F5 pressed in a 3D view moved the focus to the status bar's Cancel: the arrows,
    + and - there did nothing while the run went on, though the views may be turned
    during a run. A control the run disables still hands the focus to Cancel."""
    from ladartui.tui.canvas import ProjectionWidget

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(100, 30)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        capture_runs(app)  # the run never reports back: it goes on
        view = app.query_one("#scene3d", ProjectionWidget)
        view.focus()
        await pilot.press("f5")
        await pilot.pause()
        assert app.run_in_progress() and app.focused is view
        azimuth, zoom = view.camera.azimuth, view.camera.zoom
        await pilot.press("right", "plus")
        assert view.camera.azimuth == (azimuth + 15) % 360 and view.camera.zoom > zoom
        app.run_finished(cancelled=True)
        await pilot.pause()
        app.query_one("#btn-run").focus()  # the Run tab's button, off during a run
        await pilot.press("f5")
        await pilot.pause()
        assert app.focused is app.query_one("#status #cancel")


async def test_a_scenario_name_holding_control_characters_is_shown_escaped(
    tmp_path, scene_files, monkeypatch
):
    """A scenario named "ctl<ESC>[31mred<newline>nl.toml" reached the terminal raw: the
    File tab broke its row in two and coloured the rest red, and the status bar's line
    was torn. Its name is shown with the controls written out, as messages write them."""
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    scenario = make_scenario(tmp_path, scene_files, name="ctl\x1b[31mred\nnl")
    other = make_scenario(tmp_path, scene_files, name="other")
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        shown = "ctl\\x1b[31mred\\x0anl"
        info = str(app.query_one("#file-info").render())
        assert f"Scenario      {shown}.toml\n" in info and "\x1b" not in info, info
        assert f"Measures      {shown}.cmf" in info
        line = str(app.query_one("#status-text").render())
        assert line.startswith(f"{shown}.toml: ") and "\x1b" not in line and "\n" not in line, line
        app.open_path(other.path)
        await wait_until(pilot, lambda: app.scenario.path == other.path and app.busy is None)
        recent = app.query_one("#recent")
        listed = str(recent.get_option_at_index(0).prompt)
        assert listed.startswith(f"{shown}.toml  ") and "\x1b" not in listed, listed
        offered = [(title, where) for title, where, _ in palette_entries() if title.startswith("Open recent")]
        assert (f"Open recent: {shown}.toml", f"{tmp_path}/{shown}.toml") in offered, offered
        app.open_path(scenario.path)
        await wait_until(pilot, lambda: app.scenario.path == scenario.path and app.busy is None)
        await app.run_action("save")
        await pilot.pause()
        assert app.messages[-1] == f"Saved {tmp_path}/{shown}.toml", app.messages[-1]


async def test_a_message_its_written_out_controls_make_too_long_is_told_whole():
    """A message holding a terminal escape was measured raw, where the escape takes no
    cell, but shown written out (four cells): cut on the line, it was judged to fit and
    said nowhere whole."""
    from textual.app import App

    from ladartui.tui.status import NOT_READY

    told: list[str] = []

    class Bar(App):
        def compose(self):
            yield StatusBar(tell=told.append)

    app = Bar()
    async with app.run_test(size=(80, 3)) as pilot:
        await pilot.pause()
        bar = app.query_one(StatusBar)
        room = app.query_one("#status-text").content_size.width
        message = "a" * (room - 1) + "\x1b" + "b"  # raw: room cells; written out: room + 4
        bar.show(NOT_READY, message)
        await pilot.pause()
        assert told == ["a" * (room - 1) + "\\x1bb"]
        assert bar.message == told[0]
