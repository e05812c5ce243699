"""Scenario files' mistakes: field limits, unknown and missing keys, TOML syntax."""

import pytest

from ladartui.errors import FieldError, InputFileError
from ladartui.scenario import load_scenario
from scenario_support import BASE, edited, line_of, write_scenario

# -- field limits ----------------------------------------------------------------------

LIMITS = [
    ("voxel_size = 0.5", "voxel_size = 0", "files.voxel_size = 0", "a number from 0.001 to 100"),
    (
        "voxel_size = 0.5",
        "voxel_size = 250.0",
        "files.voxel_size = 250.0",
        "a number from 0.001 to 100",
    ),
    # a scene 1e-298 m wide, which every ray missed
    ("voxel_size = 0.5", "voxel_size = 1e-300", "files.voxel_size = 1e-300", "a number from 0.001 to 100"),
    ('scene = "models/forest.txt"', "scene = 3", "files.scene = 3", "the scene model file name (X.txt)"),
    ("grid = 32", "grid = 2000", "sensor.grid = 2000", "an integer from 1 to 1024"),
    ("grid = 32", "grid = 32.5", "sensor.grid = 32.5", "an integer from 1 to 1024"),
    ("ray_grid = 2", "ray_grid = 0", "sensor.ray_grid = 0", "an integer from 1 to 16"),
    ("fov_deg = 12.0", "fov_deg = 90.0", "sensor.fov_deg = 90.0", "a number at least 1e-14 and less than 90"),
    (
        "fov_deg = 12.0",
        'fov_deg = "wide"',
        "sensor.fov_deg = 'wide'",
        "a number at least 1e-14 and less than 90",
    ),
    (
        "depth_resolution_m = 1.5",
        "depth_resolution_m = -1",
        "sensor.depth_resolution_m = -1",
        "a number from 0 to 1000",
    ),
    (
        "pixel_pitch_um = 100.0",
        "pixel_pitch_um = 0",
        "sensor.pixel_pitch_um = 0",
        "a number from 0.1 to 10000",
    ),
    (
        "pixel_pitch_um = 100.0",
        "pixel_pitch_um = 20000.0",
        "sensor.pixel_pitch_um = 20000.0",
        "a number from 0.1 to 10000",
    ),
    (
        "pixel_pitch_um = 100.0",
        "pixel_pitch_um = true",
        "sensor.pixel_pitch_um = True",
        "a number from 0.1 to 10000",
    ),
    (
        "speed_mps = 25.0",
        "speed_mps = 0.0",
        "flight.speed_mps = 0.0",
        "a number greater than 0 and at most 1000",
    ),
    ("depression = 45.0", "depression = 0.0", "flight.start.depression = 0.0", "a number from 1 to 90"),
    ("z = 80.0", "z = -5.0", "flight.start.z = -5.0", "a number greater than 0 and at most 100000"),
    (
        "distance = 50.0",
        "distance = 0.0",
        "flight.segments[0].distance = 0.0",
        "a number greater than 0 and at most 1000000",
    ),
    ("scans = 8", "scans = 0", "flight.segments[1].scans = 0", "an integer from 1 to 10000"),
    (
        "radius = 60.0",
        "radius = -60.0",
        "flight.segments[1].radius = -60.0",
        "a number greater than 0 and at most 1000000",
    ),
    (
        "centre = [10.0, 10.0, 1.0]",
        "centre = [10.0]",
        "flight.segments[1].centre = [10.0]",
        "a point [x, y] or [x, y, z] in metres, each within +-1000000",
    ),
    (
        'kind = "orbit"',
        'kind = "circle"',
        "flight.segments[1].kind = 'circle'",
        "one of 'manual', 'straight', 'turn', 'orbit', 'flypast', 'standoff', 'log'",
    ),
    ('method = "march"', 'method = "fast"', "simulation.method = 'fast'", "one of 'exact', 'march'"),
    ("step = 0.25", "step = 0", "simulation.step = 0", "a number from 0.001 to 10"),
    ("step = 0.25", "step = 1e-12", "simulation.step = 1e-12", "a number from 0.001 to 10"),
    ('precision = "f32"', 'precision = "f16"', "simulation.precision = 'f16'", "one of 'f64', 'f32'"),
    ("fast_mode = true", "fast_mode = 1", "simulation.fast_mode = 1", "true or false"),
]


