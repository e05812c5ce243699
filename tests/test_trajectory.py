import re
from pathlib import Path

import numpy as np
import pytest

from ladartui.errors import FieldError, LadarError
from ladartui.flight import ScanPose, straight
from ladartui.trajectory import TrajectoryError, load_flight_log, log_attitude, log_poses

EXAMPLE_LOG = Path(__file__).parent.parent / "scenarios" / "flight-log.csv"


def test_a_log_path_that_is_no_path_is_a_field_error():
    # It raised TypeError from pathlib.
    with pytest.raises(FieldError) as caught:
        load_flight_log(None)
    assert (
        str(caught.value) == "path is not set: expected a flight log file's path (CSV) (str or pathlib.Path)"
    )


def test_straight_log_reproduces_straight_poses(tmp_path):
    start = ScanPose(10.0, 20.0, 60.0, heading=30.0, depression=45.0)
    poses = straight(start, 120.0, 4)
    path = tmp_path / "log.csv"
    lines = ["time,x,y,z,heading", f"0,{start.x},{start.y},{start.z},{start.heading}"]
    lines += [f"{k + 1},{p.x!r},{p.y!r},{p.z!r},{p.heading!r}" for k, p in enumerate(poses)]
    path.write_text("\n".join(lines) + "\n")
    got = log_poses(load_flight_log(path), start, times=[1, 2, 3, 4])
    for a, b in zip(got, poses):
        assert (a.x, a.y, a.z, a.heading, a.depression) == pytest.approx(
            (b.x, b.y, b.z, b.heading, b.depression)
        )
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


def test_roll_across_180_degrees_comes_back_between_minus_180_and_180(tmp_path):
    """Interpolated along the shortest arc, 170 to -170 degrees gave 185 at three
    quarters of the way: the same rotation, but not how a roll is written."""
    path = tmp_path / "log.csv"
    path.write_text("time,x,y,z,heading,roll,pitch\n0,0,0,50,0,170,-100\n1,10,0,50,0,-170,100\n")
    roll, pitch = log_attitude(load_flight_log(path), [0.0, 0.75, 1.0])
    assert roll.tolist() == pytest.approx([170.0, -175.0, -170.0])
    assert pitch.tolist() == pytest.approx([-100.0, 140.0, 100.0])  # -100 down through -180 to 100


@pytest.mark.parametrize(
    "text, where, what",
    [
        ("time,x,y,z\n0,0,0,50\n", ":1:", "header 'time,x,y,z' lacks heading"),
        ("time,x,y,z,heading\n0,0,0,50,0\n1,0,abc,50,0\n", ":3:", "y = 'abc': expected a number"),
        ("time,x,y,z,heading\n0,0,0,50,0\n0,0,1,50,0\n", ":3:", "expected times increasing"),
        ("time,x,y,z,heading\n0,0,0,50,0\n1,0,1,50\n", ":3:", "4 fields, expected 5"),
        ("time,x,y,z,heading\n0,0,0,50,0\n1,0,1,-5,0\n", ":3:", "z = -5.0: expected > 0"),
    ],
)
def test_malformed_lines_name_file_and_line(tmp_path, text, where, what):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(TrajectoryError) as error:
        load_flight_log(path)
    assert f"{path}{where}" in str(error.value) and what in str(error.value)


@pytest.mark.parametrize("separator", [";", "\t"])
def test_a_log_of_another_separator_is_told_so_not_that_its_header_lacks_every_column(tmp_path, separator):
    """A spreadsheet's semicolon CSV (or a tab-separated export) was refused with 'header
    lacks time, x, y, z, heading', a header that plainly names them."""
    path = tmp_path / "log.csv"
    header = separator.join(["time", "x", "y", "z", "heading"])
    path.write_text(f"{header}\n" + separator.join("00060") + "\n")
    with pytest.raises(TrajectoryError) as caught:
        load_flight_log(path)
    assert str(caught.value) == (
        f"{path}:1: header {header!r} is one column, separated by {separator!r}: expected columns "
        "separated by commas: time, x, y, z, heading, or time, latitude, longitude, altitude, "
        "heading (optional roll, pitch)"
    )


