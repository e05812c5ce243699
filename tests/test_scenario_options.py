"""Scenario options: the [detection] section, the sensor mount, recorded flight-log segments."""

import math
from pathlib import Path

import numpy as np
import pytest

from ladartui.attitude import body_rotation, coordinated_turn_roll, plan_attitudes
from ladartui.errors import LadarError
from ladartui.flight import ScanPose, straight
from ladartui.scenario import load_scenario, scenario_from_toml
from ladartui.trajectory import load_flight_log, log_poses

EXAMPLE_LOG = Path(__file__).resolve().parents[1] / "scenarios" / "flight-log.csv"

BASE = """\
[files]
scene = "s.txt"

[sensor]
grid = 8
ray_grid = 1
{sensor}
[flight]
speed_mps = 40.0

[[flight.segments]]
{segment}
{extra}"""

ORBIT = 'kind = "orbit"\ncentre = [0.0, 0.0]\nradius = 100.0\naltitude = 60.0\nscans = 4\n'


def _scenario(tmp_path, segment=ORBIT, sensor="", extra=""):
    path = tmp_path / "S.toml"
    path.write_text(BASE.format(sensor=sensor, segment=segment, extra=extra), encoding="utf-8")
    return load_scenario(path, check_files=False)


def _error(tmp_path, **parts):
    with pytest.raises(LadarError) as info:
        _scenario(tmp_path, **parts)
    message = str(info.value)
    assert "\n" not in message
    return message


def test_detection_section_reads_checks_and_saves(tmp_path):
    scenario = _scenario(
        tmp_path,
        extra='[detection]\nmodel = "geiger"\npulses = 50\ncoincidence = 5\nsolar_rate_hz = 2e6\nseed = 7\n',
    )
    d = scenario.detection
    assert scenario.geiger and (d.pulses, d.coincidence, d.solar_rate_hz, d.seed) == (50, 5, 2e6, 7)
    assert d.bin_width_m is None and d.bin_width(scenario.sensor.depth_resolution) == 1.0
    assert "detection  geiger, 50 pulses, k = 5" in scenario.summary()
    saved = scenario.save(tmp_path / "copy.toml")
    assert load_scenario(saved.path, check_files=False).detection == d
    text = saved.to_toml()
    assert "[detection]" in text and "bin_width_m" not in text  # unset keys stay unset


@pytest.mark.parametrize(
    "extra, expected",
    [
        (
            '[detection]\nmodel = "geiger"\npulses = 10\ncoincidence = 11\n',
            "S.toml:21: detection.coincidence = 11: expected an integer from 1 to 10",
        ),
        (
            '[detection]\nmodel = "photon"\n',
            "S.toml:19: detection.model = 'photon': expected one of 'ideal', 'geiger'",
        ),
        (
            "[detection]\nreflectance_target = 1.5\n",
            "S.toml:19: detection.reflectance_target = 1.5: expected a number from 0 to 1",
        ),
        (
            "[detection]\ndark_rate_hz = -1\n",
            "S.toml:19: detection.dark_rate_hz = -1: expected a number from 0 to 10000000000",
        ),
        ("[detection]\nn_pulses = 3\n", "S.toml:19: unknown key 'detection.n_pulses'"),
    ],
)
def test_detection_errors_name_field_value_and_range(tmp_path, extra, expected):
    assert expected in _error(tmp_path, extra=extra)


def test_zero_depth_resolution_needs_a_bin_width(tmp_path):
    message = _error(tmp_path, sensor="depth_resolution_m = 0.0\n", extra='[detection]\nmodel = "geiger"\n')
    assert "detection.bin_width_m" in message and "depth_resolution_m is 0" in message


def test_body_fixed_mount_banks_orbit_rays(tmp_path):
    stabilised = _scenario(tmp_path)
    assert plan_attitudes(stabilised.flight, stabilised.speed, stabilised.sensor) == [None] * 4
    body = _scenario(tmp_path, sensor='mount = "body-fixed"\n')
    assert 'mount = "body-fixed"' in body.to_toml() and "mount" not in stabilised.to_toml()
    attitudes = plan_attitudes(body.flight, body.speed, body.sensor)
    roll = math.degrees(math.atan(40.0**2 / (9.80665 * 100.0)))
    assert attitudes == [(pytest.approx(roll), 0.0)] * 4  # a right (clockwise) orbit rolls right
    pose = body.poses()[0]
    _, plain, _ = stabilised.sensor.rays(pose)
    _, banked, _ = body.sensor.rays(pose, attitude=attitudes[0])
    expected = plain @ body_rotation(pose.heading, *attitudes[0]).T
    np.testing.assert_allclose(banked, expected, atol=1e-12)
    # With no bank the body-fixed rays are the stabilised ones exactly, at any heading.
    for heading in (0.0, 33.0, 217.5):
        turned = ScanPose(pose.x, pose.y, pose.z, heading, pose.azimuth, pose.depression)
        _, level, _ = body.sensor.rays(turned, attitude=(0.0, 0.0))
        np.testing.assert_array_equal(level, stabilised.sensor.rays(turned)[1])


