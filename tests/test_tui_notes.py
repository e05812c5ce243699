"""Notes (toasts) and dialogs: a note never covers an open dialog."""

from __future__ import annotations

from textual.widgets._toast import Toast

from ladartui.tui.measures_screens import MeasuresScreen
from ladartui.tui.screens import FormScreen
from tui_support import field, make_scenario, opened, screen_after, type_into, wait_until


def opened_with_notes(scenario):
    """The app on ``scenario`` at 80 x 24, loaded, its notes drawn: (app, pilot)."""
    return opened(scenario, size=(80, 24), notifications=True)


def toasts(app) -> list[str]:
    """The notes drawn on the screen shown."""
    return [str(toast.render()) for toast in app.screen.query(Toast) if toast.region.area]


def shown(app, words: str) -> bool:
    return any(words in text for text in toasts(app))


async def test_a_note_waits_while_a_dialog_is_open(tmp_path, scene_files):
    """'Pixel pitch um: 0 is not allowed...' sat over the Turn dialog's OK and Cancel for
    seconds at 80 x 24. Notes on screen when a dialog opens, and notes told while it is
    open, now show once it has closed."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened_with_notes(scenario) as (app, pilot):
        app.action_show_tab("sensor")
        await pilot.pause()
        await type_into(pilot, field(app, "sensor.pixel_pitch"), "0", commit="enter")
        await wait_until(pilot, lambda: shown(app, "Pixel pitch um: 0 is not allowed"), 10)
        app.action_show_tab("flight")
        form = await screen_after(pilot, lambda: app.action_add_segment("turn"), FormScreen)
        await pilot.pause(0.2)
        assert toasts(app) == []
        # nor behind it: the screen under the dialog drew its toasts on, half covered
        assert not [t for t in app.screen_stack[0].query(Toast) if t.region.area]
        app.tell("told while the dialog is open")
        await pilot.pause(0.2)
        assert toasts(app) == [] and app.screen is form
        form.query_one("#form-cancel").press()
        await wait_until(pilot, lambda: not isinstance(app.screen, FormScreen), 10)
        await wait_until(pilot, lambda: shown(app, "Pixel pitch um: 0 is not allowed"), 10)
        await wait_until(pilot, lambda: shown(app, "told while the dialog is open"), 10)


async def test_the_measures_dialog_opens_clear_of_notes(tmp_path, scene_files):
    from ladartui.measures import Measures

    measures = Measures(target_voxels=100, obscured_coverage=0.2, scans=10)
    scenario = make_scenario(tmp_path, scene_files)
    async with opened_with_notes(scenario) as (app, pilot):
        app.tell("a note about the main screen")
        await wait_until(pilot, lambda: shown(app, "a note about the main screen"), 10)
        await screen_after(pilot, lambda: app.push_screen(MeasuresScreen(measures)), MeasuresScreen)
        await pilot.pause(0.2)
        assert toasts(app) == []


async def test_a_note_held_by_dialogs_shows_for_the_time_it_had_left(tmp_path, scene_files):
    """A note shown, then held by a dialog, came back for its whole time after each
    dialog: 'Invalid value' reappeared minutes later, after a run and a threshold."""
    from ladartui.tui.screens import ThresholdScreen

    scenario = make_scenario(tmp_path, scene_files)
    async with opened_with_notes(scenario) as (app, pilot):
        app.notify("a short note", timeout=60.0)
        await wait_until(pilot, lambda: shown(app, "a short note"), 10)
        note = next(n for n in app._notifications if n.message == "a short note")
        note.raised_at -= 45.0  # shown for 45 of its 60 s: no race with a slow machine
        form = await screen_after(pilot, "f8", ThresholdScreen)
        await pilot.pause(0.2)
        assert toasts(app) == []
        form.query_one("#form-cancel").press()
        await wait_until(pilot, lambda: not isinstance(app.screen, ThresholdScreen), 10)

        def back():  # shown again once the screen under the dialog is back (a loaded machine: later)
            return [n for n in app._notifications if n.message == "a short note"]

        await wait_until(pilot, lambda: back(), 10)
        assert len(back()) == 1 and 5.0 < back()[0].timeout <= 15.0  # what it had left, not its 60 s
