"""Undo and redo, Save As, the recent list, the folder tree and the start pose, in the app.

Each test drives a real app on a tiny generated scene with Pilot, as an
analyst would with the keyboard.
"""

from __future__ import annotations

import pytest
from rich.text import Text
from textual.widgets import Button, Input

from ladartui.flight import FlightPlan, ScanPose, Straight
from ladartui.recent import recent_scenarios
from ladartui.scenario import load_scenario
from ladartui.tui.actions import palette_entries
from ladartui.tui.file_dialogs import SaveAsScreen, SetupScreen
from ladartui.tui.file_tree import FileTree
from ladartui.tui.poses_screen import PosesScreen
from ladartui.tui.screens import FormScreen
from ladartui.tui.status import StatusBar
from ladartui.tui.unsaved import UnsavedScreen
from tui_support import LadarApp, field, loaded, make_scenario, screen_after, type_into, wait_until

SIZE = (100, 32)


def keys_in(tmp_path, monkeypatch, text: str) -> None:
    """A user home under ``tmp_path`` whose keys.toml holds ``text``."""
    home = tmp_path / "home"
    (home / "config").mkdir(parents=True)
    (home / "config" / "keys.toml").write_text(text)
    monkeypatch.setenv("LADARTUI_HOME", str(home))


def modified(app) -> bool:
    return "(modified)" in app.query_one(StatusBar).message


async def test_undo_and_redo_a_field_a_segment_and_typing(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("sensor")
        grid = field(app, "sensor.grid")
        await type_into(pilot, grid, "12")
        assert app.scenario.sensor.grid == 12 and modified(app)
        await pilot.press("ctrl+z")
        await pilot.pause()
        assert app.scenario.sensor.grid == 8 and grid.value == "8"
        assert not modified(app)  # back to what is on disk
        assert "Sensor grid n 8 -> 12" in app.messages[-1]
        await pilot.press("ctrl+y")
        await pilot.pause()
        assert app.scenario.sensor.grid == 12 and grid.value == "12" and modified(app)
        # typing not yet committed is undone first, leaving the committed edit in place
        await type_into(pilot, grid, "20", commit=None)
        await pilot.press("ctrl+z")
        await pilot.pause()
        assert grid.value == "12" and app.scenario.sensor.grid == 12
        # a segment added, then undone and redone
        app.action_show_tab("flight")
        app.action_add_segment("straight")
        await pilot.pause()
        assert isinstance(app.screen, FormScreen)
        app.screen.query_one("#form-ok").press()
        await pilot.pause()
        assert [s.kind for s in app.scenario.flight.segments] == ["orbit", "straight"]
        assert app.query_one("#segments").row_count == 2
        app.set_focus(None)
        await pilot.press("ctrl+z")
        await pilot.pause()
        assert [s.kind for s in app.scenario.flight.segments] == ["orbit"]
        assert app.query_one("#segments").row_count == 1
        await pilot.press("ctrl+y")
        await pilot.pause()
        assert [s.kind for s in app.scenario.flight.segments] == ["orbit", "straight"]
        # undo everything: the scenario on disk again, and Ctrl+S then writes nothing new
        await pilot.press("ctrl+z", "ctrl+z")
        await pilot.pause()
        assert app.scenario == load_scenario(scenario.path) and not modified(app)


async def test_undo_a_pose_edit(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_manual_poses()
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, PosesScreen)
        screen.dismiss([ScanPose(1.0, 2.0, 50.0)])
        await pilot.pause()
        assert app.scenario.flight.segments[-1].kind == "manual"
        await pilot.press("ctrl+z")
        await pilot.pause()
        assert [s.kind for s in app.scenario.flight.segments] == ["orbit"]


async def test_save_as_writes_a_new_file_and_keeps_the_old_one(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    before = scenario.path.read_bytes()
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "16", commit=None)
        await app.run_action("save_as")  # Ctrl+Shift+S where the terminal sends it
        await pilot.pause()
        assert isinstance(app.screen, SaveAsScreen)
        app.screen.query_one("#save-as-file").value = "copy"
        await pilot.press("enter")
        await pilot.pause()
        copy = tmp_path / "copy.toml"
        assert load_scenario(copy).sensor.grid == 16  # the typed value, committed first
        assert scenario.path.read_bytes() == before
        assert app.scenario.path == copy and not modified(app)
        assert recent_scenarios()[0] == copy.resolve()
        # undo cannot bring back the old name; an existing name needs OK twice
        await pilot.press("ctrl+z")
        await pilot.pause()
        assert app.scenario.path == copy
        await app.run_action("save_as")
        await pilot.pause()
        app.screen.query_one("#save-as-file").value = scenario.path.name
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, SaveAsScreen)
        assert "exists" in str(app.screen.query_one("#save-as-message").render())
        await pilot.press("escape")
        await pilot.pause()
        assert scenario.path.read_bytes() == before


