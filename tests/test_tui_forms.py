"""Dialogs that read what is typed: Compare's files, New scenario's scene model, a
segment form the whole path refuses, the threshold form; each says what is wrong in
its own words and keeps what was typed."""

from __future__ import annotations

import pytest

from ladartui.tui.measures_screens import CompareScreen
from ladartui.tui.screens import FormScreen
from test_tui_dialogs import message
from tui_support import make_scenario, opened, screen_after, type_into, wait_until


async def test_compare_reads_names_typed_in_the_folder_it_shows(tmp_path, scene_files, monkeypatch):
    """The dialog shows 'Folder: <the scenario's>' and its .cmf files in the tree, but a
    name typed there ('a.cmf b.cmf') was looked for in the working folder: 'a.cmf:
    measures file not found'. Open and Save As read typed names in their folder."""
    from ladartui.measures import Measures

    here, elsewhere = tmp_path / "here", tmp_path / "elsewhere"
    here.mkdir()
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    for name, coverage in (("a", 0.2), ("b", 0.3)):
        Measures(target_voxels=100, obscured_coverage=coverage, scans=10).write_cmf(here / f"{name}.cmf")
    scenario = make_scenario(here, scene_files)
    async with opened(scenario) as (app, pilot):
        compare = await screen_after(pilot, app.action_compare, CompareScreen)
        field = compare.query_one("#cmf-files")
        field.value = "a.cmf b.cmf"
        await pilot.press("enter")
        await pilot.pause()
        assert message(compare, "#compare-message") == ""
        table = compare.query_one("#compare-table")
        assert [str(c.label) for c in table.columns.values()] == ["Measure", "a", "b"]
        field.value = "a.cmf 'b.cmf"
        await pilot.press("enter")
        await pilot.pause()
        assert message(compare, "#compare-message") == (
            ".cmf files: a quotation mark is not closed; expected paths separated by spaces, "
            "one with spaces in quotes"
        )


async def test_a_scenario_file_given_as_the_new_scenarios_scene_model_is_named_so(tmp_path, scene_files):
    """It said 'default_Target.toml: target model file not found', of a file no one named."""
    from ladartui.tui.file_dialogs import SetupScreen

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        dialog = await screen_after(pilot, "f2", SetupScreen)
        assert dialog.mode == "new"
        dialog.query_one("#scenario-file").value = "fresh.toml"
        dialog.query_one("#scene-file").value = scenario.path.name
        dialog.query_one("#setup-ok").press()
        await pilot.pause()
        assert message(dialog, "#setup-message") == (
            f"{scenario.path}: scene model file is a scenario file (.toml); expected a scene model (.txt)"
        )
        assert not (tmp_path / "fresh.toml").exists()


@pytest.mark.parametrize(
    ("scene", "kind"), [("cloud.las", "a LAS point cloud (.las)"), ("truck.obj", "a mesh (.obj)")]
)
async def test_a_point_cloud_or_mesh_given_as_the_new_scenarios_scene_model_is_named_so(
    tmp_path, scene_files, scene, kind
):
    """The tree and the completion offered .las and .laz files as scene models, which no
    scenario reads: picked, it said 'cloud_Target.las: a LAS point cloud (.las), not a voxel
    list', of a file no one named (a mesh: 'truck.obj: scene model file not found')."""
    scenario = make_scenario(tmp_path, scene_files)
    for name in (scene, scene.replace(".", "_Target.")):
        (tmp_path / name).write_bytes(b"\x00")
    async with opened(scenario) as (app, pilot):
        said = await new_scenario_said(app, pilot, scene, "0.25")
        command = f"ladartui voxelize {tmp_path / scene} {tmp_path / 'cloud'} --voxel-size 0.25"
        advice = f": make one from it with '{command}'" if scene.endswith(".las") else ""
        assert (
            said == f"{tmp_path / scene}: scene model file is {kind}; expected a scene model (.txt){advice}"
        )
        assert not (tmp_path / "fresh.toml").exists()


