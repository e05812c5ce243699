"""Moving about the main screen: the sidebar's tabs shown by their commands whatever
has the focus."""

from __future__ import annotations

import pytest
from textual.widgets import TabbedContent

from tui_support import make_scenario, opened


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


def test_the_segments_table_says_at_of_the_altitude_alone():
    """The orbit read 'r 60 m at 60 m' (its altitude) and the fly-past '200 m at 80 m'
    (its standoff): beside each other, the pass looked flown at 80 m. The fly-past names
    its standoff as one and its altitude after 'at', as the orbit does."""
    from ladartui.flight import FlyPast, Orbit
    from ladartui.tui.bridge import segment_summary

    target = (30.0, 30.0, 1.0)
    assert segment_summary(Orbit(centre=target, radius=60.0, altitude=60.0, scans=24)) == "r 60 m at 60 m"
    flypast = FlyPast(target=target, standoff=80.0, altitude=60.0, length=200.0, scans=7)
    assert segment_summary(flypast) == "200 m, 80 m off at 60 m"
    # wrapped in the 80-column sidebar: the standoff and the altitude each on one line
    from ladartui.tui.fitted_tables import wrap_detail

    assert wrap_detail("200 m, 80 m off at 60 m", 13) == ["200 m,", "80 m off", "at 60 m"]
    assert wrap_detail("200 m, 80 m off at 60 m", 17) == ["200 m, 80 m off", "at 60 m"]


def test_the_segments_table_gives_a_partial_orbits_arc():
    """A half orbit read 'r 60 m at 60 m', as the full circle does."""
    from ladartui.flight import Orbit
    from ladartui.tui.bridge import segment_summary

    target = (30.0, 30.0, 1.0)
    half = Orbit(centre=target, radius=60.0, altitude=60.0, scans=12, arc=180.0)
    assert segment_summary(half) == "180 deg r 60 m at 60 m"
    assert segment_summary(Orbit(centre=target, radius=60.0, altitude=60.0, scans=12)) == "r 60 m at 60 m"
