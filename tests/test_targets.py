"""Several targets in one target model: the x,y,z,id file, names, measures per target."""

import json

import numpy as np
import pytest

from ladartui.cmf import measures_from_dict, read_cmf
from ladartui.errors import FieldError, InputFileError
from ladartui.flight import FlightPlan, Manual, ScanPose
from ladartui.measures import compute_measures
from ladartui.scenario import Scenario, load_scenario
from ladartui.scene.generate import generate_scene
from ladartui.scene.model import Scene
from ladartui.scene.target_model import load_target
from ladartui.scene.voxels import load_voxels, save_voxels
from ladartui.sensor import Sensor
from ladartui.simulation import simulate
from ladartui.target_measures import compute_target_measures


def box(x0, x1, y0, y1, z0, z1):
    return np.array(
        [(x, y, z) for x in range(x0, x1) for y in range(y0, y1) for z in range(z0, z1)], dtype=np.int32
    )


# --------------------------------------------------------------------------- the file


def test_four_column_file_round_trip_is_exact(tmp_path):
    voxels = np.array([[5, 0, 2], [0, 0, 0], [70000, 3, 1], [1, 2, 3]], dtype=np.int32)
    ids = np.array([2, 1, 65535, 2], dtype=np.int32)
    path = tmp_path / "m_Target.txt"
    save_voxels(path, voxels, ids=ids)
    assert path.read_text().splitlines()[0] == "5,0,2,2"
    got, got_ids = load_target(path)
    assert np.array_equal(got, voxels) and np.array_equal(got_ids, ids)


def test_large_four_column_file_round_trip_through_the_compiled_writer_and_reader(tmp_path):
    from ladartui.scene import voxels as module

    rng = np.random.default_rng(3)
    voxels = rng.integers(0, 5000, (module._COMPILED_FORMAT_ROWS + 10_000, 3)).astype(np.int32)
    voxels = np.unique(voxels, axis=0)[::-1]  # unique, in an order that is not sorted
    assert len(voxels) >= module._COMPILED_FORMAT_ROWS  # the compiled formatter's side of the limit
    ids = rng.integers(1, 65536, len(voxels))
    path = tmp_path / "big_Target.txt"
    save_voxels(path, voxels, ids=ids)
    assert path.stat().st_size > module._PLAIN_BYTES  # read by the compiled parser
    got, got_ids = load_target(path)
    assert np.array_equal(got, voxels) and np.array_equal(got_ids, ids)


def test_four_column_file_through_the_compiled_parser(tmp_path):
    # Spaces and CR LF leave the array fast path: the checked kernel reads 4 columns too.
    path = tmp_path / "m_Target.txt"
    path.write_bytes(b"1, 2, 3, 4\r\n5,6,7,1\r\n\r\n")
    voxels, ids = load_target(path)
    assert voxels.tolist() == [[1, 2, 3], [5, 6, 7]] and ids.tolist() == [4, 1]


def test_three_column_target_file_is_one_target(tmp_path):
    path = tmp_path / "m_Target.txt"
    path.write_text("1,2,3\n4,5,6\n1,2,3\n")
    voxels, ids = load_target(path)
    assert voxels.tolist() == [[1, 2, 3], [4, 5, 6]] and ids.tolist() == [1, 1]
    assert np.array_equal(load_voxels(path), voxels)


@pytest.mark.parametrize(
    "text, line, words",
    [
        ("1,2,3\n4,5,6,2\n", 2, "4 comma-separated values in '4,5,6,2' but the file's first line has 3"),
        ("1,2,3,1\n4,5,6\n", 2, "3 comma-separated values in '4,5,6' but the file's first line has 4"),
        ("1,2,3,1\n4,5,6,0\n", 2, "id = 0 is not a target id"),
        ("1,2,3,65536\n", 1, "id = 65536 is not a target id"),
        ("1,2,3,-4\n", 1, "id = -4 is not a target id"),
        ("1,2,3,x\n", 1, "id = 'x' is not a whole number"),
        ("1,2,3,1\n1,2,3,2\n", 2, "voxel 1,2,3 is target 2 here but target 1 on line 1"),
    ],
)
def test_bad_target_lines_are_one_line_naming_file_and_line(tmp_path, text, line, words):
    path = tmp_path / "m_Target.txt"
    path.write_text(text)
    with pytest.raises(InputFileError) as caught:
        load_target(path)
    message = str(caught.value)
    assert message.startswith(f"{path}:{line}: ") and "\n" not in message
    assert words in message
    assert "x,y,z or x,y,z,id" in message or "each voxel in one target" in message


