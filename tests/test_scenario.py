"""Scenario files: TOML round trips, model files (report 4.1), the API, examples."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from ladartui.errors import FieldError, InputFileError
from ladartui.flight import FlightPlan, FlyPast, Manual, Orbit, ScanPose, Standoff, Straight, Turn
from ladartui.scenario import Scenario, load_scenario, scenario_from_toml
from ladartui.sensor import Sensor
from scenario_support import BASE, edited, line_of, write_models, write_scenario

PROJECT = Path(__file__).resolve().parents[1]


def full_scenario(path, scene_file):
    start = ScanPose(-50.0, -50.0, 70.0, heading=45.0, azimuth=10.0, depression=40.0)
    plan = FlightPlan(
        start,
        [
            Straight(40.0, 2),
            Turn(30.0, 120.0, "left", 3, depression=60.0),
            Manual([ScanPose(1.5, 2.25, 90.0, 10.0, -20.0, 75.0), ScanPose(3.0, 4.0, 95.0)]),
            Orbit((10.0, 12.0, 1.0), 55.5, 65.0, 7, direction="left", start_bearing=33.3, arc=270.0),
            FlyPast((10.0, 12.0), 40.0, 50.0, 100.0, 5, heading=123.4, side="left"),
            Standoff(
                (10.0, 12.0, 0.5),
                [90.0, 60.0, 30.0],
                55.0,
                bearing=300.0,
                heading=10.0,
                aim_at=(11.0, 13.0, 0.0),
            ),
            Straight(10.0, 1, aim_at=(10.0, 12.0, 0.0)),
        ],
    )
    return Scenario(
        path,
        scene_file,
        0.3,
        Sensor(48, 3, 7.5, 0.75, 37e-6),
        plan,
        speed=22.5,
        backend="numba",
        method="march",
        step=0.3,
        fast_mode=True,
        precision="f32",
    )


# -- round trips ---------------------------------------------------------------------


def test_round_trip_every_segment_kind(tmp_path):
    scene = write_models(tmp_path / "models")
    scenario = full_scenario(tmp_path / "s.toml", scene)
    scenario.save()
    loaded = load_scenario(tmp_path / "s.toml")
    assert loaded == scenario
    assert loaded.poses() == scenario.poses()
    first_text = (tmp_path / "s.toml").read_text()
    loaded.save()
    assert (tmp_path / "s.toml").read_text() == first_text
    assert load_scenario(tmp_path / "s.toml") == scenario
    assert 'scene = "models/forest.txt"' in first_text  # relative to the scenario's folder
    assert "pixel_pitch_um = 37.0" in first_text
    assert "centre = [10.0, 12.0, 1.0]" in first_text  # points on one line


def test_a_numpy_true_or_false_is_taken_for_fast_mode_and_saved_as_toml(tmp_path):
    """fast_mode=np.True_ (a comparison of numpy numbers) was refused as 'expected true or
    false', which it is."""
    import numpy as np

    scene = write_models(tmp_path / "models")
    scenario = full_scenario(tmp_path / "s.toml", scene)
    for flag in (np.True_, np.False_):
        changed = scenario.with_changes(fast_mode=flag)
        assert changed.fast_mode is bool(flag)
        changed.save()
        assert load_scenario(changed.path) == changed


def test_saving_a_scenario_over_its_own_scene_target_or_flight_log_is_refused(tmp_path):
    """save(path) wrote the TOML over the scene model, its target model or the flight log
    it reads, whichever path it was given: the voxels were gone, and the scenario named
    itself as its scene."""
    from ladartui.errors import OutputFileError
    from ladartui.trajectory import LogSegment

    scene = write_models(tmp_path / "models")
    log = tmp_path / "log.csv"
    log.write_text("time,x,y,z,heading\n0,0,0,50,90\n1,30,0,50,90\n")
    plan = FlightPlan(None, (LogSegment(str(log), rate=1.0),))
    scenario = Scenario(tmp_path / "s.toml", scene, 1.0, Sensor(grid=4), plan)
    link = tmp_path / "linked.txt"
    link.symlink_to(scene)
    cases = [
        (scene, "the scene model (files.scene)"),
        (scene.with_name("forest_Target.txt"), "the target model of forest.txt"),
        (log, "the flight log of flight.segments[0]"),
        (link, "the scene model (files.scene)"),
    ]
    for path, what in cases:
        before = path.read_bytes()
        with pytest.raises(OutputFileError) as caught:
            scenario.save(path)
        assert str(caught.value) == f"{path}: is {what} this scenario reads: save it under another name"
        assert path.read_bytes() == before
    assert scenario.save().path.is_file()


