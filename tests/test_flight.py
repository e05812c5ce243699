"""Flight paths: poses, manoeuvres (report figures 12, 13), presets (figure 1), aiming."""

import math

import numpy as np
import pytest

from ladartui.errors import FieldError
from ladartui.flight import (
    FlightPlan,
    FlyPast,
    Manual,
    Orbit,
    ScanPose,
    Standoff,
    Straight,
    Turn,
    aim_at,
    flight_time,
    flypast,
    orbit,
    path_length,
    standoff_sweep,
    straight,
    turn,
)


def central_direction(pose):
    """Boresight from the angles alone: bearing H + A, D below the horizontal."""
    bearing = math.radians(pose.heading + pose.azimuth)
    d = math.radians(pose.depression)
    return np.array([math.cos(d) * math.sin(bearing), math.cos(d) * math.cos(bearing), -math.sin(d)])


def distance_ray_to_point(origin, direction, point):
    v = np.asarray(point, float) - np.asarray(origin, float)
    return float(np.linalg.norm(np.cross(v, direction)) / np.linalg.norm(direction))


def heading_vector(heading):
    return np.array([math.sin(math.radians(heading)), math.cos(math.radians(heading))])


# -- poses ---------------------------------------------------------------------------


def test_pose_normalises_angles():
    pose = ScanPose(1, 2, 3, heading=-90, azimuth=270, depression=90)
    assert (pose.heading, pose.azimuth) == (270.0, -90.0)
    assert ScanPose(0, 0, 1, heading=720).heading == 0.0
    assert ScanPose(0, 0, 1, azimuth=180).azimuth == 180.0


@pytest.mark.parametrize(
    "field,value,message",
    [
        ("depression", 0.5, "depression = 0.5: expected a number from 1 to 90"),
        ("depression", 91, "depression = 91: expected a number from 1 to 90"),
        ("z", 0, "z = 0: expected a number greater than 0 and at most 100000"),
        ("z", -3.0, "z = -3.0: expected a number greater than 0 and at most 100000"),
        ("x", float("nan"), "x = nan: expected a number from -1000000 to 1000000"),
        ("heading", "north", "heading = 'north': expected a finite number"),
        ("azimuth", True, "azimuth = True: expected a finite number"),
    ],
)
def test_pose_field_limits(field, value, message):
    args = {"x": 0.0, "y": 0.0, "z": 10.0, "heading": 0.0, "azimuth": 0.0, "depression": 45.0}
    args[field] = value
    with pytest.raises(FieldError) as caught:
        ScanPose(**args)
    assert str(caught.value) == message
    assert caught.value.field == field


# -- straight (figure 12) ------------------------------------------------------------


def test_straight_five_scans_start_is_not_a_scan():
    start = ScanPose(10.0, 20.0, 100.0, heading=30.0, azimuth=15.0, depression=50.0)
    poses = straight(start, 500.0, 5)
    assert len(poses) == 5
    for k, pose in enumerate(poses, start=1):
        d = 100.0 * k  # evenly spaced, first scan one interval after the start
        assert pose.x == pytest.approx(10.0 + d * math.sin(math.radians(30)))
        assert pose.y == pytest.approx(20.0 + d * math.cos(math.radians(30)))
        assert (pose.z, pose.heading, pose.azimuth, pose.depression) == (100.0, 30.0, 15.0, 50.0)
    assert math.dist(start.position, poses[-1].position) == pytest.approx(500.0)
    assert path_length(poses) == pytest.approx(400.0)  # first scan to last


# -- turn (figure 13) ------------------------------------------------------------------


@pytest.mark.parametrize(
    "direction,centre,end,end_heading",
    [
        ("right", (100.0, 0.0), (100.0, 100.0), 90.0),
        ("left", (-100.0, 0.0), (-100.0, 100.0), 270.0),
    ],
)
def test_quarter_turn_from_north(direction, centre, end, end_heading):
    start = ScanPose(0.0, 0.0, 50.0, heading=0.0, depression=60.0)
    poses = turn(start, 100.0, 90.0, direction, 4)
    assert len(poses) == 4
    assert (poses[-1].x, poses[-1].y) == pytest.approx(end, abs=1e-9)
    assert poses[-1].heading == pytest.approx(end_heading)
    for k, pose in enumerate(poses, start=1):
        radial = np.array([pose.x - centre[0], pose.y - centre[1]])
        assert np.linalg.norm(radial) == pytest.approx(100.0)  # on the arc
        # Swept angle from the start, seen from the centre: 22.5 degrees per scan.
        start_radial = np.array([0.0 - centre[0], 0.0 - centre[1]])
        cos = radial @ start_radial / 100.0**2
        assert math.degrees(math.acos(np.clip(cos, -1, 1))) == pytest.approx(22.5 * k)
        # Heading along the tangent, turning the named way.
        h = heading_vector(pose.heading)
        assert h @ radial == pytest.approx(0.0, abs=1e-9)
        turning = h[0] * radial[1] - h[1] * radial[0]  # z of (h x radial)
        assert (turning > 0) == (direction == "right")
        assert pose.z == 50.0 and pose.depression == 60.0


