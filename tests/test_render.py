"""The core renderer (ladartui.render): images with a depth buffer, no terminal needed."""

import itertools

import numpy as np
import pytest

from ladartui import colour
from ladartui.render import framing
from ladartui.render.output import classify, output_layers
from ladartui.render.raster import Layer, Overlays, render, screen_coordinates
from ladartui.views import Camera

TOP = Camera(180.0, 90.0)  # looking straight down, north up, east right
TARGET = colour.TARGET_RGB


def box(lo, hi):
    return np.array(list(itertools.product(*(range(a, b + 1) for a, b in zip(lo, hi)))))


def is_rgb(image, rgb):
    return np.all(image.rgb == np.array(rgb, np.uint8), axis=-1)


def test_a_box_target_seen_from_above_fills_its_pixels_in_the_target_colour():
    bounds = (np.zeros(3), np.array([39.0, 39.0, 10.0]))
    ground = box((0, 0, 0), (39, 39, 0))
    target = box((10, 20, 1), (17, 25, 3))  # 8 x 6 voxels in plan, 3 high
    camera = framing.fit_camera(TOP, (np.zeros(3), np.array([39.0, 39, 0])), 80, 80, bounds)
    image = render([Layer(ground), Layer(target, colour.TARGET_RGB)], camera, 80, 80, bounds)
    # the projected cube box of the target: pixels whose centres lie inside it
    row, col, _, scale = screen_coordinates(
        np.array([[9.5, 25.5, 3], [17.5, 19.5, 3]]), camera, 80, 80, bounds
    )
    assert scale == pytest.approx(80 * 0.9 / 40)  # the scene fills 90 % of the width
    r, c = np.mgrid[0:80, 0:80] + 0.5
    inside = (r > row[0] + 1) & (r < row[1] - 1) & (c > col[0] + 1) & (c < col[1] - 1)
    near = (r > row[0] - 1) & (r < row[1] + 1) & (c > col[0] - 1) & (c < col[1] + 1)
    magenta = is_rgb(image, colour.TARGET_RGB)
    assert inside.sum() > 100
    assert magenta[inside].all()  # every pixel well inside the box
    assert not magenta[~near].any()  # and none more than a pixel outside it
    # north is up: the target (y 20..25 of 0..39) sits in the upper half
    assert row.mean() < 40 and col.mean() < 40


def test_the_depth_buffer_keeps_the_nearer_voxel_in_any_drawing_order():
    bounds = (np.zeros(3), np.array([4.0, 4.0, 4.0]))
    low, high = np.array([[2, 2, 0]]), np.array([[2, 2, 4]])
    for layers in (
        [Layer(low, (255, 0, 0)), Layer(high, (0, 255, 0))],
        [Layer(high, (0, 255, 0)), Layer(low, (255, 0, 0))],
    ):
        from_above = render(layers, TOP, 20, 20, bounds)
        assert is_rgb(from_above, (0, 255, 0)).any() and not is_rgb(from_above, (255, 0, 0)).any()
        from_below = render(layers, Camera(180.0, -90.0), 20, 20, bounds)
        assert is_rgb(from_below, (255, 0, 0)).any() and not is_rgb(from_below, (0, 255, 0)).any()
        assert np.isfinite(from_above.depth[from_above.voxel_mask]).all()
        assert np.isneginf(from_above.depth[~from_above.voxel_mask]).all()


def test_squares_grow_with_the_zoom_so_voxels_leave_no_gaps():
    bounds = (np.zeros(3), np.array([9.0, 9.0, 0.0]))
    floor = box((0, 0, 0), (9, 9, 0))
    for zoom in (1.0, 3.0):
        camera = framing.fit_camera(TOP, (np.zeros(3), np.array([9.0, 9, 0])), 60, 60, bounds)
        camera = Camera(camera.azimuth, camera.elevation, camera.zoom * zoom / 3, 0, 0)
        image = render([Layer(floor, (200, 200, 200))], camera, 60, 60, bounds)
        rows, cols = np.nonzero(image.voxel_mask)
        block = image.voxel_mask[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1]
        assert block.all()  # a solid square, no holes between voxels
        assert block.shape[0] == pytest.approx(10 * 54 / 10 * zoom / 3, abs=2)


def test_zoomed_in_far_beyond_the_splat_budget_the_squares_still_cover_what_is_in_view():
    bounds = (np.zeros(3), np.array([299.0, 299.0, 0.0]))
    floor = box((0, 0, 0), (299, 299, 0))  # 90,000 voxels
    camera = framing.fit_camera(TOP, (np.array([140.0, 140, 0]), np.array([149.0, 149, 0])), 400, 400, bounds)
    image = render([Layer(floor, (200, 200, 200))], camera, 400, 400, bounds)
    assert image.voxel_mask.all()  # 36-pixel squares, no gaps: only voxels in view count