def test_a_folder_given_as_the_scenario_s_path_is_refused(tmp_path, monkeypatch):
    """Scenario("results/", ...) was taken: a run wrote results_Scene.txt and the rest
    beside the folder, and save() failed only then."""
    scene = write_models(tmp_path / "models")
    (tmp_path / "results").mkdir()
    monkeypatch.chdir(tmp_path)
    plan = FlightPlan(None, (Orbit((1.0, 1.0, 0.0), 40.0, 50.0, 4),))
    for given in ("results/", tmp_path / "results", ""):
        with pytest.raises(FieldError) as caught:
            Scenario(given, scene, 1.0, Sensor(grid=4), plan)
        folder = tmp_path / "results" if given else tmp_path
        assert (
            str(caught.value) == f"path = '{folder}': expected a scenario file's path (S.toml), not a folder"
        )
    with pytest.raises(FieldError, match=r"^path = '.*results': expected a scenario file's path \(S\.toml\)"):
        Scenario.new("results", scene, 1.0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["models", "results"]


def test_round_trip_of_the_base_text(tmp_path):
    write_models(tmp_path / "models")
    scenario = load_scenario(write_scenario(tmp_path))
    assert scenario.sensor == Sensor(32, 2, 12.0, 1.5, 100e-6)
    assert (scenario.speed, scenario.method, scenario.step) == (25.0, "march", 0.25)
    assert (scenario.precision, scenario.fast_mode, scenario.voxel_size) == ("f32", True, 0.5)
    assert len(scenario.poses()) == 10
    saved = scenario.save(tmp_path / "copy.toml")
    assert saved.path == tmp_path / "copy.toml"
    assert (
        load_scenario(tmp_path / "copy.toml") == saved == scenario.with_changes(path=tmp_path / "copy.toml")
    )


def test_paths_resolve_against_the_scenario_folder(tmp_path):
    scene = write_models(tmp_path / "models")
    scenario = load_scenario(write_scenario(tmp_path))
    assert scenario.scene_file == scene
    assert scenario.target_file == tmp_path / "models" / "forest_Target.txt"
    assert scenario.scene_output == tmp_path / "case_Scene.txt"
    assert scenario.target_output == tmp_path / "case_Target.txt"
    assert scenario.measures_file == tmp_path / "case.cmf"
    # Saved elsewhere, the scene stays the same file, written relative to the new folder.
    moved = scenario.save(tmp_path / "runs" / "later.toml")
    assert 'scene = "../models/forest.txt"' in moved.path.read_text()
    assert load_scenario(moved.path).scene_file == scene
    assert moved.measures_file == tmp_path / "runs" / "later.cmf"


def test_absolute_scene_path_kept_when_nothing_in_common(tmp_path):
    scenario = load_scenario(
        write_scenario(tmp_path, edited('scene = "models/forest.txt"', 'scene = "/opt/elsewhere/x.txt"')),
        check_files=False,
    )
    assert scenario.scene_file == Path("/opt/elsewhere/x.txt")
    assert scenario.target_file == Path("/opt/elsewhere/x_Target.txt")
    assert scenario.to_dict()["files"]["scene"] == "/opt/elsewhere/x.txt"


# -- missing model files (report 4.1) ------------------------------------------------


def test_missing_scene_model_is_named(tmp_path):
    path = write_scenario(tmp_path)
    with pytest.raises(InputFileError) as caught:
        load_scenario(path)
    scene = tmp_path / "models" / "forest.txt"
    assert str(caught.value) == f"{path}:2: scene model file {scene} not found (files.scene)"
    assert load_scenario(path, check_files=False).scene_file == scene


def test_missing_target_model_is_named(tmp_path):
    write_models(tmp_path / "models")
    (tmp_path / "models" / "forest_Target.txt").unlink()
    path = write_scenario(tmp_path)
    with pytest.raises(InputFileError) as caught:
        load_scenario(path)
    target = tmp_path / "models" / "forest_Target.txt"
    assert str(caught.value) == (
        f"{path}:2: target model file {target} not found (the target "
        "model of forest.txt must sit beside it, named forest_Target.txt)"
    )


def test_a_scene_file_naming_the_target_model_says_which_file_to_name(tmp_path):
    # It asked for forest_Target_Target.txt, a file no one should make.
    write_models(tmp_path / "models")
    path = write_scenario(
        tmp_path, edited('scene = "models/forest.txt"', 'scene = "models/forest_Target.txt"')
    )
    with pytest.raises(InputFileError) as caught:
        load_scenario(path)
    models = tmp_path / "models"
    assert str(caught.value) == (
        f"{path}:2: scene model file {models / 'forest_Target.txt'} is a target model "
        f"(files.scene): expected the scene model {models / 'forest.txt'}, whose target model it is"
    )


@pytest.mark.parametrize(("name", "kind"), [("survey.las", "a LAS point cloud"), ("truck.obj", "a mesh")])
def test_a_scene_file_of_another_kind_is_named_as_such(tmp_path, name, kind):
    # A point cloud named as the scene asked for survey_Target.las, and once that was made,
    # the scene was refused as 'not a voxel list'.
    models = tmp_path / "models"
    models.mkdir()
    (models / name).write_bytes(b"LASF")
    path = write_scenario(tmp_path, edited('scene = "models/forest.txt"', f'scene = "models/{name}"'))
    with pytest.raises(InputFileError) as caught:
        load_scenario(path)
    suffix = name[name.index(".") :]
    advice = (
        f": make one from it with 'ladartui voxelize {models / name} {models / 'survey'} --voxel-size 0.5'"
        if suffix == ".las"
        else ""
    )
    assert str(caught.value) == (
        f"{path}:2: scene model file {models / name} is {kind} ({suffix}) (files.scene): "
        f"expected a voxel list (.txt){advice}"
    )


def test_with_changes_names_a_field_it_does_not_have(tmp_path):
    # A typo raised TypeError from the dataclass machinery.
    scenario = load_scenario(write_scenario(tmp_path), check_files=False)
    with pytest.raises(FieldError) as caught:
        scenario.with_changes(sped=20.0)
    assert caught.value.field == "sped"
    assert str(caught.value).startswith("sped = 20.0: expected a Scenario field: path, scene_file, ")


@pytest.mark.parametrize(
    ("old", "new", "key", "message"),
    [
        (
            "[files]\n",
            "",
            "scene = ",
            "key 'scene' outside any section: expected it under [files]",
        ),
        (
            "[files]\n",
            "speed = 3\n",
            "speed = ",
            "key 'speed' outside any section: expected a section "
            "(files, sensor, flight, simulation, detection, levels, targets)",
        ),
    ],
)
def test_a_key_outside_any_section_is_not_called_a_section(tmp_path, old, new, key, message):
    # A file missing its [files] line was told "unknown section [scene]".
    text = edited(old, new)
    path = write_scenario(tmp_path, text)
    with pytest.raises(InputFileError) as caught:
        load_scenario(path, check_files=False)
    assert str(caught.value) == f"{path}:{line_of(text, key)}: {message}"


def test_save_to_a_path_that_is_no_path_is_a_field_error(tmp_path):
    # It raised TypeError from pathlib.
    scenario = load_scenario(write_scenario(tmp_path), check_files=False)
    with pytest.raises(FieldError) as caught:
        scenario.save(5)
    assert str(caught.value) == (
        "path = 5: expected a scenario file's path, or None for its own (str or pathlib.Path)"
    )


def test_missing_scenario_file(tmp_path):
    with pytest.raises(InputFileError) as caught:
        load_scenario(tmp_path / "nope.toml")
    assert str(caught.value) == f"{tmp_path / 'nope.toml'}: no such file; expected a scenario file (.toml)"


# -- API -----------------------------------------------------------------------------


def test_with_changes_checks_fields(tmp_path):
    write_models(tmp_path / "models")
    scenario = load_scenario(write_scenario(tmp_path))
    faster = scenario.with_changes(speed=50.0)
    assert faster.flight_time() == pytest.approx(scenario.flight_time() / 2)
    with pytest.raises(FieldError) as caught:
        scenario.with_changes(speed=-1)
    assert str(caught.value) == ("flight.speed_mps = -1: expected a number greater than 0 and at most 1000")
    with pytest.raises(FieldError) as caught:
        scenario.with_changes(flight=FlightPlan(None, []))
    assert caught.value.field == "flight.segments"


def test_load_scene_reads_both_models(tmp_path):
    pytest.importorskip("ladartui.scene.model")
    write_models(tmp_path / "models")
    scene = load_scenario(write_scenario(tmp_path)).load_scene()
    assert len(scene.voxels) == 4 and len(scene.target) == 3
    assert scene.voxel_size == 0.5


def test_new_scenario_orbits_the_target_centre(tmp_path):
    pytest.importorskip("ladartui.scene.voxels")
    target = ((10, 20, 0), (12, 20, 0), (10, 24, 2), (12, 24, 2))
    scene = write_models(tmp_path, "woods", target)
    scenario = Scenario.new(tmp_path / "new.toml", "woods.txt", 0.5)
    centre = np.mean(target, axis=0) * 0.5  # (5.5, 11, 0.5)
    for pose in scenario.poses():
        assert math.dist((pose.x, pose.y), centre[:2]) == pytest.approx(scenario.flight.segments[0].radius)
    assert scenario.scene_file == scene
    saved = scenario.save()
    assert load_scenario(saved.path) == scenario


def test_points_a_new_scenario_and_aim_all_write_are_rounded_to_millimetres(tmp_path):
    """The centroid went into the file as 29.88051470588235 beside hand-written 29.881."""
    pytest.importorskip("ladartui.scene.voxels")
    from ladartui.tui import bridge

    target = ((10, 20, 0), (12, 20, 0), (11, 23, 1))  # centroid (11, 21, 1/3) voxels
    write_models(tmp_path, "woods", target)
    scenario = Scenario.new(tmp_path / "new.toml", "woods.txt", 0.3)
    assert scenario.flight.segments[0].centre == (3.3, 6.3, 0.1)  # (3.3, 6.3, 0.0999...) m
    aimed = bridge.aim_all(scenario, (29.88051470588235, 29.902573529411764, 0.9264705882352942))
    assert aimed.flight.segments[0].aim_at == (29.881, 29.903, 0.926)
    assert "29.88051" not in aimed.save().path.read_text()


def test_a_start_pose_taken_from_the_first_scan_is_written_as_a_person_would(tmp_path):
    """An orbit turned into a straight took the orbit's first scan as its start, and the
    file read 'depression = 44.55443822900466'."""
    import re

    from ladartui.flight import Straight
    from ladartui.tui import bridge

    write_models(tmp_path, "woods", ((10, 20, 0), (12, 20, 0), (11, 23, 1)))
    scenario = Scenario.new(tmp_path / "new.toml", "woods.txt", 0.3)
    first = scenario.poses()[0]
    straight = bridge.with_segments(scenario, [Straight(distance=100.0, scans=5)])
    start = straight.flight.start
    assert start is not None and start.to_dict() == pytest.approx(first.to_dict(), abs=1e-6)
    text = straight.save().path.read_text()
    start_table = text[text.index("[flight.start]") :].split("\n\n")[0]
    assert not re.search(r"\.\d{7}", start_table), start_table
    moved = bridge.with_param(scenario, "start.x", 5.0).flight.start  # one field typed
    assert moved is not None and moved.x == 5.0 and moved.depression == start.depression


def test_summary_describes_the_collection(tmp_path):
    write_models(tmp_path / "models")
    scenario = load_scenario(write_scenario(tmp_path))
    text = scenario.summary()
    assert "10 scans: straight (2), orbit (8)" in text
    assert f"{scenario.path_length():.1f} m" in text
    assert "32x32 detectors, 2x2 rays each" in text
    assert f"{32 * 32 * 4 * 10:,} in all" in text
    assert "case_Scene.txt, case_Target.txt, case.cmf" in text


def test_summary_writes_a_huge_flight_time_with_an_exponent(tmp_path):
    # At speed_mps = 1e-300 validate printed the time as 300 digits; run's table said 3.6e+302 s.
    scenario = load_scenario(write_scenario(tmp_path), check_files=False).with_changes(speed=1e-300)
    line = next(line for line in scenario.summary().splitlines() if " s at " in line)
    assert (
        line.strip() == f"path {scenario.path_length():.1f} m, {scenario.flight_time():.4g} s at 1e-300 m/s"
    )
    assert "e+" in line and len(line) < 80


@pytest.mark.parametrize("name", ["orbit", "flypast", "standoff", "manoeuvres"])
def test_example_scenarios_are_valid(name):
    example = PROJECT / "scenarios" / f"{name}.toml"
    scenario = load_scenario(example, check_files=False)
    assert scenario.scene_file == PROJECT / "scenarios" / "generated" / "small.txt"
    assert len(scenario.poses()) >= 4
    assert "ladartui generate small scenarios/generated/small" in example.read_text()


def test_validate_command(tmp_path, capsys):
    from ladartui.cli import main

    write_models(tmp_path / "models")
    good = write_scenario(tmp_path)
    assert main(["validate", str(good)]) == 0
    assert "10 scans" in capsys.readouterr().out
    bad = write_scenario(tmp_path, edited("grid = 32", "grid = 0"), name="bad.toml")
    assert main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"ladartui: error: {bad}:{line_of(BASE, 'grid = 32')}: sensor.grid = 0: "
        "expected an integer from 1 to 1024\n"
    )


