"""SVG snapshots of the main layouts at 80x24 and 120x40 (pytest-textual-snapshot).

Deterministic: the scene comes from a seed, the views from fixed cameras, and the
pictures are taken only once loading, probing and any run have finished.
Regenerate with ``pytest tests/test_tui_snapshots.py --snapshot-update``.
"""

from __future__ import annotations

import time

import pytest

from ladartui.flight import FlightPlan, Orbit
from ladartui.precompile import one_ray_run
from ladartui.scenario import Scenario
from ladartui.scene.generate import generate_scene
from ladartui.sensor import Sensor
from ladartui.tui.app import LadarApp as _App


def LadarApp(path):
    return _App(path, compile_in_child=False)


@pytest.fixture
def scenario_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # folders are shown relative to here: stable text
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))  # no recent list from others
    generated = generate_scene("small", seed=5, width=16.0, depth=16.0, trees=5)
    scene_path, _ = generated.write(tmp_path / "forest")
    centre = tuple(round(float(v), 3) for v in generated.target_centre)
    scenario = Scenario(
        tmp_path / "snap.toml",
        scene_path,
        generated.voxel_size,
        Sensor(grid=8, ray_grid=1, fov=8.0),
        FlightPlan(None, (Orbit(centre=centre, radius=20.0, altitude=20.0, scans=6),)),
    )
    scenario = scenario.save()
    one_ray_run(scenario)  # compile the kernels here rather than in a child of each app
    return scenario.path


def settled(app) -> bool:
    return app.scene is not None and app.busy is None and app.backend_rows is not None and not app.running


async def wait_for(pilot, condition, timeout=300.0):
    start = time.monotonic()
    while not condition(pilot.app):
        assert time.monotonic() - start < timeout, "the app did not settle"
        await pilot.pause(0.05)
    await pilot.pause(0.2)


def prepare(*keys, run=False):
    async def run_before(pilot):
        app = pilot.app
        await wait_for(pilot, settled)
        if run:
            await pilot.press("f5")
            await wait_for(pilot, lambda a: a.result is not None and not a.running)
            await pilot.press("escape")  # close the measures dialog
        app.query_one("#scene3d").focus()
        for key in keys:
            await pilot.press(key)
        await pilot.pause(0.2)

    return run_before


@pytest.mark.parametrize("size", [(80, 24), (120, 40)])
def test_layout_1_scene_and_top_view(snap_compare, scenario_path, size):
    assert snap_compare(LadarApp(scenario_path), terminal_size=size, run_before=prepare())


@pytest.mark.parametrize("size", [(80, 24), (120, 40)])
def test_layout_2_scene_and_output_after_a_run(snap_compare, scenario_path, size):
    assert snap_compare(LadarApp(scenario_path), terminal_size=size, run_before=prepare("2", run=True))


def test_layout_5_scene_output_and_top_view(snap_compare, scenario_path):
    assert snap_compare(LadarApp(scenario_path), terminal_size=(120, 40), run_before=prepare("5", run=True))


def test_flight_panel(snap_compare, scenario_path):
    async def run_before(pilot):
        await wait_for(pilot, settled)
        pilot.app.action_show_tab("flight")
        pilot.app.query_one("#scene3d").focus()
        await pilot.pause(0.2)

    assert snap_compare(LadarApp(scenario_path), terminal_size=(80, 24), run_before=run_before)
