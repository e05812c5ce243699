"""Helpers shared by the TUI tests: a scenario over the small generated scene."""

from __future__ import annotations

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


async def screen_after(pilot, start, kind, timeout: float = 10.0):
    """The screen of type ``kind`` that ``start`` (a key's name, or a function) pushes,
    once it is mounted (a dialog read before its children are composed has none)."""
    import time

    app = pilot.app
    if callable(start):
        start()
    else:
        await pilot.press(start)
    began = time.monotonic()
    while not (isinstance(app.screen, kind) and app.screen.is_mounted):
        if time.monotonic() - began > timeout:
            raise AssertionError(f"no {kind.__name__} after {start!r}; the screen is {app.screen!r}")
        await pilot.pause(0.02)
    return app.screen
