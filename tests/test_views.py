"""The text-mode view maths (ladartui.views): no terminal needed."""

import numpy as np
import pytest

from ladartui import views
from ladartui.render.raster import Layer, render
from ladartui.views import Camera, TopView


def test_grey_ramp_has_the_reports_56_shades_rising_and_never_black():
    ramp = views.grey_ramp()
    assert ramp.shape == (56, 3)
    assert np.all(ramp[:, 0] == ramp[:, 1]) and np.all(ramp[:, 1] == ramp[:, 2])
    assert np.all(np.diff(ramp[:, 0].astype(int)) > 0)
    assert ramp.min() > 0


def test_shade_indices_are_linear_over_the_range_and_clipped():
    idx = views.shade_indices([0.0, 4.99, 5.0, 9.99, 10.0, -3.0, 99.0], 0.0, 10.0, 10)
    assert idx.tolist() == [0, 4, 5, 9, 9, 0, 9]


def test_ansi256_picks_the_xterm_cube_and_grey_entries():
    # xterm-256: 16 + 36 r + 6 g + b over levels (0, 95, 135, 175, 215, 255); greys 232 + k at 8 + 10 k
    rgb = np.array([[255, 0, 0], [0, 0, 0], [0, 255, 0], [95, 135, 175], [128, 128, 128], [238, 238, 238]])
    assert views.to_ansi256(rgb).tolist() == [196, 16, 46, 16 + 36 + 12 + 3, 244, 255]


def _heights(nx=12, ny=8):
    h = np.full((nx, ny), -1, np.int32)
    h[2, 5] = 20  # one tall column, north-west quarter
    h[9, 1] = 3  # a low one, south-east
    return h


def test_top_view_at_native_size_puts_north_up_and_shades_by_height():
    top = TopView(_heights(), voxel_size=0.5)
    pic = top.scene_layer(8, 12)
    ramp = views.height_ramp()
    # voxel (x, y) is pixel (row = ny - 1 - y, col = x)
    assert tuple(pic.rgb[8 - 1 - 5, 2]) == tuple(ramp[-1])
    low = views.shade_indices([3], 0, 20, len(ramp))[0]
    assert tuple(pic.rgb[8 - 1 - 1, 9]) == tuple(ramp[low])
    assert tuple(pic.rgb[0, 0]) == views.GROUND_RGB
    assert pic.mask.all()


def test_top_view_downsampling_keeps_the_highest_voxel_of_each_block():
    top = TopView(_heights(), voxel_size=1.0)
    pic = top.scene_layer(4, 6)  # 2 x 2 voxels per pixel
    ramp = views.height_ramp()
    # voxel (2, 5) lies in block x 2..3, y 4..5 -> col 1, row (8 - 6) / 2 = 1
    assert tuple(pic.rgb[1, 1]) == tuple(ramp[-1])
    assert tuple(pic.rgb[0, 1]) == views.GROUND_RGB


def test_a_map_far_from_the_origin_draws_as_it_would_at_the_origin():
    """The map spans the voxels' own columns from ``origin``; its scene frame is
    theirs, and every pixel, over the scene or over a frame past its edges, is what
    the same map at the origin draws in the frame shifted back."""
    origin = (3_000_000, 41)
    near, far = TopView(_heights(), 0.5), TopView(_heights(), 0.5, origin=origin)
    assert far.scene_frame() == (3_000_000.0, 41.0, 3_000_012.0, 49.0)
    for frame in (None, (-5.0, -3.0, 9.0, 6.0)):
        shifted = None if frame is None else np.add(frame, [*origin, *origin]).tolist()
        a, b = near.scene_layer(6, 10, frame), far.scene_layer(6, 10, shifted)
        assert a.mask.any() and not a.mask.all()  # letterboxed, or past the edges
        np.testing.assert_array_equal(a.rgb, b.rgb)
        np.testing.assert_array_equal(a.mask, b.mask)


