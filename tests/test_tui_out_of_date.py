"""Outputs out of date are said so wherever their measures are shown, and why in the
truest words: the Measures dialog (F9) as the Results tab and the status bar do."""

from __future__ import annotations

from ladartui.sensor import Sensor
from ladartui.simulation import simulate
from ladartui.tui.screens import MeasuresScreen
from test_tui_dialogs import opened
from test_tui_flow import make_scenario, wait_until


def stale_note(screen) -> str:
    notes = screen.query("#measures-stale")
    return str(notes.first().render()) if notes and notes.first().display else ""


async def test_the_measures_dialog_says_when_its_measures_are_out_of_date(tmp_path, scene_files):
    """F9 showed the measures of a run with other settings with no word of it, while
    the status bar was yellow and the Results tab named the setting."""
    scenario = make_scenario(tmp_path, scene_files)  # saved with an 8 x 8 grid
    simulate(scenario.with_changes(sensor=Sensor(grid=12, ray_grid=1, fov=8.0)))  # never saved
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        await pilot.press("f9")
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen), timeout=10.0)
        screen = app.screen
        assert str(screen.query_one(".dialog").border_title) == "Comparison measures (out of date)"
        assert stale_note(screen) == (
            "Out of date: made from other settings: sensor.grid 12 (here 8). "
            f"The run's settings are in {scenario.name}_Run.toml. F5 reruns."
        )
        await pilot.press("escape")
        await app.run_action("run")  # up to date: nothing more is said
        await wait_until(pilot, lambda: isinstance(app.screen, MeasuresScreen))
        await pilot.pause()
        assert "out of date" not in str(app.screen.query_one(".dialog").border_title)
        assert stale_note(app.screen) == ""