def test_scene_model_keeps_three_columns(tmp_path):
    path = tmp_path / "m.txt"
    path.write_text("1,2,3,1\n")
    with pytest.raises(InputFileError, match="4 comma-separated values.*three non-negative integers"):
        load_voxels(path)


def test_las_carries_the_target_ids(tmp_path):
    from ladartui.scene.las import export_las, import_las, import_las_target

    voxels = np.array([[0, 0, 0], [3, 1, 2], [7, 7, 0], [2, 2, 2]], dtype=np.int32)
    ids = np.array([1, 3, 65535, 3])
    path = tmp_path / "t.laz"
    export_las(path, voxels, 0.25, origin=(0.0, 0.0, 0.0), ids=ids)
    got, got_ids, _ = import_las_target(path, 0.25, origin=(0.0, 0.0, 0.0))
    assert np.array_equal(got, voxels) and got_ids.tolist() == ids.tolist()
    assert np.array_equal(import_las(path, 0.25, origin=(0.0, 0.0, 0.0))[0], voxels)
    plain = tmp_path / "plain.las"
    export_las(plain, voxels, 0.25)  # no ids: source id 0 on every point reads as one target
    assert import_las_target(plain, 0.25)[1].tolist() == [1, 1, 1, 1]
    # Two targets' points in one voxel cannot be told apart: refused, one line.
    export_las(path, np.array([[0, 0, 0], [0, 0, 1]]), 0.1, ids=np.array([1, 2]))
    with pytest.raises(InputFileError, match="holds points of targets 1 and 2"):
        import_las_target(path, 1.0)


def test_generator_labels_each_vehicle(tmp_path):
    scene = generate_scene("small", trees=4, vehicles=3, camouflage=True)
    assert sorted(set(scene.target_ids.tolist())) == [1, 2, 3]
    centres = [scene.target[scene.target_ids == k].mean(axis=0) for k in (1, 2, 3)]
    # Each id is one vehicle: its voxels lie together, metres away from the others'.
    for k in range(3):
        part = scene.target[scene.target_ids == k + 1]
        assert np.abs(part[:, :2] - centres[k][:2]).max() * 0.25 < 4.0
    assert min(np.linalg.norm(centres[i] - centres[j]) for i, j in ((0, 1), (0, 2), (1, 2))) * 0.25 > 10
    # The net (scene, not target) lies over vehicle 1, the one at the centre.
    assert np.allclose(centres[0][:2] * 0.25, (30.0, 30.0), atol=1.0)
    _, target_path = scene.write(tmp_path / "c")
    assert target_path.read_text().count(",") == 3 * len(scene.target)
    loaded = Scene.load(tmp_path / "c.txt", 0.25)
    assert np.array_equal(loaded.target, scene.target) and np.array_equal(loaded.target_ids, scene.target_ids)
    # One vehicle keeps the report's three columns (outputs as before).
    single = generate_scene("small", trees=4)
    _, target_path = single.write(tmp_path / "one")
    assert target_path.read_text().splitlines()[0].count(",") == 2


# --------------------------------------------------------------------------- measures

OPEN = box(10, 14, 10, 14, 0, 3)  # 48 voxels, roof 16, 8 hidden inside
ROOFED = box(24, 28, 10, 13, 0, 2)  # 24 voxels, roof 12, 2 hidden inside
ROOF = box(19, 34, 4, 19, 5, 6)  # solid, 3 voxels above ROOFED, wider than any ray reaches


def two_box_scenario(tmp_path, names=None):
    target = np.concatenate([OPEN, ROOFED])
    ids = np.array([1] * len(OPEN) + [2] * len(ROOFED))
    save_voxels(tmp_path / "boxes.txt", np.concatenate([target, ROOF]))
    save_voxels(tmp_path / "boxes_Target.txt", target, ids=ids)
    # Nadir over each box centre: diverging rays from above enter only the roof
    # of the box below (or the solid roof over it); 5 degrees half-view reaches
    # 6.2 m from the centre at the ground, short of the other box.
    poses = (ScanPose(12.0, 12.0, 50.0, depression=90.0), ScanPose(26.0, 11.5, 50.0, depression=90.0))
    return Scenario(
        tmp_path / "S.toml",
        "boxes.txt",
        1.0,
        Sensor(grid=32, ray_grid=2, fov=10.0, depth_resolution=0.5),
        FlightPlan(segments=[Manual(poses)]),
        speed=25.0,
        backend="numba",
        target_names=names or (),
    )