@pytest.mark.parametrize(
    "header, lacks",
    [
        ("time,latitude,longitude,alt,heading", "altitude"),
        ("time,latitude,longitude,altitude", "heading"),
        ("time,lat,longitude,altitude,heading", "latitude"),
    ],
)
def test_a_log_in_latitude_and_longitude_lacking_one_of_them_is_told_which(tmp_path, header, lacks):
    """A latitude and longitude log whose height was headed 'alt' was said to lack x, y
    and z, columns it was never meant to have, and not the altitude it lacked."""
    path = tmp_path / "log.csv"
    path.write_text(f"{header}\n0,51,0,60,90\n1,51.0001,0,60,90\n")
    with pytest.raises(TrajectoryError) as caught:
        load_flight_log(path, origin=(51.0, 0.0, 0.0))
    assert str(caught.value).startswith(f"{path}:1: header {header!r} lacks {lacks}: expected columns ")


def test_example_log_loads():
    from pathlib import Path

    log = load_flight_log(Path(__file__).parents[1] / "scenarios" / "flight-log.csv")
    poses = log_poses(log, ScanPose(0, 0, 60, depression=60.0), rate=2.0)
    assert len(poses) == 7 and np.isclose(poses[-1].x, 110.0)


def test_geodetic_to_local_matches_known_lengths_on_the_wgs84_ellipsoid():
    from ladartui.trajectory import geodetic_to_local

    # a thousandth of a degree of longitude on the equator: 111.319 m east (a / 1000 * pi/180)
    east = geodetic_to_local([0.0], [0.001], [0.0], (0.0, 0.0, 0.0))[0]
    assert east[0] == pytest.approx(6378137.0 * np.radians(0.001), rel=1e-9)
    assert abs(east[1]) < 1e-9 and east[2] == pytest.approx(0.0, abs=1e-3)
    # straight up from the origin is up, anywhere
    up = geodetic_to_local([52.1], [-1.3], [180.0], (52.1, -1.3, 80.0))[0]
    assert up == pytest.approx([0.0, 0.0, 100.0], abs=1e-6)
    # north along a meridian: a thousandth of a degree at 45 deg is about 111.13 m
    north = geodetic_to_local([45.001], [7.0], [0.0], (45.0, 7.0, 0.0))[0]
    assert north[1] == pytest.approx(111.13, abs=0.01) and abs(north[0]) < 1e-9


def test_a_log_in_latitude_and_longitude_flies_the_same_poses_as_its_local_copy(tmp_path):
    from ladartui.trajectory import LogSegment, geodetic_to_local

    origin = (-35.28, 149.13, 560.0)
    lat = np.array([-35.2805, -35.2800, -35.2795])
    lon = np.array([149.1290, 149.1300, 149.1310])
    alt = np.array([660.0, 661.0, 662.0])
    geo = tmp_path / "geo.csv"
    geo.write_text(
        "time,latitude,longitude,altitude,heading\n"
        + "".join(f"{t},{a},{o},{h},45\n" for t, a, o, h in zip((0, 1, 2), lat, lon, alt))
    )
    local = geodetic_to_local(lat, lon, alt, origin)
    xyz = tmp_path / "xyz.csv"
    xyz.write_text(
        "time,x,y,z,heading\n"
        + "".join(
            f"{t},{float(x)!r},{float(y)!r},{float(z)!r},45\n" for t, (x, y, z) in zip((0, 1, 2), local)
        )
    )
    from_geo = LogSegment(str(geo), rate=2.0, origin=list(origin)).build(None)
    from_xyz = LogSegment(str(xyz), rate=2.0).build(None)
    assert [p.position for p in from_geo] == pytest.approx([p.position for p in from_xyz])
    assert local[1] == pytest.approx([0.0, 0.0, 101.0], abs=1e-6)  # over the origin
    assert 90.0 < local[2, 0] < 92.0 and 55.0 < local[2, 1] < 56.0  # 0.001 deg E, 0.0005 deg N
    with pytest.raises(LadarError, match="origin"):
        LogSegment(str(geo), rate=2.0)  # a geodetic log without its origin
    with pytest.raises(FieldError, match=r"origin\[0\] = 95.0: expected a latitude from -90 to 90"):
        LogSegment(str(geo), rate=2.0, origin=[95.0, 0.0, 0.0])