async def test_save_as_onto_a_run_record_is_refused_in_the_dialog(tmp_path, scene_files):
    """'S_Run.toml exists: OK again replaces it'; OK again closed the dialog and the
    note said it was a run record, the name typed lost."""
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files)
    simulate(scenario)
    record = scenario.run_record
    before = record.read_bytes()
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        dialog = await screen_after(pilot, app.action_save_as, SaveAsScreen)
        dialog.query_one("#save-as-file").value = record.name
        for _ in range(2):
            await pilot.press("enter")
            await pilot.pause()
            assert app.screen is dialog
            said = str(dialog.query_one("#save-as-message").render())
            assert said == (
                f"{record}: is a run record (the settings that made {scenario.path.name}'s "
                "outputs, written by its runs): save under another name"
            ), said
    assert record.read_bytes() == before


async def test_save_as_a_name_whose_runs_would_replace_a_model_is_refused_in_the_dialog(
    tmp_path, scene_files
):
    """Save As forest.toml beside forest.txt wrote a file whose run would write
    forest_Target.txt over the target model: 'Saved', then Run off for good."""
    scenario = make_scenario(tmp_path, scene_files)
    scene_path = scene_files[0]
    beside = scene_path.with_suffix(".toml")
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        dialog = await screen_after(pilot, app.action_save_as, SaveAsScreen)
        dialog.query_one("#save-as-file").value = str(beside)
        await pilot.press("enter")
        await pilot.pause()
        assert app.screen is dialog and not beside.exists()
        said = str(dialog.query_one("#save-as-message").render())
        assert said.startswith(f"{beside}: files.scene = '{scene_path.name}': expected a scene model"), said
        assert f"{scene_path.stem}_Target.txt would overwrite a model file" in said
        # another name is saved
        dialog.query_one("#save-as-file").value = "plan"
        await pilot.press("enter")
        await pilot.pause()
        assert app.scenario.path == tmp_path / "plan.toml" and not beside.exists()


async def test_recent_scenarios_are_listed_and_open_after_asking(tmp_path, scene_files, monkeypatch):
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    first = make_scenario(tmp_path, scene_files, name="first")
    second = make_scenario(tmp_path, scene_files, name="second")
    app = LadarApp(first.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.open_path(second.path)
        await wait_until(pilot, lambda: app.scenario.path == second.path and app.busy is None)
        app.action_show_tab("file")
        await pilot.pause()
        listing = app.query_one("#recent")
        assert listing.option_count == 1 and listing.get_option_at_index(0).id == str(first.path.resolve())
        assert any(a.startswith("open_recent") and "first.toml" in a for _, _, a in palette_entries())
        app.action_show_tab("sensor")
        await type_into(pilot, field(app, "sensor.grid"), "12")
        app.action_show_tab("file")
        listing.focus()
        listing.highlighted = 0
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, UnsavedScreen)  # the edit is not lost unasked
        await pilot.click("#unsaved-discard")
        await wait_until(pilot, lambda: app.scenario.path == first.path and app.busy is None)
        # one deleted since: opening it fails, and it leaves the list (it stayed, to fail again)
        second.path.unlink()
        assert listing.get_option_at_index(0).id == str(second.path.resolve())
        app.open_path(second.path)
        await wait_until(pilot, lambda: app.busy is None and any("Could not load" in m for m in app.messages))
        await pilot.pause()
        assert listing.option_count == 0
        assert second.path.resolve() not in recent_scenarios()  # nor offered to the next session