@pytest.mark.parametrize("old,new,head,expected", LIMITS, ids=[row[2] for row in LIMITS])
def test_every_field_limit_names_file_line_field_value_and_range(tmp_path, old, new, head, expected):
    text = edited(old, new)
    path = write_scenario(tmp_path, text)
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    line = line_of(text, new)
    assert str(caught.value) == f"{path}:{line}: {head}: expected {expected}"


def test_backend_must_be_known(tmp_path):
    path = write_scenario(tmp_path, edited('backend = "auto"', 'backend = "cuda"'))
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    message = str(caught.value)
    assert message.startswith(
        f"{path}:{line_of(BASE, 'backend')}: simulation.backend = 'cuda': expected one of 'auto', "
    )


def test_aim_above_the_horizon_names_the_segment(tmp_path):
    text = edited("scans = 2\n", "scans = 2\naim_at = [0.0, 5000.0, 0.0]\n")
    path = write_scenario(tmp_path, text)
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    assert caught.value.field == "flight.segments[0].aim_at"
    assert str(caught.value).startswith(f"{path}:{line_of(text, 'aim_at')}: ")


@pytest.mark.parametrize(
    ("pointing", "given"),
    [
        ("depression = 30.0", "depression is"),
        ("azimuth = 90.0\ndepression = 30.0", "azimuth and depression are"),
    ],
)
def test_a_manoeuvre_with_an_aim_point_and_a_sensor_pointing_is_refused(tmp_path, pointing, given):
    """A straight with depression = 30 and an aim point flew its scans aimed, the depression
    dropped without a word (the TUI's form refuses the two together for that reason)."""
    text = edited("scans = 2\n", f"scans = 2\n{pointing}\naim_at = [10.0, 10.0, 1.0]\n")
    path = write_scenario(tmp_path, text)
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    assert str(caught.value) == (
        f"{path}:{line_of(text, 'aim_at')}: flight.segments[0].aim_at = [10.0, 10.0, 1.0]: "
        f"expected no aim point while {given} given (an aim point sets both)"
    )


def test_relative_segment_first_needs_a_start(tmp_path):
    start = BASE[BASE.index("[flight.start]") : BASE.index("[[flight.segments]]")]
    path = write_scenario(tmp_path, BASE.replace(start, ""))
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    assert caught.value.field == "flight.start"


# -- unknown and missing keys, syntax ------------------------------------------------


@pytest.mark.parametrize(
    "old,new,message",
    [
        (
            "grid = 32",
            "gird = 32",
            "unknown key 'sensor.gird' (allowed: grid, ray_grid, fov_deg, "
            "depth_resolution_m, pixel_pitch_um, mount)",
        ),
        (
            "radius = 60.0",
            "raduis = 60.0",
            "unknown key 'flight.segments[1].raduis' (orbit segment) "
            "(allowed: kind, centre, radius, altitude, scans, direction, start_bearing, arc, aim_at)",
        ),
        (
            "[simulation]",
            "[simulatoin]",
            "unknown section [simulatoin] "
            "(allowed: files, sensor, flight, simulation, detection, levels, targets)",
        ),
        (
            "heading = 0.0",
            "headin = 0.0",
            "unknown key 'flight.start.headin' (allowed: x, y, z, heading, azimuth, depression)",
        ),
        # arrays of tables had no line ("[[flight.segmnts]]" was named without one)
        (
            "[[flight.segments]]",
            "[[flight.segmnts]]",
            "unknown key 'flight.segmnts' (allowed: speed_mps, start, segments)",
        ),
        (
            "[simulation]",
            "[[simulatoin]]",
            "unknown section [simulatoin] "
            "(allowed: files, sensor, flight, simulation, detection, levels, targets)",
        ),
        # a sweep spec given as a scenario: said to be one, with the command that runs it
        (
            "[simulation]",
            "[sweep]",
            "a sweep spec ([sweep]), not a scenario: 'ladartui sweep FILE' runs it",
        ),
    ],
)
def test_unknown_keys_are_named_with_their_line(tmp_path, old, new, message):
    text = edited(old, new)
    path = write_scenario(tmp_path, text)
    with pytest.raises(InputFileError) as caught:
        load_scenario(path, check_files=False)
    assert str(caught.value) == f"{path}:{line_of(text, new)}: {message}"


def test_missing_keys(tmp_path):
    path = write_scenario(tmp_path, edited('scene = "models/forest.txt"\n', ""))
    with pytest.raises(InputFileError) as caught:
        load_scenario(path, check_files=False)
    assert str(caught.value) == f"{path}:1: missing key 'files.scene'"
    text = edited("radius = 60.0\n", "")
    path = write_scenario(tmp_path, text)
    with pytest.raises(InputFileError) as caught:
        load_scenario(path, check_files=False)
    header = line_of(text, 'kind = "orbit"') - 1
    assert str(caught.value) == (f"{path}:{header}: missing key 'flight.segments[1].radius' (orbit segment)")