def test_the_ground_plane_beyond_the_maps_columns_is_drawn_as_ground():
    """Tracing returns ground over [0, nx) x [0, ny) from the origin; the map spans only
    the voxels' columns, so the rest of that plane is drawn as bare ground, and what
    lies past it (a miss) is not drawn."""
    top = TopView(_heights(), 1.0, origin=(100, 0), ground=(112, 8))
    pic = top.scene_layer(8, 24, (88.0, 0.0, 124.0, 12.0))  # 1.5 cells a pixel
    ground = (pic.rgb == np.array(views.GROUND_RGB, np.uint8)).all(axis=2) & pic.mask
    assert ground[6, 0] and ground[6, 7]  # x 88.75 and 99.25: the plane west of the map
    assert not pic.mask[6, 16] and not pic.mask[6, 23]  # x 112.75 on: past the plane
    assert not pic.mask[0, 4]  # y 11.25: north of the plane
    assert tuple(pic.rgb[4, 9]) == tuple(views.height_ramp()[-1])  # x 101..103, y 4..6: the tall column


def test_zoomed_in_each_pixel_shows_the_column_under_its_centre_where_the_target_is_marked():
    """Zoomed on a target at the scene's corner, its magenta cells sat a pixel off the
    tall columns under them (a strip of the scene's top colour beside them): the scene
    showed the column under each pixel's west and south edges, the target's cells those
    under its centre."""
    heights = np.ones((40, 40), np.int32)
    cells = np.array([[0, 39], [1, 39], [0, 38]])
    heights[cells[:, 0], cells[:, 1]] = 2
    top = TopView(heights, 0.25, target_columns=cells, ground=(40, 40))
    tallest = np.array(views.height_ramp()[-1], np.uint8)
    for frame in ((-1.0, 37.0, 3.0, 41.0), (-3.3, 30.1, 9.7, 41.7)):
        for rows, cols in ((20, 41), (36, 78), (55, 63)):
            scene = top.scene_layer(rows, cols, frame)
            marked = (top.render(rows, cols, frame=frame).rgb == views.TARGET_RGB).all(axis=2)
            centre_r, centre_c = np.meshgrid(np.arange(rows) + 0.5, np.arange(cols) + 0.5, indexing="ij")
            x, y = top.to_cells(centre_r, centre_c, rows, cols, frame)
            under = np.isin(np.floor(x) * 100 + np.floor(y), cells[:, 0] * 100 + cells[:, 1])
            np.testing.assert_array_equal((scene.rgb == tallest).all(axis=2), under)
            np.testing.assert_array_equal(marked, under)


def test_top_view_letterboxes_a_wide_scene_and_leaves_the_margin_undrawn():
    top = TopView(np.zeros((10, 5), np.int32))
    pic = top.scene_layer(10, 10)  # 10 x 5 scene into 10 x 10 pixels: rows 2.5..7.5 drawn
    assert pic.mask[3:7].all()
    assert not pic.mask[:2].any() and not pic.mask[8:].any()


def test_overlays_mark_scans_path_and_footprint_without_redrawing_the_scene():
    top = TopView(np.zeros((20, 20), np.int32), voxel_size=2.0)
    first = top.render(
        20,
        20,
        path=np.array([[0.0, 0.0], [38.0, 0.0]]),
        scans=np.array([[10.0, 20.0], [30.0, 20.0]]),
        footprints=[np.array([[4.0, 4.0], [16.0, 4.0], [16.0, 16.0], [4.0, 16.0]])],
    )
    # metres / 2 = voxel; scan (30, 20) m -> voxel (15, 10) -> row 19 - 10, col 15
    assert tuple(first.rgb[9, 15]) == views.SCAN_RGB
    assert tuple(first.rgb[9, 5]) == views.START_RGB
    assert tuple(first.rgb[19, 10]) == views.PATH_RGB  # path along y = 0
    assert tuple(first.rgb[19 - 2, 5]) == views.FOOTPRINT_RGB  # corner (4, 4) m -> voxel (2, 2)
    second = top.render(20, 20, scans=np.array([[0.0, 0.0]]))
    assert tuple(second.rgb[9, 15]) != views.SCAN_RGB
    assert top.renders == 1  # the scene layer was drawn once and reused


