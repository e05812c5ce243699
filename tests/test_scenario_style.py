"""Saving keeps the analyst's file: comments, key order and layout survive, only changed
values change (tomlkit, see ladartui.scenario_style)."""

from __future__ import annotations

import dataclasses
import difflib
import shutil
import tomllib
from pathlib import Path

import pytest

from ladartui.levels import LevelThresholds
from ladartui.scenario import load_scenario
from ladartui.scenario_style import restyle
from ladartui.scene.generate import generate_scene

SHIPPED = Path(__file__).resolve().parent.parent / "scenarios"
NAMES = ["flypast.toml", "manoeuvres.toml", "orbit.toml", "standoff.toml"]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The shipped scenarios beside a small generated scene where they expect it."""
    folder = tmp_path_factory.mktemp("shipped")
    (folder / "generated").mkdir()
    generate_scene("small", seed=1, width=16.0, depth=16.0, trees=3).write(folder / "generated" / "small")
    return folder


def changed_lines(before: str, after: str) -> list[str]:
    return [
        line
        for line in difflib.unified_diff(before.splitlines(), after.splitlines(), lineterm="", n=0)
        if line[:1] in "+-" and line[:3] not in ("+++", "---")
    ]


@pytest.mark.parametrize("name", NAMES)
def test_a_shipped_scenario_saved_unchanged_is_byte_for_byte_the_same(folder, name):
    path = folder / name
    shutil.copy(SHIPPED / name, path)
    before = path.read_bytes()
    load_scenario(path).save()
    assert path.read_bytes() == before


@pytest.mark.parametrize("name", NAMES)
def test_an_edit_changes_only_its_own_line(folder, name):
    path = folder / name
    shutil.copy(SHIPPED / name, path)
    before = path.read_text()
    scenario = load_scenario(path)
    scenario.with_changes(sensor=dataclasses.replace(scenario.sensor, grid=48)).save()
    assert changed_lines(before, path.read_text()) == ["-grid = 64", "+grid = 48"]
    assert load_scenario(path).sensor.grid == 48


def test_a_segment_edit_keeps_the_comments_beside_its_keys(folder):
    path = folder / "flypast.toml"
    shutil.copy(SHIPPED / "flypast.toml", path)
    before = path.read_text()
    scenario = load_scenario(path)
    segment = dataclasses.replace(scenario.flight.segments[0], altitude=75.0)
    flight = dataclasses.replace(scenario.flight, segments=(segment,))
    scenario.with_changes(flight=flight).save()
    assert changed_lines(before, path.read_text()) == ["-altitude = 60.0", "+altitude = 75.0"]
    assert "# horizontal distance at the closest point" in path.read_text()


def test_a_segment_made_another_kind_leaves_the_old_kinds_comments_behind(folder):
    """An orbit made a fly-past kept the orbit's notes beside the keys both share:
    'scans = 6  # one look every 15 degrees' under a straight pass. A segment of the
    same kind keeps its comments (above), one of another kind starts bare."""
    from ladartui.flight.plan import FlyPast

    path = folder / "orbit.toml"
    shutil.copy(SHIPPED / "orbit.toml", path)
    scenario = load_scenario(path)
    orbit = scenario.flight.segments[0]
    pass_by = FlyPast(orbit.centre, 60.0, orbit.altitude, 160.0, orbit.scans)
    scenario.with_changes(flight=dataclasses.replace(scenario.flight, segments=(pass_by,))).save()
    text = path.read_text()
    segment = text[text.index("[[flight.segments]]") : text.index("[simulation]")]
    assert 'kind = "flypast"' in segment and "#" not in segment  # was: 'altitude = 70.0  # steeper ...'
    assert text.startswith("# Orbit (report figure 1a)")  # the file's own notes stay
    assert 'scene = "generated/small.txt"   # its target model is' in text
    assert load_scenario(path).flight.segments == (pass_by,)


def test_a_segment_made_another_kind_keeps_the_note_above_the_next_table():
    """tomlkit keeps a comment line above a table with the table before it: a segment
    written anew as another kind took away the note over the segment after it."""
    old = (
        "[flight]\nspeed_mps = 30.0\n\n"
        '[[flight.segments]]\nkind = "orbit"\nradius = 60.0  # wide\n\n'
        "# second: the run out north, keep it short\n"
        '[[flight.segments]]\nkind = "straight"\ndistance = 50.0\n\n'
        "# the run's settings\n[simulation]\nfast_mode = true\n"
    )
    data = tomllib.loads(old)
    new = {**data, "flight": {**data["flight"], "segments": [{"kind": "flypast", "standoff": 40.0}]}}
    new["flight"]["segments"].append(data["flight"]["segments"][1])
    text = restyle(old, new, data)
    assert "# wide" not in text  # the orbit's own note went with it
    assert "\n\n# second: the run out north, keep it short\n[[flight.segments]]\n" in text
    assert tomllib.loads(text) == new
    new["flight"]["segments"] = [{"kind": "flypast", "standoff": 40.0}, {"kind": "turn", "arc": 90.0}]
    text = restyle(old, new, data)
    assert "\n\n# the run's settings\n[simulation]\n" in text and tomllib.loads(text) == new


def test_save_as_keeps_the_comments_and_points_at_the_same_scene(folder, tmp_path):
    path = folder / "orbit.toml"
    shutil.copy(SHIPPED / "orbit.toml", path)
    copy = load_scenario(path).save(tmp_path / "copy.toml")
    text = copy.path.read_text()
    assert text.startswith(SHIPPED.joinpath("orbit.toml").read_text().splitlines()[0])
    assert load_scenario(copy.path).scene_file == (folder / "generated" / "small.txt")


def test_text_that_is_not_toml_is_not_restyled():
    assert restyle("grid = = 3", {"grid": 3}) is None
    assert restyle("# kept\ngrid = 3\n", {"grid": 4}) == "# kept\ngrid = 4\n"


def test_adding_a_segment_adds_its_lines_and_changes_no_other(folder):
    """Adding a segment rewrote every segment: the orbit lost its comments and gained
    'arc = 360.0', and an unused [flight.start] with float noise came after it."""
    from ladartui.flight import Straight
    from ladartui.tui import bridge

    path = folder / "orbit.toml"
    shutil.copy(SHIPPED / "orbit.toml", path)
    before = path.read_text()
    scenario = load_scenario(path)
    segments = [*scenario.flight.segments, Straight(distance=100.0, scans=3)]
    bridge.with_segments(scenario, segments).save()
    added = changed_lines(before, path.read_text())
    assert all(line.startswith("+") for line in added), added
    assert [line for line in added if line.strip("+")] == [
        "+[[flight.segments]]",
        '+kind = "straight"',
        "+distance = 100.0",
        "+scans = 3",
    ]
    assert load_scenario(path).flight.start is None
    lines = path.read_text().splitlines()
    assert all(lines[n - 1] == "" for n, line in enumerate(lines) if n and line.startswith("["))


def test_deleting_moving_or_inserting_segments_saves_a_file_that_reads_back_the_same(folder):
    """tomlkit keeps a table's comment line with the table before it: matching tables to
    segments put comments on the wrong segment, and an inline array took a standard
    table, which is not TOML. Such lists are written afresh."""
    from ladartui.flight import Straight

    path = folder / "manoeuvres.toml"
    inline = folder / "inline.toml"
    manoeuvres = SHIPPED.joinpath("manoeuvres.toml").read_text()
    inline.write_text(  # the same plan, its segments an inline array under [flight]
        manoeuvres.split("[flight.start]")[0]
        + "start = { x = -30.0, y = -60.0, z = 60.0, azimuth = 90.0, depression = 45.0 }\n"
        + 'segments = [ { kind = "straight", distance = 90.0, scans = 3 },\n'
        + '  { kind = "turn", radius = 40.0, arc = 90.0, direction = "right", scans = 3 },\n'
        + '  { kind = "straight", distance = 30.0, scans = 2 } ]\n'
    )
    for source in (path, inline):
        if source is path:
            shutil.copy(SHIPPED / "manoeuvres.toml", path)
        scenario = load_scenario(source)
        first, *rest = scenario.flight.segments
        for segments in ((first, rest[-1]), (rest[-1], first, *rest[:-1]), (first, Straight(5.0, 2), *rest)):
            flight = dataclasses.replace(scenario.flight, segments=tuple(segments))
            scenario.with_changes(flight=flight).save()
            assert load_scenario(source).flight.segments == flight.segments
            scenario = load_scenario(source)


def test_save_as_renames_the_files_the_programs_header_names(folder, tmp_path):
    """'Check it with: ladartui validate noext.toml' stayed in the copy's header."""
    scenario = load_scenario(SHIPPED / "orbit.toml", check_files=False)
    first = scenario.with_changes(path=tmp_path / "noext.toml")
    first.path.write_text(first.to_toml())
    copy = load_scenario(first.path, check_files=False).save(tmp_path / "s1.toml")
    text = copy.path.read_text()
    assert text.startswith(copy.to_toml().split("\n\n")[0]) and "noext" not in text
    # an analyst's own header stays as written
    own = tmp_path / "own.toml"
    own.write_text("# my notes on noext\n" + first.toml_body())
    assert (
        "# my notes on noext"
        in load_scenario(own, check_files=False).save(tmp_path / "s2.toml").path.read_text()
    )