async def test_a_new_scenario_whose_scene_cannot_be_read_is_not_written_and_its_form_comes_back(
    tmp_path, scene_files
):
    """A scene model with a bad line: the dialog closed, the new .toml was written anyway
    and its load failed; what was typed was gone, and the name was then refused as taken."""
    from ladartui.tui.file_dialogs import SetupScreen

    scenario = make_scenario(tmp_path, scene_files)
    (tmp_path / "bad.txt").write_text("1,2,3\n1,2,abc\n", encoding="utf-8")
    (tmp_path / "bad_Target.txt").write_text("1,2,3\n", encoding="utf-8")
    async with opened(scenario) as (app, pilot):
        dialog = await screen_after(pilot, "f2", SetupScreen)
        dialog.query_one("#scenario-file").value = "fresh"  # came back as "fresh.toml"
        dialog.query_one("#scene-file").value = "bad.txt"
        dialog.query_one("#voxel-size").value = "0.25"
        dialog.query_one("#setup-ok").press()
        await wait_until(
            pilot,
            lambda: app.busy is None and isinstance(app.screen, SetupScreen) and app.screen is not dialog,
            60,
        )
        again = app.screen
        await wait_until(pilot, lambda: again.is_mounted, 10)
        assert not (tmp_path / "fresh.toml").exists()
        assert again.mode == "new"
        assert [
            again.query_one(f"#{name}").value for name in ("scenario-file", "scene-file", "voxel-size")
        ] == ["fresh", "bad.txt", "0.25"]
        assert message(again, "#setup-message").startswith(f"{tmp_path / 'bad.txt'}:2: z = 'abc'")
        assert app.scenario.path == scenario.path  # the one open before stays


async def new_scenario_on_an_unreadable_scene(folder, app, pilot, scene: str):
    """New (F2) for a scenario 'fresh' on the scene model ``scene``, written in ``folder``
    with a bad second line: the form that comes back, mounted."""
    from ladartui.tui.file_dialogs import SetupScreen

    (folder / scene).write_text("1,2,3\n1,2,abc\n", encoding="utf-8")
    (folder / scene.replace(".txt", "_Target.txt")).write_text("1,2,3\n", encoding="utf-8")
    dialog = await screen_after(pilot, "f2", SetupScreen)
    await pilot.press(*"fresh", "tab", *scene, "tab", "ctrl+u", *"0.25", "enter")
    await wait_until(
        pilot,
        lambda: app.busy is None and isinstance(app.screen, SetupScreen) and app.screen is not dialog,
        60,
    )
    again = app.screen
    await wait_until(pilot, lambda: again.is_mounted, 10)
    await pilot.pause()
    return again


async def test_a_new_scenario_whose_scene_cannot_be_read_comes_back_at_its_scene_model(tmp_path, scene_files):
    """The form came back with the focus on Scenario file, its name selected, while the
    message named the scene model: the corrected model name, typed, replaced the
    scenario's name. The focus is now on 3D scene model."""

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        again = await new_scenario_on_an_unreadable_scene(tmp_path, app, pilot, "bad.txt")
        scene_field = again.query_one("#scene-file")
        assert app.focused is scene_field, app.focused
        await pilot.press("ctrl+u", *"forest.txt")
        assert again.query_one("#scenario-file").value == "fresh"
        assert scene_field.value == "forest.txt"


async def test_a_scene_model_named_after_the_new_scenario_still_gets_the_focus(tmp_path, scene_files):
    """The field was chosen by whether the error began with the scenario's path: a scene
    model fresh.toml.txt beside a new fresh.toml read as the scenario file's error."""

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        again = await new_scenario_on_an_unreadable_scene(tmp_path, app, pilot, "fresh.toml.txt")
        assert message(again, "#setup-message").startswith(f"{tmp_path / 'fresh.toml.txt'}:2: ")
        assert app.focused is again.query_one("#scene-file"), app.focused


