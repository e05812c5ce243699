"""Sensor rays (report section 7.2, equations 1 and 2, figure 14)."""

import math

import numpy as np
import pytest

from ladartui.errors import FieldError
from ladartui.flight import ScanPose
from ladartui.sensor import Sensor


def report_rx(depression):
    """Equation (1), typed from the report: rotation about x by 90 - D."""
    a = math.radians(90.0 - depression)
    return np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])


def report_rz(heading, azimuth):
    """Equation (2), typed from the report: rotation about z by -(H + A)."""
    a = math.radians(-(heading + azimuth))
    return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])


def down_looking_rays(n, m, fov, pitch):
    """Rays at the origin, one by one: detector row-major, then sub-rows, sub-columns."""
    side = n * m
    step = fov / side
    origins, directions, detectors = [], [], []
    for r in range(n):
        for c in range(n):
            for i in range(m):
                for j in range(m):
                    kx, ky = c * m + j, r * m + i
                    ax = -fov / 2 + (kx + 0.5) * step  # column 0 on the left (-x)
                    ay = fov / 2 - (ky + 0.5) * step  # row 0 at the top (+y)
                    d = np.array([math.tan(math.radians(ax)), math.tan(math.radians(ay)), -1.0])
                    directions.append(d / np.linalg.norm(d))
                    origins.append(
                        [(kx + 0.5 - side / 2) * pitch / m, (side / 2 - ky - 0.5) * pitch / m, 0.0]
                    )
                    detectors.append(r * n + c)
    return np.array(origins), np.array(directions), np.array(detectors)


def test_figure_14_case_matches_the_report_rotations():
    sensor = Sensor(grid=3, ray_grid=2, fov=45.0, pixel_pitch=100e-6)
    pose = ScanPose(100.0, -50.0, 300.0, heading=20.0, azimuth=40.0, depression=60.0)
    origins, directions, detector = sensor.rays(pose)
    assert origins.shape == directions.shape == (36, 3)
    assert origins.dtype == directions.dtype == np.float64 and detector.dtype == np.int32

    local_o, local_d, local_det = down_looking_rays(3, 2, 45.0, 100e-6)
    rotation = report_rz(20.0, 40.0) @ report_rx(60.0)
    expected_d = np.array([rotation @ d for d in local_d])
    expected_o = np.array([rotation @ o + (100.0, -50.0, 300.0) for o in local_o])
    np.testing.assert_allclose(directions, expected_d, atol=1e-12)
    np.testing.assert_allclose(origins, expected_o, atol=1e-9)
    np.testing.assert_array_equal(detector, local_det)
    assert list(detector) == [d for d in range(9) for _ in range(4)]  # contiguous, row-major


def test_nadir_points_straight_down():
    sensor = Sensor(grid=4, ray_grid=2, fov=20.0)
    pose = ScanPose(0, 0, 100, heading=37.0, azimuth=0.0, depression=90.0)
    origin, direction = sensor.central_ray(pose)
    np.testing.assert_allclose(direction, [0, 0, -1], atol=1e-15)
    _, directions, _ = sensor.rays(pose)
    np.testing.assert_allclose(directions.mean(axis=0)[:2], [0, 0], atol=1e-12)
    assert (directions[:, 2] < 0).all()


@pytest.mark.parametrize(
    "heading,azimuth,expected",
    [
        (0.0, 0.0, (0.0, 0.5, -math.sqrt(3) / 2)),  # north and down
        (90.0, 0.0, (0.5, 0.0, -math.sqrt(3) / 2)),  # east
        (30.0, 60.0, (0.5, 0.0, -math.sqrt(3) / 2)),  # H + A = 90: east
        (0.0, -90.0, (-0.5, 0.0, -math.sqrt(3) / 2)),  # west
        (180.0, 0.0, (0.0, -0.5, -math.sqrt(3) / 2)),  # south
    ],
)
def test_central_ray_directions(heading, azimuth, expected):
    sensor = Sensor(grid=8, ray_grid=1, fov=10.0)
    pose = ScanPose(1.0, 2.0, 50.0, heading=heading, azimuth=azimuth, depression=60.0)
    origin, direction = sensor.central_ray(pose)
    np.testing.assert_allclose(origin, (1.0, 2.0, 50.0))
    np.testing.assert_allclose(direction, expected, atol=1e-12)
    # An odd-free grid has no ray on the axis; the mean of all rays still is.
    _, directions, _ = sensor.rays(pose)
    mean = directions.mean(axis=0)
    np.testing.assert_allclose(mean / np.linalg.norm(mean), expected, atol=1e-9)