def test_a_save_that_cannot_be_written_names_the_file_not_its_temporary(tmp_path):
    """'[Errno 2] No such file or directory: /proc/.a.toml.v5ert5rs.tmp'."""
    from ladartui.errors import OutputFileError

    scenario = load_scenario(SHIPPED / "orbit.toml", check_files=False)
    with pytest.raises(OutputFileError) as caught:
        scenario.save(Path("/proc/a.toml"))
    assert str(caught.value).startswith("/proc/a.toml: cannot be written") and ".tmp" not in str(caught.value)


def test_the_header_command_works_as_written_for_a_name_with_spaces(tmp_path):
    """'Check it with: ladartui validate new [b]x.toml' ran validate on 'new' and '[b]x.toml'."""
    import shlex

    scenario = load_scenario(SHIPPED / "orbit.toml", check_files=False)
    named = scenario.with_changes(path=tmp_path / "my [b]x plan.toml")
    first = named.header().splitlines()[0]
    command = first.split("Check it with: ", 1)[1]
    assert shlex.split(command) == ["ladartui", "validate", "my [b]x plan.toml"]
    # a plain name stays plain
    plain = scenario.with_changes(path=tmp_path / "plan.toml").header().splitlines()[0]
    assert plain.endswith("ladartui validate plan.toml")
    # a file whose header was written before the name was quoted is renamed on Save As too
    old = tmp_path / "old plan.toml"
    unquoted = scenario.with_changes(path=old)
    old.write_text(unquoted.header(quoted=False) + unquoted.toml_body())
    assert (
        "old plan" not in load_scenario(old, check_files=False).save(tmp_path / "new.toml").path.read_text()
    )