def test_two_boxes_one_under_a_roof(tmp_path):
    scenario = two_box_scenario(tmp_path, names=((2, "roofed"),))
    m = simulate(scenario, write=False).measures
    # All targets together, as before.
    assert m.target_voxels == 72
    assert m.unobscured_coverage == pytest.approx(28 / 72)
    assert m.obscured_coverage == pytest.approx(16 / 72)
    per = m.targets
    assert [(t.target_id, t.name) for t in per.targets] == [(1, "target 1"), (2, "roofed")]
    a, b = (t.measures for t in per.targets)
    assert (a.target_voxels, a.visible_voxels, b.target_voxels, b.visible_voxels) == (48, 40, 24, 22)
    assert (a.unobscured_voxels, a.obscured_voxels) == (16, 16)
    assert (b.unobscured_voxels, b.obscured_voxels) == (12, 0)
    assert a.missed_share == 0.0 and b.missed_share == 1.0
    assert a.unobscured_directions.mean_direction == pytest.approx((0.0, 0.0, 1.0), abs=1e-9)
    assert b.obscured_directions.count == 0 and b.direction_shift_rad is None
    assert a.obscured_after_scan == (1 / 3, 1 / 3) and b.obscured_after_scan == (0.0, 0.0)
    assert b.unobscured_after_scan == (0.0, 0.5)
    # Worst and mean follow from the two.
    worst, mean = per.worst, per.mean
    assert worst.obscured_coverage == 0.0 and mean.obscured_coverage == pytest.approx(1 / 6)
    assert worst.unobscured_coverage == pytest.approx(1 / 3)
    assert mean.unobscured_coverage == pytest.approx(5 / 12)
    assert worst.maximum_coverage == pytest.approx(40 / 48)
    assert mean.maximum_coverage == pytest.approx((40 / 48 + 22 / 24) / 2)
    assert worst.missed_share == 1.0 and mean.missed_share == 0.5
    assert worst.unobscured_after_scan == (0.0, pytest.approx(1 / 3))
    assert mean.unobscured_after_scan == (pytest.approx(1 / 6), pytest.approx(5 / 12))
    # Undefined for one target: the worst and mean are over the others.
    assert worst.direction_shift_rad == a.direction_shift_rad
    # Each target's own levels: the open box's roof (16 of its 40 visible voxels, every
    # footprint column) is seen at scan 1; the roofed box is never seen through.
    reached = {
        t.target_id: [(r.level, r.scan) for r in t.measures.levels.levels if r.reached] for t in per.targets
    }
    assert reached == {1: [("detect", 1), ("recognise", 1)], 2: []}
    assert a.levels.visible_share == pytest.approx(16 / 40) and a.levels.footprint_share == 1.0
    assert a.levels.level("identify").describe() == "not reached"
    assert a.levels.level("detect").distance_m == 0.0


def test_new_cmf_and_json_round_trip_exactly(tmp_path):
    scenario = two_box_scenario(tmp_path, names=((1, 'open "A" [b]'), (2, "roofed")))
    result = simulate(scenario)
    written = read_cmf(scenario.measures_file)
    assert written == result.measures
    assert written.targets.targets[0].name == 'open "A" [b]'
    text = scenario.measures_file.read_text()
    assert text.startswith("# ladartui comparison measures, format cmf 2\n")
    assert "[target 2 / obscured 3d target output]" in text and "[targets / worst]" in text
    data = json.loads(json.dumps(result.measures.to_dict(), allow_nan=False))
    assert data["targets"]["worst"]["obscured_coverage"] == 0.0
    assert measures_from_dict(data) == result.measures