def test_an_origin_for_a_log_in_scene_metres_is_refused(tmp_path):
    """origin = [lat, lon, alt] beside an x,y,z log was taken and ignored without a word."""
    from pathlib import Path

    from ladartui.scenario import load_scenario
    from ladartui.trajectory import LogSegment

    log = Path(__file__).parent.parent / "scenarios" / "flight-log.csv"
    with pytest.raises(FieldError) as caught:
        LogSegment(str(log), rate=2.0, origin=[51.0, -1.0, 0.0])
    assert str(caught.value) == (
        f"origin = (51.0, -1.0, 0.0): expected none: {log.name} is in scene metres (x, y, z); "
        "an origin places a log in latitude and longitude"
    )
    path = tmp_path / "s.toml"
    path.write_text(
        '[files]\nscene = "s.txt"\n[[flight.segments]]\nkind = "log"\n'
        f'file = "{log}"\nrate = 2.0\norigin = [51.0, -1.0, 0.0]\n'
    )
    with pytest.raises(FieldError, match=r"s\.toml:7: flight\.segments\[0\]\.origin = "):
        load_scenario(path, check_files=False)


def test_scan_times_out_of_order_are_refused(tmp_path):
    """times = [0.9, 0.1, 0.5] was taken: the aircraft flew backwards along its log."""
    from pathlib import Path

    from ladartui.trajectory import LogSegment

    log = Path(__file__).parent.parent / "scenarios" / "flight-log.csv"
    assert LogSegment(str(log), times=[0.1, 0.5, 0.9]).times == (0.1, 0.5, 0.9)
    with pytest.raises(FieldError, match=r"times .*expected .*increasing"):
        LogSegment(str(log), times=[0.9, 0.1, 0.5])


def test_a_log_saved_with_a_byte_order_mark_is_read(tmp_path):
    """Excel writes CSV with a BOM: it read as 'header lacks time'."""
    path = tmp_path / "log.csv"
    path.write_bytes(b"\xef\xbb\xbftime,x,y,z,heading\n0,20,64,60,90\n1,50,64,60,90\n")
    assert list(load_flight_log(path).time) == [0.0, 1.0]


def test_a_log_that_is_not_utf8_is_named_on_its_line(tmp_path):
    """It said "cannot read flight log ('utf-8' codec can't decode byte 0xff in position 48:
    invalid start byte)": no line, and Python's words for what was expected."""
    path = tmp_path / "log.csv"
    path.write_bytes(b"time,x,y,z,heading\n0,20,64,60,90\n1,50,64,\xb060,90\n")
    with pytest.raises(TrajectoryError) as caught:
        load_flight_log(path)
    assert str(caught.value) == f"{path}:3: not UTF-8 text (byte 0xb0); expected a flight log (CSV)"


@pytest.mark.parametrize(
    ("origin", "found"),
    [("[95.0, 0.0, 0.0]", "origin[0] = 95.0"), ("[0.0, 200.0, 0.0]", "origin[1] = 200.0")],
)
def test_a_bad_origin_in_a_scenario_is_named_on_its_line(tmp_path, origin, found):
    """The error named 'origin latitude' on the segment's [[flight.segments]] line."""
    from ladartui.scenario import load_scenario

    geo = tmp_path / "geo.csv"
    geo.write_text(
        "time,latitude,longitude,altitude,heading\n0,-35.28,149.13,660,45\n1,-35.27,149.13,660,45\n"
    )
    (tmp_path / "s.txt").write_text("0,0,0\n")
    path = tmp_path / "s.toml"
    path.write_text(
        '[files]\nscene = "s.txt"\nvoxel_size = 1.0\n\n[flight]\n[[flight.segments]]\n'
        f'kind = "log"\nfile = "geo.csv"\nrate = 1.0\norigin = {origin}\n'
    )
    with pytest.raises(FieldError) as caught:
        load_scenario(path)
    message = str(caught.value)
    assert message.startswith(f"{path}:10: flight.segments[0].{found}: expected ")
    assert ("latitude" if "[0]" in found else "longitude") in message


