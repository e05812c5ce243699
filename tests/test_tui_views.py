"""The views in the app: zoom to target, top-view zoom and pan, output colouring, PNG."""

from __future__ import annotations

import time

import numpy as np
import pytest
import pytest_asyncio
from textual import events

from ladartui import colour
from ladartui.errors import LadarError
from ladartui.flight import FlightPlan, Orbit
from ladartui.number_text import top_view_width
from ladartui.render.raster import screen_coordinates
from ladartui.scenario import Scenario
from ladartui.scene.generate import generate_scene
from ladartui.sensor import Sensor
from ladartui.tui.app import LadarApp
from ladartui.tui.canvas import ProjectionWidget, TopViewWidget
from ladartui.tui.view_area import ViewArea
from tui_support import field, loaded, type_into, wait_until

SIZE = (120, 40)


def orbit_scenario(folder, name: str, scans: int) -> Scenario:
    """A small generated forest and a saved scenario orbiting it at 30 m, ``scans`` scans."""
    generated = generate_scene("small", seed=3, width=16.0, depth=16.0, trees=5)
    scene_path, _ = generated.write(folder / "forest")
    centre = tuple(round(float(v), 3) for v in generated.target_centre)
    return Scenario(
        folder / name,
        scene_path,
        generated.voxel_size,
        Sensor(grid=8, ray_grid=1, fov=8.0),
        FlightPlan(None, (Orbit(centre=centre, radius=30.0, altitude=30.0, scans=scans),)),
    ).save()


@pytest.fixture(scope="module")
def scenario_path(tmp_path_factory):
    return orbit_scenario(tmp_path_factory.mktemp("views"), "views.toml", 6).path


@pytest_asyncio.fixture(loop_scope="module", scope="module")
async def app_pilot(scenario_path):
    app = LadarApp(scenario_path, compile_in_child=False)
    async with app.run_test(size=SIZE) as pilot:
        start = time.monotonic()
        while app.scene is None or app.busy is not None:
            assert time.monotonic() - start < 120, "the app did not load the scene"
            await pilot.pause(0.05)
        yield pilot


async def reset(pilot):
    app = pilot.app
    area = app.query_one(ViewArea)
    app.action_layout(5)
    area.fit_path()
    area.query_one("#scene3d", ProjectionWidget).action_reset_view()
    await pilot.pause()
    return app, area


def target_pixels(widget: ProjectionWidget, box):
    rows, cols = widget.picture_size()
    lo, hi = box
    corners = np.array(
        [
            [x, y, z]
            for x in (lo[0] - 0.5, hi[0] + 0.5)
            for y in (lo[1] - 0.5, hi[1] + 0.5)
            for z in (lo[2] - 0.5, hi[2] + 0.5)
        ]
    )
    row, col, _, _ = screen_coordinates(corners, widget.camera, rows, cols, widget.bounds)
    return row, col, rows, cols