async def test_a_scene_model_name_holding_a_terminal_escape_is_said_written_out(tmp_path, scene_files):
    """Open on a scenario whose scene = "sm\\u001b[2Jall.txt" (a model not there) said so
    with the escape raw: the terminal cleared the screen under the dialog."""
    from ladartui.tui.file_dialogs import SetupScreen

    scenario = make_scenario(tmp_path, scene_files)
    lines = scenario.path.read_text(encoding="utf-8").splitlines()
    lines = ['scene = "sm\\u001b[2Jall.txt"' if line.startswith("scene = ") else line for line in lines]
    (tmp_path / "bad.toml").write_text("\n".join(lines) + "\n", encoding="utf-8")
    async with opened(scenario) as (app, pilot):
        dialog = await screen_after(pilot, "f3", SetupScreen)
        await type_into(pilot, dialog.query_one("#scenario-file"), "bad.toml")
        said = message(dialog, "#setup-message")
        assert "sm\\x1b[2Jall.txt not found" in said and "\x1b" not in said, said


async def test_open_shows_only_the_fields_it_reads(tmp_path, scene_files):
    """Open showed New's scene model and voxel size, the voxel size in plain text as if
    it were read; they show again on switching to New."""
    from textual.widgets import RadioButton

    from ladartui.tui.file_dialogs import SetupScreen

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        dialog = await screen_after(pilot, "f3", SetupScreen)
        rows = [dialog.query_one(name).parent for name in ("#scene-file", "#voxel-size")]
        assert not any(row.display for row in rows)
        dialog.query_one("#mode-new", RadioButton).value = True
        await pilot.pause()
        assert dialog.mode == "new" and all(row.display for row in rows)


async def test_a_segment_the_whole_path_refuses_keeps_its_form_open(tmp_path, scene_files):
    """A straight of 9999 scans after a 6-scan orbit: each field was allowed, the form
    closed, and the path's own limit was said after it ('Flight path not changed'),
    with what had been typed gone."""
    scenario = make_scenario(tmp_path, scene_files)  # 6 scans
    async with opened(scenario) as (app, pilot):
        app.action_show_tab("flight")
        form = await screen_after(pilot, lambda: app.action_add_segment("straight"), FormScreen)
        await type_into(pilot, form.query_one("#f-scans"), "9999", commit="tab")
        form.query_one("#form-ok").press()
        await pilot.pause()
        assert app.screen is form
        # in the form's words, of the field that makes the path too long, focused
        assert message(form) == (
            "Scans: 9999 is not allowed; expected at most 9994 here "
            "(the path's other segments have 6 scans; a path has at most 10000)"
        )
        assert app.focused is form.query_one("#f-scans")
        assert form.query_one("#f-scans").value == "9999"
        assert len(app.scenario.flight.segments) == 1
        await type_into(pilot, form.query_one("#f-scans"), "9994", commit="tab")
        form.query_one("#form-ok").press()
        await pilot.pause()
        assert app.screen is not form and len(app.scenario.poses()) == 10000


async def test_a_standoff_the_whole_path_refuses_names_its_standoffs(tmp_path, scene_files):
    """'flight.segments = '10002 scans': expected at most 10000 scans' named no field of
    the form; a standoff's scans are its standoffs."""
    from ladartui.flight import FlightPlan, Straight

    scenario = make_scenario(tmp_path, scene_files)  # 6 scans
    long = Straight(distance=1000.0, scans=9993)
    scenario = scenario.with_changes(flight=FlightPlan(None, (*scenario.flight.segments, long)))
    scenario.save()
    async with opened(scenario) as (app, pilot):
        app.action_show_tab("flight")
        form = await screen_after(pilot, lambda: app.action_add_segment("standoff"), FormScreen)
        form.query_one("#form-ok").press()
        await pilot.pause()
        assert app.screen is form
        assert message(form) == (
            "Standoffs m: 50, 100, 150 is not allowed; expected at most 1 standoff here "
            "(the path's other segments have 9999 scans; a path has at most 10000)"
        )
        assert app.focused is form.query_one("#f-standoffs")