def test_validate_notes_a_start_pose_the_path_does_not_use(tmp_path, capsys):
    """A [flight.start] before an orbit went unmentioned; the TUI greys it out and says why."""
    from ladartui.cli import main

    write_models(tmp_path / "models")
    straight = BASE[
        BASE.index('[[flight.segments]]\nkind = "straight"') : BASE.index(
            '[[flight.segments]]\nkind = "orbit"'
        )
    ]
    unused = write_scenario(tmp_path, BASE.replace(straight, ""), name="orbit.toml")
    assert main(["validate", str(unused)]) == 0
    assert (
        "\nnote       [flight.start] is not used: the path starts at its first segment (orbit), "
        "which places its own scans\n"
    ) in capsys.readouterr().out
    assert main(["validate", str(write_scenario(tmp_path))]) == 0  # a straight run flies from it
    assert "[flight.start]" not in capsys.readouterr().out


def test_text_parses_like_a_file(tmp_path):
    scenario = scenario_from_toml(BASE, tmp_path / "x.toml")
    assert scenario.path == tmp_path / "x.toml"
    assert scenario.flight.segments[1] == Orbit((10.0, 10.0, 1.0), 60.0, 60.0, 8)


def test_round_trip_of_arbitrary_values(tmp_path):
    hypothesis = pytest.importorskip("hypothesis")
    st = hypothesis.strategies
    metres = st.floats(-5000, 5000, allow_nan=False)
    positive = st.floats(0.01, 5000, allow_nan=False)

    @hypothesis.settings(max_examples=25, deadline=None)
    @hypothesis.given(
        centre=st.tuples(metres, metres, st.floats(0, 30)),
        radius=positive,
        altitude=st.floats(500, 5000),
        scans=st.integers(1, 12),
        bearing=st.floats(0, 359.9),
        fov=st.floats(0.01, 89.9),
        pitch_um=st.floats(0.5, 5000),
        depth=st.floats(0, 100),
        voxel=st.floats(0.01, 100),
    )
    def check(centre, radius, altitude, scans, bearing, fov, pitch_um, depth, voxel):
        plan = FlightPlan(None, [Orbit(centre, radius, altitude, scans, start_bearing=bearing)])
        scenario = Scenario(
            tmp_path / "s.toml", "x.txt", voxel, Sensor(16, 2, fov, depth, pitch_um / 1e6), plan
        )
        again = scenario_from_toml(scenario.to_toml(), scenario.path)
        assert again == scenario
        assert again.to_toml() == scenario.to_toml()

    check()


