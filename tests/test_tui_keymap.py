"""A keys.toml in the running app: a remapped key shown in the footer, the help, the
palette, the buttons and the messages that name a key, its bad lines named; a key given
to a palette-only command runs it; every footer key fits an 80-column terminal (the
file itself read: test_tui_keys.py).

Each test drives a real app on a tiny generated scene with Pilot.
"""

from __future__ import annotations

from ladartui.tui.status import StatusBar
from tui_support import LadarApp, loaded, make_scenario, screen_after, wait_until


def keys_in(tmp_path, monkeypatch, text: str) -> None:
    """A user home under ``tmp_path`` whose keys.toml holds ``text``."""
    home = tmp_path / "home"
    (home / "config").mkdir(parents=True)
    (home / "config" / "keys.toml").write_text(text)
    monkeypatch.setenv("LADARTUI_HOME", str(home))


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


async def test_a_remapped_help_key_is_the_one_shown_on_the_sweep_and_study_screens(
    tmp_path, scene_files, monkeypatch
):
    """With help = "ctrl+g", the sweep screen's footer showed "f1 Help" and "^g Help" both
    (at 80 columns the second under the palette's key), and the help still listed F1 / ?
    there: the screens' own Help kept its default keys."""
    from textual.widgets._footer import FooterKey

    from ladartui.tui.app import help_rows
    from ladartui.tui.help_rows import tool_screen_entries
    from ladartui.tui.screens import HelpScreen
    from ladartui.tui.study_screen import StudyScreen
    from ladartui.tui.sweep_screen import SweepScreen

    keys_in(tmp_path, monkeypatch, '[keys]\nhelp = "ctrl+g"\n')
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        for key, kind, where in (("f12", SweepScreen, "Sweep"), ("f11", StudyScreen, "Study")):
            screen = await screen_after(pilot, key, kind)
            await pilot.pause()
            helps = [k.key for k in screen.query(FooterKey) if k.action in ("help", "app.help")]
            assert helps == ["ctrl+g"], helps
            assert (f"{where} screen", "Ctrl+G", "Help") in help_rows(app)
            assert (f"{where}: Help", "Ctrl+G", "app.help") in tool_screen_entries(screen)
            await screen_after(pilot, "ctrl+g", HelpScreen)
            await pilot.press("escape")
            await pilot.pause()
            await pilot.press("escape")
            await pilot.pause()
            assert app.screen is not screen