def ground_points(origins, directions):
    t = -origins[:, 2] / directions[:, 2]
    return origins + t[:, None] * directions


def test_row_zero_is_the_far_edge_and_column_zero_the_left():
    n, m = 6, 3
    sensor = Sensor(grid=n, ray_grid=m, fov=30.0)
    pose = ScanPose(0.0, 0.0, 100.0, heading=0.0, depression=60.0)  # looking north
    origins, directions, detector = sensor.rays(pose)
    ground = ground_points(origins, directions)
    centre = np.array([ground[detector == d].mean(axis=0) for d in range(n * n)])
    grid_y = centre[:, 1].reshape(n, n)
    grid_x = centre[:, 0].reshape(n, n)
    assert (np.diff(grid_y, axis=0) < 0).all()  # later rows are nearer (further south)
    assert (np.diff(grid_x, axis=1) > 0).all()  # later columns are further east (right)


def test_rays_are_equally_spaced_in_angle_and_do_not_cross():
    n, m, fov = 5, 4, 20.0
    sensor = Sensor(grid=n, ray_grid=m, fov=fov, pixel_pitch=1e-3)
    origins, directions, _ = sensor.rays(ScanPose(0.0, 0.0, 10.0, depression=90.0))
    side = n * m
    # Put rays back on the (row, column) grid of the whole view.
    order = np.arange(side * side).reshape(n, n, m, m).transpose(0, 2, 1, 3).ravel()
    d = directions[order].reshape(side, side, 3)
    o = origins[order].reshape(side, side, 3)
    angle_x = np.degrees(np.arctan2(d[..., 0], -d[..., 2]))
    angle_y = np.degrees(np.arctan2(d[..., 1], -d[..., 2]))
    step = fov / side
    np.testing.assert_allclose(np.diff(angle_x, axis=1), step, atol=1e-9)
    np.testing.assert_allclose(np.diff(angle_y, axis=0), -step, atol=1e-9)
    assert angle_x[0, 0] == pytest.approx(-fov / 2 + step / 2)
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0)
    # Origins on the focal plane, pitch / m apart, spanning n pitches.
    np.testing.assert_allclose(np.diff(o[..., 0], axis=1), 1e-3 / m)
    np.testing.assert_allclose(np.diff(o[..., 1], axis=0), -1e-3 / m)
    assert o[..., 0].max() - o[..., 0].min() == pytest.approx((side - 1) * 1e-3 / m)
    # Not crossing: order on the ground is the order on the focal plane.
    ground = ground_points(origins[order], directions[order]).reshape(side, side, 3)
    assert (np.diff(ground[..., 0], axis=1) > 0).all()
    assert (np.diff(ground[..., 1], axis=0) < 0).all()


def test_row_chunks_are_slices_of_the_whole_scan():
    sensor = Sensor(grid=7, ray_grid=3, fov=12.0)
    pose = ScanPose(3.0, 4.0, 60.0, heading=200.0, azimuth=-30.0, depression=35.0)
    whole = sensor.rays(pose)
    per_row = 7 * 9
    for rows in (slice(0, 2), slice(2, 7), range(6, 7)):
        part = sensor.rays(pose, rows=rows)
        start, stop = rows.start * per_row, rows.stop * per_row
        for got, full in zip(part, whole):
            np.testing.assert_array_equal(got, full[start:stop])


@pytest.mark.parametrize("rows", [3, "0:2", slice("a", 2), [0, 1]])
def test_rows_that_are_no_slice_or_range_are_a_field_error(rows):
    """rows=3 failed with "'int' object has no attribute 'indices'", slice("a", 2)
    with a TypeError from inside Python's slice arithmetic."""
    with pytest.raises(FieldError) as caught:
        Sensor(grid=4, ray_grid=1).rays(ScanPose(0.0, 0.0, 50.0), rows=rows)
    assert str(caught.value) == f"rows = {rows!r}: expected a contiguous range of detector rows"