def test_turn_spacing_is_even_along_the_arc():
    poses = turn(ScanPose(5.0, -3.0, 80.0, heading=123.0), 40.0, 200.0, "left", 8)
    chords = [math.dist(a.position, b.position) for a, b in zip(poses, poses[1:])]
    expected = 2 * 40.0 * math.sin(math.radians(200.0 / 8) / 2)
    assert chords == pytest.approx([expected] * 7)
    assert poses[-1].heading == pytest.approx((123.0 - 200.0) % 360)


# -- plans: continuity and length ----------------------------------------------------


def test_segments_continue_from_the_last_scan_with_continuous_heading():
    start = ScanPose(0.0, 0.0, 100.0, heading=90.0, depression=45.0)
    plan = FlightPlan(start, [Straight(300.0, 3), Turn(50.0, 180.0, "left", 3), Straight(100.0, 2)])
    first, second, third = plan.segment_poses()
    # The turn starts at the straight's end, turning left from heading 90 (east):
    # its centre is 50 m north of (300, 0); it ends at (300, 100) heading west.
    for pose in second:
        assert math.dist((pose.x, pose.y), (300.0, 50.0)) == pytest.approx(50.0)
    assert (second[-1].x, second[-1].y, second[-1].heading) == pytest.approx((300.0, 100.0, 270.0))
    assert (third[0].x, third[0].y) == pytest.approx((250.0, 100.0))
    assert (third[1].x, third[1].y) == pytest.approx((200.0, 100.0))
    assert plan.poses() == first + second + third
    # Length from the first scan: 2 x 100 m straight, three 60-degree pieces of
    # arc (the first from the turn's start), then 2 x 50 m.
    expected = 200.0 + 3 * 50.0 * math.radians(60.0) + 50.0 + 50.0
    assert plan.path_length() == pytest.approx(expected)
    assert plan.flight_time(25.0) == pytest.approx(expected / 25.0)