@pytest.mark.parametrize(
    ("header", "record", "said"),
    [
        ("time,x,y,z,heading,x", "1,0,0,60,0,5", "log.csv:1: header names x twice (columns 2 and 6)"),
        ("time,x,y,z,heading", "1,1e300,0,60,0", "log.csv:3: x = '1e300': expected a coordinate within"),
        (
            "time,latitude,longitude,altitude,heading",
            "1,-35.28,1000,660,0",
            "log.csv:3: longitude = 1000.0: expected -180..180",
        ),
        ("time,x,y,z,heading", "1,0,0,150000,0", "log.csv:3: z = '150000': expected at most 100000 m"),
        (
            "time,latitude,longitude,altitude,heading",
            "1,-25.28,149.13,660,0",
            "log.csv:3: latitude = -25.28, longitude = 149.13 put the aircraft 0 km east and "
            "1103 km north of the origin: expected within 1000 km of it each way",
        ),
        (
            "time,latitude,longitude,altitude,heading",
            "1,-35.28,149.13,200000,0",
            "log.csv:3: altitude = 200000.0 puts the aircraft 199440.0 m above the origin: "
            "expected at most 100000 m above it",
        ),
        # times whose span passes the float range ended in OverflowError at the scan count
        (
            "time,x,y,z,heading",
            "1.7e308,0,0,60,0",
            "log.csv:3: time = '1.7e308': expected seconds within +-1e+15",
        ),
        # angles past any a log holds were taken (a body-fixed sensor turned by them)
        (
            "time,x,y,z,heading",
            "1,0,0,60,1e20",
            "log.csv:3: heading = '1e20': expected degrees within +-36000",
        ),
        (
            "time,x,y,z,heading,roll",
            "1,0,0,60,0,1e6",
            "log.csv:3: roll = '1e6': expected degrees within +-360",
        ),
        (
            "time,x,y,z,heading,pitch",
            "1,0,0,60,0,-400",
            "log.csv:3: pitch = '-400': expected degrees within +-360",
        ),
    ],
)
def test_a_bad_log_column_or_value_is_named_in_the_log(tmp_path, header, record, said):
    """A repeated column was taken without a word, 1e300 was blamed on the scenario's
    flight.segments[0].x, a longitude of 1000 was taken (and np.float64 reached a message);
    a z of 150 km, and a point 1,100 km from a geodetic log's origin or 200 km above it,
    were still blamed on the scenario's segment, not the log's line."""
    from ladartui.trajectory import TrajectoryError

    path = tmp_path / "log.csv"
    first = "0," + ",".join(
        ["-35.28", "149.13", "660", "0"] if "latitude" in header else ["0", "0", "60", "0"]
    )
    if header.endswith(",x"):
        first += ",5"
    elif header.endswith(("roll", "pitch")):
        first += ",0"
    path.write_text(f"{header}\n{first}\n{record}\n")
    with pytest.raises(TrajectoryError) as caught:
        load_flight_log(path, origin=(-35.28, 149.13, 560.0) if "latitude" in header else None)
    assert str(caught.value).startswith(f"{path.parent}/{said}")


def test_a_missing_log_is_named_on_its_scenario_line(tmp_path):
    from ladartui.scenario import load_scenario

    (tmp_path / "s.txt").write_text("0,0,0\n")
    path = tmp_path / "s.toml"
    path.write_text(
        '[files]\nscene = "s.txt"\nvoxel_size = 1.0\n\n[flight]\n[[flight.segments]]\n'
        'kind = "log"\nfile = "nope.csv"\nrate = 1.0\n'
    )
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    assert str(caught.value).startswith(
        f"{path}:8: flight.segments[0].file = 'nope.csv': expected a flight log"
    )


def test_scans_at_a_rate_end_on_the_last_record_when_its_time_rounds_short(tmp_path):
    """A log from 0.1 to 0.3 s at 5 Hz: 0.1 + 1/5 is 0.30000000000000004 in floating
    point, a rounding step past the log's last time, and the log was refused."""
    from ladartui.trajectory import LogSegment

    path = tmp_path / "log.csv"
    path.write_text("time,x,y,z,heading\n0.1,0,0,50,90\n0.3,10,0,50,90\n")
    poses = log_poses(load_flight_log(path), ScanPose(0, 0, 50), rate=5.0)
    assert [p.x for p in poses] == pytest.approx([0.0, 10.0])
    segment = LogSegment(str(path), rate=5.0)
    assert list(segment.scan_times()) == [0.1, 0.3]
    assert [p.x for p in segment.build(None)] == pytest.approx([0.0, 10.0])
    assert len(segment.attitudes()) == 2