@pytest.mark.asyncio(loop_scope="module")
async def test_zoom_to_target_frames_the_target_in_every_view(app_pilot):
    pilot = app_pilot
    app, area = await reset(pilot)
    scene3d = app.query_one("#scene3d", ProjectionWidget)
    output3d = app.query_one("#output3d", ProjectionWidget)
    top = app.query_one(TopViewWidget)
    box = area.prepared["target_box"]
    row, col, rows, cols = target_pixels(scene3d, box)
    before = max(np.ptp(row) / rows, np.ptp(col) / cols)
    assert before < 0.3  # a small patch while the views show the whole flight path
    scene3d.focus()
    await pilot.press("t")
    await pilot.pause()
    for widget in (scene3d, output3d):
        row, col, rows, cols = target_pixels(widget, box)
        assert row.min() >= 0 and row.max() <= rows and col.min() >= 0 and col.max() <= cols
        assert max(np.ptp(row) / rows, np.ptp(col) / cols) == pytest.approx(0.9, abs=0.05)
    # the top view's window holds the target's columns and little else
    x0, y0, x1, y1 = top.frame
    assert x0 < box[0][0] and box[1][0] + 1 < x1 and y0 < box[0][1] and box[1][1] + 1 < y1
    assert (x1 - x0) < 1.3 * (box[1][0] - box[0][0] + 1) + 2
    # and the target shows there in its colour
    rows, cols = top.picture_size()
    picture = top.make_picture(rows, cols)
    magenta = np.all(picture.rgb == colour.TARGET_RGB, axis=-1)
    scale, _, _ = top.top.fit(rows, cols, top.frame)  # cells per pixel
    columns = len(np.unique(area.prepared["target"][:, :2], axis=0))
    assert magenta.sum() == pytest.approx(columns / scale**2, rel=0.25)
    assert magenta.sum() > 200
    # turning the view keeps the target in the middle
    await pilot.press("right")
    row, col, rows, cols = target_pixels(scene3d, box)
    assert (row.mean(), col.mean()) == pytest.approx((rows / 2, cols / 2), abs=1.0)
    # a scene loaded again is framed whole again, at the same angles
    azimuth = scene3d.camera.azimuth
    area.set_scene(area.prepared, area.voxel_size)
    await pilot.pause()
    assert scene3d.camera.centre is None and scene3d.camera.zoom == 1.0
    assert scene3d.camera.azimuth == azimuth and top.framing == "path"


@pytest.mark.asyncio(loop_scope="module")
async def test_top_view_zooms_pans_and_goes_back_to_the_path(app_pilot):
    pilot = app_pilot
    app, area = await reset(pilot)
    top = app.query_one(TopViewWidget)
    start = top.frame
    top.focus()
    await pilot.press("plus")
    x0, y0, x1, y1 = top.frame
    assert (x1 - x0) == pytest.approx((start[2] - start[0]) / 1.25)
    assert (x0 + x1) / 2 == pytest.approx((start[0] + start[2]) / 2)
    assert "m across" in top.border_title
    await pilot.press("d")
    assert top.frame[0] == pytest.approx(x0 + 0.1 * (x1 - x0))
    await pilot.press("minus", "minus")
    assert top.frame[2] - top.frame[0] == pytest.approx((start[2] - start[0]) * 1.25 / 1.25 / 0.8, rel=1e-9)
    # a new flight path leaves a zoomed window alone; 0 follows the path again
    frame = top.frame
    app.update_scenario(app.scenario)
    await pilot.pause()
    assert top.frame == frame
    await pilot.press("0")
    assert top.frame == start and top.border_title == "Top view"
    # the wheel zooms about the point under the pointer (cell 10, 5 of the content area)
    rows, cols = top.picture_size()
    under = top.top.to_cells(2 * 5 + 1, 10.5, rows, cols, top.frame)
    # the pilot's own mouse-event helper (textual is pinned)
    await pilot._post_mouse_events([events.MouseScrollUp], top, offset=(11, 6))
    await pilot.pause()
    x0, y0, x1, y1 = top.frame
    assert x1 - x0 == pytest.approx((start[2] - start[0]) / 1.25)
    assert top.top.to_cells(2 * 5 + 1, 10.5, rows, cols, top.frame) == pytest.approx(under)
    # a scene opened after a zoom is framed by its path, and the title drops the zoom's width
    assert "m across" in top.border_title
    top.set_scene(top.top, top.target_box)  # as opening a scenario does
    await pilot.pause()
    assert top.frame == start and top.border_title == "Top view"


@pytest.mark.asyncio(loop_scope="module")
async def test_the_top_views_width_is_what_a_wide_view_shows(app_pilot):
    """Layout 5's top view is wide and low: fitted on the scene it showed the scene's
    width in its middle and some three times as much beside it, yet its title gave the
    scene's width ("Top view 16 m across") as the view's."""
    pilot = app_pilot
    app, area = await reset(pilot)
    top = app.query_one(TopViewWidget)
    top.focus()
    for key in ("f", "t", "plus"):
        await pilot.press(key)
        await pilot.pause()
        rows, cols = top.picture_size()
        assert cols > 2 * rows  # the window's height sets its scale
        # metres across the picture, from two points a metre apart as drawn
        (_, west), (_, east) = top.top.to_pixels([(0.0, 0.0), (1.0, 0.0)], rows, cols, top.frame)
        shown = cols / (east - west)
        assert str(top.border_title).endswith(top_view_width(shown) + " across"), (key, shown)