async def test_the_folder_tree_fills_the_scenario_field(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "x"\n')  # .toml, no scenario
    (tmp_path / "cloud.las").write_bytes(b"")  # a point cloud: no scene model a scenario reads
    from ladartui.simulation import simulate

    simulate(scenario)  # writes demo_Run.toml: an output, not a scenario to open
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        await pilot.press("f3")
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, SetupScreen)
        tree = screen.query_one(FileTree)
        await wait_until(pilot, lambda: len(tree.root.children) > 0)
        names = [node.data.path.name for node in tree.root.children]
        assert "demo.toml" in names and all(not n.startswith(".") for n in names)
        assert "pyproject.toml" not in names and "demo_Run.toml" not in names and "cloud.las" not in names
        assert all(n.endswith((".toml", ".txt")) or (tmp_path / n).is_dir() for n in names)
        tree.focus()
        tree.move_cursor(tree.root.children[names.index("demo.toml")])
        await pilot.press("enter")
        await pilot.pause()
        assert screen.query_one("#scenario-file").value == "demo.toml"


async def test_start_pose_fields_follow_the_path_kind_and_refuse_impractical_values(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("flight")
        await pilot.pause()
        assert field(app, "start.z").disabled  # an orbit starts at its own first scan
        straight = app.scenario.with_changes(
            flight=FlightPlan(ScanPose(0.0, 0.0, 100.0), (Straight(distance=50.0, scans=3),))
        )
        app.edit(straight, "a straight path")
        await pilot.pause()
        altitude, heading = field(app, "start.z"), field(app, "start.heading")
        assert not altitude.disabled and not heading.disabled
        await type_into(pilot, altitude, "100000")
        assert app.scenario.flight.start.z == 100.0
        assert "Altitude m: 100000 is not allowed" in app.messages[-1]
        await type_into(pilot, heading, "400")
        assert app.scenario.flight.start.heading == 0.0
        assert "Heading deg: 400 is not allowed; expected a number from 0 to 360 deg" in app.messages[-1]


async def test_compare_takes_files_picked_in_the_tree(tmp_path, scene_files):
    from ladartui.tui.measures_screens import CompareScreen

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        for name in ("a", "b"):
            (tmp_path / f"{name}.cmf").write_text("")
        await app.run_action("compare")
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, CompareScreen)
        tree = screen.query_one(FileTree)
        await wait_until(pilot, lambda: len(tree.root.children) > 0)
        names = [node.data.path.name for node in tree.root.children]
        assert {"a.cmf", "b.cmf"} <= set(names) and "demo.toml" not in names
        chosen = screen.query_one("#cmf-files")
        a, b = "a.cmf", "b.cmf"  # in the dialog's folder: by name
        assert chosen.value.split() == [a, b]  # the folder's .cmf files to start with
        tree.focus()
        picks = []
        for name in ("a.cmf", "a.cmf", "b.cmf"):  # a pick adds a file, a second one drops it
            tree.move_cursor(tree.root.children[names.index(name)])
            await pilot.press("enter")
            await pilot.pause()
            picks.append(chosen.value.split())
        assert picks == [[b], [b, a], [a]]


async def test_compare_moves_its_tree_up_to_pick_a_run_in_the_folder_beside(tmp_path, scene_files):
    """As in Open and Save As, "Up a folder" reaches the measures of a scenario kept beside."""
    from ladartui.tui.measures_screens import CompareScreen

    here, beside = tmp_path / "here", tmp_path / "beside"
    here.mkdir()
    beside.mkdir()
    (beside / "other.cmf").write_text("")
    app = LadarApp(make_scenario(here, scene_files).path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        await app.run_action("compare")
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, CompareScreen)
        screen.query_one("#tree-up", Button).press()
        await pilot.pause()
        tree = screen.query_one(FileTree)
        assert tree.path == tmp_path
        await wait_until(pilot, lambda: len(tree.root.children) == 2)
        folder = next(node for node in tree.root.children if node.data.path == beside)
        tree.focus()
        tree.move_cursor(folder)
        await pilot.press("enter")  # opens the folder
        await wait_until(pilot, lambda: len(folder.children) == 1)
        tree.move_cursor(folder.children[0])
        await pilot.press("enter")
        await pilot.pause()
        # named in the folder now shown, where names typed are read too
        assert screen.query_one("#cmf-files", Input).value.split()[-1] == "beside/other.cmf"


