"""Whether a scenario's scans can see its scene and its target, told without tracing."""

import dataclasses
import math

import numpy as np
import pytest

from ladartui.flight import ScanPose
from ladartui.sensor import Sensor
from ladartui.view_reach import ScanViews


def _ray_hits_box(origins, directions, lo, hi) -> bool:
    """Whether any ray (forward from its origin) passes through the box: the slab test."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / directions
        t1, t2 = (lo - origins) * inv, (hi - origins) * inv
    near = np.nanmax(np.minimum(t1, t2), axis=1)
    far = np.nanmin(np.maximum(t1, t2), axis=1)
    return bool(np.any(far >= np.maximum(near, 0.0)))


def test_a_straight_down_view_meets_a_box_inside_its_cone_and_not_one_just_outside():
    """Down from 100 m with a 10 degree view: at the ground the view reaches
    100 tan 5 + the focal plane's half width = 8.750 m either side of the aircraft."""
    sensor = Sensor(grid=16, ray_grid=1, fov=10.0)
    pose = ScanPose(0.0, 0.0, 100.0, depression=90.0)
    edge = 100.0 * math.tan(math.radians(5.0)) + 16 * 100e-6 / 2
    views = ScanViews(sensor, [pose], [None])
    assert views.meet(np.array([edge - 0.01, -1.0, 0.0]), np.array([20.0, 1.0, 1.0])).tolist() == [True]
    assert views.meet(np.array([edge + 0.01, -1.0, 0.0]), np.array([20.0, 1.0, 1.0])).tolist() == [False]
    # above the aircraft, and behind the focal plane: no ray goes up
    assert views.meet(np.array([-1.0, -1.0, 100.5]), np.array([1.0, 1.0, 101.0])).tolist() == [False]


def test_a_box_is_met_whenever_a_ray_passes_through_it():
    """Against every ray of the scan, slab-tested: a box a ray passes is always met (no
    scan is said to miss what it sees); boxes of both kinds are drawn."""
    rng = np.random.default_rng(7)
    sensor = Sensor(grid=8, ray_grid=4, fov=20.0, pixel_pitch=0.004)
    told = {True: 0, False: 0}
    for _ in range(300):
        pose = ScanPose(
            *rng.uniform(-80, 80, 2),
            rng.uniform(5, 120),
            heading=rng.uniform(0, 360),
            azimuth=rng.uniform(-180, 180),
            depression=rng.uniform(1, 90),
        )
        attitude = tuple(rng.uniform(-30, 30, 2)) if rng.random() < 0.5 else None
        centre, half = rng.uniform(-40, 40, 3), rng.uniform(0.5, 25, 3)
        centre[2] = abs(centre[2]) / 2
        lo, hi = centre - half, centre + half
        origins, directions, _ = sensor.rays(pose, attitude=attitude)
        hit = _ray_hits_box(origins, directions, lo, hi)
        met = bool(ScanViews(sensor, [pose], [attitude]).meet(lo, hi)[0])
        assert met or not hit, (pose, attitude, lo, hi)
        told[met] += 1
    assert min(told.values()) > 30, told


def test_views_far_from_the_box_are_told_apart_from_scan_to_scan():
    sensor = Sensor(grid=16, ray_grid=1, fov=10.0)
    poses = [ScanPose(x, 50.0, 60.0, depression=90.0) for x in (-500.0, 50.0, 5000.0, 500000.0)]
    box = (np.zeros(3), np.array([100.0, 100.0, 20.0]))
    assert ScanViews(sensor, poses, [None] * 4).meet(*box).tolist() == [False, True, False, False]


@pytest.mark.parametrize("azimuth, met", [(0.0, True), (180.0, False)])
def test_a_view_aimed_away_from_the_box_misses_it(azimuth, met):
    """20 m south of a box, flying east, looking right (south: away) or left (north)."""
    sensor = Sensor(grid=16, ray_grid=1, fov=10.0)
    pose = ScanPose(0.0, -20.0, 30.0, heading=90.0, azimuth=-90.0 + azimuth, depression=40.0)
    box = (np.array([-10.0, 0.0, 0.0]), np.array([10.0, 20.0, 10.0]))
    assert ScanViews(sensor, [pose], [None]).meet(*box).tolist() == [met]