def test_a_rate_giving_the_most_scans_allowed_is_taken(tmp_path):
    """999.95 s at 10 Hz is 10,000 scans (0 .. 999.9 s), the limit, yet the check
    counted span x rate + 1 = 10,000.5 of them and refused the rate."""
    from ladartui.flight import MAX_SCANS
    from ladartui.trajectory import LogSegment

    path = tmp_path / "log.csv"
    path.write_text("time,x,y,z,heading\n0,0,0,50,90\n999.95,9999.5,0,50,90\n")
    assert len(LogSegment(str(path), rate=10.0).scan_times()) == MAX_SCANS == 10_000
    path.write_text("time,x,y,z,heading\n0,0,0,50,90\n1000,10000,0,50,90\n")
    with pytest.raises(FieldError, match="at most 10000 scans over the log"):
        LogSegment(str(path), rate=10.0)


def test_a_log_keeps_its_own_clock_for_scan_times_and_flight_time(tmp_path):
    """A log spanning 3 s at 30 m/s flew 90 m; the plan said 9 s (90 m at the scenario's
    10 m/s), and the levels' times came from the same division."""
    from ladartui.flight import FlightPlan, Straight
    from ladartui.trajectory import LogSegment

    path = tmp_path / "log.csv"
    path.write_text("time,x,y,z,heading\n" + "".join(f"{t},{30 * t},0,60,90\n" for t in range(4)))
    log = LogSegment(str(path), rate=2.0)
    plan = FlightPlan(segments=(log,))
    assert plan.scan_times(10.0) == pytest.approx([0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0])
    assert plan.flight_time(10.0) == pytest.approx(3.0) and plan.path_length() == pytest.approx(90.0)
    # a straight after it flies at the plan's speed, from the log's last scan
    both = FlightPlan(segments=(log, Straight(distance=50.0, scans=2)))
    assert both.scan_times(10.0)[-3:] == pytest.approx([3.0, 5.5, 8.0])
    assert both.flight_time(10.0) == pytest.approx(8.0)