def test_the_path_drawn_follows_the_turn_from_the_scan_before_it():
    """The views drew a turn as chords between its scans, from the straight's end
    cutting inside the 50 m circle; the points drawn now lie on it, every 5 degrees."""
    start = ScanPose(0.0, 0.0, 100.0, heading=90.0, depression=45.0)
    plan = FlightPlan(start, [Straight(300.0, 3), Turn(50.0, 180.0, "left", 3), Straight(100.0, 2)])
    points = np.array(plan.path_points())
    scans = np.array([pose.position for pose in plan.poses()])
    assert len(points) == len(scans) + 3 * (60 // 5 - 1)  # 11 between each pair on the arc
    on_turn = points[(points[:, 0] >= 300.0 - 1e-9) & (points[:, 1] > 1e-9)]
    assert len(on_turn) == 3 * 12  # the turn's scans and the 11 points before each
    assert np.hypot(on_turn[:, 0] - 300.0, on_turn[:, 1] - 50.0) == pytest.approx(50.0)
    assert (on_turn[:, 2] == 100.0).all()
    length = np.linalg.norm(np.diff(points, axis=0), axis=1).sum()
    assert length == pytest.approx(plan.path_length(), rel=1e-3)
    # the scans are all on it, in order
    assert [tuple(p) for p in points if any(np.allclose(p, s) for s in scans)] == [tuple(s) for s in scans]


def test_relative_segment_without_start_names_the_field():
    with pytest.raises(FieldError) as caught:
        FlightPlan(None, [Straight(100.0, 2)]).poses()
    assert caught.value.field == "start"


def test_absolute_then_relative_segment():
    manual = Manual([ScanPose(0, 0, 50, heading=180.0, depression=70.0)])
    plan = FlightPlan(None, [manual, Straight(20.0, 2, depression=30.0)])
    poses = plan.poses()
    assert plan.path_length() == pytest.approx(20.0)
    np.testing.assert_allclose([(p.x, p.y) for p in poses], [(0, 0), (0, -10), (0, -20)], atol=1e-9)
    assert [p.depression for p in poses] == [70.0, 30.0, 30.0]
    # Between two absolute segments the plan counts the straight jump.
    jump = FlightPlan(None, [manual, Manual([ScanPose(30, 40, 50)])])
    assert jump.path_length() == pytest.approx(50.0)


def test_segment_errors_name_the_segment():
    segments = [Straight(10.0, 1), Straight(10.0, 1, aim_at=(0, 500, 50))]
    plan = FlightPlan(ScanPose(0, 0, 10), segments)
    with pytest.raises(FieldError) as caught:
        plan.poses()
    assert caught.value.field == "segments[1].aim_at"


@pytest.mark.parametrize(
    "make,message",
    [
        (lambda: Straight(-5, 3), "distance = -5: expected a number greater than 0 and at most 1000000"),
        (lambda: Straight(5, 0), "scans = 0: expected an integer from 1 to 10000"),
        (lambda: Turn(10, 400, "right", 3), "arc = 400: expected a number greater than 0 and at most 360"),
        (lambda: Turn(10, 90, "up", 3), "direction = 'up': expected one of 'left', 'right'"),
        (lambda: Orbit((0, 0), 0, 50, 3), "radius = 0: expected a number greater than 0 and at most 1000000"),
        (
            lambda: Orbit((0,), 10, 50, 3),
            "centre = (0,): expected a point [x, y] or [x, y, z] in metres, each within +-1000000",
        ),
        (
            lambda: FlyPast((0, 0), 10, 50, 100, 3, 0, side="below"),
            "side = 'below': expected one of 'left', 'right'",
        ),
        (
            lambda: Standoff((0, 0), [], 50),
            "standoffs = []: expected a list of 1 to 10000 distances from 0 to 1000000 metres",
        ),
        (
            lambda: Standoff((0, 0), [10, -1], 50),
            "standoffs = [10, -1]: expected a list of 1 to 10000 distances from 0 to 1000000 metres",
        ),
    ],
)
def test_segment_field_limits(make, message):
    with pytest.raises(FieldError) as caught:
        make()
    assert str(caught.value) == message


# -- presets (figure 1) and aiming --------------------------------------------------


@pytest.mark.parametrize("direction", ["right", "left"])
def test_orbit_scans_equidistant_and_aimed(direction):
    centre = (40.0, -25.0, 2.0)
    poses = orbit(centre, 120.0, 90.0, 12, direction=direction, start_bearing=180.0)
    assert len(poses) == 12
    assert (poses[0].x, poses[0].y) == pytest.approx((40.0, -145.0))  # due south
    for k, pose in enumerate(poses):
        assert math.dist((pose.x, pose.y), centre[:2]) == pytest.approx(120.0)
        assert pose.z == 90.0
        bearing = math.degrees(math.atan2(pose.x - centre[0], pose.y - centre[1])) % 360
        step = 30.0 if direction == "right" else -30.0
        assert (bearing - (180.0 + step * k) + 180) % 360 - 180 == pytest.approx(0.0, abs=1e-9)
        assert distance_ray_to_point(pose.position, central_direction(pose), centre) < 1e-9
        # Tangent heading; a clockwise orbit has the target on its right.
        assert pose.azimuth == pytest.approx(90.0 if direction == "right" else -90.0)
    # Full circle: no repeated scan; arc length between scans is 30 degrees.
    plan = FlightPlan(None, [Orbit(centre, 120.0, 90.0, 12, direction=direction)])
    assert plan.poses() == poses
    assert plan.path_length() == pytest.approx(11 * 120.0 * math.radians(30.0))
    assert path_length(poses) == pytest.approx(11 * 2 * 120.0 * math.sin(math.radians(15.0)))


def test_partial_orbit_includes_both_ends():
    poses = orbit((0.0, 0.0), 50.0, 40.0, 3, arc=90.0, start_bearing=0.0)
    np.testing.assert_allclose(
        [(p.x, p.y) for p in poses],
        [(0.0, 50.0), (50 * math.sin(math.pi / 4), 50 * math.cos(math.pi / 4)), (50.0, 0.0)],
        atol=1e-9,
    )


def test_flypast_passes_at_the_standoff_with_target_on_the_side():
    target = (10.0, 20.0, 1.5)
    for side in ("right", "left"):
        poses = flypast(target, 80.0, 60.0, 200.0, 5, heading=45.0, side=side)
        assert len(poses) == 5
        assert all(p.heading == 45.0 and p.z == 60.0 for p in poses)
        assert math.dist(poses[0].position, poses[-1].position) == pytest.approx(200.0)
        middle = poses[2]
        assert math.dist((middle.x, middle.y), target[:2]) == pytest.approx(80.0)
        h = heading_vector(45.0)
        to_target = np.array(target[:2]) - (middle.x, middle.y)
        assert h @ to_target == pytest.approx(0.0, abs=1e-9)  # closest point of approach
        cross = h[0] * to_target[1] - h[1] * to_target[0]
        assert (cross < 0) == (side == "right")  # right of the nose is clockwise
        for pose in poses:
            assert distance_ray_to_point(pose.position, central_direction(pose), target) < 1e-9


def test_standoff_sweep_distances_and_heading():
    target = (0.0, 0.0, 0.0)
    poses = standoff_sweep(target, [300.0, 200.0, 100.0], 70.0, bearing=270.0)
    np.testing.assert_allclose([(p.x, p.y) for p in poses], [(-300, 0), (-200, 0), (-100, 0)], atol=1e-9)
    assert all(p.heading == pytest.approx(90.0) for p in poses)  # towards the target
    assert [p.azimuth for p in poses] == pytest.approx([0.0] * 3, abs=1e-9)
    assert [p.depression for p in poses] == pytest.approx(
        [math.degrees(math.atan2(70.0, d)) for d in (300, 200, 100)]
    )


@pytest.mark.parametrize("seed", range(5))
def test_aim_at_points_the_central_ray_at_the_target(seed):
    rng = np.random.default_rng(seed)
    pose = ScanPose(
        *rng.uniform(-500, 500, 2),
        rng.uniform(100, 400),
        heading=rng.uniform(0, 360),
        azimuth=rng.uniform(-180, 180),
        depression=30,
    )
    target = (*rng.uniform(-500, 500, 2), rng.uniform(0, 20))
    aimed = aim_at(pose, target)
    assert aimed.position == pose.position and aimed.heading == pose.heading
    assert distance_ray_to_point(pose.position, central_direction(aimed), target) < 1e-6
    assert central_direction(aimed) @ (np.array(target) - pose.position) > 0  # in front


def test_aim_at_straight_down_and_above_the_horizon():
    pose = ScanPose(5.0, 5.0, 100.0, heading=10.0, azimuth=33.0, depression=20.0)
    below = aim_at(pose, (5.0, 5.0, 0.0))
    assert (below.depression, below.azimuth) == (90.0, 33.0)
    with pytest.raises(FieldError) as caught:
        aim_at(pose, (1000.0, 5.0, 95.0))  # 0.29 degrees below the horizon
    assert caught.value.field == "aim_at"
    assert "at least 1 degree below the horizon" in str(caught.value)


def test_flight_time_checks_speed():
    assert flight_time(300.0, 25.0) == 12.0
    with pytest.raises(FieldError) as caught:
        flight_time(300.0, 0)
    assert str(caught.value) == "speed = 0: expected a number > 0"


def test_altitudes_people_ask_for_are_practical_and_headings_they_type_are_compass_angles():
    from ladartui.checks import compass_field
    from ladartui.flight import MAX_FLIGHT_ALTITUDE, Orbit

    with pytest.raises(FieldError, match="at most 20000"):
        Orbit(centre=(0.0, 0.0, 0.0), radius=50.0, altitude=MAX_FLIGHT_ALTITUDE + 1, scans=4)
    assert (
        Orbit(centre=(0.0, 0.0, 0.0), radius=50.0, altitude=MAX_FLIGHT_ALTITUDE, scans=4).altitude
        == MAX_FLIGHT_ALTITUDE
    )
    assert compass_field("heading", 360.0) == 360.0
    for bad in (400.0, -1.0):
        with pytest.raises(FieldError, match="from 0 to 360"):
            compass_field("heading", bad)


def test_a_centre_too_near_the_horizon_is_blamed_on_the_distance_the_user_wrote():
    from ladartui.flight import orbit, standoff_sweep

    with pytest.raises(FieldError) as caught:
        orbit((0.0, 0.0, 0.0), 1e6, 100.0, 4)
    assert caught.value.field == "radius" and "at most 5729 m at altitude 100 m" in str(caught.value)
    with pytest.raises(FieldError) as caught:
        standoff_sweep((0.0, 0.0, 0.0), (50.0, 9000.0), 100.0)
    assert caught.value.field == "standoffs"
    with pytest.raises(FieldError) as caught:  # an aim point the user wrote is named as such
        orbit((0.0, 0.0, 0.0), 1e6, 100.0, 4, aim_at=(0.0, 0.0, 0.0))
    assert caught.value.field == "aim_at"


def test_an_altitude_at_or_below_the_target_is_blamed_on_the_altitude(tmp_path):
    # No radius can help here; the message asked for "a radius of at most 0 m".
    from ladartui.flight import flypast, orbit
    from ladartui.scenario import load_scenario

    with pytest.raises(FieldError) as caught:
        orbit((0.0, 0.0, 5.0), 50.0, 3.0, 4)
    assert caught.value.field == "altitude"
    assert str(caught.value) == (
        "altitude = 3.0: expected an altitude above the centre's height of 5 m, so the centre "
        "is at least 1 degree below the horizon (or an aim_at point)"
    )
    with pytest.raises(FieldError) as caught:
        flypast((0.0, 0.0, 5.0), 30.0, 5.0, 100.0, 4, 0.0)
    assert caught.value.field == "altitude" and "above the target's height of 5 m" in str(caught.value)
    path = tmp_path / "low.toml"
    path.write_text(
        '[files]\nscene = "scene.txt"\nvoxel_size = 1.0\n[[flight.segments]]\n'
        'kind = "orbit"\ncentre = [0.0, 0.0, 0.926]\nradius = 50.0\naltitude = 0.5\n'
        "scans = 4\n"
    )
    with pytest.raises(FieldError, match=r"low.toml:8: flight.segments\[0\].altitude = 0.5"):
        load_scenario(path, check_files=False)


@pytest.mark.parametrize(
    ("call", "field", "shown"),
    [
        (lambda: straight(None, 100.0, 4), "start", "start is not set"),
        (lambda: turn((0.0, 0.0, 50.0), 50.0, 90.0, "right", 3), "start", "start = (0.0, 0.0, 50.0)"),
        (lambda: aim_at("pose", (0.0, 0.0, 0.0)), "pose", "pose = 'pose'"),
        (lambda: path_length([1, 2, 3]), "poses[0]", "poses[0] = 1"),
    ],
)
def test_a_pose_that_is_no_scan_pose_is_a_field_error(call, field, shown):
    # These raised AttributeError ('NoneType' object has no attribute 'heading').
    with pytest.raises(FieldError) as caught:
        call()
    assert caught.value.field == field
    assert str(caught.value) == f"{shown}: expected a ScanPose"


@pytest.mark.parametrize(
    ("segments", "shown"),
    [(None, "segments is not set"), (["orbit"], "segments[0] = 'orbit'"), (Straight, "segments = ")],
)
def test_segments_that_are_no_flight_segments_are_refused(segments, shown):
    # They raised TypeError ('NoneType' object is not iterable) or, on poses(), AttributeError.
    with pytest.raises(FieldError) as caught:
        FlightPlan(ScanPose(0, 0, 10), segments)
    assert str(caught.value).startswith(shown)
    assert str(caught.value).endswith(
        "expected a list of flight segments (Manual, Straight, Turn, Orbit, FlyPast, Standoff "
        "or a flight log's LogSegment)"
    )


def test_the_scenario_file_names_the_radius_line(tmp_path):
    from ladartui.scenario import load_scenario

    path = tmp_path / "far.toml"
    path.write_text(
        '[files]\nscene = "scene.txt"\nvoxel_size = 1.0\n[[flight.segments]]\n'
        'kind = "orbit"\ncentre = [0.0, 0.0, 0.0]\nradius = 1e6\naltitude = 100.0\n'
        "scans = 4\n"
    )
    with pytest.raises(FieldError, match=r"far.toml:7: flight.segments\[0\].radius"):
        load_scenario(path, check_files=False)


def test_a_scan_past_the_coordinate_limit_is_blamed_on_a_field_the_user_wrote(tmp_path):
    # The message named the pose's "y", a key no segment has, at the segment's first line.
    from ladartui.flight import flypast, standoff_sweep, straight, turn
    from ladartui.scenario import load_scenario

    path = tmp_path / "far.toml"
    path.write_text(
        '[files]\nscene = "scene.txt"\nvoxel_size = 1.0\n[[flight.segments]]\n'
        'kind = "orbit"\ncentre = [10.0, 0.0, 0.0]\nradius = 1e6\naltitude = 20000.0\n'
        "scans = 4\n"
    )
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    assert str(caught.value) == (
        f"{path}:7: flight.segments[0].radius = 1000000.0: expected a radius that puts every "
        "scan within 1000000 m of the scene's origin in x and y (a scan would be at x = 1000010.0 m)"
    )
    start = ScanPose(999_990.0, 0.0, 100.0, heading=90.0)
    for build, field in (
        (lambda: flypast((0.0, 10.0, 0.0), 1e6, 100.0, 200.0, 3, 90.0), "standoff"),
        (lambda: standoff_sweep((0.0, 10.0, 0.0), (1e6,), 100.0, bearing=0.0), "standoffs"),
        # a target farther out than its scans reach is the one to move
        (lambda: flypast((999_990.0, 0.0, 0.0), 10.0, 100.0, 200.0, 3, 90.0), "target"),
        (lambda: standoff_sweep((999_990.0, 0.0, 0.0), (50.0,), 100.0, bearing=90.0), "target"),
        (lambda: orbit((1e6, 1.0, 2.0), 60.0, 100.0, 12), "centre"),
        (lambda: straight(start, 50.0, 2), "distance"),
        (lambda: turn(start, 50.0, 90.0, "left", 2), "radius"),
    ):
        with pytest.raises(FieldError) as caught:
            build()
        assert caught.value.field == field
        assert "within 1000000 m of the scene's origin in x and y" in str(caught.value)


def test_a_plan_builds_its_scans_once_however_often_it_is_asked(monkeypatch):
    """A 9,000-scan fly-past was built 16 times for one OK in its form (0.3 s each): the
    screen froze for seconds. A plan is immutable, so its scans are made once; what it
    hands out is the caller's own to change."""
    import pickle

    built = []
    original = FlyPast.build
    monkeypatch.setattr(FlyPast, "build", lambda self, current: built.append(1) or original(self, current))
    plan = FlightPlan(
        segments=(FlyPast(target=(0.0, 0.0, 0.0), standoff=50.0, altitude=60.0, length=400.0, scans=40),)
    )
    first = plan.poses()
    assert plan.poses() == first and plan.segment_poses()[0] == first
    assert plan.path_length() == pytest.approx(400.0) and len(plan.scan_times(10.0)) == 40
    assert len(built) == 1
    first.clear()  # the caller's list: the plan's scans stay whole
    plan.segment_poses()[0].clear()
    assert len(plan.poses()) == 40 and len(built) == 1
    again = pickle.loads(pickle.dumps(plan))  # sent to a sweep's workers without its scans
    assert again == plan and len(pickle.dumps(plan)) < 2000
    assert again.poses() == plan.poses()


def test_the_scans_of_plans_long_unused_are_not_kept():
    """Each edit of a path makes a new plan, and an undo history holds 200 of them: a
    10,000-scan path kept with every one pinned half a gigabyte."""
    import gc
    import weakref

    from ladartui.flight import plan as plan_module

    plans = [
        FlightPlan(segments=(Orbit(centre=(0.0, 0.0, 0.0), radius=50.0 + k, altitude=60.0, scans=10),))
        for k in range(3 * plan_module._KEPT_PLANS)
    ]
    for plan in plans:
        plan.poses()
    held = [entry for _, entry in plan_module._made.items() if any(entry[0]() is p for p in plans)]
    assert len(held) == plan_module._KEPT_PLANS  # the plans used last, of all still alive
    gone = weakref.ref(plans[-1])
    del plans, plan
    gc.collect()
    assert gone() is None  # the cache holds no plan alive


def test_manual_poses_and_plan_segments_of_the_wrong_kind_are_named_whole():
    """Manual(poses=None) raised TypeError from tuple(); FlightPlan(segments="orbit") said
    segments[0] = 'o', walking the word letter by letter."""
    with pytest.raises(FieldError, match=r"^poses is not set: expected a list of 1 to"):
        Manual(None)
    with pytest.raises(FieldError, match=r"^segments = 'orbit': expected a list of flight segments"):
        FlightPlan(segments="orbit")


def test_path_length_of_no_list_of_poses_names_the_argument():
    # It raised TypeError: 'NoneType' object is not iterable.
    with pytest.raises(FieldError, match=r"^poses is not set: expected a list of ScanPose$"):
        path_length(None)
    with pytest.raises(FieldError, match=r"^poses = 3: expected a list of ScanPose$"):
        path_length(3)
    assert path_length([]) == 0