async def test_the_top_views_width_follows_a_new_voxel_size(scenario_path):
    """The top view zoomed showed 'Top view 16 m across'; with the voxel size doubled the
    same voxels spanned 32 m, and the title still said 16."""
    app = LadarApp(scenario_path, compile_in_child=False)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        top = app.query_one(TopViewWidget)
        top.focus()
        await pilot.press("f")
        await pilot.pause()
        before = top.shown_width()
        assert str(top.border_title).endswith(top_view_width(before) + " across")
        app.action_show_tab("run")
        await type_into(pilot, field(app, "scenario.voxel_size"), f"{2 * app.scenario.voxel_size:g}")
        await wait_until(pilot, lambda: top.top.voxel_size == app.scenario.voxel_size)
        await pilot.pause()
        assert top.shown_width() == pytest.approx(2 * before)
        assert str(top.border_title).endswith(top_view_width(2 * before) + " across"), top.border_title


async def test_the_views_draw_an_orbit_as_flown_not_as_chords_between_its_scans(tmp_path):
    """A 3-scan orbit of radius 30 m was drawn as a triangle through its scans, its sides
    15 m from the centre over the scene, and the top view was framed on the triangle:
    the path drawn was not the one flown (nor the one Path m measures)."""
    scenario = orbit_scenario(tmp_path, "three.toml", 3)
    centre = scenario.flight.segments[0].centre
    app = LadarApp(scenario.path, compile_in_child=False)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        top = app.query_one(TopViewWidget)
        path = np.asarray(top.path, float)
        # every point drawn lies on the circle flown, and the path is as long as Path m
        assert np.hypot(path[:, 0] - centre[0], path[:, 1] - centre[1]) == pytest.approx(30.0, rel=0.01)
        drawn = float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())
        assert drawn == pytest.approx(scenario.flight.path_length(), rel=0.01)
        # the top view frames the whole arc; the 3D views draw it too (in voxel units)
        x0, y0, x1, y1 = np.asarray(top.frame) * top.top.voxel_size
        assert (path[:, 0].min() >= x0) and (path[:, 0].max() <= x1)
        assert (path[:, 1].min() >= y0) and (path[:, 1].max() <= y1)
        scene3d = app.query_one("#scene3d", ProjectionWidget)
        drawn3d = np.asarray(scene3d.overlays.path, float) * scenario.voxel_size
        assert len(drawn3d) == len(path)
        assert np.hypot(drawn3d[:, 0] - centre[0], drawn3d[:, 1] - centre[1]) == pytest.approx(30.0, rel=0.01)


