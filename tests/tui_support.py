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
