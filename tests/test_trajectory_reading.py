"""Reading flight logs as analysts' tools write them: long logs, and the spellings of a
record that the csv module reads."""

import numpy as np
import pytest

from ladartui.trajectory import load_flight_log


def test_a_clean_log_is_read_at_once_and_to_the_same_numbers(tmp_path, monkeypatch):
    """A million records (an hour's INS log at 300 Hz) took 20 s to read, each value
    checked in turn, before validate or the editor showed anything. Plain records are
    read in one pass, to the very numbers the record-by-record reading gives."""
    from ladartui import trajectory

    rng = np.random.default_rng(7)
    count = 20_000
    columns = [np.cumsum(rng.uniform(0.001, 0.01, count)), rng.normal(0, 500, count)]
    columns += [rng.normal(0, 500, count), rng.uniform(1, 900, count), rng.uniform(-360, 360, count)]
    columns += [rng.uniform(-60, 60, count), rng.uniform(-30, 30, count)]
    records = [",".join(map(repr, record)) for record in zip(*(c.tolist() for c in columns))]
    clean, quoted = tmp_path / "clean.csv", tmp_path / "quoted.csv"
    clean.write_text("time,x,y,z,heading,roll,pitch\n" + "\n".join(records) + "\n")
    first = records[0].split(",")
    records[0] = ",".join([*first[:4], f'"{first[4]}"', *first[5:]])  # csv reading only
    quoted.write_text("time,x,y,z,heading,roll,pitch\n" + "\n".join(records) + "\n")
    one_by_one = trajectory._parsed_records
    calls = []
    monkeypatch.setattr(trajectory, "_parsed_records", lambda *args: calls.append(1) or one_by_one(*args))
    at_once = load_flight_log(clean)
    assert not calls  # a clean log is not read record by record
    checked = load_flight_log(quoted)
    assert calls == [1]
    for log in (at_once, checked):  # to the last bit: both read the same text
        got = [log.time, *log.xyz.T, log.heading, log.roll, log.pitch]
        assert [g.tolist() for g in got] == [c.tolist() for c in columns]


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