def test_single_target_fields_keep_meaning_all_targets():
    target = np.concatenate([OPEN, ROOFED])
    ids = np.array([1] * len(OPEN) + [2] * len(ROOFED))
    seen = np.concatenate([OPEN[:5], ROOFED[:7]])
    overall = compute_measures(target, seen, target)
    per = compute_target_measures(target, ids, seen, target)
    assert overall.obscured_voxels == sum(t.measures.obscured_voxels for t in per.targets) == 12
    single = compute_target_measures(OPEN, np.ones(len(OPEN), int), seen, target).targets[0].measures
    assert single == compute_measures(OPEN, seen, target)


OLD_CMF = """# ladartui comparison measures, format cmf 1
# shares are fractions 0..1, angles radians, lengths metres, times seconds;

[3d target model]
target_voxels = 3
visible_voxels = 3
maximum_target_coverage = 1.0
directions_counted = 3
sample_mean_vector = -0.08663106189552978, 0.0, -0.08663106189552981
mean_resultant_length = 0.1225148226554413
mean_direction = -0.7071067811865474, 0.0, -0.7071067811865476

[unobscured 3d target output]
covered_voxels = 3
target_coverage = 1.0
directions_counted = 3
sample_mean_vector = -0.08663106189552978, 0.0, -0.08663106189552981
mean_resultant_length = 0.1225148226554413
mean_direction = -0.7071067811865474, 0.0, -0.7071067811865476

[obscured 3d target output]
covered_voxels = 2
target_coverage = 0.6666666666666666
directions_counted = 2
sample_mean_vector = 0.09366020490668425, 0.0, -0.5771601883432527
mean_resultant_length = 0.5847102846637648
mean_direction = 0.16018224300696737, 0.0, -0.9870874576374968

[comparison]
shift_in_mean_direction_rad = 0.9462734405957693
missed_share = 0.3333333333333333
coverage_ratio = 0.6666666666666666
obscured_only_voxels = 0

[coverage after each scan]
scans = 2
scans_for_90_percent_of_final = 2
scan_1 = 0.3333333333333333, 0.6666666666666666
scan_2 = 0.6666666666666666, 1.0

[flight]
path_length_m = 10.0
flight_time_s = 0.5
voxel_size_m = 0.25
"""


def test_old_single_target_cmf_still_reads(tmp_path):
    path = tmp_path / "old.cmf"
    path.write_text(OLD_CMF)
    t = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 1]])
    expected = compute_measures(
        t,
        t[:2],
        t,
        scene_per_scan=[t[:1], t[1:2]],
        target_per_scan=[t[:2], t[2:]],
        path_length_m=10.0,
        flight_time_s=0.5,
        voxel_size=0.25,
    )
    assert read_cmf(path) == expected and expected.targets is None
    # Per-target sections belong to format 2 only.
    path.write_text(OLD_CMF + '\n[target 1]\nname = "a"\n')
    with pytest.raises(InputFileError, match=r"old.cmf:\d+: unknown section \[target 1\]"):
        read_cmf(path)


def test_target_count_must_match_in_cmf(tmp_path):
    scenario = two_box_scenario(tmp_path)
    simulate(scenario)
    text = scenario.measures_file.read_text().replace("count = 2", "count = 3")
    scenario.measures_file.write_text(text)
    with pytest.raises(InputFileError, match=r"count = 3 but 2 targets follow"):
        read_cmf(scenario.measures_file)


def test_a_cmf_cut_short_in_a_targets_measures_names_that_target(tmp_path):
    """A file cut in a target's sections read that target as undefined measures."""
    scenario = two_box_scenario(tmp_path)
    simulate(scenario)
    lines = scenario.measures_file.read_text().splitlines(keepends=True)
    path = tmp_path / "cut.cmf"
    header = lines.index("[target 2 / comparison]\n") + 1
    path.write_text("".join(lines[: header + 1]))
    with pytest.raises(InputFileError) as error:
        read_cmf(path)
    said = (
        f"{path}:{header}: [target 2 / comparison] lacks missed_share, coverage_ratio, obscured_only_voxels"
    )
    assert str(error.value) == said
    section = lines.index("[target 2 / coverage after each scan]\n")
    first_scan = next(i for i in range(section, len(lines)) if lines[i].startswith("scan_1 "))
    path.write_text("".join(lines[: first_scan + 1]))
    with pytest.raises(InputFileError) as error:
        read_cmf(path)
    scans_line = section + 2
    assert lines[scans_line - 1] == "scans = 2\n"
    said = f"{path}:{scans_line}: [target 2 / coverage after each scan] scans = 2 but 1 scan_k line follows"
    assert str(error.value) == said
    path.write_text("".join(lines[:section]))  # ends with a blank line after the comparison
    with pytest.raises(InputFileError) as error:
        read_cmf(path)
    last = section - 1  # the comparison's last key: where target 2's measures end
    assert lines[last - 1].startswith("obscured_only_voxels = ")
    assert str(error.value) == f"{path}:{last}: lacks the [target 2 / coverage after each scan] section"


