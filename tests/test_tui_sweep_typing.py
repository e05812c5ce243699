"""The sweep screen takes what the analyst types: the Spec field keeps the focus when
the screen reopens the last sweep by itself.

A two-variant sweep over the tiny scenario runs once, serially; each test opens it.
"""

from __future__ import annotations

import pytest
from textual.widgets import DataTable, Input

from ladartui.recent import remember_path
from ladartui.tui.sweep_screen import SweepScreen
from sweep_screen_support import SIZE, SweepHost, opened, swept_folder, wait_for


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """A folder holding the base, the spec and its finished two-variant results."""
    return swept_folder(tmp_path_factory)


async def test_text_typed_after_the_last_sweep_reopens_goes_into_the_spec_field(swept, tmp_path, monkeypatch):
    """The reopened sweep's table took the focus: what was typed next was lost, and F5
    ran the reopened spec instead of the one typed."""
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    remember_path("sweeps", swept / "spec.toml")
    screen = SweepScreen()  # no path: the last sweep comes back
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        assert screen.query_one("#sweep-table", DataTable).row_count == 2
        field = screen.query_one("#sweep-path", Input)
        assert screen.focused is field
        await pilot.press("ctrl+u", *"other.toml")
        assert field.value == "other.toml"


async def test_a_sweep_opened_on_enter_gives_its_table_the_focus(swept, tmp_path, monkeypatch):
    """Opened on the analyst's Enter, the ranking is browsed at once with the arrows."""
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))  # no sweep to reopen
    screen = SweepScreen()
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        screen.query_one("#sweep-path", Input).value = str(swept / "spec-results")
        await pilot.press("enter")
        await opened(pilot)
        await wait_for(pilot, lambda: screen.query_one("#sweep-table", DataTable).row_count == 2)
        assert screen.focused is screen.query_one("#sweep-table", DataTable)


async def test_a_sweep_opened_on_f3_from_another_field_gives_its_table_the_focus(
    swept, tmp_path, monkeypatch
):
    """Only a sweep opened from the Spec field got the focus on its table; F3 from the
    Budget field (or a click on Browse) left it where it was, as docs/tui.md says it is not."""
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))  # no sweep to reopen
    screen = SweepScreen()
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        screen.query_one("#sweep-path", Input).value = str(swept / "spec-results")
        screen.query_one("#sweep-budget", Input).focus()
        await pilot.press("f3")
        await opened(pilot)
        await wait_for(pilot, lambda: screen.query_one("#sweep-table", DataTable).row_count == 2)
        assert screen.focused is screen.query_one("#sweep-table", DataTable)