@pytest.mark.parametrize("size", [(80, 24), (120, 40)])
async def test_no_sidebar_label_or_button_is_clipped(tmp_path, scene_files, size):
    from rich.cells import cell_len
    from textual.widgets import Button, Label

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=size) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        clipped = []
        for tab in ("file", "sensor", "flight", "run", "results"):
            app.action_show_tab(tab)
            await pilot.pause(0.2)
            pane = app.query_one(f"#tab-{tab}")
            for widget in [*pane.query(Button), *pane.query(".row Label")]:
                if not widget.display or widget.region.width == 0:
                    continue
                text = str(widget.label if isinstance(widget, Button) else widget.render())
                margin = 2 if isinstance(widget, Button) else 0  # a button pads its label
                if cell_len(text.strip()) + margin > widget.content_region.width:
                    clipped.append((tab, text, widget.content_region.width))
        assert not clipped
        assert any(isinstance(w, Label) for w in app.query(".row Label"))


async def test_a_key_remapped_in_keys_toml_changes_the_footer_help_and_palette(
    tmp_path, scene_files, monkeypatch
):
    from textual.widgets import Button

    from ladartui.tui.app import help_rows
    from ladartui.tui.app import palette_entries as app_palette
    from ladartui.tui.screens import HelpScreen
    from test_tui_edits import capture_runs
    from test_tui_flow import shown_keys

    keys_in(
        tmp_path,
        monkeypatch,
        '[keys]\nrun = "ctrl+r"\nnonsense = "x"\nthreshold = 3\nlayout = "[bold red]q"\nsave = "ctrl+w"\n',
    )
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        keys = shown_keys(app)
        assert "ctrl+r" in keys and "f5" not in keys  # the footer
        assert ("Anywhere", "Ctrl+R", "Run simulation") in help_rows(app)  # the help screen
        assert ("Anywhere", "F5", "Run simulation") not in help_rows(app)
        await pilot.press("f1")
        await pilot.pause()
        assert isinstance(app.screen, HelpScreen)
        await pilot.press("escape")
        entries = {title: text for title, text, _ in app_palette(app)}
        assert entries["Run simulation"].endswith("(Ctrl+R)")  # the palette
        # the bad lines are named, and the rest of the file still applies
        problems = [m for m in app.messages if m.startswith("Key not remapped")]
        assert len(problems) == 3 and "keys.nonsense" in problems[0]
        assert "keys.threshold = 3" in problems[1]
        assert "keys.layout = '[bold red]q': expected a key name" in problems[2]
        assert "f6" in shown_keys(app)  # the layout key stays the default
        # buttons and messages name the keys in force
        labels = {str(b.id): str(b.label) for b in app.query(Button)}
        assert labels["btn-run"] == "Run ^R" and labels["btn-save"] == "Save ^W"
        assert labels["btn-open"] == "Open F3"
        assert app.query_one(StatusBar).message.endswith("rays. Ctrl+R runs.")
        runs = capture_runs(app)
        await pilot.press("ctrl+r")
        await pilot.pause()
        assert len(runs) == 1


async def test_a_key_given_in_keys_toml_to_a_palette_only_command_runs_it(tmp_path, scene_files, monkeypatch):
    """Commands without a default key (the tabs, fit scene, ...) took a key in keys.toml
    and showed it in the help, but pressing it did nothing."""
    from textual.widgets import TabbedContent

    from ladartui.tui.app import help_rows

    keys_in(tmp_path, monkeypatch, '[keys]\ntab-sensor = "ctrl+k"\n')
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        assert ("Anywhere", "Ctrl+K", "Show sensor panel") in help_rows(app)
        tabs = app.query_one("#tabs", TabbedContent)
        assert tabs.active != "tab-sensor"
        await pilot.press("ctrl+k")
        await pilot.pause()
        assert tabs.active == "tab-sensor"