def test_a_voxel_near_the_edge_whose_square_misses_the_picture_draws_nothing():
    """Zoomed far in, a voxel within a square's reach of the edge counted as near the
    picture though none of its pixels fell inside: the TUI died with an IndexError."""
    bounds = (np.zeros(3), np.array([9.0, 9.0, 0.0]))
    voxel = np.array([[0, 0, 0]])
    camera = Camera(180.0, 90.0, 50.0, 0.0, 0.0, (0.0, 0.65, 0.0))  # the voxel just below the picture
    row, _, _, scale = screen_coordinates(voxel.astype(float), camera, 20, 20, bounds)
    assert 20 + scale / 2 < row[0] < 20 + scale  # near, yet its square starts past the last row
    image = render([Layer(voxel, (200, 200, 200))], camera, 20, 20, bounds)
    assert not image.voxel_mask.any()


def test_a_threshold_rescales_the_colours_to_the_heights_that_remain():
    column = np.array([[0, 0, z] for z in range(21)])
    layers, (lo, hi) = output_layers(column, np.zeros((0, 3)), mode="height")
    assert (lo, hi) == (0.0, 20.0)
    layers, (lo, hi) = output_layers(
        column, np.zeros((0, 3)), mode="height", voxel_size=0.25, threshold_m=2.0
    )
    assert (lo, hi) == (0.0, 8.0) and len(layers[0].voxels) == 9
    bounds = (np.zeros(3), np.array([1.0, 1.0, 20.0]))
    side = Camera(180.0, 0.0)
    full = render(
        output_layers(column, np.zeros((0, 3)), mode="height")[0], side, 60, 60, bounds, height_range=(0, 20)
    )
    cut = render(layers, side, 60, 60, bounds, height_range=(lo, hi))
    table = colour.height_map()
    # the top remaining voxel takes the top colour after the threshold, not a middling one
    assert is_rgb(cut, table[-1]).any() and not is_rgb(full, table[-1])[cut.voxel_mask].any()
    assert len(np.unique(cut.rgb[cut.voxel_mask], axis=0)) == 9


def test_fit_with_points_frames_a_box_and_a_flight_off_one_side_of_it_centred():
    """A new scene's 3D views frame it with its flight's scan positions; an orbit wider
    than the scene left the views' sides (their framing took the box alone)."""
    bounds = (np.zeros(3), np.array([59.0, 59.0, 20.0]))
    scene = (np.zeros(3), np.array([59.0, 59.0, 20.0]))
    angle = np.radians(np.arange(0, 270, 15))  # three quarters of an orbit, off to one side
    path = np.column_stack([150 + 120 * np.cos(angle), 30 + 120 * np.sin(angle), np.full(angle.size, 60.0)])
    for camera in (Camera(), Camera(45.0, 60.0), TOP):
        fitted = framing.fit_camera(camera, scene, 40, 100, bounds, points=path)
        corners = np.array(list(itertools.product(*zip(scene[0] - 0.5, scene[1] + 0.5))))
        row, col, _, _ = screen_coordinates(np.vstack([corners, path]), fitted, 40, 100, bounds)
        # the larger side fills the shorter one, less the margins: in a view of any shape
        assert max(np.ptp(row), np.ptp(col)) == pytest.approx(0.9 * 40, abs=1e-6)
        assert (row.min() + row.max()) / 2 == pytest.approx(20)
        assert (col.min() + col.max()) / 2 == pytest.approx(50)
        for rows, cols in ((100, 40), (60, 60)):  # the same camera in views of other shapes
            row, col, _, _ = screen_coordinates(np.vstack([corners, path]), fitted, rows, cols, bounds)
            assert row.min() >= 0 and row.max() <= rows and col.min() >= 0 and col.max() <= cols


def test_fit_frames_a_flight_many_times_wider_than_a_one_voxel_scene_or_far_from_it():
    """A one-voxel scene under a 30-voxel orbit, or a small scene with its flight 2 km
    off, opened on a black 3D view: the fit's zoom stopped at the keys' least (0.1)."""
    one = (np.zeros(3), np.array([0.0, 0.0, 1.0]))
    angle = np.radians(np.arange(0, 360, 30))
    orbit = np.column_stack([30 * np.cos(angle), 30 * np.sin(angle), np.full(angle.size, 30.0)])
    small = (np.zeros(3), np.array([39.0, 39.0, 1.0]))
    for box_, path in ((one, orbit), (small, orbit * 10 + [8000.0, 6000.0, 0.0])):
        fitted = framing.fit_camera(Camera(), box_, 40, 100, box_, points=path)
        row, col, _, _ = screen_coordinates(np.vstack([box_[0], path]), fitted, 40, 100, box_)
        assert row.min() >= 0 and row.max() <= 40 and col.min() >= 0 and col.max() <= 100
        # from there the zoom keys zoom in, and out no further: never a jump back to 0.1
        assert fitted.zoomed(0.8).zoom == fitted.zoom < fitted.zoomed(1.25).zoom < 0.1