def test_toml_syntax_error_gives_the_line(tmp_path):
    text = edited("grid = 32", "grid = = 32")
    path = write_scenario(tmp_path, text)
    with pytest.raises(InputFileError) as caught:
        load_scenario(path, check_files=False)
    assert caught.value.line == line_of(text, "grid = = 32")
    assert str(caught.value).startswith(f"{path}:{caught.value.line}: not valid TOML: ")


@pytest.mark.parametrize(
    ("old", "new", "first", "second"),
    [
        # a key written twice in one table, and in a segment's
        ("speed_mps = 25.0", "speed_mps = 25.0\nspeed_mps = 30.0", "speed_mps = 25", "speed_mps = 30"),
        ("radius = 60.0", "radius = 60.0\nradius = 50.0", "radius = 60", "radius = 50"),
        # a key, then a table of the same name
        ("speed_mps = 25.0", "speed_mps = 25.0\nstart = 3", "start = 3", "[flight.start]"),
        # a table header written twice
        (
            "[simulation]",
            "[sensor] # again\nmount = 'body-fixed'\n\n[simulation]",
            "[sensor]",
            "again",
        ),
    ],
)
def test_a_key_or_table_written_twice_is_named_with_both_lines(tmp_path, old, new, first, second):
    """A key set twice read 'not valid TOML: Cannot overwrite a value', a table declared
    twice "Cannot declare ('sensor',) twice": neither said which key, or where it was first."""
    text = edited(old, new)
    path = write_scenario(tmp_path, text)
    with pytest.raises(InputFileError) as caught:
        load_scenario(path, check_files=False)
    name = {
        "speed_mps": "key 'flight.speed_mps'",
        "radius = ": "key 'flight.segments[1].radius'",
        "start = 3": "table [flight.start]",
        "[sensor]": "table [sensor]",
    }[first[:9]]
    assert str(caught.value) == (
        f"{path}:{line_of(text, second)}: not valid TOML: {name} written twice (first on line "
        f"{line_of(text, first)}); expected each key and table once"
    )


@pytest.mark.parametrize("tail", ["x = [\n", "x = [\n\n\n", "x = [1,"])
def test_a_toml_mistake_at_the_end_of_the_file_names_its_last_line(tmp_path, tail):
    """A file cut off in a value read 'not valid TOML: Invalid value (at end of
    document)': no line where every other mistake has one."""
    text = BASE + tail
    path = write_scenario(tmp_path, text)
    with pytest.raises(InputFileError) as caught:
        load_scenario(path, check_files=False)
    last = line_of(text, tail.strip())
    assert str(caught.value).startswith(f"{path}:{last}: not valid TOML: ")
    assert str(caught.value).endswith(" at the end of the file")


@pytest.mark.parametrize("mark", ["\u2028", "\u2029", "\x85"])
def test_a_comment_holding_a_unicode_line_separator_keeps_the_lines_that_follow(tmp_path, mark):
    """TOML ends a line at a newline alone; a line separator pasted into a comment
    (from a document or a web page) counted as one more line, and every error
    below it named the line after its own."""
    text = f"# flown as the report's figure 9{mark} (orbit, then straight)\n" + edited(
        "grid = 32", "grid = 0"
    )
    path = write_scenario(tmp_path, text)
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    line = text[: text.index("grid = 0")].count("\n") + 1  # 7: the file's line, as an editor numbers it
    assert str(caught.value).startswith(f"{path}:{line}: sensor.grid = 0")


def test_a_path_of_millions_of_scans_is_refused_before_its_scans_are_made(tmp_path, monkeypatch):
    """500 orbits of 10,000 scans each were each built, 5 million poses over 114 s and
    1.6 GB, before 'expected at most 10000 scans'; the scans the segments declare are
    counted first."""
    from ladartui.flight import Orbit

    def never(self, current):
        raise AssertionError("an orbit's scans were made")

    orbit = (
        '[[flight.segments]]\nkind = "orbit"\ncentre = [0.0, 0.0, 0.0]\n'
        "radius = 60.0\naltitude = 60.0\nscans = 10000\n"
    )
    monkeypatch.setattr(Orbit, "build", never)
    path = write_scenario(tmp_path, BASE + orbit * 500)
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    assert caught.value.field == "flight.segments"
    assert str(caught.value).endswith("flight.segments is 5,000,010 scans: expected at most 10,000 scans")


