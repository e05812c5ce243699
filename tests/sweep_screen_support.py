"""Helpers shared by the sweep screen's tests at 80 x 24 (test_tui_sweep_fit.py,
test_tui_sweep_typing.py): a bare app showing the screen, a finished sweep, waits."""

from __future__ import annotations

import time

from textual.app import App

from ladartui.sweep import run_sweep
from ladartui.tui.sweep_screen import SweepScreen
from tiny_sweep import write_spec, write_tiny_scenario

SIZE = (80, 24)


class SweepHost(App):
    """A bare app showing one SweepScreen."""

    def __init__(self, screen: SweepScreen):
        super().__init__()
        self.sweep_screen = screen

    def on_mount(self) -> None:
        self.push_screen(self.sweep_screen)


def swept_folder(tmp_path_factory):
    """A folder holding the tiny base, a spec and its finished two-variant results."""
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
    """Once the screen has finished opening a sweep (or had none to open)."""
    screen = pilot.app.sweep_screen
    await wait_for(pilot, lambda: screen.opening is None or screen.opening.is_finished)
    await pilot.pause()
