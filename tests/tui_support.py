"""Helpers shared by the TUI tests: a scenario over the small generated scene, the app
without its warm-up, waits, typing into a field, and one app shared by a module's tests."""

from __future__ import annotations

import time
from contextlib import asynccontextmanager
from pathlib import Path

from ladartui.flight import FlightPlan, Orbit
from ladartui.scenario import Scenario
from ladartui.sensor import Sensor
from ladartui.tui.app import LadarApp
from ladartui.tui.fields import NumberField
from ladartui.tui.status import StatusBar


class LadarApp(LadarApp):
    """The app without the child-process warm-up (the fixture compiled the kernels)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("compile_in_child", False)
        super().__init__(*args, **kwargs)


SIZE = (100, 32)


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


@asynccontextmanager
async def opened(scenario, size=SIZE, notifications=False):
    """The app on ``scenario``, loaded: (app, pilot); ``notifications``: its notes drawn."""
    app = LadarApp(scenario.path)
    async with app.run_test(size=size, notifications=notifications) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        yield app, pilot


def loaded(app):
    return app.scene is not None and app.busy is None


def field(app, key) -> NumberField:
    return app.query_one("#f-" + key.replace(".", "-").replace("_", "-"), NumberField)


async def type_into(pilot, widget, text, commit="enter"):
    widget.focus()
    await pilot.pause()
    widget.value = ""
    await pilot.press(*list(text))
    if commit:
        await pilot.press(commit)
    await pilot.pause()


def status(app) -> StatusBar:
    return app.query_one(StatusBar)


@asynccontextmanager
async def shared_app(folder: Path, scene_files):
    """The app on a scenario in ``folder``, loaded: (pilot, scenario). A module's
    ``shared`` fixture holds one for the tests that do not run a simulation."""
    scenario = make_scenario(folder, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        yield pilot, scenario


async def fresh(shared):
    """The shared app back at its starting state: scenario, views, no dialogs."""
    pilot, scenario = shared
    app = pilot.app
    while len(app.screen_stack) > 1:
        app.pop_screen()
    app.set_scenario(scenario, modified=False)
    app.threshold = None
    app.output_voxels = None
    app.show_output()
    app.action_layout(1)
    app.query_one("#sidebar").display = True
    app.query_one("#scene3d").set_camera(app.query_one("#scene3d").camera.__class__())
    app.messages.clear()
    app.clear_notifications()  # a toast left by an earlier test could catch a click
    await pilot.pause()
    return pilot, app