def test_flight_logs_flown_at_a_rate_count_their_scans_before_they_are_made(tmp_path, monkeypatch):
    """A log flown at a rate was counted as one scan, so 500 of them (up to 10,000 scans
    each) were all built before the path was refused."""
    from pathlib import Path

    from ladartui.trajectory import LogSegment

    def never(self, current):
        raise AssertionError("a log's scans were made")

    log = Path(__file__).parent.parent / "scenarios" / "flight-log.csv"  # 3 s: 3,001 scans at 1 kHz
    segment = f'[[flight.segments]]\nkind = "log"\nfile = "{log}"\nrate = 1000.0\n'
    monkeypatch.setattr(LogSegment, "build", never)
    path = write_scenario(tmp_path, BASE + segment * 4)
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    assert str(caught.value).endswith("flight.segments is 12,014 scans: expected at most 10,000 scans")


def test_a_scenario_with_no_flight_is_told_what_a_flight_is(tmp_path):
    """A scenario of files alone was refused "missing key 'flight.segments'", with
    nothing on what a flight is written as."""
    from ladartui.scenario_file import SEGMENT_FILE_KINDS

    path = tmp_path / "plan.toml"
    path.write_text('[files]\nscene = "forest.txt"\nvoxel_size = 0.25\n')
    with pytest.raises(InputFileError) as caught:
        load_scenario(path, check_files=False)
    assert str(caught.value) == (
        f"{path}: missing key 'flight.segments': expected one or more [[flight.segments]] tables, "
        f"each with its kind ({', '.join(SEGMENT_FILE_KINDS)}), as in the bundled scenarios "
        "('ladartui validate default' writes one to copy)"
    )


@pytest.mark.parametrize("model", ["geiger", "ideal"])
def test_fewer_pulses_than_the_default_coincidence_names_the_pulses_written(tmp_path, model):
    """'pulses = 4' alone was reported as 'detection.coincidence = 10', a key not in the
    file, on the [detection] line."""
    text = BASE + f'\n[detection]\nmodel = "{model}"\npulses = 4\n'
    path = write_scenario(tmp_path, text)
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files=False)
    assert str(caught.value) == (
        f"{path}:{line_of(text, 'pulses = 4')}: detection.pulses = 4: expected at least "
        "detection.coincidence (10, its default: set it too; k of the pulses must fire "
        "to declare a point)"
    )
    written = path.read_text().replace("pulses = 4\n", "pulses = 4\ncoincidence = 2\n")
    path.write_text(written)
    assert load_scenario(path, check_files=False).detection.coincidence == 2


def test_a_bad_value_in_a_segment_written_one_a_line_is_named_on_its_own_line(tmp_path):
    """A scenario saved afresh writes short segments as 'segments = [' then one inline
    table a line, and a manual segment's poses likewise; a bad distance in the third
    segment was reported on the 'segments = [' line, as was a bad pose among a hundred."""
    from ladartui.flight import FlightPlan, Manual, ScanPose, Straight
    from ladartui.scenario import Scenario
    from ladartui.sensor import Sensor
    from scenario_support import write_models

    scene = write_models(tmp_path / "models")
    legs = tuple(Straight(distance, 2) for distance in (40.0, 50.0, 60.0))
    poses = Manual(tuple(ScanPose(x, 0.0, 50.0) for x in range(100)))
    cases = [
        (FlightPlan(ScanPose(0.0, -100.0, 50.0), legs), "segments = [", "distance = 60.0", "distance = -6.0"),
        (
            FlightPlan(None, (poses,)),
            "poses = [",
            "x = 77.0, y = 0.0, z = 50.0",
            "x = 77.0, y = 0.0, z = -5.0",
        ),
    ]
    heads = ["flight.segments[2].distance = -6.0", "flight.segments[0].poses[77].z = -5.0"]
    for (plan, opening, old, new), head in zip(cases, heads):
        saved = Scenario(tmp_path / "s.toml", scene, 1.0, Sensor(grid=4), plan).save()
        text = saved.path.read_text()
        assert f"{opening}\n" in text
        written = text.replace(old, new, 1)
        saved.path.write_text(written)
        with pytest.raises(FieldError) as caught:
            load_scenario(saved.path)
        assert str(caught.value).startswith(f"{saved.path}:{line_of(written, new)}: {head}: expected ")
        saved.path.unlink()