def test_body_fixed_roll_moves_nadir_footprint_by_h_tan_roll(tmp_path):
    body = _scenario(tmp_path, sensor='mount = "body-fixed"\n')
    pose = ScanPose(0.0, 0.0, 50.0, heading=0.0, depression=90.0)
    level = body.sensor.footprint(pose).mean(axis=0)
    rolled = body.sensor.footprint(pose, attitude=(30.0, 0.0)).mean(axis=0)
    # Right wing down: a nadir view swings to the left of track (west when flying north).
    centre, direction = body.sensor.central_ray(pose, attitude=(30.0, 0.0))
    hit = centre + direction * (50.0 / -direction[2])
    assert hit[0] == pytest.approx(-50.0 * math.tan(math.radians(30.0)))
    assert rolled[0] < level[0] - 25.0
    assert coordinated_turn_roll(40.0, 100.0) == pytest.approx(
        math.degrees(math.atan(1600 / (9.80665 * 100)))
    )


def test_log_segment_reads_the_log_and_saves_it_relative(tmp_path):
    (tmp_path / "logs").mkdir()
    (tmp_path / "logs" / "pass.csv").write_text(EXAMPLE_LOG.read_text(), encoding="utf-8")
    scenario = _scenario(
        tmp_path,
        segment='kind = "log"\nfile = "logs/pass.csv"\nrate = 2.0\ndepression = 60.0\n',
        sensor='mount = "body-fixed"\n',
    )
    log = load_flight_log(EXAMPLE_LOG)
    expected = log_poses(log, ScanPose(0.0, 0.0, 1.0, 0.0, 0.0, 60.0), rate=2.0)
    assert scenario.poses() == expected and len(expected) == 7
    attitudes = plan_attitudes(scenario.flight, scenario.speed, scenario.sensor)
    assert attitudes[2] == (pytest.approx(2.0), pytest.approx(0.5))  # the record at t = 1 s
    assert "log (7)" in scenario.summary()
    saved = scenario.save(tmp_path / "other" / "S2.toml")
    assert 'file = "../logs/pass.csv"' in saved.path.read_text()
    assert load_scenario(saved.path, check_files=False).poses() == expected


def test_straight_log_reproduces_straight_manoeuvre(tmp_path):
    (tmp_path / "line.csv").write_text("time,x,y,z,heading\n0,0,0,60,90\n4,120,0,60,90\n", encoding="utf-8")
    scenario = _scenario(tmp_path, segment='kind = "log"\nfile = "line.csv"\ntimes = [1.0, 2.0, 3.0, 4.0]\n')
    start = ScanPose(0.0, 0.0, 60.0, heading=90.0)
    for got, want in zip(scenario.poses(), straight(start, 120.0, 4), strict=True):
        assert got.position == pytest.approx(want.position) and got.heading == want.heading


def test_log_segment_errors(tmp_path):
    assert "flight.segments[0].times" in _error(
        tmp_path, segment=f'kind = "log"\nfile = "{EXAMPLE_LOG}"\ntimes = [9.0]\n'
    )
    assert "either a scan rate" in _error(tmp_path, segment=f'kind = "log"\nfile = "{EXAMPLE_LOG}"\n')
    (tmp_path / "bad.csv").write_text("time,x,y,z,heading\n0,0,0,60,0\n1,zz,0,60,0\n")
    assert _error(tmp_path, segment='kind = "log"\nfile = "bad.csv"\nrate = 1.0\n').endswith(
        "bad.csv:3: x = 'zz': expected a number"
    )
    assert _error(tmp_path, segment='kind = "log"\nfile = "missing.csv"\nrate = 1.0\n').endswith(
        "file = 'missing.csv': expected a flight log file (CSV): not found"
    )


def test_scenario_from_toml_without_options_has_none():
    scenario = scenario_from_toml(BASE.format(sensor="", segment=ORBIT, extra=""), "/tmp/x.toml")
    assert scenario.detection is None and scenario.sensor.mount == "stabilised"
    assert "detection" not in scenario.to_dict() and "mount" not in scenario.to_dict()["sensor"]


def test_scan_footprints_fall_with_attitude(tmp_path):
    from ladartui.attitude import scan_footprints

    stabilised = _scenario(tmp_path)
    plain = scan_footprints(stabilised)
    assert all(np.array_equal(f, stabilised.sensor.footprint(p)) for f, p in zip(plain, stabilised.poses()))
    banked = scan_footprints(_scenario(tmp_path, sensor='mount = "body-fixed"\n'))
    # A right orbit banks right: each footprint moves away from the centre, outwards.
    for before, after in zip(plain, banked):
        assert np.linalg.norm(after.mean(axis=0)[:2]) > np.linalg.norm(before.mean(axis=0)[:2]) + 5


def test_shipped_realism_example_loads_and_saves_unchanged(tmp_path):
    import shutil

    shipped = EXAMPLE_LOG.parent / "realism.toml"
    path = tmp_path / "realism.toml"
    shutil.copy(shipped, path)
    shutil.copy(EXAMPLE_LOG, tmp_path / "flight-log.csv")
    scenario = load_scenario(path, check_files=False)
    assert scenario.geiger and scenario.sensor.mount == "body-fixed"
    assert [s.kind for s in scenario.flight.segments] == ["orbit", "log"]
    assert len(scenario.poses()) == 12 + 7
    roll = plan_attitudes(scenario.flight, scenario.speed, scenario.sensor)[0][0]
    assert f"banks atan(v^2 / g r) = {roll:.1f} degrees" in shipped.read_text()
    before = path.read_bytes()
    scenario.save()
    assert path.read_bytes() == before