def test_same_outputs_ignores_only_the_name_backend_and_fast_mode(tmp_path):
    scenario = load_scenario(write_scenario(tmp_path), check_files=False)
    assert scenario.same_outputs(scenario.with_changes(path=tmp_path / "other.toml"))
    assert scenario.same_outputs(scenario.with_changes(backend="numba", fast_mode=not scenario.fast_mode))
    grid = dataclasses.replace(scenario.sensor, grid=scenario.sensor.grid + 1)
    assert not scenario.same_outputs(scenario.with_changes(sensor=grid))
    assert not scenario.same_outputs(scenario.with_changes(speed=scenario.speed + 1.0))
    assert not scenario.same_outputs(scenario.with_changes(step=scenario.step * 2))


def test_a_scenario_saved_with_a_byte_order_mark_is_read(tmp_path):
    """Windows editors start UTF-8 with a BOM: it read as ':1: not valid TOML'."""
    from tiny_sweep import write_tiny_scenario

    scenario = write_tiny_scenario(tmp_path)
    text = scenario.path.read_text(encoding="utf-8")
    scenario.path.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    loaded = load_scenario(scenario.path)
    assert loaded.sensor == scenario.sensor and loaded.flight == scenario.flight
    loaded.with_changes(speed=12.0).save()  # saved again as UTF-8 without the mark
    assert scenario.path.read_bytes()[:1] == b"#" and load_scenario(scenario.path).speed == 12.0
    spec = tmp_path / "spec.toml"
    spec.write_bytes(b'\xef\xbb\xbf[sweep]\nscenario = "base.toml"\n[grid]\nradius = [20.0]\n')
    from ladartui.sweep import load_sweep_spec

    assert load_sweep_spec(spec).scenario_path == tmp_path / "base.toml"
    # the open dialog lists it, and a run record with a mark is still a record
    from ladartui.scenario_file import RECORD_HEADER, is_record
    from ladartui.tui.file_tree import opens_table

    plain = tmp_path / "plain.toml"
    plain.write_bytes(b"\xef\xbb\xbf[files]\nscene = 'tiny.txt'\n")
    assert opens_table(plain, "[files]")
    record = tmp_path / "base_Run.toml"
    record.write_bytes(b"\xef\xbb\xbf" + (RECORD_HEADER + "\n").encode("utf-8"))
    assert is_record(record)


