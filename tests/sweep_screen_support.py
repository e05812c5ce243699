"""Helpers shared by the sweep screen's tests at 80 x 24 (test_tui_sweep.py,
test_tui_sweep_run.py, test_tui_sweep_fit.py, test_tui_sweep_typing.py): a bare app
showing the screen, a hand-made 24 x 24 base and its finished sweep, the tiny base's
two-variant sweep, waits."""

from __future__ import annotations

import time

import numpy as np
from textual.app import App

import tiny_sweep
from ladartui.sweep import run_sweep
from ladartui.tui.status import StatusBar
from ladartui.tui.sweep_screen import SweepScreen

SIZE = (80, 24)
CENTRE = (11.5, 11.5, 0.5)  # the 24 x 24 base's target (write_base)


class SweepHost(App):
    """A bare app that shows one SweepScreen and records the scenarios it asks to open."""

    def __init__(self, screen: SweepScreen):
        super().__init__()
        self.sweep_screen = screen
        self.opened = []

    def on_mount(self) -> None:
        self.push_screen(self.sweep_screen)

    def on_sweep_screen_open_scenario(self, message: SweepScreen.OpenScenario) -> None:
        self.opened.append(message.path)


def write_base(folder):
    """A 24 x 24 canopy with gaps over a 4 x 2 x 2 vehicle; a 2-scan orbit, 8 x 8 detectors."""
    from ladartui.flight import FlightPlan, Orbit
    from ladartui.scenario import Scenario
    from ladartui.scene.voxels import save_voxels
    from ladartui.sensor import Sensor

    target = np.array([(i, j, k) for i in range(10, 14) for j in range(11, 13) for k in range(2)], np.int32)
    canopy = np.array([(i, j, 5) for i in range(24) for j in range(24) if (i * 5 + j * 3) % 4 == 0], np.int32)
    save_voxels(folder / "tiny.txt", np.concatenate([target, canopy]))
    save_voxels(folder / "tiny_Target.txt", target)
    flight = FlightPlan(segments=(Orbit(centre=CENTRE, radius=15.0, altitude=15.0, scans=2),))
    Scenario(
        folder / "base.toml", "tiny.txt", 1.0, Sensor(grid=8, ray_grid=1, fov=25.0), flight, backend="numba"
    ).save()


# A spec named "tiny" over write_base's base.toml (tiny_sweep.write_spec writes no name).
def write_spec(folder, body, name="spec.toml"):
    path = folder / name
    path.write_text(f'[sweep]\nscenario = "base.toml"\nname = "tiny"\n{body}', encoding="utf-8")
    return path


SMALL_GRID = """
[grid]
radius = [8.0, 15.0, 30.0]
scans = [1, 3]
sensor_grid = [8, 0]
"""


def finished_sweep(tmp_path_factory):
    """A sweep run to the end by the core (serially): its spec and results folder (for
    conftest's session fixture ``finished``)."""
    folder = tmp_path_factory.mktemp("sweep")
    write_base(folder)
    spec = write_spec(folder, SMALL_GRID)
    result = run_sweep(spec, serial=True)
    return spec, result.results_path.parent


def swept_folder(tmp_path_factory):
    """A folder holding the tiny base, a spec and its finished two-variant results."""
    folder = tmp_path_factory.mktemp("swept")
    tiny_sweep.write_tiny_scenario(folder)
    spec = tiny_sweep.write_spec(folder, "[grid]\nradius = [15.0, 25.0]\n")
    run_sweep(spec, serial=True)
    return folder


# Generous: a numba kernel recompiled after an edit elsewhere can take minutes on a busy machine.
async def wait_for(pilot, condition, timeout=300.0):
    start = time.monotonic()
    while not condition():
        if time.monotonic() - start > timeout:
            screen = pilot.app.sweep_screen
            raise AssertionError(f"timed out; status: {screen.last_message!r}")
        await pilot.pause(0.05)


async def opened(pilot, screen=None):
    """Wait until the screen's open (read in a worker) is shown."""
    screen = screen or pilot.app.sweep_screen
    await wait_for(pilot, lambda: screen.opening is None or screen.opening.is_finished)
    await pilot.pause()


def status_of(screen) -> StatusBar:
    return screen.query_one("#sweep-status", StatusBar)


def footer_keys(screen) -> dict:
    """The footer's keys as shown: action -> region (the palette's key as "command_palette")."""
    from textual.widgets._footer import FooterKey

    return {key.action: key.region for key in screen.query(FooterKey)}


def assert_clear_of_the_palette_key(shown_keys: dict) -> None:
    """Every key ends before the palette's key, docked at the footer's right, begins: one
    under it cannot be read."""
    palette = shown_keys.pop("command_palette")
    for action, region in shown_keys.items():
        assert region.right <= palette.x, (action, region, palette)