@pytest.mark.asyncio(loop_scope="module")
async def test_output_colours_show_what_the_foliage_hid_and_switch_to_height(app_pilot):
    pilot = app_pilot
    app, area = await reset(pilot)
    target = area.prepared["target"]
    seen, hidden = target[: len(target) // 2], target[len(target) // 2 :]
    canopy = np.array([[x, y, 30] for x in range(5) for y in range(5)])
    area.show_output(np.vstack([canopy, seen]), None, target_output=target)
    output3d = app.query_one("#output3d", ProjectionWidget)
    rgbs = [layer.rgb for layer in output3d.voxel_layers]
    counts = [len(layer.voxels) for layer in output3d.voxel_layers]
    assert rgbs == [None, colour.HIDDEN_RGB, colour.TARGET_RGB]
    assert counts == [len(canopy), len(hidden), len(seen)]
    output3d.focus()
    await pilot.press("c")
    assert "(height)" in output3d.border_title
    assert [layer.rgb for layer in output3d.voxel_layers] == [None, colour.TARGET_RGB]
    await pilot.press("c")
    assert "(height)" not in output3d.border_title
    # with each scan's returns, a third colouring counts the scans that saw each target voxel
    area.show_output(np.vstack([canopy, seen]), None, target_output=target, per_scan=[seen, seen[:3]])
    await pilot.press("c", "c")
    assert "scans" in output3d.border_title  # "(target: scans that saw it)", or "Out scans" where narrow
    values = output3d.voxel_layers[1].values
    assert sorted(values.tolist()) == sorted([2] * 3 + [1] * (len(seen) - 3))
    await pilot.press("c")
    assert "scans" not in output3d.border_title and "(height)" not in output3d.border_title
    area.show_output(np.vstack([canopy, seen]), None, target_output=target)  # no per-scan data
    await pilot.press("c", "c")
    assert "scans" not in output3d.border_title and "(height)" not in output3d.border_title
    # the threshold keeps the target, drops the canopy and spreads the colours over what is left
    ground = np.array([[x, y, 0] for x in range(10) for y in range(10)])
    area.show_output(np.vstack([canopy, ground, seen]), 2.0, target_output=target)
    assert len(output3d.voxel_layers[0].voxels) == len(ground)
    assert output3d.height_range == (0.0, max(float(target[:, 2].max()), 1.0))
    # what the view draws keeps a contrast of 3 against its background, in both colourings
    for _ in range(2):
        await pilot.press("c")
        image = output3d.make_picture(*output3d.picture_size())
        drawn = np.unique(image.rgb[image.voxel_mask], axis=0)
        assert len(drawn) >= 2 and (~image.mask).any()
        assert colour.contrast_ratio(drawn, colour.BACKGROUND).min() >= 3.0


@pytest.mark.asyncio(loop_scope="module")
async def test_a_view_saves_as_a_png_of_the_requested_size(app_pilot, tmp_path):
    from PIL import Image

    pilot = app_pilot
    app, area = await reset(pilot)
    for view in ("scene3d", "topview"):
        path = area.save_png(tmp_path / f"{view}.png", 321, 123, view)
        with Image.open(path) as image:
            assert image.format == "PNG" and image.size == (321, 123)
            assert len(np.unique(np.asarray(image).reshape(-1, 3), axis=0)) > 5  # not blank
    with pytest.raises(LadarError, match="width = 5: expected a whole number of pixels from 16 to 8192"):
        area.save_png(tmp_path / "bad.png", 5, 123)
    assert not (tmp_path / "bad.png").exists()


@pytest.mark.asyncio(loop_scope="module")
async def test_a_narrow_view_keeps_its_camera_in_its_title(app_pilot):
    """At 80 columns '3D scene az 210 el 30' was cut to '3D scene az 210 …'."""
    pilot = app_pilot
    app, area = await reset(pilot)
    scene3d = app.query_one("#scene3d", ProjectionWidget)
    c = scene3d.camera
    await pilot.resize_terminal(80, 24)
    await pilot.pause()
    try:
        title = scene3d.border_title
        assert len(title) <= scene3d.size.width - 4, title
        assert title.endswith(f"{c.azimuth:.0f}/{c.elevation:.0f}") or title.endswith(f"el {c.elevation:.0f}")
        # zoomed in, it dropped its camera with its zoom ("3D scene" alone)
        from dataclasses import replace

        scene3d.set_camera(replace(c, zoom=11.0))
        await pilot.pause()
        assert scene3d.border_title.endswith(f"{c.azimuth:.0f}/{c.elevation:.0f}"), scene3d.border_title
        scene3d.set_camera(c)
    finally:
        await pilot.resize_terminal(*SIZE)
        await pilot.pause()
    zoom = f" x{c.zoom:.2g}" if c.zoom != 1.0 else ""  # the opening view frames the flight path
    assert scene3d.border_title == f"3D scene az {c.azimuth:.0f} el {c.elevation:.0f}{zoom}"


@pytest.mark.asyncio(loop_scope="module")
async def test_a_3d_views_zoom_reads_without_an_exponent(app_pilot):
    """Zoomed in past 100 ('+' a dozen times after 'z'), the title read
    '3D scene az 210 el 30 x1.6e+02'."""
    from dataclasses import replace

    pilot = app_pilot
    app, area = await reset(pilot)
    scene3d = app.query_one("#scene3d", ProjectionWidget)
    c = scene3d.camera
    try:
        for zoom, shown in ((163.8, "x160"), (1234.0, "x1200"), (0.65, "x0.65"), (0.00047, "x0.00047")):
            scene3d.set_camera(replace(c, zoom=zoom))
            await pilot.pause()
            assert scene3d.border_title == f"3D scene az {c.azimuth:.0f} el {c.elevation:.0f} {shown}"
    finally:
        scene3d.set_camera(c)


@pytest.mark.asyncio(loop_scope="module")
async def test_a_narrow_output_view_keeps_its_threshold_whole(app_pilot):
    """At 80 columns the output view read '3D output <= 12.…' and lost its camera."""
    pilot = app_pilot
    app, area = await reset(pilot)
    target = area.prepared["target"]
    area.show_output(target, 12.5, target_output=target, per_scan=[target])
    output3d = app.query_one("#output3d", ProjectionWidget)
    output3d.focus()
    await pilot.resize_terminal(80, 24)
    await pilot.pause()
    try:
        for _ in range(3):  # class, height, scans colourings
            title = output3d.border_title
            assert len(title) <= output3d.size.width - 4 and "12.5" in title, title
            await pilot.press("c")
    finally:
        await pilot.resize_terminal(*SIZE)
        await pilot.pause()


async def test_a_message_leaves_the_status_bar_in_sight(scenario_path):
    """A toast sits above the status bar, so its colour, its text and Cancel stay readable."""
    from textual.widgets._toast import Toast

    from ladartui.tui.status import StatusBar

    app = LadarApp(scenario_path, compile_in_child=False)
    async with app.run_test(size=(80, 24), notifications=True) as pilot:
        app.tell("a message long enough to need a few lines of the toast " * 2)
        await pilot.pause(0.3)
        bar = app.query_one(StatusBar)
        toasts = list(app.screen.query(Toast))
        assert toasts
        assert all(toast.region.bottom <= bar.region.y for toast in toasts)


async def test_the_top_views_width_reads_whole_at_80_columns_at_any_zoom(scenario_path):
    """Zoomed out, the title read 'Top view 3.07e+0…' at 80 columns: a number cut inside
    its exponent (3070 m read as 3.07), and '3.07e+03 m across' where it had room."""
    assert [top_view_width(w) for w in (5.784, 61.44, 999.4, 999.6, 3072.0, 2.5e6)] == [
        "5.78 m",
        "61.4 m",
        "999 m",
        "1 km",
        "3.07 km",
        "2,500 km",
    ]
    app = LadarApp(scenario_path, compile_in_child=False)
    async with app.run_test(size=(80, 24)) as pilot:
        start = time.monotonic()
        while app.scene is None or app.busy is not None:
            assert time.monotonic() - start < 120, "the app did not load the scene"
            await pilot.pause(0.05)
        top = app.query_one(TopViewWidget)
        top.focus()
        for _ in range(40):
            await pilot.press("minus")
        await pilot.pause()
        width = (top.frame[2] - top.frame[0]) * top.top.voxel_size
        title = str(top.border_title)
        assert title.endswith(top_view_width(width)) and "e+" not in title, title
        assert len(title) <= top.size.width - 4, title  # drawn whole, not cut at the border


async def test_a_view_too_narrow_for_its_placeholder_wraps_it_whole():
    """'no output yet: F5 runs' was cut to 'no output yet: F5 run' in a narrow view."""
    from textual.app import App

    class One(App):
        def compose(self):
            view = ProjectionWidget("Out")
            view.placeholder = "no output yet: F5 runs"
            yield view

    app = One()
    async with app.run_test(size=(18, 9)) as pilot:
        await pilot.pause()
        view = app.query_one(ProjectionWidget)
        width, height = view.size
        assert width < len(view.placeholder)
        lines = [view.render_line(y).text.strip() for y in range(height)]
        assert " ".join(line for line in lines if line) == "no output yet: F5 runs"


def marker_pixels(widget: ProjectionWidget):
    rows, cols = widget.picture_size()
    row, col, _, _ = screen_coordinates(widget.markers, widget.camera, rows, cols, widget.bounds)
    return row, col, rows, cols


def all_in_view(widget: ProjectionWidget) -> bool:
    row, col, rows, cols = marker_pixels(widget)
    return bool(np.all((row >= 0) & (row < rows) & (col >= 0) & (col < cols)))


@pytest.mark.asyncio(loop_scope="module")
async def test_the_3d_views_open_on_the_whole_flight_and_an_edit_does_not_move_them(scenario_path):
    """The 3D views framed the scene alone, so an orbit wider than the scene (the
    default scenario's) opened with its sides off the view; the top view showed it."""
    app = LadarApp(scenario_path, compile_in_child=False)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app), timeout=120)
        app.action_layout(5)
        await pilot.pause()
        await pilot.pause()
        views = [app.query_one(f"#{name}", ProjectionWidget) for name in ("scene3d", "output3d")]
        assert all_in_view(views[0])  # (the output's view frames so once it has an output)
        cameras = [view.camera for view in views]
        wider = Orbit(centre=app.scenario.flight.segments[0].centre, radius=60.0, altitude=30.0, scans=6)
        app.set_scenario(app.scenario.with_changes(flight=FlightPlan(None, (wider,))))
        await pilot.pause()
        assert [view.camera for view in views] == cameras  # editing never moves the picture
        assert not all_in_view(views[0])
        app.action_view("fit_path")  # (p in a view) the whole flight again
        await pilot.pause()
        assert all(all_in_view(view) for view in views)