def test_a_target_id_named_twice_is_refused(tmp_path):
    """names = { 1 = "alpha", 01 = "beta" }: "beta" won without a word."""
    from ladartui.errors import LadarError
    from tiny_sweep import write_tiny_scenario

    scenario = write_tiny_scenario(tmp_path)
    text = scenario.path.read_text(encoding="utf-8")
    scenario.path.write_text(text + '\n[targets]\nnames = { 1 = "alpha", 01 = "beta" }\n', encoding="utf-8")
    with pytest.raises(LadarError, match=r"targets\.names.*each target id once \(id 1 is named twice\)"):
        load_scenario(scenario.path)


@pytest.mark.parametrize("bad", [3, None, b"orbit.toml"])
def test_load_scenario_names_a_path_that_is_no_path(bad):
    """load_scenario(3) failed inside pathlib with a TypeError naming no argument."""
    with pytest.raises(FieldError, match=r"^path (= .*|is not set): expected a scenario file's path"):
        load_scenario(bad)


@pytest.mark.parametrize(
    ("field", "bad", "message"),
    [
        ("path", None, "path is not set: expected a scenario file's path (str or pathlib.Path)"),
        ("path", 3, "path = 3: expected a scenario file's path (str or pathlib.Path)"),
        ("scene_file", 3, "files.scene = 3: expected a scene model's path (str or pathlib.Path)"),
        ("scene_file", None, "files.scene is not set: expected a scene model's path (str or pathlib.Path)"),
    ],
)
def test_a_scenario_path_that_is_no_path_is_a_field_error(tmp_path, field, bad, message):
    """Scenario(path=None) and with_changes(scene_file=3) failed inside pathlib with a
    TypeError naming no field."""
    scenario = load_scenario(write_scenario(tmp_path), check_files=False)
    with pytest.raises(FieldError) as caught:
        scenario.with_changes(**{field: bad})
    assert str(caught.value) == message
    with pytest.raises(FieldError) as caught:
        dataclasses.replace(scenario, **{field: bad})
    assert str(caught.value) == message