async def test_the_threshold_form_says_why_an_infinite_height_is_refused(tmp_path, scene_files):
    """'Max height (m): 1e400 is not allowed; expected a number >= 0': 1e400 is >= 0;
    what it is not is finite. Its limit is in metres, as the other forms give theirs."""
    from ladartui.tui.screens import ThresholdScreen

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        form = await screen_after(pilot, "f8", ThresholdScreen)
        threshold = form.query_one("#f-threshold")
        await type_into(pilot, threshold, "1e400", commit="enter")
        assert message(form) == "Max height m: 1e400 is not allowed; expected a finite number >= 0 m"
        await type_into(pilot, threshold, "-5", commit="enter")
        assert message(form) == "Max height m: -5 is not allowed; expected a number >= 0 m"


async def test_a_field_without_limits_says_finite_once(tmp_path, scene_files):
    """'Azimuth (deg): nan is not allowed; expected a finite finite number'."""
    from ladartui.tui.screens import AngleScreen

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        form = await screen_after(pilot, "f7", AngleScreen)
        for typed in ("nan", "1e400"):
            await type_into(pilot, form.query_one("#f-azimuth"), typed, commit="enter")
            assert message(form) == f"Azimuth (deg): {typed} is not allowed; expected a finite number"


async def test_compare_names_the_files_in_its_folder_by_their_names(tmp_path, scene_files):
    """The field held whole paths: at 80 columns it showed '…/default/[red.cmf'
    /tmp/h2home/default/default.cmf', scrolled; names in the folder shown read whole."""
    from ladartui.measures import Measures

    scenario = make_scenario(tmp_path, scene_files)
    Measures(target_voxels=100, obscured_coverage=0.2, scans=10).write_cmf(scenario.measures_file)
    Measures(target_voxels=100, obscured_coverage=0.3, scans=10).write_cmf(tmp_path / "other run.cmf")
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        compare = await screen_after(pilot, app.action_compare, CompareScreen)
        assert compare.query_one("#cmf-files").value == "demo.cmf 'other run.cmf'"
        table = compare.query_one("#compare-table")
        assert [str(c.label) for c in table.columns.values()] == ["Measure", "demo", "other run"]


async def test_compare_writes_out_the_controls_in_a_file_name(tmp_path, scene_files):
    """A column headed by "run<ESC>[2J.cmf", and the field of files filled in with it,
    sent the escape to the terminal: the screen was cleared under the dialog."""
    from ladartui.measures import Measures

    scenario = make_scenario(tmp_path, scene_files)
    Measures(target_voxels=100, obscured_coverage=0.2, scans=10).write_cmf(scenario.measures_file)
    Measures(target_voxels=100, obscured_coverage=0.3, scans=10).write_cmf(tmp_path / "run\x1b[2J.cmf")
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        compare = await screen_after(pilot, app.action_compare, CompareScreen)
        table = compare.query_one("#compare-table")
        await wait_until(pilot, lambda: len(table.columns) == 3, 10)
        assert [str(c.label) for c in table.columns.values()] == ["Measure", "demo", "run\\x1b[2J"]
        field = compare.query_one("#cmf-files")
        shown = field.render_line(0).text
        assert "run\u241b[2J.cmf" in shown and "\x1b" not in shown, shown
        assert field.value == "demo.cmf 'run\x1b[2J.cmf'"  # the name on disk, to be read


async def test_open_offers_the_open_scenario_so_enter_reopens_it(tmp_path, scene_files):
    """'changed on disk; reopen (F3)' left the user to find and pick the file again in an
    empty Open dialog. Open now holds the open scenario's name, selected (typing replaces
    it), so F3 then Enter reads the file as it is on disk."""
    from ladartui.tui.file_dialogs import SetupScreen

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        text = scenario.path.read_text(encoding="utf-8")
        assert "speed_mps = " in text
        before = app.scenario.speed
        scenario.path.write_text(text.replace("speed_mps = ", "speed_mps = 1"), encoding="utf-8")
        dialog = await screen_after(pilot, "f3", SetupScreen)
        assert dialog.mode == "load"
        field = dialog.query_one("#scenario-file")
        assert field.value == scenario.path.name and field.selected_text == scenario.path.name
        await pilot.press("enter")
        await wait_until(pilot, lambda: not isinstance(app.screen, SetupScreen) and app.busy is None, 10)
        assert app.scenario.speed == load_speed(scenario.path) != before