def contrast(a, b) -> float:
    """The WCAG contrast ratio of two colours (1 to 21)."""

    def luminance(colour) -> float:
        def linear(v: int) -> float:
            c = v / 255
            return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4

        r, g, b = colour.get_truecolor()
        return 0.2126 * linear(r) + 0.7152 * linear(g) + 0.0722 * linear(b)

    lighter, darker = sorted((luminance(a), luminance(b)), reverse=True)
    return (lighter + 0.05) / (darker + 0.05)


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.parametrize("theme", ["textual-dark", "textual-light", "solarized-light", "nord"])
async def test_the_views_titles_read_in_every_theme(app_pilot, theme):
    """In a light theme (the palette's Theme) the views' titles, which carry the camera
    and the top view's width, were drawn near white on a near-white border line."""
    from textual.geometry import Region

    from ladartui.tui.canvas import PictureWidget

    pilot = app_pilot
    app, area = await reset(pilot)
    app.theme = theme
    await pilot.pause()
    try:
        for view in app.query(PictureWidget):
            width = view.outer_size.width
            top = view.render_lines(Region(0, 0, width, 1))[0]
            title = str(view.border_title)
            segments = [seg for seg in top if seg.text.strip() and seg.text.strip() in title]
            assert segments, (view.id, title, top.text)
            for seg in segments:
                ratio = contrast(seg.style.color, seg.style.bgcolor)
                assert ratio >= 4.5, (theme, view.id, seg.text, round(ratio, 2))
    finally:
        app.theme = "textual-dark"
        await pilot.pause()


