"""The views on one shared app: the five layouts and the panel key, the output view's
height threshold, the 3D view's keys and exact angle, the top view's overlay following
the parameters without redrawing the scene; and the pictures' 24-bit or 256 colours.

Every test runs on a tiny generated scene (seeded) in tmp_path.
"""

from __future__ import annotations

import numpy as np
import pytest
import pytest_asyncio

from ladartui.tui.canvas import ProjectionWidget, TopViewWidget
from ladartui.tui.screens import AngleScreen, FormScreen
from tui_support import field, fresh, shared_app, type_into, wait_until


@pytest_asyncio.fixture(loop_scope="module", scope="module")
async def shared(tmp_path_factory, scene_files):
    """One app for the tests that do not run a simulation (each starts from ``fresh``)."""
    async with shared_app(tmp_path_factory.mktemp("shared"), scene_files) as pilot_and_scenario:
        yield pilot_and_scenario


@pytest.mark.asyncio(loop_scope="module")
async def test_layout_keys_switch_between_the_five_layouts(shared, tmp_path, scene_files):
    expected = {
        1: {"scene3d", "topview"},
        2: {"scene3d", "output3d"},
        3: {"scene3d"},
        4: {"output3d"},
        5: {"scene3d", "output3d", "topview"},
    }
    pilot, app = await fresh(shared)
    app.query_one("#scene3d").focus()
    for number, shown in expected.items():
        await pilot.press(str(number))
        await pilot.pause()
        visible = {w.id for w in app.query("#views > *") if w.display}
        assert visible == shown
        assert all(app.query_one(f"#{w}").size.width > 0 for w in shown)
    await pilot.press("f6")  # cycles back to the first
    await pilot.pause()
    assert app.layout_number == 1
    await pilot.press("f4")  # hide the panel: the views get the whole width
    await pilot.pause()
    assert not app.query_one("#sidebar").display


@pytest.mark.asyncio(loop_scope="module")
async def test_height_threshold_limits_the_output_view(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    column = np.array([[3, 4, z] for z in range(21)])
    app.output_voxels = column
    app.show_output()
    output = app.query_one("#output3d", ProjectionWidget)
    assert len(output.points) == 21
    await pilot.press("f8")
    await pilot.pause()
    assert isinstance(app.screen, FormScreen)
    await pilot.press("2", "enter")
    await pilot.pause()
    # voxel size 0.25 m: centres at z * 0.25 <= 2.0 m are layers 0..8
    assert sorted(output.points[:, 2].tolist()) == list(range(9))
    assert "2 m" in output.border_title
    await pilot.press("f8")
    await pilot.pause()
    app.screen.query_one("#f-threshold").value = ""
    await pilot.press("enter")
    await pilot.pause()
    assert len(output.points) == 21 and app.threshold is None


@pytest.mark.asyncio(loop_scope="module")
async def test_3d_view_rotates_zooms_and_takes_an_exact_angle(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    scene3d = app.query_one("#scene3d", ProjectionWidget)
    output3d = app.query_one("#output3d", ProjectionWidget)
    scene3d.focus()
    az = scene3d.camera.azimuth
    await pilot.press("right", "up", "plus", "d")
    assert scene3d.camera.azimuth == pytest.approx((az + 15) % 360)
    assert scene3d.camera.zoom == pytest.approx(1.25)
    assert scene3d.camera.pan_x < 0  # the view pans right: its picture moves left
    assert output3d.camera == scene3d.camera  # the views turn together
    await pilot.press("f7")
    await pilot.pause()
    app.screen.query_one("#f-azimuth").value = "45"
    app.screen.query_one("#f-elevation").value = "60"
    app.screen.query_one("#form-ok").press()
    await pilot.pause()
    await pilot.pause()
    assert (scene3d.camera.azimuth, scene3d.camera.elevation) == (45.0, 60.0)
    await pilot.press("f7")
    await pilot.pause()
    app.screen.query_one("#f-elevation").value = "120"
    app.screen.query_one("#form-ok").press()
    await pilot.pause()
    await pilot.pause()
    # refused in the form's words; the dialog stays open with the value to correct
    assert "Elevation (deg): 120 is not allowed" in str(app.screen.query_one("#form-message").render())
    assert isinstance(app.screen, AngleScreen)
    assert app.screen.query_one("#f-elevation").value == "120"
    await pilot.press("escape")


@pytest.mark.asyncio(loop_scope="module")
async def test_top_view_overlay_follows_parameters_without_redrawing_the_scene(shared, tmp_path, scene_files):
    pilot, app = await fresh(shared)
    top = app.query_one(TopViewWidget)
    await pilot.pause()
    renders = top.top.renders
    before = [f.copy() for f in top.footprints]
    app.action_show_tab("sensor")
    await type_into(pilot, field(app, "sensor.fov"), "20")

    # a wider field of view gives larger footprints (drawn once the commit is through:
    # on a busy machine that takes more than one pause)
    def area(p):
        x, y = p[:, 0], p[:, 1]
        return abs(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1))) / 2

    await wait_until(pilot, lambda: area(top.footprints[0]) > 4 * area(before[0]), timeout=60)
    assert top.top.renders == renders


def test_pictures_use_24_bit_colour_or_the_256_colour_palette():
    from ladartui import views
    from ladartui.tui.canvas import UPPER, picture_strips

    picture = views.Picture.blank(2, 2)
    picture.rgb[0, 0] = (255, 0, 0)
    picture.rgb[1, 0] = (0, 0, 255)
    picture.mask[:, 0] = True
    (strip,) = picture_strips(picture)
    first = list(strip)[0]
    assert first.text.startswith(UPPER)
    assert first.style.color.triplet == (255, 0, 0) and first.style.bgcolor.triplet == (0, 0, 255)
    (strip,) = picture_strips(picture, use_256=True)
    first = list(strip)[0]
    assert (first.style.color.number, first.style.bgcolor.number) == (196, 21)  # xterm red, blue


async def test_0_in_a_3d_view_goes_back_to_the_view_it_opened_with(tmp_path, scene_files):
    """0 gave zoom 1 on the scene alone, which cut off the far side of the flight path
    the opening view (the scene and the path framed) had shown; the top view's 0 goes
    back to its opening framing."""
    from tui_support import make_scenario, opened

    async with opened(make_scenario(tmp_path, scene_files)) as (app, pilot):
        scene3d = app.query_one("#scene3d", ProjectionWidget)
        await pilot.pause()
        opening = scene3d.camera
        assert opening.zoom != 1.0  # framed to hold the flight path, not the default
        scene3d.focus()
        await pilot.press("right", "up", "plus", "d")
        assert scene3d.camera != opening
        await pilot.press("0")
        await pilot.pause()
        assert scene3d.camera == opening