def load_speed(path):
    from ladartui.scenario import load_scenario

    return load_scenario(path).speed


async def test_names_typed_after_up_a_folder_are_read_in_the_folder_shown(tmp_path, scene_files):
    """'Up a folder' moved the tree and the Folder line, but names typed were still read
    in the folder the dialog opened in; what the fields held is now put in the new
    folder's terms, and typed names are read there."""
    from ladartui.measures import Measures
    from ladartui.tui.file_dialogs import SetupScreen

    here = tmp_path / "here"
    here.mkdir()
    scenario = make_scenario(here, scene_files)
    for name in ("a", "b"):
        Measures(target_voxels=100, obscured_coverage=0.2, scans=10).write_cmf(here / f"{name}.cmf")
    async with opened(scenario) as (app, pilot):
        dialog = await screen_after(pilot, "f3", SetupScreen)
        assert dialog.query_one("#scenario-file").value == "demo.toml"
        dialog.query_one("#tree-up").press()
        await pilot.pause()
        assert str(dialog.query_one("#tree-root").render()) == f"Folder: {tmp_path}"
        assert dialog.query_one("#scenario-file").value == "here/demo.toml"
        dialog.query_one("#setup-ok").press()
        await wait_until(pilot, lambda: not isinstance(app.screen, SetupScreen) and app.busy is None)
        assert app.scenario.path == scenario.path
        compare = await screen_after(pilot, app.action_compare, CompareScreen)
        field = compare.query_one("#cmf-files")
        field.value = "a.cmf 'b.cmf'"
        compare.query_one("#tree-up").press()
        await pilot.pause()
        assert field.value == "here/a.cmf here/b.cmf"
        field.focus()
        await pilot.press("enter")
        await pilot.pause()
        assert message(compare, "#compare-message") == ""


async def test_a_new_scenario_on_a_scene_without_a_target_is_refused_in_its_form(tmp_path, scene_files):
    """A scene made with 'generate --no-target': OK ended the app in a ValueError
    traceback from the default orbit's sums. The form now names the empty target model."""
    scenario = make_scenario(tmp_path, scene_files)
    (tmp_path / "bare.txt").write_text("1,2,3\n", encoding="utf-8")
    (tmp_path / "bare_Target.txt").write_text("", encoding="utf-8")
    async with opened(scenario) as (app, pilot):
        said = await new_scenario_said(app, pilot, "bare.txt", "0.25")
        assert said.startswith(f"{tmp_path / 'bare_Target.txt'}: target model holds no voxels; ")
        assert not (tmp_path / "fresh.toml").exists()


async def new_scenario_said(app, pilot, scene: str, voxel_size: str) -> str:
    """What New's form says on OK with ``scene`` and ``voxel_size`` typed ('' once it closed)."""
    from ladartui.tui.file_dialogs import SetupScreen

    dialog = await screen_after(pilot, "f2", SetupScreen)
    dialog.query_one("#scenario-file").value = "fresh.toml"
    dialog.query_one("#scene-file").value = scene
    dialog.query_one("#voxel-size").value = voxel_size
    dialog.query_one("#setup-ok").press()
    await pilot.pause()
    return message(dialog, "#setup-message") if app.screen is dialog else ""