@pytest.mark.asyncio(loop_scope="module")
async def test_w_a_s_d_move_the_3d_views_and_the_top_view_the_same_way(app_pilot):
    """The top view's d showed more to the east, its picture sliding left; the 3D views'
    d slid their picture right, showing more to the west: one key, two directions."""
    from ladartui.views import project_float

    pilot = app_pilot
    app, area = await reset(pilot)
    scene3d = app.query_one("#scene3d", ProjectionWidget)
    top = app.query_one(TopViewWidget)
    target_m = np.array(area.prepared["target_m"])

    def on_top():  # the target's (row, col) pixel in the top view
        rows, cols = top.picture_size()
        return top.top.to_pixels(target_m[None, :2], rows, cols, top.frame)[0]

    def in_3d():  # ... and in the 3D scene view
        rows, cols = scene3d.picture_size()
        row, col, _, _ = project_float(target_m / area.voxel_size, scene3d.camera, rows, cols, scene3d.bounds)
        return np.array([row[0], col[0]])

    for key, moved in (("d", (0, -1)), ("a", (0, 1)), ("w", (1, 0)), ("s", (-1, 0))):
        for view, where in ((top, on_top), (scene3d, in_3d)):
            view.focus()
            before = where()
            await pilot.press(key)
            step = where() - before
            # the picture slides against the key: d shows more to the right, w more above
            assert np.sign(step).tolist() == list(moved), (key, view.id, step)