def test_footprint_at_nadir_and_tilted():
    sensor = Sensor(grid=16, ray_grid=1, fov=20.0)
    corners = sensor.footprint(ScanPose(10.0, 20.0, 100.0, depression=90.0))
    half = 100.0 * math.tan(math.radians(10.0))
    np.testing.assert_allclose(
        corners,
        [
            [10 - half, 20 + half, 0],
            [10 + half, 20 + half, 0],
            [10 + half, 20 - half, 0],
            [10 - half, 20 - half, 0],
        ],
    )
    tilted = sensor.footprint(ScanPose(0.0, 0.0, 100.0, depression=45.0), ground_z=5.0)
    assert (tilted[:, 2] == 5.0).all()
    assert tilted[0, 1] > tilted[3, 1] > 0  # far edge beyond the near edge, both ahead
    # Far edge: centre line at 45 - 10 = 35 degrees below horizontal (projected angles).
    assert np.mean(tilted[:2, 1]) > 95.0 / math.tan(math.radians(35.0)) - 1e-9
    # Each corner where the report's rotations (equations 1, 2) take the view's corner
    # ray (tan 10 degrees off the boresight on both axes) down 95 m to z = 5.
    np.testing.assert_allclose(tilted, hand_footprint((0.0, 0.0, 100.0), 0.0, 45.0, 20.0, 5.0), atol=1e-9)
    turned = ScanPose(30.0, -40.0, 80.0, heading=120.0, azimuth=-25.0, depression=35.0)
    np.testing.assert_allclose(
        sensor.footprint(turned), hand_footprint((30.0, -40.0, 80.0), 95.0, 35.0, 20.0, 0.0), atol=1e-9
    )
    above = sensor.footprint(ScanPose(0.0, 0.0, 100.0, depression=5.0))
    assert np.isnan(above[:2]).all() and np.isfinite(above[2:]).all()
    np.testing.assert_allclose(above[2:], hand_footprint((0.0, 0.0, 100.0), 0.0, 5.0, 20.0, 0.0)[2:])


def hand_footprint(position, bearing, depression, fov, ground_z):
    """The four corners (far left, far right, near right, near left) by hand: the corner
    rays of a down-looking view, turned by equations 1 and 2, met with z = ground_z."""
    rotation = report_rz(bearing, 0.0) @ report_rx(depression)
    half = math.tan(math.radians(fov / 2))
    corners = []
    for sx, sy in ((-1, 1), (1, 1), (1, -1), (-1, -1)):
        d = rotation @ np.array([sx * half, sy * half, -1.0])
        t = (ground_z - position[2]) / d[2] if d[2] < 0 else math.nan
        corners.append(np.array(position) + t * d)
    return np.array(corners)


def test_a_ground_plane_above_the_sensor_has_no_footprint():
    """ground_z above the aircraft gave four corners behind the sensor (each ray run
    backwards up to the plane), mirrored through the aircraft, as if seen."""
    sensor = Sensor(grid=4, ray_grid=1, fov=10.0)
    pose = ScanPose(0.0, 0.0, 10.0, depression=60.0)
    assert np.isnan(sensor.footprint(pose, ground_z=20.0)).all()
    np.testing.assert_allclose(sensor.footprint(pose, ground_z=10.0)[:, :2], 0.0, atol=1e-12)
    with pytest.raises(FieldError, match=r"^ground_z = 'low': expected a finite number$"):
        sensor.footprint(pose, ground_z="low")


@pytest.mark.parametrize(
    "field,value,message",
    [
        ("grid", 0, "grid = 0: expected an integer from 1 to 1024"),
        ("grid", 1025, "grid = 1025: expected an integer from 1 to 1024"),
        ("grid", 64.0, "grid = 64.0: expected an integer from 1 to 1024"),
        ("grid", True, "grid = True: expected an integer from 1 to 1024"),
        ("ray_grid", 17, "ray_grid = 17: expected an integer from 1 to 16"),
        ("ray_grid", 0, "ray_grid = 0: expected an integer from 1 to 16"),
        ("fov", 0, "fov = 0: expected a number at least 1e-14 and less than 90"),
        ("fov", 90, "fov = 90: expected a number at least 1e-14 and less than 90"),
        ("depth_resolution", -0.1, "depth_resolution = -0.1: expected a number from 0 to 1000"),
        ("depth_resolution", 1001, "depth_resolution = 1001: expected a number from 0 to 1000"),
        ("pixel_pitch", 0.0, "pixel_pitch = 0.0: expected a number from 1e-07 to 0.01"),
        ("pixel_pitch", float("inf"), "pixel_pitch = inf: expected a number from 1e-07 to 0.01"),
    ],
)
def test_sensor_field_limits(field, value, message):
    with pytest.raises(FieldError) as caught:
        Sensor(**{field: value})
    assert str(caught.value) == message