# -- ladartui validate: a note for a path that never looks at the scene or the target --

SCENARIO = """\
[files]
scene = "m.txt"
voxel_size = 1.0

[sensor]
grid = 8
ray_grid = 1
fov_deg = 10.0

[flight]
speed_mps = 10.0

{flight}
"""

LOG_SEGMENT = """\
[[flight.segments]]
kind = "log"
file = "{name}.csv"
rate = 1.0
depression = 60.0
"""


def _models(folder, targets=((50, 50, 0, 1), (51, 50, 0, 1))):
    """A scene 0..100 m across (its voxels' centres), its target at (50, 50)."""
    scene = [(0, 0, 0), (100, 100, 5), *(voxel[:3] for voxel in targets)]
    (folder / "m.txt").write_text("".join(f"{x},{y},{z}\n" for x, y, z in scene))
    (folder / "m_Target.txt").write_text("".join(f"{x},{y},{z},{i}\n" for x, y, z, i in targets))


def _log(folder, name, x0, y0, step=(10.0, 0.0), records=11, heading=90.0):
    lines = ["time,x,y,z,heading"]
    lines += [f"{t},{x0 + t * step[0]},{y0 + t * step[1]},60.0,{heading}" for t in range(records)]
    (folder / f"{name}.csv").write_text("\n".join(lines) + "\n")


def _validate(path, capsys) -> list[str]:
    from ladartui.cli import main

    assert main(["validate", str(path)]) == 0  # a note, not a refusal
    return [line for line in capsys.readouterr().out.splitlines() if line.startswith("note")]


def _scenario(folder, flight, name="case.toml"):
    path = folder / name
    path.write_text(SCENARIO.format(flight=flight))
    return path


def test_validate_notes_a_flight_log_far_east_of_the_scene(tmp_path, capsys):
    """x = 5000 m over a 100 m scene ran silently to 0 % coverage."""
    _models(tmp_path)
    _log(tmp_path, "far", 5000.0, 50.0)
    notes = _validate(_scenario(tmp_path, LOG_SEGMENT.format(name="far")), capsys)
    assert notes == [
        "note       none of the 11 scans looks at the scene: the path lies 4.9 km east of it "
        "(x 5000..5100 against the scene's -0.5..100.5)"
    ]


def test_validate_notes_a_flight_log_left_in_map_coordinates(tmp_path, capsys):
    _models(tmp_path)
    _log(tmp_path, "utm", 500000.0, 400000.0)
    notes = _validate(_scenario(tmp_path, LOG_SEGMENT.format(name="utm")), capsys)
    assert notes == [
        "note       none of the 11 scans looks at the scene: the path lies 640 km north-east of it "
        "(x 500000..500100, y 400000 against the scene's x -0.5..100.5, y -0.5..100.5); "
        "utm.csv gives x and y in metres from the scene's origin: map coordinates (UTM) "
        "are to be shifted to it"
    ]


def test_validate_notes_a_straight_run_whose_sensor_looks_away(tmp_path, capsys):
    """South of the scene, flying east, the sensor aimed right (south): away from it."""
    _models(tmp_path)
    flight = """\
[flight.start]
x = 0.0
y = -10.0
z = 30.0
heading = 90.0
azimuth = 90.0
depression = 30.0

[[flight.segments]]
kind = "straight"
distance = 100.0
scans = 6
"""
    notes = _validate(_scenario(tmp_path, flight), capsys)
    assert notes == [
        "note       none of the 6 scans looks at the scene: the path lies 9.5 m south of it "
        "(y -10 against the scene's -0.5..100.5)"
    ]
    # aimed left (north), steeply: the near edge of the scene, short of the target
    north = flight.replace("azimuth = 90.0", "azimuth = -90.0").replace(
        "depression = 30.0", "depression = 60.0"
    )
    looking = _scenario(tmp_path, north, "north.toml")
    assert _validate(looking, capsys) == [
        "note       none of the 6 scans looks at the target: their views reach the scene but "
        "not the target's box (x 49.5..51.5, y 49.5..50.5, z -0.5..0.5)"
    ]