def test_a_new_scenario_on_a_scene_without_a_target_names_its_empty_target_model(tmp_path):
    """A scene made with 'generate --no-target' (an empty target model) raised ValueError
    from the default orbit's sums ('zero-size array to reduction operation maximum')."""
    write_models(tmp_path, "woods", target=())
    with pytest.raises(InputFileError) as caught:
        Scenario.new(tmp_path / "new.toml", "woods.txt", 0.5)
    assert str(caught.value) == (
        f"{tmp_path / 'woods_Target.txt'}: target model holds no voxels; expected a target "
        "to circle (a new scenario's default orbit circles the target this file holds)"
    )


def test_a_new_scenario_on_a_missing_scene_model_names_that_file(tmp_path):
    """Scenario.new on a scene model that is not there blamed its target model, which the
    default orbit reads first: 'x_Target.txt: target model not found'."""
    with pytest.raises(InputFileError) as caught:
        Scenario.new(tmp_path / "new.toml", "models/x.txt", 0.5)
    assert (
        str(caught.value)
        == f"{tmp_path / 'models' / 'x.txt'}: no such file; expected a scene model (voxel list)"
    )
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "x.txt").mkdir()
    with pytest.raises(InputFileError, match=r"x\.txt: is a folder; expected a scene model"):
        Scenario.new(tmp_path / "new.toml", "models/x.txt", 0.5)