@pytest.mark.asyncio(loop_scope="module")
async def test_a_fitted_3d_view_stays_fitted_as_the_terminal_is_resized(scenario_path):
    """A tall thin scene fitted (f) at 80x24 lost its top and bottom once the terminal
    grew to 200x60: the zoom made for a narrow view was kept for a wider one. A view the
    analyst turned keeps its camera."""
    app = LadarApp(scenario_path, compile_in_child=False)
    async with app.run_test(size=(80, 24)) as pilot:
        await wait_until(pilot, lambda: loaded(app), timeout=120)
        app.action_layout(1)
        await pilot.pause()
        view = app.query_one("#scene3d", ProjectionWidget)
        tall = (np.array([30.0, 30.0, 0.0]), np.array([33.0, 33.0, 70.0]))
        corners = np.array([[x, y, z] for x in (29.5, 33.5) for y in (29.5, 33.5) for z in (-0.5, 70.5)])

        def fills() -> float:
            rows, cols = view.picture_size()
            row, col, _, _ = screen_coordinates(corners, view.camera, rows, cols, view.bounds)
            inside = (row >= 0) & (row <= rows) & (col >= 0) & (col <= cols)
            return float(np.ptp(row) / rows) if inside.all() else 0.0

        view.fit_box(tall)
        await pilot.pause()
        assert fills() == pytest.approx(0.9)
        for size in ((200, 60), (120, 40), (80, 24)):
            await pilot.resize_terminal(*size)
            await pilot.pause()
            await pilot.pause()
            assert fills() == pytest.approx(0.9), size
        view.action_rotate(15, 0)  # the analyst's own camera from here
        camera = view.camera
        await pilot.resize_terminal(200, 60)
        await pilot.pause()
        assert view.camera == camera


@pytest.mark.asyncio(loop_scope="module")
async def test_a_fitted_3d_view_saved_in_another_shape_keeps_what_it_framed_whole(tmp_path):
    """A long low target fitted (t) in a wide view and saved as a tall PNG lost both its
    ends: the PNG took the view's zoom, made for the view's shape."""
    from PIL import Image
    from textual.app import App

    class Views(App):
        def compose(self):
            yield ViewArea()

    app = Views()
    async with app.run_test(size=(200, 30)) as pilot:
        await pilot.pause()
        area = app.query_one(ViewArea)
        view = area.query_one("#scene3d", ProjectionWidget)
        slab = np.array([[x, y, z] for x in range(40) for y in range(8) for z in range(3)])
        view.set_points(slab, (np.zeros(3), np.array([39.0, 7.0, 2.0])))
        view.fit_box((slab.min(axis=0), slab.max(axis=0)))
        await pilot.pause()
        path = area.save_png(tmp_path / "tall.png", 300, 900, "scene3d")
        with Image.open(path) as image:
            rgb = np.asarray(image.convert("RGB"))
        rows, cols = np.nonzero(np.any(rgb != np.array(colour.BACKGROUND, np.uint8), axis=2))
        assert cols.min() > 0 and cols.max() < 299 and rows.min() > 0 and rows.max() < 899
        assert np.ptp(cols) == pytest.approx(0.9 * 300, abs=3)  # filling the PNG's width as the view's
