"""Helpers shared by the TUI tests: a scenario over the small generated scene."""

from __future__ import annotations

import time
from pathlib import Path

from ladartui.flight import FlightPlan, Orbit
from ladartui.scenario import Scenario
from ladartui.sensor import Sensor


def make_scenario(folder: Path, scene_files, name="demo", scans=6, grid=8, ray_grid=1):
    scene_path, centre, voxel_size = scene_files
    scenario = Scenario(
        folder / f"{name}.toml",
        scene_path,
        voxel_size,
        Sensor(grid=grid, ray_grid=ray_grid, fov=8.0),
        FlightPlan(None, (Orbit(centre=centre, radius=30.0, altitude=30.0, scans=scans),)),
    )
    return scenario.save()


async def wait_until(pilot, condition, timeout=300.0, said=None):
    """Pause until ``condition()`` holds; ``said()``: what to report when it never does
    (by default the app's state). Generous by default: a cold numba cache compiles the
    tracing kernels during the first run."""
    start = time.monotonic()
    while not condition():
        if time.monotonic() - start > timeout:
            app = pilot.app
            raise AssertionError(
                said()
                if said is not None
                else f"timed out waiting for the app; busy={app.busy!r}, messages={app.messages[-3:]}"
            )
        await pilot.pause(0.05)


async def screen_after(pilot, start, kind, timeout: float = 10.0):
    """The screen of type ``kind`` that ``start`` (a key's name, or a function) pushes,
    once it is mounted (a dialog read before its children are composed has none)."""
    app = pilot.app
    if callable(start):
        start()
    else:
        await pilot.press(start)
    await wait_until(
        pilot,
        lambda: isinstance(app.screen, kind) and app.screen.is_mounted,
        timeout,
        said=lambda: f"no {kind.__name__} after {start!r}; the screen is {app.screen!r}",
    )
    return app.screen
