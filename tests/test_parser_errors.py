"""Bad input is one line of the project's own error, never a traceback.

Regression tests for each parser traceback once seen, then model files and files
given for another kind (the fuzzers over the same readers: test_parser_fuzz.py).
"""

import json
from pathlib import Path

import numpy as np
import pytest

from cli_support import one_error_line
from ladartui.cli import main
from ladartui.errors import LadarError
from ladartui.scenario import load_scenario, scenario_from_toml
from ladartui.scene.voxels import EXPECTED, load_voxels, save_voxels
from ladartui.sweep.spec import load_sweep_spec
from scenario_support import VALID_SCENARIO

# ---------------------------------------------------------------- regressions


def test_voxel_index_of_4301_digits(tmp_path):
    path = tmp_path / "big.txt"
    path.write_text("0,0," + "9" * 4301 + "\n")
    with pytest.raises(
        LadarError,
        match=r"big.txt:1: z = 999999999999\.\.\.\(4301 digits\) is "
        "too large",
    ) as caught:
        load_voxels(path)
    assert len(str(caught.value)) < 200


def test_segment_kind_a_list(tmp_path):
    with pytest.raises(LadarError, match=r"flight.segments\[0\].kind = \[\]: expected one of"):
        scenario_from_toml('[files]\nscene = "s.txt"\n[[flight.segments]]\nkind = []\n', tmp_path / "k.toml")


def test_arrays_nested_1000_deep(tmp_path):
    text = '[files]\nscene = "s.txt"\nx = ' + "[" * 1000 + "]" * 1000 + "\n"
    with pytest.raises(LadarError, match="nested too deep"):
        scenario_from_toml(text, tmp_path / "deep.toml")
    spec = tmp_path / "spec.toml"
    spec.write_text('[sweep]\nscenario = "default"\nx = ' + "[" * 1000 + "]" * 1000 + "\n")
    with pytest.raises(LadarError, match="spec.toml: not valid TOML: arrays or tables nested"):
        load_sweep_spec(spec)


def test_file_name_of_5000_characters(tmp_path, capsys):
    assert main(["validate", str(tmp_path / ("a" * 5000 + ".toml"))]) == 2
    err = one_error_line(capsys)
    assert len(err) < 1000


@pytest.mark.parametrize(
    "rule, key",
    [
        ("radius = { min = -1e308, max = 1e308 }", "random.radius"),
        ("scans = { min = 1, max = 1e300 }", "random.scans"),
    ],
)
def test_random_bounds_that_overflow(tmp_path, rule, key):
    spec = tmp_path / "spec.toml"
    spec.write_text(f'[sweep]\nscenario = "default"\n[random]\nsamples = 3\n{rule}\n')
    with pytest.raises(
        LadarError,
        match=rf"spec.toml:5: {key}: expected numbers with min <= max, "
        "within",
    ):
        load_sweep_spec(spec)


# ---------------------------------------------------------------- model files


@pytest.mark.parametrize(
    "text, rows",
    [
        (b"0,0,0\r\n1,2,3\r\n", [[0, 0, 0], [1, 2, 3]]),  # Windows line ends are fine
        (b"1 , 2 ,3\n4,5,6\r", [[1, 2, 3], [4, 5, 6]]),
    ],
)
def test_crlf_line_ends_are_read(tmp_path, text, rows):
    (tmp_path / "v.txt").write_bytes(text)
    assert load_voxels(tmp_path / "v.txt").tolist() == rows


@pytest.mark.parametrize(
    "text, message",
    [
        (b"0,0,0\n1,2\r,3\n", r"v.txt:2: stray carriage return \(\\r\) in '1,2\\r,3'"),
        (b"0,0,0\n1,\r2,3\n", r"v.txt:2: stray carriage return"),
        (b"0,0,0\n\r\r\n1,1,1\n", r"v.txt:2: stray carriage return"),
    ],
)
def test_stray_carriage_return_is_an_error(tmp_path, text, message):
    (tmp_path / "v.txt").write_bytes(text)
    with pytest.raises(LadarError, match=message):
        load_voxels(tmp_path / "v.txt")


def write_scenario(folder, scene_text):
    (folder / "m.txt").write_bytes(scene_text)
    save_voxels(folder / "m_Target.txt", np.array([[0, 0, 0]], np.int32))
    path = folder / "plan.toml"  # (m.toml would write m_Target.txt over the target model)
    path.write_text(VALID_SCENARIO.replace("s.txt", "m.txt"))
    return path


