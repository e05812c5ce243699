"""Moving about the main screen: the sidebar's tabs shown by their commands whatever
has the focus."""

from __future__ import annotations

import pytest
from textual.widgets import TabbedContent

from test_tui_dialogs import opened
from test_tui_flow import make_scenario


@pytest.mark.parametrize("focus", ["#btn-new", "#btn-save-as"])
async def test_a_tab_command_shows_its_tab_while_a_button_of_another_tab_has_the_focus(
    tmp_path, scene_files, focus
):
    """With the focus on a File-tab button (Tab from the tab bar), the palette's 'Show
    sensor panel' (and a key given to tab-sensor in keys.toml) left the File tab shown:
    the hidden button handed the focus to its neighbour, whose tab took over again."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        tabs = app.query_one("#tabs", TabbedContent)
        assert tabs.active == "tab-file"
        app.query_one(focus).focus()
        await pilot.pause()
        await app.run_action("show_tab('sensor')")  # as the palette's command runs it
        await pilot.pause()
        assert tabs.active == "tab-sensor"
        # and the keys go on from there: Tab moves within the shown tab, not back
        await pilot.press("tab")
        await pilot.pause()
        assert tabs.active == "tab-sensor"
        assert app.focused is not None and app.focused.is_on_screen
