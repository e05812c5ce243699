"""The sweep screen takes what the analyst types: the Spec field keeps the focus when
the screen reopens the last sweep by itself.

A two-variant sweep over the tiny scenario runs once, serially; each test opens it.
"""

from __future__ import annotations

import time

import pytest
from textual.app import App
from textual.widgets import DataTable, Input

from ladartui.recent import remember_path
from ladartui.sweep import run_sweep
from ladartui.tui.sweep_screen import SweepScreen
from tiny_sweep import write_spec, write_tiny_scenario

SIZE = (80, 24)


class _Host(App):
    """A bare app showing one SweepScreen."""

    def __init__(self, screen: SweepScreen):
        super().__init__()
        self.sweep_screen = screen

    def on_mount(self) -> None:
        self.push_screen(self.sweep_screen)


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """A folder holding the base, the spec and its finished two-variant results."""
    folder = tmp_path_factory.mktemp("swept")
    write_tiny_scenario(folder)
    spec = write_spec(folder, "[grid]\nradius = [15.0, 25.0]\n")
    run_sweep(spec, serial=True)
    return folder


async def wait_for(pilot, condition, timeout=300.0):
    start = time.monotonic()
    while not condition():
        assert time.monotonic() - start < timeout, pilot.app.sweep_screen.last_message
        await pilot.pause(0.05)


async def opened(pilot):
    screen = pilot.app.sweep_screen
    await wait_for(pilot, lambda: screen.opening is None or screen.opening.is_finished)
    await pilot.pause()


async def test_text_typed_after_the_last_sweep_reopens_goes_into_the_spec_field(swept, tmp_path, monkeypatch):
    """The reopened sweep's table took the focus: what was typed next was lost, and F5
    ran the reopened spec instead of the one typed."""
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    remember_path("sweeps", swept / "spec.toml")
    screen = SweepScreen()  # no path: the last sweep comes back
    async with _Host(screen).run_test(size=SIZE) as pilot:
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
    async with _Host(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        screen.query_one("#sweep-path", Input).value = str(swept / "spec-results")
        await pilot.press("enter")
        await opened(pilot)
        await wait_for(pilot, lambda: screen.query_one("#sweep-table", DataTable).row_count == 2)
        assert screen.focused is screen.query_one("#sweep-table", DataTable)
