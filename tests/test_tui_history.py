"""Undo and redo, Save As, the recent list, the folder tree (Open's and Compare's) and
the start pose, in the app; no sidebar label clipped, a flight-log segment listed (a
keys.toml in the app: test_tui_keymap.py; LAS, PNG and the views: test_tui_exports.py).

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


async def test_the_folder_tree_writes_out_the_controls_in_a_file_name(tmp_path, scene_files):
    """Open's tree showed "ctl<ESC>[31mred<newline>nl.toml" as "ctl" and its escape, raw:
    the terminal coloured the rows below red, and the name was cut at its newline."""
    scenario = make_scenario(tmp_path, scene_files)
    make_scenario(tmp_path, scene_files, name="ctl\x1b[31mred\nnl")
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        screen = await screen_after(pilot, "f3", SetupScreen)
        tree = screen.query_one(FileTree)
        await wait_until(pilot, lambda: len(tree.root.children) > 1, 10)
        labels = [node.label.plain for node in tree.root.children]
        assert "ctl\\x1b[31mred\\x0anl.toml" in labels, labels


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
        import numpy as np

        from ladartui.measures import compute_measures

        voxels = np.array([(0, 0, 0), (1, 0, 0)], np.int32)
        for name in ("a", "b"):  # measures files that read: Compare offers no other
            (tmp_path / f"{name}.cmf").write_text(compute_measures(voxels, voxels, voxels[:1]).to_cmf())
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


async def test_the_palette_names_a_recent_scenario_whose_path_holds_brackets(
    tmp_path, scene_files, monkeypatch
):
    """A recent scenario "run [final].toml" was offered in the palette as "run .toml" (its
    name read as markup), and one in a folder named "[" (its path holding "[/red]", or
    "[/run [final]", which escaping each tag missed) ended the app with a MarkupError
    once the palette was opened."""
    from textual.command import CommandPalette
    from textual.widgets import OptionList

    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    (tmp_path / "[").mkdir()
    first = make_scenario(tmp_path / "[", scene_files, name="red]x")
    second = make_scenario(tmp_path / "[", scene_files, name="run [final]")
    third = make_scenario(tmp_path, scene_files, name="third")
    app = LadarApp(first.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        for path in (second.path, third.path):
            app.open_path(path)
            await wait_until(pilot, lambda path=path: app.scenario.path == path and app.busy is None)
        await pilot.press("ctrl+p")
        palette = await screen_after(pilot, lambda: None, CommandPalette)
        await pilot.press(*"recent")
        hits = palette.query_one(OptionList)
        await wait_until(pilot, lambda: hits.option_count >= 3 or not app.is_running, timeout=30)
        shown = [str(hits.get_option_at_index(i).prompt) for i in range(hits.option_count)]
        assert any("Open recent: run [final].toml" in s and str(second.path) in s for s in shown), shown
        assert any("Open recent: red]x.toml" in s and f"{tmp_path}/[/red]x.toml" in s for s in shown), shown
        assert app.is_running


def test_names_holding_brackets_or_backslashes_show_as_written_in_markup():
    """rich's escape, used for the unsaved-edits question, the measures' title and the
    forms' messages, escapes only what looks like a tag: "x[b [c].toml" showed as
    "x[b \\[c].toml", and a backslash before a bracket or at the end came out twice."""
    from textual.content import Content

    from ladartui.tui.plain_text import literal

    for name in (
        "x[b [c].toml",
        "[a[b]].toml",
        "a\\[red]b.toml",
        "tail\\",
        "/p/[/run [final].toml",
        "[@click=quit]",
    ):
        assert Content.from_markup(literal(name)).plain == name