async def test_a_new_scenario_at_the_largest_voxel_size_gets_a_flight_it_can_fly(tmp_path, scene_files):
    """Voxel size 100 (the form allows 0.001 to 100 m) was refused with 'altitude =
    22894.1: expected ... at most 20000', a field the form has not: the default orbit
    climbed with the scene's size in metres. It now stays at or below that ceiling."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        assert await new_scenario_said(app, pilot, str(scene_files[0]), "100") == ""
        await wait_until(pilot, lambda: app.busy is None and app.scenario.path.name == "fresh.toml", 60)
        assert app.scenario.voxel_size == 100
        (orbit,) = app.scenario.flight.segments
        assert 0 < orbit.altitude <= 20000 and orbit.altitude > orbit.centre[2]


async def test_a_target_too_high_to_orbit_is_blamed_on_the_voxel_size(tmp_path, scene_files):
    """A target whose centre is above the highest altitude a flight may have at this voxel
    size cannot be orbited from above: the form names its voxel size and says why."""
    scenario = make_scenario(tmp_path, scene_files)
    (tmp_path / "high.txt").write_text("0,0,0\n1,1,250\n", encoding="utf-8")
    (tmp_path / "high_Target.txt").write_text("1,1,250\n", encoding="utf-8")
    async with opened(scenario) as (app, pilot):
        said = await new_scenario_said(app, pilot, "high.txt", "100")
        assert said.startswith("Voxel size m: 100 is not allowed; expected a voxel size that puts ")
        assert "25000 m" in said and "20000 m" in said and "\n" not in said
        assert not (tmp_path / "fresh.toml").exists()


async def test_a_value_just_under_a_limit_is_not_shown_rounded_onto_it(tmp_path, scene_files):
    """fov 89.99999 was shown as 90, a value the field refuses: committing the field as
    shown then failed. Six digits stay where they show an allowed value."""
    import dataclasses

    from tui_support import field

    scenario = make_scenario(tmp_path, scene_files)
    sensor = dataclasses.replace(scenario.sensor, fov=89.99999)
    scenario = scenario.with_changes(sensor=sensor).save()
    async with opened(scenario) as (app, pilot):
        app.action_show_tab("sensor")
        await pilot.pause()
        fov = field(app, "sensor.fov")
        assert fov.value == "89.99999" and fov.parsed() == 89.99999
        assert field(app, "sensor.ray_grid").value == "1"
        await type_into(pilot, fov, "12.3456789", commit="enter")
        assert fov.value == "12.3457" and app.scenario.sensor.fov == 12.3456789  # six digits shown


async def test_forms_open_on_values_of_many_digits(tmp_path, scene_files):
    """A view angle of 10.1234567, or an orbit radius of 60.1234567 (a sweep's best path
    writes such), crashed the app as its form opened: the field asked the form to check
    its value before the form's other fields were built."""
    import dataclasses

    from ladartui.tui.screens import AngleScreen

    scenario = make_scenario(tmp_path, scene_files)
    orbit = dataclasses.replace(scenario.flight.segments[0], radius=60.1234567)
    scenario = scenario.with_changes(flight=dataclasses.replace(scenario.flight, segments=(orbit,))).save()
    async with opened(scenario) as (app, pilot):
        form = await screen_after(pilot, "f7", AngleScreen)
        await type_into(pilot, form.query_one("#f-azimuth"), "10.1234567", commit="enter")
        await wait_until(pilot, lambda: app.screen is not form)
        form = await screen_after(pilot, "f7", AngleScreen)
        await pilot.pause()
        assert form.query_one("#f-azimuth").value == "10.1235"
        form.query_one("#form-cancel").press()
        await wait_until(pilot, lambda: app.screen is not form)
        app.action_show_tab("flight")
        await pilot.pause()
        form = await screen_after(pilot, app.action_edit_segment, FormScreen)
        await pilot.pause()
        assert form.query_one("#f-radius").value == "60.1235"


def test_the_room_a_path_leaves_a_segment_is_said_in_english(tmp_path, scene_files):
    """'the path's other segments have 1 scans'."""
    import pytest

    from ladartui.errors import FieldError
    from ladartui.flight import Manual, ScanPose, Straight
    from ladartui.tui import bridge

    scenario = make_scenario(tmp_path, scene_files)
    segments = [Manual((ScanPose(0.0, 0.0, 40.0),)), Straight(distance=1000.0, scans=10000)]
    with pytest.raises(FieldError) as caught:
        bridge.with_segment_at(scenario, segments, 1)
    assert "at most 9999 here (the path's other segments have 1 scan; a path has" in str(caught.value)