def test_a_pixel_maps_back_to_the_cell_under_it():
    top = TopView(np.zeros((20, 10), np.int32), voxel_size=0.5)
    frame = (-5.0, -2.0, 25.0, 12.0)
    xy_m = np.array([[3.0, 1.5], [9.75, 4.0]])
    pixels = top.to_pixels(xy_m, 30, 70, frame)
    for (row, col), (x, y) in zip(pixels, xy_m):
        assert top.to_cells(row, col, 30, 70, frame) == pytest.approx((x / 0.5 + 0.5, y / 0.5 + 0.5))


def test_frame_grows_to_hold_a_flight_path_outside_the_scene():
    top = TopView(np.zeros((16, 16), np.int32), voxel_size=1.0)
    frame = top.frame_for(np.array([[-40.0, 8.0], [56.0, 8.0]]))
    assert frame[0] <= -39.5 and frame[2] >= 56.5
    assert frame[1] <= 0 and frame[3] >= 16
    pic = top.render(32, 64, scans=np.array([[-40.0, 8.0], [56.0, 8.0]]), frame=frame)
    assert (pic.rgb == np.array(views.SCAN_RGB, np.uint8)).all(axis=2).any()
    assert (pic.rgb == np.array(views.START_RGB, np.uint8)).all(axis=2).any()


def test_view_axes_are_orthonormal_and_match_the_compass():
    right, up, toward = views.view_axes(180.0, 90.0)  # from straight above, south at the bottom
    assert np.allclose(toward, [0, 0, 1], atol=1e-12)
    assert np.allclose(right, [1, 0, 0], atol=1e-12)
    assert np.allclose(up, [0, 1, 0], atol=1e-12)
    for az, el in [(0, 0), (37.5, 30), (210, -20)]:
        m = np.stack(views.view_axes(az, el))
        assert np.allclose(m @ m.T, np.eye(3), atol=1e-12)


def test_projection_from_above_shows_the_highest_voxel_of_a_column():
    pts = np.array([[5, 5, 0], [5, 5, 9]])
    bounds = (np.zeros(3), np.array([10.0, 10.0, 9.0]))
    image = render([Layer(pts)], Camera(180.0, 90.0), 20, 20, bounds)
    drawn = image.rgb[image.voxel_mask]
    assert 1 <= len(drawn) <= 4  # 1.3 pixels per voxel: a 2 x 2 square
    assert (drawn == views.height_ramp()[-1]).all()  # only the top voxel shows


def test_projection_side_view_keeps_the_nearer_point():
    # viewer due south (azimuth 180), level: y grows away from the viewer
    pts = np.array([[5, 8, 3], [5, 2, 3]])
    bounds = (np.zeros(3), np.array([10.0, 10.0, 6.0]))
    image = render([Layer(pts)], Camera(180.0, 0.0), 20, 20, bounds)
    assert 1 <= image.voxel_mask.sum() <= 4
    # depth is distance toward the viewer from the bounds' centre (y = 5): nearer point y = 2
    assert image.depth[image.voxel_mask] == pytest.approx(5 - 2)


def test_a_camera_centred_on_a_point_keeps_it_in_the_middle_as_it_turns():
    bounds = (np.zeros(3), np.array([100.0, 100.0, 20.0]))
    for az in (0.0, 75.0, 210.0):
        camera = Camera(az, 30.0, 8.0, centre=(80.0, 20.0, 2.0))
        row, col, _, _ = views.project_float([[80.0, 20.0, 2.0]], camera, 30, 50, bounds)
        assert (row[0], col[0]) == pytest.approx((15.0, 25.0))
    assert Camera(10.0, 20.0, 3.0, centre=(1, 2, 3)).at_angle(400, 100) == Camera(
        40.0, 90.0, 3.0, centre=(1, 2, 3)
    )


def test_zoom_and_pan_move_points_on_screen():
    pts = np.array([[0, 0, 0], [10, 0, 0]])
    bounds = (np.zeros(3), np.array([10.0, 0.0, 0.0]))
    r1, c1, _ = views.project(pts, Camera(180.0, 90.0), 40, 40, bounds)
    r2, c2, _ = views.project(pts, Camera(180.0, 90.0, zoom=2.0), 40, 40, bounds)
    assert (c2[1] - c2[0]) == pytest.approx(2 * (c1[1] - c1[0]), abs=1)
    r3, c3, _ = views.project(pts, Camera(180.0, 90.0).panned(0.25, 0.0), 40, 40, bounds)
    assert c3[0] > c1[0]