def test_a_huge_value_is_cut_so_that_what_was_expected_shows(tmp_path, capsys):
    """20,000 manual poses filled the 400-character line with the list, and what was
    expected (at most 10,000 poses) was cut off."""
    pose = "{ x = 1, y = 0, z = 60, heading = 0, azimuth = 0, depression = 45 }"
    orbit = VALID_SCENARIO[VALID_SCENARIO.index("[[flight.segments]]") :]
    manual = f'[[flight.segments]]\nkind = "manual"\nposes = [{", ".join([pose] * 20_000)}]\n'
    path = tmp_path / "plan.toml"
    path.write_text(VALID_SCENARIO.replace(orbit, manual))
    assert main(["validate", str(path)]) == 2
    line = one_error_line(capsys)
    assert "... (20,000 items): expected " in line and "more characters)" not in line, line


def test_validate_reads_the_model_files(tmp_path, capsys):
    path = write_scenario(tmp_path, b"0,0,0\n1,x,2\n")
    assert main(["validate", str(path)]) == 2
    err = one_error_line(capsys)
    assert "m.txt:2: y = 'x' is not a whole number" in err


def test_validate_summary_gives_scene_size_and_memory(tmp_path, capsys):
    path = write_scenario(tmp_path, b"0,0,0\n1,2,3\n9,4,5\n")
    assert main(["validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert "scene      3 voxels, target 1 voxel; extent 10 x 5 x 6 voxels" in out  # not "1 voxels"
    assert "memory     about " in out and "available" in out


def test_validate_refuses_a_scene_too_large_for_memory(tmp_path, capsys):
    """Its root grid (4 bytes a 512-voxel cell of the box) alone: about 64 TiB; two voxels
    2^31 apart on x alone take 16 MiB since their column tops are left out."""
    path = write_scenario(tmp_path, b"0,0,0\n2147483647,2147483647,0\n")
    assert main(["validate", str(path)]) == 2
    assert "m.txt: 2 voxels spanning 2147483648 x 2147483648 x 1 voxels need about" in one_error_line(capsys)


def las_with(tmp_path, offset, value):
    import struct

    from ladartui.scene.las import export_las

    voxels = np.array([(x, y, z) for x in range(6) for y in range(5) for z in range(2)], np.int32)
    path = tmp_path / "c.las"
    export_las(path, voxels, 0.25)
    data = bytearray(path.read_bytes())
    data[offset : offset + 8] = struct.pack("<d", value)  # x scale at 131, x offset at 155
    path.write_bytes(bytes(data))
    return path


@pytest.mark.parametrize(
    "offset, value, message",
    [
        (131, float("nan"), r"c.las: header scale factors \(nan, "),
        (131, 0.0, r"c.las: header scale factors \(0, .*expected finite non-zero"),
        (155, float("inf"), r"c.las: header offsets \(inf, 0, 0\): expected finite"),
        (155, 1e308, r"c.las: header offsets \(1e\+308, .* too large for the scale factors"),
    ],
)
def test_las_with_degenerate_scale_or_offset_is_refused(tmp_path, offset, value, message):
    from ladartui.scene.las import import_las

    with pytest.raises(LadarError, match=message):
        import_las(las_with(tmp_path, offset, value), 0.25)


def test_las_points_that_collapse_are_reported(tmp_path):
    import laspy

    from ladartui.scene.las import _check_no_collapse

    path = las_with(tmp_path, 155, 0.0)
    cloud = laspy.read(path)
    points = np.stack([np.asarray(cloud.x), np.asarray(cloud.y), np.asarray(cloud.z)], axis=1)
    _check_no_collapse(path, cloud, points)  # distinct points stay distinct
    # Rounded to whole metres, as a huge offset rounds them, neighbours merge.
    with pytest.raises(LadarError, match=r"c.las: 60 distinct stored points collapse to 4 once"):
        _check_no_collapse(path, cloud, np.floor(points))


def test_flag_errors_escape_what_the_user_typed(capsys):
    with pytest.raises(SystemExit):
        main(["validate", "x.toml", "\n\x1b]0;PWNED\x07"])
    err = capsys.readouterr().err  # told by validate's own parser, as its other flags are
    assert err.count("\n") == 1 and err.startswith("ladartui validate: error: unrecognized arguments:")
    assert "\\x0a\\x1b]0;PWNED\\x07" in err


def test_a_scenario_path_that_is_a_folder_or_not_text_says_so_in_words(tmp_path):
    with pytest.raises(LadarError) as folder:
        load_scenario(tmp_path)
    assert str(folder.value) == f"{tmp_path}: is a folder; expected a scenario file (.toml)"
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00junk")
    with pytest.raises(LadarError) as undecodable:
        load_scenario(binary)
    assert (
        str(undecodable.value) == f"{binary}:1: not UTF-8 text (byte 0xff); expected a scenario file (.toml)"
    )


def test_a_folder_given_as_a_sweep_spec_results_table_or_measures_file_says_so_in_words(tmp_path):
    """'sweep /tmp' said '/tmp: cannot read: Is a directory', with nothing of what was expected."""
    from ladartui.cmf import read_cmf
    from ladartui.sweep.table import read_table

    readers = (
        (load_sweep_spec, "expected a sweep spec (.toml)"),
        (read_table, "expected the sweep results table (CSV)"),
        (read_cmf, "expected a measures file (.cmf)"),
    )
    for read, expected in readers:
        with pytest.raises(LadarError) as caught:
            read(tmp_path)
        assert str(caught.value) == f"{tmp_path}: is a folder; {expected}"


def test_text_that_is_not_utf8_is_named_on_its_line(tmp_path):
    """A Latin-1 comment said only "not UTF-8 text" of a scenario, and Python's "'utf-8' codec
    can't decode byte 0xe9 in position 24" of a sweep spec or its results table."""
    from ladartui.sweep.table import read_table

    latin = b"# made by hand\n# caf\xe9\n"
    readers = (
        (load_scenario, "s.toml", "expected a scenario file (.toml)"),
        (load_sweep_spec, "spec.toml", "expected a sweep spec (.toml)"),
        (read_table, "results.csv", "expected the sweep results table (CSV)"),
    )
    for read, name, expected in readers:
        path = tmp_path / name
        path.write_bytes(latin)
        with pytest.raises(LadarError) as caught:
            read(path)
        assert str(caught.value) == f"{path}:2: not UTF-8 text (byte 0xe9); {expected}"


@pytest.mark.parametrize(
    "name, data, what",
    [
        ("forest.laz", b"LASF\x00\x00\x01\x02binary", "a LAS point cloud (.laz)"),
        ("truck.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "a mesh (.obj)"),
    ],
)
def test_a_point_cloud_or_mesh_given_as_a_voxel_list_is_named(tmp_path, capsys, name, data, what):
    """A scenario's files.scene, trace --scene or voxelize --into naming a .laz said
    'binary data, not text', and an .obj "1 comma-separated values in 'v 0 0 0'"."""
    path = tmp_path / name
    path.write_bytes(data)
    with pytest.raises(LadarError) as caught:
        load_voxels(path)
    assert str(caught.value) == f"{path}: {what}, not a voxel list; {EXPECTED}"
    np.save(tmp_path / "rays.npy", np.array([[1.0, 1.0, 9.0, 0.0, 0.0, -1.0]]))
    command = [
        "trace",
        "--scene",
        str(path),
        "--rays",
        str(tmp_path / "rays.npy"),
        "--out",
        str(tmp_path / "h.npy"),
    ]
    assert main(command) == 2
    assert capsys.readouterr().err == f"ladartui: error: {path}: {what}, not a voxel list; {EXPECTED}\n"


@pytest.mark.parametrize(
    "name, data, what",
    [
        ("small.txt", b"0,0,0\n1,2,3\n", "a voxel list (.txt)"),
        ("truck.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "a mesh (.obj)"),
        ("forest.laz", b"LASF\x00\xff\x01\x02binary", "a LAS point cloud (.laz)"),
    ],
)
def test_a_voxel_list_mesh_or_point_cloud_given_as_a_scenario_is_named(tmp_path, capsys, name, data, what):
    """'run small.txt' said "not valid TOML: Expected '=' after a key", and a .laz
    'not UTF-8 text (byte 0xff)'."""
    path = tmp_path / name
    path.write_bytes(data)
    assert main(["run", str(path)]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: {path}: {what}, not a scenario; expected a scenario file (.toml)"
    )


def test_binary_data_given_as_a_voxel_list_says_so(tmp_path):
    path = tmp_path / "rays.npy"
    np.save(path, np.zeros((2, 6)))
    with pytest.raises(LadarError) as caught:
        load_voxels(path)
    assert str(caught.value).startswith(f"{path}:1: binary data, not text; expected three")


def test_a_json_that_is_no_study_names_what_it_lacks(tmp_path):
    from ladartui.study.results import read_study

    (tmp_path / "j.json").write_text('{"a": 1}')
    (tmp_path / "bad.json").write_text("{\n")
    with pytest.raises(LadarError) as lacking:
        read_study(tmp_path / "j.json")
    assert (
        str(lacking.value)
        == f"{tmp_path / 'j.json'}: no 'rows' entry; expected a study.json written by 'ladartui study'"
    )
    with pytest.raises(LadarError) as broken:
        read_study(tmp_path / "bad.json")
    assert str(broken.value).startswith(f"{tmp_path / 'bad.json'}:2: not JSON (")
    # a RecursionError, an AttributeError and 'list indices' traceback or words before
    good = json.loads((Path(__file__).parent.parent / "docs" / "study.json").read_text())
    good["rows"][0]["misses"] = "x"
    cases = {
        "deep.json": "[" * 3000 + "]" * 3000,
        "misses.json": json.dumps(good),
        "list.json": "[1, 2]",
        "latin.json": b'{"a": "\xe9"}',
    }
    for name, text in cases.items():
        path = tmp_path / name
        path.write_bytes(text if isinstance(text, bytes) else text.encode())
        with pytest.raises(LadarError) as caught:
            read_study(path)
        said = str(caught.value)
        assert said.startswith(f"{path}: ") and "\n" not in said and "list indices" not in said, said
    assert "not UTF-8" in str(pytest.raises(LadarError, read_study, tmp_path / "latin.json").value)


@pytest.mark.parametrize(
    ("command", "missing"),
    [
        ("study --chart-from {d}/nope.json --out {d}/out", "nope.json"),
        ("validate {d}/nope.toml", "nope.toml"),
        ("run {d}/nope.toml", "nope.toml"),
        ("tui {d}/nope.toml", "nope.toml"),
        ("sweep {d}/nope.toml", "nope.toml"),
        ("info {d}/nope.txt", "nope.txt"),
        ("trace --scene {d}/s.txt --rays {d}/nope.npy --out {d}/h.npy", "nope.npy"),
        ("voxelize {d}/nope.obj {d}/v.txt --voxel-size 1", "nope.obj"),
    ],
)
def test_a_missing_input_file_says_no_such_file_in_every_command(tmp_path, capsys, command, missing):
    """study said "cannot read it (No such file or directory)", scenarios "scenario file not
    found", sweep "no such sweep spec", trace --rays "no such file" with nothing expected."""
    (tmp_path / "s.txt").write_text("0,0,0\n")
    assert main(command.format(d=tmp_path).split()) == 2
    assert one_error_line(capsys).startswith(
        f"ladartui: error: {tmp_path / missing}: no such file; expected "
    )


def test_a_folder_given_as_a_study_json_is_named_a_folder(tmp_path, capsys):
    """It said "cannot read it (Is a directory)"."""
    assert main(["study", "--chart-from", str(tmp_path), "--out", str(tmp_path / "out")]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: {tmp_path}: is a folder; expected a study.json written by 'ladartui study'"
    )


def test_validate_notes_an_empty_or_misplaced_target_model(tmp_path, capsys):
    from ladartui.resources import gib

    path = write_scenario(tmp_path, b"0,0,0\n1,2,3\n9,4,5\n")
    (tmp_path / "m_Target.txt").write_text("")
    assert main(["validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert "note       m_Target.txt holds no voxels: the target measures will be undefined" in out
    (tmp_path / "m_Target.txt").write_text("0,0,0\n50,50,50\n60,50,50\n")
    assert main(["validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert (
        "note       2 of 3 target voxels are not in the scene model m.txt: the scene run cannot see them"
        in out
    )
    (tmp_path / "m_Target.txt").write_text("50,50,50\n")  # said '1 of 1 target voxels are not'
    assert main(["validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert (
        "note       1 of 1 target voxel is not in the scene model m.txt: the scene run cannot see it" in out
    )
    assert gib(4096) == "4 KiB" and gib(100) == "100 bytes" and gib(3 * 2**20) == "3 MiB"


def test_a_missing_or_folder_path_is_said_so_whatever_its_suffix(tmp_path, capsys):
    """The suffix named the kind of any file that failed: a mistyped 'nothere.laz' read
    'a LAS point cloud (.laz), not a voxel list', a folder 'dir.txt' given as a scenario
    'a voxel list (.txt), not a scenario'."""
    import os

    with pytest.raises(LadarError) as caught:
        load_voxels(tmp_path / "nothere.laz")
    assert str(caught.value).startswith(f"{tmp_path / 'nothere.laz'}: no such file; ")
    (tmp_path / "dir.obj").mkdir()
    with pytest.raises(LadarError) as caught:
        load_voxels(tmp_path / "dir.obj")
    assert str(caught.value) == f"{tmp_path / 'dir.obj'}: is a folder; expected a voxel-list file"
    (tmp_path / "dir.txt").mkdir()
    os.mkfifo(tmp_path / "pipe.txt")
    for name, said in (("dir.txt", "is a folder"), ("pipe.txt", "is not a regular file")):
        assert main(["validate", str(tmp_path / name)]) == 2
        err = one_error_line(capsys)
        assert err.startswith(f"ladartui: error: {tmp_path / name}: {said}"), err
