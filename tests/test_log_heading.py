"""A flight log whose heading disagrees with its direction of travel is noted."""

import math

import pytest

from ladartui.trajectory import heading_note, load_flight_log


def _log(tmp_path, track_deg, heading_of, records=20, speed=20.0, name="log.csv"):
    """A log flying straight along ``track_deg`` (clockwise from north), its heading
    column ``heading_of(track)``."""
    east, north = math.sin(math.radians(track_deg)), math.cos(math.radians(track_deg))
    lines = ["time,x,y,z,heading"]
    lines += [
        f"{t},{t * speed * east!r},{t * speed * north!r},60.0,{heading_of(track_deg)!r}"
        for t in range(records)
    ]
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return load_flight_log(path)


@pytest.mark.parametrize("track", [0.0, 30.0, 135.0, 250.0])
def test_a_heading_along_the_track_or_crabbing_in_wind_is_not_noted(tmp_path, track):
    assert heading_note(_log(tmp_path, track, lambda t: t)) is None
    assert heading_note(_log(tmp_path, track, lambda t: (t + 25.0) % 360.0)) is None


@pytest.mark.parametrize(
    "track, heading_of, said",
    [
        (
            120.0,
            lambda t: math.radians(t),
            "the headings read as radians (2.094 for 120 degrees): expected degrees clockwise from north",
        ),
        (
            160.0,
            lambda t: (90.0 - t) % 360.0,
            "the headings read as degrees counter-clockwise from east (290 for 160 degrees clockwise "
            "from north): expected degrees clockwise from north",
        ),
        (
            200.0,
            lambda t: (t + 150.0) % 360.0,
            "expected degrees clockwise from north (an aircraft flying sideways, as a multirotor can, "
            "gives this too)",
        ),
    ],
)
def test_a_heading_in_another_convention_is_noted_with_which(tmp_path, track, heading_of, said):
    note = heading_note(_log(tmp_path, track, heading_of), "log.csv")
    assert note is not None
    assert note.startswith(
        "log.csv: the logged heading differs from the direction of travel by more than 45 degrees "
        "over 100% of the distance flown: "
    )
    assert note.endswith(said)


def test_a_hovering_log_is_not_noted(tmp_path):
    """Standing still (drifting centimetres), a heading says nothing of a track."""
    assert heading_note(_log(tmp_path, 90.0, lambda t: 0.0, speed=0.01)) is None


def test_validate_notes_a_log_s_heading_in_radians(tmp_path, capsys):
    from ladartui.cli import main

    (tmp_path / "m.txt").write_text("0,0,0\n100,100,5\n50,50,0\n")
    (tmp_path / "m_Target.txt").write_text("50,50,0\n")
    lines = ["time,x,y,z,heading"] + [f"{t},{10 * t},50,60,{math.pi / 2!r}" for t in range(11)]
    (tmp_path / "east.csv").write_text("\n".join(lines) + "\n")
    path = tmp_path / "case.toml"
    path.write_text(
        '[files]\nscene = "m.txt"\nvoxel_size = 1.0\n\n[sensor]\ngrid = 8\nray_grid = 1\n\n'
        '[[flight.segments]]\nkind = "log"\nfile = "east.csv"\nrate = 1.0\n'
    )
    assert main(["validate", str(path)]) == 0
    notes = [line for line in capsys.readouterr().out.splitlines() if line.startswith("note")]
    assert notes == [
        "note       east.csv: the logged heading differs from the direction of travel by more than 45 "
        "degrees over 100% of the distance flown: the headings read as radians (1.571 for 90 degrees): "
        "expected degrees clockwise from north"
    ]