@pytest.mark.parametrize("edit", ["deleted", "straight"])
def test_a_segment_list_written_anew_keeps_a_blank_line_before_every_table(folder, edit):
    """A segment deleted (the list is written anew) left '[simulation]' straight under
    the last segment's keys; the orbit replaced by a straight, which brings a start pose,
    put '[simulation]' straight under '[flight.start]': the blank lines the file had
    between its tables were lost."""
    from ladartui.flight import Straight
    from ladartui.tui import bridge

    path = folder / "orbit.toml"
    shutil.copy(SHIPPED / "orbit.toml", path)
    scenario = load_scenario(path)
    orbit, straight = scenario.flight.segments[0], Straight(distance=100.0, scans=5)
    if edit == "deleted":  # a straight after the orbit, saved; then the orbit deleted
        bridge.with_segments(scenario, [orbit, straight]).save()
        scenario = load_scenario(path)
    saved = bridge.with_segments(scenario, [straight])
    saved.save()
    text = path.read_text()
    lines = text.splitlines()
    headers = [n for n, line in enumerate(lines) if line.startswith("[")]
    assert [lines[n - 1] for n in headers] == [""] * len(headers), text
    assert text.endswith("fast_mode = false\n")  # and the file ends as it did
    assert load_scenario(path).flight == saved.flight