def test_validate_names_a_target_no_scan_looks_at(tmp_path, capsys):
    """Two targets, the path over one of them only."""
    _models(tmp_path, targets=((50, 50, 0, 1), (90, 90, 0, 2)))
    _log(tmp_path, "over", 20.0, 50.0, step=(6.0, 0.0))
    path = _scenario(tmp_path, LOG_SEGMENT.format(name="over").replace("60.0", "90.0"))
    path.write_text(path.read_text() + '\n[targets]\nnames = { 1 = "tank", 2 = "truck" }\n')
    assert _validate(path, capsys) == [
        "note       none of the 11 scans looks at target 2 'truck' (x 89.5..90.5, y 89.5..90.5, z -0.5..0.5)"
    ]


def test_validate_says_nothing_of_a_path_that_looks_at_its_target(tmp_path, capsys):
    _models(tmp_path)
    _log(tmp_path, "over", 20.0, 50.0, step=(6.0, 0.0))
    assert (
        _validate(_scenario(tmp_path, LOG_SEGMENT.format(name="over").replace("60.0", "90.0")), capsys) == []
    )


def test_validate_counts_the_scans_that_do_not_look_at_the_scene(tmp_path, capsys):
    """A log flown in from 200 m west of the scene: its first scans look at the ground
    short of it (straight down, 5.3 m either side at 60 m), the rest over it."""
    _models(tmp_path)
    _log(tmp_path, "inbound", -200.0, 50.0, step=(25.0, 0.0))
    path = _scenario(tmp_path, LOG_SEGMENT.format(name="inbound").replace("60.0", "90.0"))
    # scans at x -200, -175, ..., -25: eight short of the scene's -0.5; the last over its target
    assert _validate(path, capsys) == [
        "note       8 of the 11 scans do not look at the scene: 8 of segment 1 (log)"
    ]


def test_the_bundled_body_fixed_orbit_is_said_to_look_away_from_the_scene():
    """realism.toml's orbit banks its body-fixed sensor out of the circle (its comment
    says so; a run shows 0 % after each of its 12 scans), over the generated small
    forest's box (240 x 240 x 73 voxels of 0.25 m, its vehicle at the middle)."""
    from pathlib import Path

    from ladartui.scenario import load_scenario
    from ladartui.scene.model import Scene
    from ladartui.view_reach import reach_notes

    scenario = load_scenario(Path(__file__).parents[1] / "scenarios" / "realism.toml", check_files=False)
    target = [(112, 112, 0), (127, 127, 8)]
    scene = Scene([(0, 0, 0), (239, 239, 72), *target], target, 0.25)
    assert reach_notes(scenario, scene) == [
        "12 of the 19 scans do not look at the scene: all 12 of segment 1 (orbit)"
    ]
    stabilised = scenario.with_changes(sensor=dataclasses.replace(scenario.sensor, mount="stabilised"))
    assert reach_notes(stabilised, scene) == []


def test_without_partial_misses_only_the_notes_of_nothing_seen_are_given(tmp_path):
    """The app's status bar warns of scans that see nothing of the scene or a target, not
    of a path some of whose scans look elsewhere (lead-ins, turns)."""
    from ladartui.scenario import load_scenario
    from ladartui.view_reach import reach_notes

    _models(tmp_path)
    _log(tmp_path, "inbound", -200.0, 50.0, step=(25.0, 0.0))
    path = _scenario(tmp_path, LOG_SEGMENT.format(name="inbound").replace("60.0", "90.0"))
    scenario = load_scenario(path)
    scene = scenario.load_scene()
    assert reach_notes(scenario, scene) == [
        "8 of the 11 scans do not look at the scene: 8 of segment 1 (log)"
    ]
    assert reach_notes(scenario, scene, partial=False) == []
    _log(tmp_path, "far", 5000.0, 50.0)
    far = load_scenario(_scenario(tmp_path, LOG_SEGMENT.format(name="far"), "far.toml"))
    assert reach_notes(far, scene, partial=False) == reach_notes(far, scene)
    assert reach_notes(far, scene)[0].startswith("none of the 11 scans looks at the scene")