# --------------------------------------------------------------------------- names


def test_target_names_in_the_scenario(tmp_path):
    scenario = two_box_scenario(tmp_path, names=((2, "van"), (1, "truck")))
    saved = scenario.save()
    text = saved.path.read_text()
    assert '[targets.names]\n1 = "truck"\n2 = "van"\n' in text
    loaded = load_scenario(saved.path)
    assert loaded.target_names == ((1, "truck"), (2, "van"))
    assert loaded.target_name(2) == "van" and loaded.target_name(7) == "target 7"
    for bad in ('2 = ""', '0 = "none"', "2 = 5"):
        saved.path.write_text(text.replace('2 = "van"', bad))
        with pytest.raises(FieldError, match=r"S.toml:\d+: targets.names = .*target id \(1..65535\)"):
            load_scenario(saved.path)


def test_run_prints_a_table_per_target_and_info_counts_them(tmp_path, capsys):
    from ladartui.cli import main

    scenario = two_box_scenario(tmp_path, names=((2, "[red]roofed"),)).save()
    assert main(["run", str(scenario.path), "--no-write"]) == 0
    out = capsys.readouterr().out
    assert "Measures per target (2 targets)" in out
    assert "[red]roofed" in out  # a name is text, not markup
    rows = {line.split("│")[1].strip(): line for line in out.splitlines() if line.count("│") > 5}
    assert rows["worst"].split("│")[5].strip() == "0.0%"  # obscured coverage column
    assert rows["mean"].split("│")[6].strip() == "50.0%"  # missed share column
    assert main(["run", str(scenario.path), "--no-write", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [t["name"] for t in data["measures"]["targets"]["per_target"]] == ["target 1", "[red]roofed"]
    assert main(["info", str(tmp_path / "boxes.txt")]) == 0
    assert "2 targets (ids 1, 2)" in capsys.readouterr().out


def test_run_prints_each_targets_levels_as_its_json_holds_them(tmp_path, capsys):
    """With several targets the table showed only the levels of all targets together:
    a target never detected went unmentioned, though --json held each target's levels."""
    from ladartui.cli import main

    scenario = two_box_scenario(tmp_path, names=((2, "roofed"),)).save()
    assert main(["run", str(scenario.path), "--no-write", "--json"]) == 0
    per_target = json.loads(capsys.readouterr().out)["measures"]["targets"]["per_target"]
    assert main(["run", str(scenario.path), "--no-write"]) == 0
    out = capsys.readouterr().out
    assert "Levels of all targets together" in out
    section = out[out.index("Levels per target") :]
    for target in per_target:
        levels = [target["measures"]["levels"][level] for level in ("detect", "recognise", "identify")]
        expected = [
            f"scan {level['scan']} ({level['flight_time_s']:.1f} s)" if level["reached"] else "not reached"
            for level in levels
        ]
        row = next(
            line for line in section.splitlines() if line.startswith(f"│ {target['id']} {target['name']} ")
        )
        assert [cell.strip() for cell in row.split("│")[2:-1]] == expected
    assert "not reached" in section


def test_convoy_is_made_on_first_use_with_three_named_targets():
    from ladartui.user_data import bundled_or_path

    path = bundled_or_path("convoy")
    assert path.name == "convoy.toml" and path.is_file()
    scenario = load_scenario(path)
    assert [name for _, name in scenario.target_names] == ["netted truck", "truck B", "truck C"]
    scene = scenario.load_scene()
    assert scene.target_id_list == [1, 2, 3]
    # Its orbit circles the centre of all three vehicles.
    centre = np.array(scenario.flight.segments[0].centre)
    assert np.allclose(centre, scene.target.mean(axis=0) * scene.voxel_size, atol=0.01)
    small = scenario.with_changes(sensor=Sensor(grid=24, ray_grid=1, fov=36.0), backend="numba")
    m = simulate(small).measures
    assert [t.name for t in m.targets.targets] == ["netted truck", "truck B", "truck C"]
    assert all(t.measures.obscured_after_scan is not None for t in m.targets.targets)
    # Its outputs sit beside it without touching its models: a second run reads the same.
    assert read_cmf(small.measures_file) == m
    assert load_scenario(path).load_scene().target_id_list == [1, 2, 3]


def test_a_run_never_overwrites_its_own_model_files(tmp_path):
    # Scenario forest.toml writes forest_Target.txt: the target model of forest.txt.
    scenario = two_box_scenario(tmp_path).with_changes(path=tmp_path / "boxes.toml")
    before = (tmp_path / "boxes_Target.txt").read_bytes()
    with pytest.raises(FieldError, match=r"boxes.toml: files.scene = 'boxes.txt'.*boxes_Target.txt would"):
        simulate(scenario)
    assert (tmp_path / "boxes_Target.txt").read_bytes() == before
    assert not (tmp_path / "boxes.cmf").exists()


def test_a_scene_named_after_its_scenario_is_refused_on_its_line(tmp_path, capsys):
    """The refusal named the scenario file but not the line of files.scene."""
    from ladartui.cli import main

    saved = two_box_scenario(tmp_path).with_changes(path=tmp_path / "boxes.toml").save()
    lines = saved.path.read_text().splitlines()
    line = next(number for number, text in enumerate(lines, start=1) if text.startswith("scene ="))
    assert main(["validate", str(saved.path)]) == 2
    assert capsys.readouterr().err.startswith(
        f"ladartui: error: {saved.path}:{line}: files.scene = 'boxes.txt': expected a scene model"
    )


@pytest.mark.parametrize(
    "names, said",
    [
        (((1, "open"), (3, "van")), "names id 3, which is not in"),
        (((3, "van"), (4, "car"), (5, "bus")), "names ids 3, 4 and 5, which are not in"),
    ],
)
def test_validate_notes_names_of_ids_the_target_model_lacks_in_good_grammar(tmp_path, capsys, names, said):
    """It said '[targets] names ids 3 are not in boxes_Target.txt'."""
    from ladartui.cli import main

    assert main(["validate", str(two_box_scenario(tmp_path, names).save().path)]) == 0
    assert f"\nnote       [targets] {said} boxes_Target.txt (its ids: 1, 2)\n" in capsys.readouterr().out


def test_las_outputs_mark_each_voxel_with_its_target(tmp_path):
    laspy = pytest.importorskip("laspy")
    scenario = two_box_scenario(tmp_path)
    result = simulate(scenario, las=True)
    for name, output in (("S_Target.las", result.target_output), ("S_Scene.las", result.scene_output)):
        cloud = laspy.read(tmp_path / name)
        voxels = np.floor(np.stack([cloud.x, cloud.y, cloud.z], axis=1) + 0.5).astype(int)
        assert {tuple(v) for v in voxels.tolist()} == {tuple(v) for v in np.asarray(output).tolist()}
        owner = {
            **dict.fromkeys(map(tuple, OPEN.tolist()), 1),
            **dict.fromkeys(map(tuple, ROOFED.tolist()), 2),
        }
        expected = [owner.get(tuple(v), 0) for v in voxels.tolist()]
        assert np.asarray(cloud.point_source_id).tolist() == expected
    # The scene output holds roof voxels (0) and the open box (1), never the roofed box.
    assert sorted(set(laspy.read(tmp_path / "S_Scene.las").point_source_id.tolist())) == [0, 1]


def test_chart_draws_each_targets_coverage(tmp_path):
    import xml.etree.ElementTree as ET

    from ladartui.charts import save_figure
    from ladartui.charts.coverage import coverage_figure

    scenario = two_box_scenario(tmp_path, names=((2, "cost $5 $x^2$"),))
    measures = simulate(scenario, write=False).measures
    path = save_figure(coverage_figure(measures), tmp_path / "c.svg")
    groups = {g.get("id"): g for g in ET.parse(path).iter("{http://www.w3.org/2000/svg}g") if g.get("id")}
    assert {"series-obscured", "series-unobscured", "target-1", "target-2"} <= set(groups)
    assert "cost $5 $x^2$" in path.read_text()  # the name as written, not as mathtext