@pytest.mark.parametrize(
    ("old", "data", "new"),
    [
        # a new table: its blank line before it, as the file's tables have, and none after
        ("[a]\nx = 1\n\n[b]\ny = 2", {"a": {"x": 1}, "b": {"y": 2}, "c": {"q": 1}}, "\n\n[c]\nq = 1\n"),
        ("[a]\nx = 1", {"a": {"x": 2}}, "[a]\nx = 2\n"),  # a value changed: its line ended
        ("[a]\nx = 1", {"a": {"x": 1}}, "[a]\nx = 1"),  # nothing changed: not a byte
    ],
)
def test_a_file_without_a_final_newline_is_restyled_as_one_with_it(old, data, new):
    """A table added to a file whose last line had no newline came straight under the
    last key, and the file then ended with a blank line."""
    text = restyle(old, data)
    assert text is not None and text.endswith(new), repr(text)
    assert tomllib.loads(text) == data


def test_a_default_written_by_hand_stays_when_another_value_of_its_table_changes(folder):
    """'mount = "stabilised"' and its comment went from the file when the grid was
    changed: the program writes the mount only when it is body-fixed, so the save took
    the analyst's line for one the new settings no longer have."""
    path = folder / "mount.toml"
    text = (SHIPPED / "orbit.toml").read_text()
    path.write_text(
        text.replace("pixel_pitch_um = 100.0\n", 'pixel_pitch_um = 100.0\nmount = "stabilised"  # kept\n')
    )
    before = path.read_text()
    scenario = load_scenario(path)
    scenario.with_changes(sensor=dataclasses.replace(scenario.sensor, grid=48)).save()
    assert changed_lines(before, path.read_text()) == ["-grid = 64", "+grid = 48"]
    scenario = load_scenario(path)
    scenario.with_changes(sensor=dataclasses.replace(scenario.sensor, mount="body-fixed")).save()
    assert load_scenario(path).sensor.mount == "body-fixed"
    scenario = load_scenario(path)
    scenario.with_changes(sensor=dataclasses.replace(scenario.sensor, mount="stabilised")).save()
    assert load_scenario(path).sensor.mount == "stabilised"


@pytest.mark.parametrize("mark", ["", "\ufeff"])
def test_a_file_with_windows_line_ends_keeps_them(folder, mark):
    """A scenario written on Windows (CRLF) came back from a save with every line end
    changed to LF: every line differed, even after a save that changed nothing. (A byte
    order mark is dropped, as before: other TOML readers refuse it.)"""
    path = folder / "windows.toml"
    lines = (SHIPPED / "orbit.toml").read_text().splitlines()
    before = ("\r\n".join(lines) + "\r\n").encode()
    path.write_bytes(mark.encode() + before)
    load_scenario(path).save()
    assert path.read_bytes() == before
    scenario = load_scenario(path)
    scenario.with_changes(sensor=dataclasses.replace(scenario.sensor, grid=48), speed=40.0).save()
    after = path.read_bytes()
    assert b"\n" not in after.replace(b"\r\n", b"")
    assert changed_lines(before.decode(), after.decode()) == [
        "-grid = 64",
        "+grid = 48",
        "-speed_mps = 30.0",
        "+speed_mps = 40.0",
    ]
    scenario = load_scenario(path)
    scenario.with_changes(levels=LevelThresholds(detect=0.2)).save()  # a table added
    assert b"\n" not in path.read_bytes().replace(b"\r\n", b"")
    assert load_scenario(path).levels == LevelThresholds(detect=0.2)
