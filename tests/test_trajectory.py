import numpy as np
import pytest

from ladartui.flight import ScanPose, straight
from ladartui.trajectory import TrajectoryError, load_flight_log, log_attitude, log_poses


def test_straight_log_reproduces_straight_poses(tmp_path):
    start = ScanPose(10.0, 20.0, 60.0, heading=30.0, depression=45.0)
    poses = straight(start, 120.0, 4)
    path = tmp_path / "log.csv"
    lines = ["time,x,y,z,heading", f"0,{start.x},{start.y},{start.z},{start.heading}"]
    lines += [f"{k + 1},{p.x!r},{p.y!r},{p.z!r},{p.heading!r}" for k, p in enumerate(poses)]
    path.write_text("\n".join(lines) + "\n")
    got = log_poses(load_flight_log(path), start, times=[1, 2, 3, 4])
    for a, b in zip(got, poses):
        assert (a.x, a.y, a.z, a.heading, a.depression) == pytest.approx((b.x, b.y, b.z, b.heading, b.depression))
    # At 2 Hz a scan falls halfway between records.
    half = log_poses(load_flight_log(path), start, rate=2.0)
    assert len(half) == 9 and half[1].x == pytest.approx((start.x + poses[0].x) / 2)


def test_headings_and_roll_interpolate_along_the_shortest_arc(tmp_path):
    path = tmp_path / "log.csv"
    path.write_text("time,x,y,z,heading,roll\n0,0,0,50,350,-10\n1,10,0,50,10,10\n")
    log = load_flight_log(path)
    assert log_poses(log, ScanPose(0, 0, 50), times=[0.5])[0].heading == pytest.approx(0.0)
    roll, pitch = log_attitude(log, [0.5])
    assert roll[0] == pytest.approx(0.0) and pitch[0] == 0.0


@pytest.mark.parametrize("text, where, what", [
    ("time,x,y,z\n0,0,0,50\n", ":1:", "header lacks heading"),
    ("time,x,y,z,heading\n0,0,0,50,0\n1,0,abc,50,0\n", ":3:", "y = 'abc': expected a number"),
    ("time,x,y,z,heading\n0,0,0,50,0\n0,0,1,50,0\n", ":3:", "expected times increasing"),
    ("time,x,y,z,heading\n0,0,0,50,0\n1,0,1,50\n", ":3:", "4 fields, expected 5"),
    ("time,x,y,z,heading\n0,0,0,50,0\n1,0,1,-5,0\n", ":3:", "z = -5.0: expected > 0"),
])
def test_malformed_lines_name_file_and_line(tmp_path, text, where, what):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(TrajectoryError) as error:
        load_flight_log(path)
    assert f"{path}{where}" in str(error.value) and what in str(error.value)


def test_example_log_loads():
    from pathlib import Path
    log = load_flight_log(Path(__file__).parents[1] / "scenarios" / "flight-log.csv")
    poses = log_poses(log, ScanPose(0, 0, 60, depression=60.0), rate=2.0)
    assert len(poses) == 7 and np.isclose(poses[-1].x, 110.0)