async def test_a_flight_log_segment_is_listed_and_says_where_it_is_edited(tmp_path, scene_files):
    import shutil
    from pathlib import Path

    from ladartui.trajectory import LogSegment

    log = tmp_path / "[b]flight-log.csv"  # brackets: text from a file is never markup
    shutil.copy(Path(__file__).parents[1] / "scenarios" / "flight-log.csv", log)
    scenario = make_scenario(tmp_path, scene_files)
    scenario = scenario.with_changes(
        flight=FlightPlan(None, (*scenario.flight.segments, LogSegment(str(log), rate=2.0)))
    ).save()
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("flight")
        await pilot.pause()
        table = app.query_one("#segments")
        assert table.row_count == 2
        cells = table.get_row_at(1)
        row = [str(cell) for cell in cells]
        assert row[1] == "Log" and "".join(row[3].split()) == "[b]flight-log.csv,2Hz"  # wrapped or not
        assert isinstance(cells[3], Text)  # drawn as it is: a str cell would be read as markup
        table.move_cursor(row=1)
        app.action_edit_segment()
        await pilot.pause()
        assert not isinstance(app.screen, FormScreen)  # no number form for a file's data
        assert "scenario file" in app.messages[-1]


async def test_every_footer_key_fits_an_80_column_terminal(tmp_path, scene_files):
    from textual.widgets._footer import FooterKey

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(80, 24)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        await pilot.pause()
        shown = {key.key: key.region for key in app.screen.query(FooterKey)}
        assert {"f1", "f5", "f6", "f8", "f10", "f11", "f12"} <= set(shown)
        assert all(0 < region.right <= 80 for region in shown.values())
        assert "escape" not in shown  # Cancel joins the footer only while a run goes


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


async def test_the_flight_tables_are_drawn_to_their_new_cells_at_once(tmp_path, scene_files):
    """After a segment was deleted the scans table showed x -12 as "-" and y 82 as "8"
    until the next change: its columns took their widths from the cells only when
    Textual next measured them, and a frame drawn before that cut every value."""
    from rich.cells import cell_len

    from ladartui.flight import Turn

    scenario = make_scenario(tmp_path, scene_files)
    turn = Turn(radius=100.0, arc=90.0, direction="right", scans=4)
    scenario = scenario.with_changes(flight=FlightPlan(None, (*scenario.flight.segments, turn))).save()
    app = LadarApp(scenario.path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("flight")
        await pilot.pause()
        app.query_one("#segments").move_cursor(row=0)
        app.flight_panel.delete_selected()
        # no pause: the frame drawn next must already have the widths
        for table in (app.query_one("#scans"), app.query_one("#segments")):
            columns = list(table.columns.values())
            rows = [[str(cell) for cell in table.get_row_at(i)] for i in range(table.row_count)]
            for index, column in enumerate(columns[: len(columns) if table.id == "scans" else 3]):
                widest = max(cell_len(str(column.label)), *(cell_len(row[index]) for row in rows))
                assert column.get_render_width(table) == widest + 2 * table.cell_padding, (table.id, index)


async def test_messages_that_name_a_key_name_the_one_in_force(tmp_path, scene_files, monkeypatch):
    """With the run on Ctrl+R, F9 before a run said 'run the scenario first (F5)', and the
    Open dialog 'missing outputs are listed, and F5 writes them'."""
    from ladartui.tui.file_dialogs import SetupScreen

    keys_in(tmp_path, monkeypatch, '[keys]\nrun = "ctrl+r"\nsave = "ctrl+w"\n')
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_measures()
        assert app.messages[-1] == "No measures yet: run the scenario first (Ctrl+R)."
        dialog = await screen_after(pilot, "f3", SetupScreen)
        said = str(dialog.query_one("#derived").render())
        assert "a run (Ctrl+R) writes them" in said and "F5" not in said