def test_fit_target_frames_the_targets_projected_box_with_a_small_margin():
    bounds = (np.zeros(3), np.array([199.0, 199.0, 30.0]))
    target = box((120, 40, 0), (126, 43, 2))
    for camera in (Camera(), Camera(45.0, 60.0), TOP):
        fitted = framing.fit_camera(camera, framing.box_of(target), 40, 100, bounds)
        corners = np.array(list(itertools.product(*zip(target.min(0) - 0.5, target.max(0) + 0.5))))
        row, col, _, _ = screen_coordinates(corners, fitted, 40, 100, bounds)
        assert row.min() >= 0 and row.max() <= 40 and col.min() >= 0 and col.max() <= 100
        # fills the tighter direction to within the margin, centred
        fill = max((row.max() - row.min()) / 40, (col.max() - col.min()) / 100)
        assert fill == pytest.approx(0.9, abs=1e-6)
        assert (row.min() + row.max()) / 2 == pytest.approx(20) and (
            col.min() + col.max()
        ) / 2 == pytest.approx(50)
        image = render([Layer(target, colour.TARGET_RGB)], fitted, 40, 100, bounds)
        box_area = np.ptp(row) * np.ptp(col)
        assert (
            0.5 * box_area
            < is_rgb(image, colour.TARGET_RGB).sum()
            <= box_area + 2 * (np.ptp(row) + np.ptp(col)) + 4
        )


def test_output_classes_mark_what_the_foliage_hid():
    target = box((5, 5, 0), (6, 6, 1))  # 8 voxels
    seen = target[:3]
    scene_output = np.vstack([seen, [[0, 0, 5], [1, 1, 7]]])
    target_output = np.vstack([target[:6], [[0, 0, 0], [9, 9, 0]]])  # and ground returns
    scene, target_seen, hidden = classify(scene_output, target, target_output)
    assert sorted(map(tuple, scene)) == [(0, 0, 5), (1, 1, 7)]
    assert sorted(map(tuple, target_seen)) == sorted(map(tuple, seen))
    assert sorted(map(tuple, hidden)) == sorted(map(tuple, target[3:6]))


def test_drawn_voxels_keep_a_contrast_of_3_against_the_background_after_a_threshold():
    rng = np.random.default_rng(1)
    canopy = np.column_stack(
        [rng.integers(0, 30, 3000), rng.integers(0, 30, 3000), rng.integers(8, 20, 3000)]
    )
    ground = box((0, 0, 0), (29, 29, 0))
    target = box((12, 12, 1), (16, 14, 3))
    scene_output = np.unique(np.vstack([canopy, ground, target[::2]]), axis=0)
    bounds = (np.zeros(3), np.array([29.0, 29.0, 19.0]))
    for mode in ("class", "height"):
        for cmap in ("height", "grey"):
            layers, heights = output_layers(
                scene_output, target, target, mode=mode, voxel_size=0.5, threshold_m=2.0
            )
            image = render(layers, Camera(), 60, 80, bounds, height_range=heights, colour_map=cmap)
            drawn = image.rgb[image.voxel_mask]
            background = image.rgb[~image.mask]
            assert len(drawn) > 100 and len(background) > 100
            assert np.all(background == colour.BACKGROUND)
            ratio = colour.contrast_ratio(np.unique(drawn, axis=0), colour.BACKGROUND)
            assert ratio.min() >= 3.0, (mode, cmap, ratio.min())


def test_colour_maps_are_monotone_in_lightness_and_distinct_from_the_target():
    for table in (colour.height_map(), colour.grey_map()):
        luminance = colour.relative_luminance(table)
        assert np.all(np.diff(luminance) > 0)
    assert len(colour.grey_map()) == 56
    # the target colour is far from every height colour
    distance = np.abs(colour.height_map().astype(int) - colour.TARGET_RGB).sum(axis=1)
    assert distance.min() > 150
    assert colour.contrast_ratio((255, 255, 255), (0, 0, 0)) == pytest.approx(21)


