"""Path completion in the file dialogs: a name is completed from the folder the dialog
reads typed names in (its Folder line), not from the working folder."""

from __future__ import annotations

from ladartui.tui.screens import PathSuggester
from tui_support import make_scenario, opened, screen_after, wait_until


async def test_a_relative_name_is_completed_in_the_base_folder(tmp_path, monkeypatch):
    (tmp_path / "plans").mkdir()
    (tmp_path / "plans" / "orbit.toml").write_text("")
    (tmp_path / "plans" / "orbit.txt").write_text("")
    (tmp_path / "plans" / "other").mkdir()
    (tmp_path / "plans" / ".hidden.toml").write_text("")
    monkeypatch.chdir(tmp_path)
    suggester = PathSuggester((".toml",), lambda: tmp_path / "plans")
    assert await suggester.get_suggestion("or") == "orbit.toml"  # not orbit.txt: its suffix
    assert await suggester.get_suggestion("ot") == "other/"  # a folder, whatever its suffix
    assert await suggester.get_suggestion("./or") == "./orbit.toml"
    assert await suggester.get_suggestion(".") is None  # hidden names are not offered
    assert await suggester.get_suggestion("zz") is None
    assert await suggester.get_suggestion("") is None
    absolute = f"{tmp_path}/plans/or"
    assert await PathSuggester((".toml",), lambda: tmp_path / "nowhere").get_suggestion(absolute) == (
        absolute + "bit.toml"
    )
    assert await PathSuggester((".toml",)).get_suggestion("plans/or") == "plans/orbit.toml"  # cwd


async def test_a_field_of_several_paths_completes_its_last_word(tmp_path):
    for name in ("a.cmf", "b.cmf"):
        (tmp_path / name).write_text("")
    several = PathSuggester((".cmf",), lambda: tmp_path, several=True)
    assert await several.get_suggestion("a.cmf b") == "a.cmf b.cmf"
    assert await several.get_suggestion("a.cmf ") is None
    assert await PathSuggester((".cmf",), lambda: tmp_path).get_suggestion("a.cmf b") is None


async def test_the_open_dialog_completes_in_the_folder_it_shows(tmp_path, scene_files, monkeypatch):
    """Names typed in the Open dialog are read in its folder, but they were completed
    from the working folder: 'de' offered nothing there, and after 'Up a folder' the
    folder shown was not the one completed from either."""
    from ladartui.tui.file_dialogs import SetupScreen

    here, elsewhere = tmp_path / "here", tmp_path / "elsewhere"
    here.mkdir()
    elsewhere.mkdir()
    (elsewhere / "decoy.toml").write_text("")
    monkeypatch.chdir(elsewhere)
    scenario = make_scenario(here, scene_files)
    async with opened(scenario) as (app, pilot):
        dialog = await screen_after(pilot, "f3", SetupScreen)
        field = dialog.query_one("#scenario-file")
        field.focus()
        field.value = ""
        await pilot.press("d", "e")
        await wait_until(pilot, lambda: field._suggestion == "demo.toml", 10)
        await pilot.press("right")  # takes the suggestion
        assert field.value == "demo.toml"
        dialog.query_one("#tree-up").press()
        await pilot.pause()
        field.focus()
        field.value = ""
        await pilot.press("h", "e")
        await wait_until(pilot, lambda: field._suggestion == "here/", 10)