def test_a_new_scenario_checks_its_voxel_size_before_the_default_orbit(tmp_path):
    """Scenario.new(..., voxel_size="a") raised ValueError from the default orbit's sums."""
    write_models(tmp_path / "models")
    with pytest.raises(FieldError) as caught:
        Scenario.new(tmp_path / "new.toml", "models/forest.txt", "a")
    assert str(caught.value) == "files.voxel_size = 'a': expected a number from 0.001 to 100"


def test_check_files_given_text_is_refused_not_taken_as_true(tmp_path):
    """load_scenario(path, check_files="no") checked the files: text is true."""
    write_models(tmp_path / "models")
    path = tmp_path / "new.toml"
    Scenario.new(path, "models/forest.txt", 0.5).save()
    with pytest.raises(FieldError) as caught:
        load_scenario(path, check_files="no")
    assert str(caught.value) == "check_files = 'no': expected True or False"
    assert load_scenario(path, check_files=False).path == path


@pytest.mark.parametrize("name, kind", [("survey.las", "a LAS point cloud"), ("truck.obj", "a mesh")])
def test_a_new_scenario_on_a_scene_file_of_another_kind_is_named_as_such(tmp_path, name, kind):
    """New (the TUI's form, the API) on a survey's point cloud asked for survey_Target.las
    for its default orbit, with nothing on the cloud not being a scene model."""
    from ladartui.scenario import Scenario

    scene = tmp_path / name
    scene.write_bytes(b"LASF" if name.endswith(".las") else b"v 0 0 0\n")
    with pytest.raises(FieldError) as caught:
        Scenario.new(tmp_path / "plan.toml", scene, 0.5)
    assert caught.value.field == "files.scene"
    advice = (
        f": make one from it with 'ladartui voxelize {scene} {tmp_path / 'survey'} --voxel-size 0.5'"
        if name.endswith(".las")
        else ""
    )
    assert str(caught.value) == (
        f"files.scene = '{scene}': expected a voxel list (.txt), not {kind} ({scene.suffix}){advice}"
    )