def test_overlays_are_drawn_over_the_voxels_and_can_be_switched_off():
    bounds = (np.zeros(3), np.array([20.0, 20.0, 10.0]))
    floor = box((0, 8, 0), (20, 12, 0))  # a strip under the path, across the footprint
    post = box((10, 5, 0), (10, 5, 6))  # a voxel column standing on a footprint edge
    path = np.array([[0.0, 10, 8], [20.0, 10, 8]])
    overlays = Overlays(
        path=path, scans=path, footprints=[np.array([[5.0, 5, 0], [15, 5, 0], [15, 15, 0], [5, 15, 0]])]
    )
    image = render([Layer(floor, (90, 90, 90))], TOP, 40, 40, bounds, overlays=overlays)
    for rgb in (colour.PATH_RGB, colour.SCAN_RGB, colour.START_RGB, colour.FOOTPRINT_RGB):
        assert is_rgb(image, rgb).any(), rgb
    strip = is_rgb(image, (90, 90, 90))
    rows = np.nonzero(strip.any(axis=1))[0]
    assert not is_rgb(image, colour.FOOTPRINT_RGB)[rows].any()  # under the voxels
    assert is_rgb(image, colour.PATH_RGB)[rows].any()  # over them
    # footprints lie on the ground: voxels hide them, the flight path stays on top
    side = Camera(180.0, 10.0)
    image = render([Layer(post, TARGET)], side, 40, 40, bounds, overlays=overlays)
    column = is_rgb(image, TARGET)
    assert column.any() and is_rgb(image, colour.FOOTPRINT_RGB).any()
    image_without = render([Layer(post, TARGET)], side, 40, 40, bounds)
    assert np.array_equal(column, is_rgb(image_without, TARGET) & ~is_rgb(image, colour.PATH_RGB))
    overlays.shown = frozenset({"path"})
    image = render([Layer(floor, (90, 90, 90))], TOP, 40, 40, bounds, overlays=overlays)
    assert is_rgb(image, colour.PATH_RGB).any()
    assert not is_rgb(image, colour.FOOTPRINT_RGB).any() and not is_rgb(image, colour.SCAN_RGB).any()


def test_scan_counts_colour_the_target_by_how_many_scans_saw_it():
    from ladartui.render.output import scan_counts

    target = box((0, 0, 0), (2, 0, 0))  # three voxels
    per_scan = [target[:1], target[:2], target[:2], np.zeros((0, 3), np.int32)]
    assert scan_counts(target, per_scan).tolist() == [3, 2, 0]
    ground = box((0, 2, 0), (2, 2, 0))
    layers, _ = output_layers(np.vstack([ground, target[:2]]), target, mode="scans", per_scan=per_scan)
    assert [len(layer.voxels) for layer in layers] == [3, 2]
    bounds = (np.zeros(3), np.array([2.0, 2.0, 0.0]))
    image = render(layers, TOP, 30, 30, bounds)
    table = colour.height_map()
    seen = {tuple(c) for c in image.rgb[image.voxel_mask]}
    # 3 of 4 scans and 2 of 4 scans: colours half and a quarter of the way up the map
    assert tuple(table[int(2 / 4 * len(table))]) in seen
    assert tuple(table[int(1 / 4 * len(table))]) in seen


def test_the_top_view_window_zooms_about_a_point_that_stays_put_and_pans_by_fractions():
    frame = (0.0, 0.0, 100.0, 50.0)
    assert framing.zoom_window(frame, 2.0) == (25.0, 12.5, 75.0, 37.5)
    zoomed = framing.zoom_window(frame, 2.0, about=(80.0, 10.0))
    assert zoomed == (40.0, 5.0, 90.0, 30.0)
    # the point keeps its place: 80 % across, 20 % up, before and after
    assert ((80 - zoomed[0]) / (zoomed[2] - zoomed[0]), (10 - zoomed[1]) / (zoomed[3] - zoomed[1])) == (
        0.8,
        0.2,
    )
    assert framing.zoom_window(frame, 1000.0)[2] - framing.zoom_window(frame, 1000.0)[0] == 2.0
    assert framing.pan_window(frame, 0.1, -0.2) == (10.0, -10.0, 110.0, 40.0)


def test_a_picture_saved_large_marks_each_scan_and_the_start_as_a_square_one_can_see():
    """A view saved as a 1200 x 800 PNG marked each scan and the start with one pixel,
    lost in the picture; at the terminal's sizes a pixel is half a cell and stays one."""
    from ladartui.views import SCAN_RGB, START_RGB, TopView

    bounds = (np.zeros(3), np.array([39.0, 39.0, 10.0]))
    scans = np.array([[5.0, 5.0, 30.0], [20.0, 35.0, 30.0], [35.0, 5.0, 30.0]])
    top = TopView(np.zeros((40, 40), np.int32), voxel_size=1.0)
    for rows, cols, side in ((800, 1200, 5), (40, 80, 1)):
        camera = framing.fit_camera(TOP, bounds, rows, cols, bounds, points=scans)
        pictures = (
            render(
                [], camera, rows, cols, bounds, overlays=Overlays(None, scans, shown=frozenset({"scans"}))
            ),
            top.render(rows, cols, scans=scans[:, :2], shown=("scans",)),
        )
        for picture in pictures:
            assert is_rgb(picture, START_RGB).sum() == side * side
            assert is_rgb(picture, SCAN_RGB).sum() == 2 * side * side