@pytest.mark.parametrize(
    "attitude", [(float("nan"), 0.0), (0.0, float("inf")), (5.0,), "level", (1, 2, 3, 4)]
)
def test_an_attitude_that_is_not_two_or_three_finite_angles_is_refused(attitude):
    """A NaN roll made every ray NaN, silently; a short tuple failed inside numpy."""
    sensor = Sensor(grid=2, ray_grid=1)
    pose = ScanPose(0, 0, 50)
    for call in (
        lambda: sensor.rays(pose, attitude=attitude),
        lambda: sensor.footprint(pose, attitude=attitude),
    ):
        with pytest.raises(FieldError, match=r"^attitude = .*: expected \(roll, pitch\)"):
            call()
    turned = sensor.rays(pose, attitude=(10.0, -5.0, 2.0))[1]  # yaw may follow
    assert np.isfinite(turned).all()


@pytest.mark.parametrize("method", ["rays", "central_ray", "corner_directions", "footprint"])
@pytest.mark.parametrize("pose", [None, (0.0, 0.0, 50.0)])
def test_a_pose_that_is_no_scan_pose_is_refused(method, pose):
    # They raised AttributeError ('NoneType' object has no attribute 'heading').
    with pytest.raises(FieldError) as caught:
        getattr(Sensor(grid=4, ray_grid=1), method)(pose)
    assert caught.value.field == "pose" and "expected a ScanPose" in str(caught.value)


def test_limits_are_accepted():
    sensor = Sensor(grid=1, ray_grid=16, fov=89.9, depth_resolution=0.0, pixel_pitch=1e-7)
    origins, directions, detector = sensor.rays(ScanPose(0, 0, 10, depression=1.0))
    assert origins.shape == (256, 3) and (detector == 0).all()
    assert Sensor(grid=1024, ray_grid=1).rays_per_scan == 1024**2


def test_a_field_of_view_or_pixel_pitch_too_small_to_mean_a_sensor_is_refused(tmp_path):
    """fov 1e-300 deg and pixel pitch 1e-300 um were taken (IFOV 1e-299 mdeg, READY); a
    pitch of 1e-320 um in a file was refused as 'at most 0.01', in metres."""
    import pytest

    from ladartui.errors import FieldError
    from ladartui.scenario import load_scenario
    from ladartui.sensor import MIN_FOV, Sensor

    for field, value in (("fov", 1e-300), ("pixel_pitch", 1e-300)):
        with pytest.raises(FieldError) as caught:
            Sensor(**{field: value})
        assert caught.value.field == field and (
            "from " in caught.value.expected or "least" in caught.value.expected
        )
    assert Sensor(fov=MIN_FOV).fov == MIN_FOV
    orbit = __import__("pathlib").Path(__file__).resolve().parent.parent / "scenarios" / "orbit.toml"
    path = tmp_path / "s.toml"
    path.write_text(orbit.read_text().replace("pixel_pitch_um = 100.0", "pixel_pitch_um = 1e-320"))
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    assert "sensor.pixel_pitch_um = 1e-320: expected a number from 0.1 to 10000" in str(caught.value)


def test_too_many_manual_poses_are_counted_in_the_message_not_listed():
    """10,001 poses: the message listed them all and was cut before 'expected'."""
    import pytest

    from ladartui.errors import FieldError
    from ladartui.flight import MAX_SCANS, Manual, ScanPose

    with pytest.raises(FieldError) as caught:
        Manual((ScanPose(0.0, 0.0, 50.0),) * (MAX_SCANS + 1))
    assert str(caught.value) == "poses = '10,001 items': expected a list of 1 to 10,000 scan poses"
