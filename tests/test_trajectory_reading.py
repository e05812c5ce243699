"""Reading flight logs as analysts' tools write them: long logs, and the spellings of a
record that the csv module reads."""

import time

import numpy as np
import pytest

from ladartui.trajectory import load_flight_log


def test_an_hour_of_a_300_hz_log_loads_in_seconds(tmp_path):
    """A million records (an hour's INS log at 300 Hz) took 20 s to read, each value
    checked in turn, before validate or the editor showed anything."""
    path = tmp_path / "log.csv"
    count = 1_000_000
    steps = np.arange(count)
    lines = [f"{k / 300:.4f},{k % 3000 * 0.01:.2f},30,60,90,1.5,-0.5" for k in steps.tolist()]
    path.write_text("time,x,y,z,heading,roll,pitch\n" + "\n".join(lines) + "\n")
    started = time.perf_counter()
    log = load_flight_log(path)
    assert time.perf_counter() - started < 5.0
    assert log.time.shape == (count,) and log.time[-1] == pytest.approx(999_999 / 300, abs=1e-4)
    assert log.xyz[-1].tolist() == [9.99, 30.0, 60.0] and set(log.roll) == {1.5}


@pytest.mark.parametrize(
    "header, record",
    [
        ("time,fix,x,y,z,heading", "{t},RTK,{x},0,60,90"),  # a column of words beside the numbers
        ("time,x,y,z,heading", '{t},"{x}",0,60,90'),  # quoted numbers
        ("time,x,y,z,heading", "{t},{x}_0,0,60,90"),  # what Python reads as a number
    ],
)
def test_logs_of_every_spelling_read_the_same_numbers(tmp_path, header, record):
    path = tmp_path / "log.csv"
    path.write_text(header + "\n" + "\n".join(record.format(t=t, x=2 * t) for t in range(4)) + "\n")
    log = load_flight_log(path)
    x = [20.0 * t for t in range(4)] if "_0" in record else [2.0 * t for t in range(4)]
    assert log.time.tolist() == [0.0, 1.0, 2.0, 3.0] and log.xyz[:, 0].tolist() == x


def test_a_rate_too_high_for_a_log_in_milliseconds_names_the_span_it_was_given(tmp_path):
    """A minute's log timed in milliseconds was refused 'expected at most 10000 scans over
    the log': nothing showed that the log's clock read 60,000 s."""
    from ladartui.errors import FieldError
    from ladartui.trajectory import LogSegment

    path = tmp_path / "log.csv"
    path.write_text("time,x,y,z,heading\n1700000000000,0,0,50,90\n1700000060000,1800,0,50,90\n")
    with pytest.raises(FieldError) as caught:
        LogSegment(str(path), rate=2.0)
    assert str(caught.value) == (
        "rate = 2.0: expected at most 10000 scans over the log, which spans 60000 s "
        "(from 1700000000000 to 1700000060000 s): 120,001 at this rate"
    )


@pytest.mark.parametrize("first", ["sep=,", "Logger v2.1 exported 2024-05-01"])
def test_a_log_whose_first_line_is_no_header_shows_the_line_it_took_for_one(tmp_path, first):
    """A log whose exporter wrote a line above the header was said to lack time, x, y, z
    and heading, with nothing of the line read as its header."""
    from ladartui.trajectory import TrajectoryError

    path = tmp_path / "log.csv"
    path.write_text(f"{first}\ntime,x,y,z,heading\n0,0,0,60,0\n1,1,0,60,0\n")
    with pytest.raises(TrajectoryError) as caught:
        load_flight_log(path)
    assert str(caught.value).startswith(
        f"{path}:1: header {first!r} lacks time, x, y, z, heading: expected columns time, x, y, z, "
    )