def test_a_run_whose_output_would_replace_its_flight_log_is_refused(tmp_path, capsys):
    """A log named lg.cmf beside lg.toml was replaced by the run's measures, and the
    next run failed on it; the models were already spared, the log was not."""
    from ladartui.cli import main
    from ladartui.scene.voxels import save_voxels

    target = np.array([(x, y, 0) for x in range(4) for y in range(4)], np.int32)
    save_voxels(tmp_path / "woods.txt", target)
    save_voxels(tmp_path / "woods_Target.txt", target)
    log_text = "time,x,y,z,heading\n" + "".join(f"{t},{t},2,30,90\n" for t in range(3))
    (tmp_path / "lg.cmf").write_text(log_text)
    scenario = tmp_path / "lg.toml"
    scenario.write_text(
        '[files]\nscene = "woods.txt"\nvoxel_size = 1.0\n[sensor]\ngrid = 4\nray_grid = 1\n'
        '[[flight.segments]]\nkind = "log"\nfile = "lg.cmf"\nrate = 1.0\n'
    )
    assert main(["run", str(scenario)]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith(f"ladartui: error: {scenario}:9: flight.segments[0].file = 'lg.cmf'")
    assert "would overwrite the flight log" in err
    assert (tmp_path / "lg.cmf").read_text() == log_text and not (tmp_path / "lg_Scene.txt").exists()
    # the same file reached through a link is the same file
    (tmp_path / "lg.cmf").rename(tmp_path / "kept.cmf")
    (tmp_path / "link.csv").symlink_to("lg.cmf")
    (tmp_path / "kept.cmf").rename(tmp_path / "lg.cmf")
    scenario.write_text(scenario.read_text().replace('file = "lg.cmf"', 'file = "link.csv"'))
    assert main(["run", str(scenario)]) == 2
    assert "would overwrite the flight log" in capsys.readouterr().err
    assert (tmp_path / "lg.cmf").read_text() == log_text


def test_a_sweep_over_speed_of_a_flight_log_alone_is_refused(tmp_path, capsys):
    """Three speeds over a log's own clock gave three identical rows, all on the front."""
    from ladartui.cli import main
    from ladartui.scene.voxels import save_voxels

    target = np.array([(x, y, 0) for x in range(4) for y in range(4)], np.int32)
    save_voxels(tmp_path / "woods.txt", target)
    save_voxels(tmp_path / "woods_Target.txt", target)
    (tmp_path / "log.csv").write_text(
        "time,x,y,z,heading\n" + "".join(f"{t},{t},2,30,90\n" for t in range(3))
    )
    (tmp_path / "lg.toml").write_text(
        '[files]\nscene = "woods.txt"\nvoxel_size = 1.0\n[sensor]\ngrid = 4\nray_grid = 1\n'
        '[[flight.segments]]\nkind = "log"\nfile = "log.csv"\nrate = 1.0\n'
    )
    spec = tmp_path / "sl.toml"
    spec.write_text('[sweep]\nscenario = "lg.toml"\n[grid]\nspeed = [10.0, 30.0]\n')
    assert main(["sweep", str(spec), "--serial"]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert f"{spec}:4: grid.speed: no variant can run" in err and "keeps the log's own clock" in err


@pytest.mark.parametrize("mark", ["\u2028", "\x85", "\x0c"])
def test_a_line_separator_inside_a_comment_keeps_the_log_s_line_numbers(tmp_path, mark):
    """A comment holding a line separator (or a form feed) was counted as two lines,
    so a bad record below it was named on the line after its own."""
    path = tmp_path / "log.csv"
    path.write_text(f"# pass 2{mark} east\ntime,x,y,z,heading\n0,0,0,60,0\n1,0,abc,60,0\n", encoding="utf-8")
    with pytest.raises(TrajectoryError) as caught:
        load_flight_log(path)
    assert str(caught.value) == f"{path}:4: y = 'abc': expected a number"


@pytest.mark.parametrize("end", ["\r", "\r\n", "\n"])
def test_bytes_that_are_not_utf8_are_named_on_the_line_a_bad_number_would_be(tmp_path, end):
    """In a log whose lines end in CR alone, a bad number on line 3 was named at :3: but
    a byte that is not UTF-8 on line 3 at :1: (only LF was counted for it)."""
    path = tmp_path / "log.csv"
    lines = ["time,x,y,z,heading", "0,0,0,60,0", "1,0,abc,60,0"]
    path.write_bytes(end.join(lines).encode() + end.encode())
    with pytest.raises(TrajectoryError, match=rf"^{re.escape(str(path))}:3: y = 'abc'"):
        load_flight_log(path)
    path.write_bytes(end.join(lines).replace("abc", "a\xffc").encode("latin-1") + end.encode())
    with pytest.raises(TrajectoryError, match=rf"^{re.escape(str(path))}:3: not UTF-8 text \(byte 0xff\)"):
        load_flight_log(path)


def _log_scenario(tmp_path, pointing):
    (tmp_path / "log.csv").write_text("time,x,y,z,heading\n0,0,0,60,0\n1,10,0,60,0\n")
    (tmp_path / "s.txt").write_text("0,0,0\n")
    path = tmp_path / "s.toml"
    path.write_text(
        '[files]\nscene = "s.txt"\nvoxel_size = 1.0\n\n[flight]\n[[flight.segments]]\n'
        f'kind = "log"\nfile = "log.csv"\nrate = 1.0\naim_at = [5.0, 20.0, 0.0]\n{pointing}'
    )
    return path


def test_a_log_s_sensor_pointing_beside_an_aim_point_is_refused_not_dropped(tmp_path):
    """The aim point set both angles, so a pointing written beside it was dropped without a word."""
    from ladartui.scenario import load_scenario

    path = _log_scenario(tmp_path, "depression = 30.0\n")
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    assert str(caught.value).startswith(f"{path}:10: flight.segments[0].aim_at = [5.0, 20.0, 0.0]: expected ")
    assert "no aim point while depression is given" in str(caught.value)


def test_a_log_written_with_the_default_pointing_beside_its_aim_point_still_reads(tmp_path):
    """Earlier versions wrote azimuth 0 and depression 90 with every log segment, aimed or not;
    those files read as before, and a new file is written without the pointing the aim sets."""
    from ladartui.scenario import load_scenario

    scenario = load_scenario(_log_scenario(tmp_path, "azimuth = 0.0\ndepression = 90.0\n"), check_files=False)
    segment = scenario.flight.segments[0]
    assert (segment.azimuth, segment.depression) == (None, None)
    poses = scenario.poses()
    assert all(p.depression < 90.0 for p in poses)  # aimed, not straight down
    again = tmp_path / "again.toml"
    again.write_text(scenario.to_toml())
    text = again.read_text()
    assert "aim_at" in text and "depression" not in text and "azimuth" not in text
    assert [p.to_dict() for p in load_scenario(again, check_files=False).poses()] == [
        p.to_dict() for p in poses
    ]


def test_a_log_without_an_aim_point_keeps_its_pointing_and_its_defaults(tmp_path):
    from ladartui.flight import ScanPose
    from ladartui.trajectory import LogSegment

    (tmp_path / "log.csv").write_text("time,x,y,z,heading\n0,0,0,60,0\n1,10,0,60,0\n")
    plain = LogSegment(str(tmp_path / "log.csv"), rate=1.0).build(None)
    assert [(p.azimuth, p.depression) for p in plain] == [(0.0, 90.0)] * 2
    tilted = LogSegment(str(tmp_path / "log.csv"), rate=1.0, azimuth=30.0, depression=45.0).build(None)
    assert [(p.azimuth, p.depression) for p in tilted] == [(30.0, 45.0)] * 2
    assert isinstance(tilted[0], ScanPose)


@pytest.mark.parametrize(
    "arguments, said",
    [
        # It flew NaN as the scan's x and blamed 'x', a name the caller never gave.
        ({"times": [float("nan")]}, "times = [nan]: expected a list of 1 to 10000 times from 0 to 3 s"),
        ({"times": ["a"]}, "times = ['a']: expected a list of 1 to 10000 times from 0 to 3 s"),
        ({"times": [2.0, 1.0]}, "times = [2.0, 1.0]: expected a list of 1 to 10000 times from 0 to 3 s"),
        ({"times": []}, "times = []: expected a list of 1 to 10000 times from 0 to 3 s"),
        # Both were taken, the rate dropped without a word.
        ({"rate": 2.0, "times": [0.5]}, "rate = 2.0: expected either a scan rate (Hz) or a list of scan"),
        # TypeError from the comparison.
        ({"rate": "a"}, "rate = 'a': expected a number greater than 0 and at most 1000"),
        ({}, "rate is not set: expected either a scan rate (Hz) or a list of scan times (s)"),
    ],
)
def test_scan_times_or_rate_given_to_log_poses_are_checked_and_named(arguments, said):
    log = load_flight_log(EXAMPLE_LOG)
    with pytest.raises(FieldError) as caught:
        log_poses(log, ScanPose(0, 0, 60), **arguments)
    assert str(caught.value).startswith(said)


def test_log_poses_without_a_scan_pose_template_names_it():
    # It raised TypeError from dataclasses.replace.
    with pytest.raises(FieldError, match=r"^template is not set: expected a ScanPose$"):
        log_poses(load_flight_log(EXAMPLE_LOG), None, rate=2.0)


def test_the_span_of_a_log_in_gps_seconds_is_written_to_the_decimal_its_records_have(tmp_path):
    """A log timed in GPS seconds was said to span 'from 1.4e+09 to 1.4e+09 s': the
    times a user had to write were not in the message."""
    path = tmp_path / "log.csv"
    path.write_text("time,x,y,z,heading\n1400000000.5,0,0,60,0\n1400000010.25,10,0,60,0\n")
    with pytest.raises(FieldError) as caught:
        log_poses(load_flight_log(path), ScanPose(0, 0, 60), times=[0.5])
    assert str(caught.value) == (
        "times = [0.5]: expected a list of 1 to 10000 times from 1400000000.5 to "
        "1400000010.25 s (the log's span)"
    )


@pytest.mark.parametrize(
    "header, column",
    [
        ("time (s),x (m),y (m),z (m),heading (deg)", "time (s)"),
        ("time,x,y,z,heading,roll [deg],pitch [deg]", "roll [deg]"),
        ("time,x,y,z,heading,roll_rad,pitch_rad", "roll_rad"),
    ],
)
def test_a_log_whose_columns_are_named_with_their_units_is_told_so(tmp_path, header, column):
    """A header 'time (s),x (m),...' was said to lack time, x, y, z and heading; a roll
    headed 'roll [deg]' was left out without a word and the log flown wings level."""
    path = tmp_path / "log.csv"
    path.write_text(f"{header}\n0,0,0,60,0,5,1\n1,1,0,60,0,5,1\n")
    with pytest.raises(TrajectoryError) as caught:
        load_flight_log(path)
    assert str(caught.value) == (
        f"{path}:1: header column {column!r} is named with a unit: expected the names alone, "
        "time, x, y, z, heading, or time, latitude, longitude, altitude, heading (optional roll, "
        "pitch), in seconds, metres and degrees"
    )