def test_camera_rotation_wraps_azimuth_and_clamps_elevation():
    cam = Camera(350.0, 80.0).rotated(20.0, 30.0)
    assert cam.azimuth == pytest.approx(10.0)
    assert cam.elevation == 90.0


def test_threshold_keeps_voxels_up_to_the_height_in_metres():
    vox = np.array([[0, 0, 0], [0, 0, 4], [0, 0, 5], [0, 0, 6]])
    kept = views.threshold_points(vox, 0.5, 2.5)
    assert kept[:, 2].tolist() == [0, 4, 5]
    assert len(views.threshold_points(vox, 0.5, None)) == 4


def test_subsample_is_bounded_deterministic_and_a_subset():
    vox = np.arange(3000).reshape(1000, 3)
    a = views.subsample(vox, 100, seed=1)
    b = views.subsample(vox, 100, seed=1)
    assert len(a) == 100 and np.array_equal(a, b)
    assert set(map(tuple, a)) <= set(map(tuple, vox))
    assert views.subsample(vox, 5000) is vox


def test_surface_points_follow_the_height_map():
    h = np.full((4, 4), -1, np.int32)
    h[1, 2] = 7
    pts = views.surface_points(h)
    assert pts.tolist() == [[1, 2, 7]]
    assert views.surface_points(h, origin=(500, 60)).tolist() == [[501, 62, 7]]


def test_half_block_cells_pair_rows_and_pad_an_odd_last_row():
    pic = views.Picture.blank(3, 2)
    pic.rgb[2, 1] = (1, 2, 3)
    pic.mask[2, 1] = True
    top, top_mask, bottom, bottom_mask = views.half_block_cells(pic)
    assert top.shape == (2, 2, 3) and bottom_mask.shape == (2, 2)
    assert top_mask[1, 1] and tuple(top[1, 1]) == (1, 2, 3)
    assert not bottom_mask[1].any()


def _polyline_one_segment_at_a_time(picture, pixels, rgb):
    """The polyline as its segments drawn one by one, each a linspace of a pixel per step
    of its longer axis: the answer drawing it whole must give."""
    from ladartui.views import draw_points

    rows, cols = picture.shape
    limit = 4.0 * (rows + cols)
    for a, b in zip(pixels[:-1], pixels[1:]):
        if np.all(np.isfinite(a)) and np.all(np.isfinite(b)):
            a, b = np.clip(a, -limit, limit), np.clip(b, -limit, limit)
            steps = min(int(np.ceil(np.abs(b - a).max())) + 1, 100_000)
            draw_points(picture, a + (b - a) * np.linspace(0.0, 1.0, max(steps, 2))[:, None], rgb)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("batch", [1_000_000, 7])
def test_a_polyline_drawn_whole_sets_the_pixels_its_segments_drawn_one_by_one_set(seed, batch, monkeypatch):
    """A 9,000-scan path took 0.7 s a view segment by segment, and the screen froze as
    it was drawn; drawn whole, in batches of any size, it must set the same pixels."""
    from ladartui.views import Picture, draw_polyline

    monkeypatch.setattr(views, "POLYLINE_BATCH", batch)

    rng = np.random.default_rng(seed)
    points = rng.uniform(-20.0, 80.0, (400, 2))
    points[[5, 77]] = np.nan  # a point off the view's plane: the segments beside it skipped
    points[100] = (1e9, -1e9)  # far away: clamped, not drawn a billion pixels long
    points[200:210] = points[200]  # repeated scans: one pixel each
    pictures = [Picture(np.zeros((60, 70, 3), np.uint8), np.zeros((60, 70), bool)) for _ in range(2)]
    draw_polyline(pictures[0], points, (255, 0, 0))
    _polyline_one_segment_at_a_time(pictures[1], points, (255, 0, 0))
    np.testing.assert_array_equal(pictures[0].mask, pictures[1].mask)
    np.testing.assert_array_equal(pictures[0].rgb, pictures[1].rgb)
    assert pictures[0].mask.sum() > 500
