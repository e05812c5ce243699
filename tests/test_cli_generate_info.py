"""``ladartui generate`` and ``ladartui info`` through the command-line entry point."""

import re

import numpy as np
import pytest

from cli_support import one_error_line
from ladartui.cli import main
from ladartui.scene.generate import generate_scene
from ladartui.scene.voxels import load_voxels, save_voxels


def test_generate_writes_the_pair_and_reports_it(tmp_path, capsys):
    stem = tmp_path / "scenes" / "forest"
    assert main(["generate", "small", str(stem), "--seed", "3", "--density", "0.5"]) == 0
    out = capsys.readouterr().out
    expected = generate_scene("small", seed=3, density=0.5)
    scene = load_voxels(tmp_path / "scenes" / "forest.txt")
    target = load_voxels(tmp_path / "scenes" / "forest_Target.txt")
    np.testing.assert_array_equal(scene, expected.voxels)
    np.testing.assert_array_equal(target, expected.target)
    assert f"({len(scene):,} voxels)" in out and f"({len(target):,} voxels)" in out
    assert "voxel size 0.25 m" in out
    assert "area 60 x 60 m (240 x 240 voxels of 0.25 m)" in out
    assert "extent x 0..239, y 0..239, z 0.." in out
    x, y, z = expected.target_centre
    assert f"target centre ({x:.2f}, {y:.2f}, {z:.2f}) m" in out


def test_generate_gives_the_extent_the_file_reads_back_with_and_the_area_laid_out(tmp_path, capsys):
    """'generate reference' said 'extent 1500 x 1500 x 900 voxels', the preset's grid,
    where info on the file it wrote said 'z 0..279': a voxel list keeps no empty space."""
    stem = tmp_path / "ref"
    assert main(["generate", "reference", str(stem), "--trees", "2"]) == 0
    said = dict(line.split(" ", 1) for line in capsys.readouterr().out.splitlines())
    assert main(["info", str(tmp_path / "ref.txt")]) == 0
    info = dict(line.strip().split(None, 1) for line in capsys.readouterr().out.splitlines()[1:])
    assert said["extent"] == info["extent"]  # "x 667..842, y 710..840, z 0..262  (shape ...)"
    assert said["area"] == "150 x 150 m (1500 x 1500 voxels of 0.1 m)"
    assert "900" not in said["extent"]


def test_generate_accepts_a_txt_stem_and_options(tmp_path, capsys):
    out_path = tmp_path / "plain.txt"
    assert main(["generate", "small", str(out_path), "--no-target", "--terrain", "--trees", "10"]) == 0
    assert (tmp_path / "plain.txt").is_file()
    assert load_voxels(tmp_path / "plain_Target.txt").shape == (0, 3)
    out = capsys.readouterr().out
    assert "no target" in out and "terrain" in out


def test_generate_refuses_an_empty_out(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["generate", "small", ""]) == 2
    assert (
        capsys.readouterr().err == "ladartui: error: OUT = '': expected a name such as dir/name or a folder\n"
    )
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("name", ["forest.toml", "forest.laz", "forest.obj"])
def test_generate_refuses_an_out_named_as_another_kind_of_file(tmp_path, capsys, monkeypatch, name):
    """'forest.toml' wrote forest.toml.txt and forest.toml_Target.txt."""
    monkeypatch.chdir(tmp_path)
    assert main(["generate", "small", name]) == 2
    assert capsys.readouterr().err == (
        f"ladartui: error: OUT = {name!r}: expected a stem such as dir/name or dir/name.txt "
        f"(it writes name.txt and name_Target.txt), not a .{name.rsplit('.', 1)[1]} file name\n"
    )
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("name", ["forest_Target", "forest_Target.txt"])
def test_generate_refuses_an_out_named_as_a_target_model(tmp_path, capsys, monkeypatch, name):
    """'forest_Target.txt' wrote a scene over forest.txt's target model."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "forest_Target.txt").write_text("1,2,3\n")
    assert main(["generate", "small", name]) == 2
    assert capsys.readouterr().err == (
        f"ladartui: error: OUT = {name!r}: expected the scene's stem, such as forest "
        "(it writes forest.txt and forest_Target.txt), not a target model's name\n"
    )
    assert [p.name for p in tmp_path.iterdir()] == ["forest_Target.txt"]
    assert (tmp_path / "forest_Target.txt").read_text() == "1,2,3\n"


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--no-target", "--vehicles", "3"], "--no-target and --vehicles 3 contradict each other: drop one"),
        (
            ["--no-target", "--camouflage"],
            "--camouflage: the net is draped over a vehicle, and there is none",
        ),
        (
            ["--vehicles", "0", "--camouflage"],
            "--camouflage: the net is draped over a vehicle, and there is none",
        ),
    ],
)
def test_generate_refuses_flags_it_would_ignore(tmp_path, capsys, flags, message):
    """--no-target dropped --vehicles and --camouflage without a word."""
    assert main(["generate", "small", str(tmp_path / "x"), *flags]) == 2
    assert capsys.readouterr().err == f"ladartui: error: {message}\n"
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("folder", ["g/", "existing"])
def test_generate_into_a_folder_names_the_files_after_the_preset(tmp_path, capsys, monkeypatch, folder):
    """'generate small g/' wrote g.txt beside the folder."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "existing").mkdir()
    assert main(["generate", "small", folder, "--trees", "3"]) == 0
    where = tmp_path / folder.rstrip("/")
    assert sorted(p.name for p in where.iterdir()) == ["small.txt", "small_Target.txt"]
    assert not (tmp_path / f"{folder.rstrip('/')}.txt").exists()
    assert f"wrote {where.name}/small.txt" in capsys.readouterr().out


def test_generate_las_copy(tmp_path, capsys):
    laspy = pytest.importorskip("laspy")
    assert main(["generate", "small", str(tmp_path / "f"), "--las", "--trees", "5"]) == 0
    cloud = laspy.read(tmp_path / "f.laz")
    assert len(cloud.x) == len(load_voxels(tmp_path / "f.txt"))


def test_generate_without_las_names_the_copies_an_earlier_scene_left(tmp_path, capsys):
    """f.laz and f_Target.laz of an earlier scene stayed beside the new f.txt without a word."""
    assert main(["generate", "small", str(tmp_path / "f"), "--las", "--trees", "5"]) == 0
    capsys.readouterr()
    assert main(["generate", "small", str(tmp_path / "f"), "--trees", "3"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == (
        "note: f.laz and f_Target.laz are from an earlier scene, not this one (--las writes them again)"
    )


def test_generate_rejects_bad_input_on_one_line(tmp_path, capsys):
    assert main(["generate", "huge", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert err == "ladartui: error: PRESET = 'huge': expected one of small, reference\n"  # as the usage line
    assert main(["generate", "small", str(tmp_path / "x"), "--seed", "-1"]) == 2
    assert capsys.readouterr().err == "ladartui: error: --seed = -1: expected a non-negative whole number\n"
    assert main(["generate", "small", str(tmp_path / "x"), "--density", "2"]) == 2
    assert capsys.readouterr().err == "ladartui: error: --density = 2.0: expected a number from 0 to 0.99\n"
    assert main(["generate", "small", str(tmp_path / "x"), "--vehicles", "1000"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ladartui: error: --vehicles = 1000: expected at most ")
    assert not list(tmp_path.iterdir())


def test_info_describes_a_voxel_list_and_its_target(tmp_path, capsys):
    (tmp_path / "s.txt").write_text("0,0,0\n5,2,9\n5,2,9\n3,7,1\n")
    (tmp_path / "s_Target.txt").write_text("3,7,1\n4,4,4\n")
    assert main(["info", str(tmp_path / "s.txt"), "--voxel-size", "0.5"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"voxels\s+3 \(1 duplicate line dropped\)", out)
    assert "x 0..5, y 0..7, z 0..9  (shape 6 x 8 x 10)" in out
    assert "3 x 4 x 5 at 0.5 m" in out
    assert "s_Target.txt: 2 voxels, 1 of them in the scene" in out
    assert "centre (3.5, 5.5, 2.5) voxels = (1.75, 2.75, 1.25) m" in out
    pytest.importorskip("ladartui.scene.occupancy")
    assert re.search(r"occupancy\s+\d+\.\d MiB \(2 bricks, 1 tile, 1 region\), built in", out)


def test_info_and_validate_give_a_scene_the_same_extent(tmp_path, capsys):
    """info said 18.2 m where validate said 18.25 m for the same scene."""
    scenario = pytest.importorskip("ladartui.scenario")
    (tmp_path / "s.txt").write_text("5,5,0\n9,9,72\n")
    (tmp_path / "s_Target.txt").write_text("5,5,0\n")
    assert main(["info", str(tmp_path / "s.txt"), "--voxel-size", "0.25"]) == 0
    assert re.search(
        r"extent \(m\)\s+1.25 x 1.25 x 18.25 at 0.25 m \(2.5 x 2.5 x 18.25 from the origin\)\n",
        capsys.readouterr().out,
    )
    path = tmp_path / "plan.toml"
    scenario.Scenario.new(path, tmp_path / "s.txt", 0.25).save()
    assert main(["validate", str(path)]) == 0
    assert "extent 10 x 10 x 73 voxels = 2.5 x 2.5 x 18.25 m" in capsys.readouterr().out


def test_info_gives_in_metres_the_span_its_index_line_gives(tmp_path, capsys):
    """'extent x 35..190, ...' was followed by 'extent (m) 47.75 x ...', the shape from
    the origin in metres, not the 39 m the voxels span."""
    (tmp_path / "s.txt").write_text("35,43,0\n190,195,70\n")
    assert main(["info", str(tmp_path / "s.txt"), "--voxel-size", "0.25"]) == 0
    rows = [line.split(None, 1)[1] for line in capsys.readouterr().out.splitlines()[1:]]
    assert "x 35..190, y 43..195, z 0..70  (shape 191 x 196 x 71)" in rows
    assert "(m)  39 x 38.25 x 17.75 at 0.25 m (47.75 x 49 x 17.75 from the origin)" in rows


def test_info_says_an_extent_in_metres_once_where_the_voxels_start_at_the_origin(tmp_path, capsys):
    """'extent (m) 60 x 60 x 18.25 at 0.25 m (shape 60 x 60 x 18.25)': the same metres
    twice, the second called a shape as if it counted voxels."""
    (tmp_path / "s.txt").write_text("0,0,0\n239,239,72\n")
    assert main(["info", str(tmp_path / "s.txt"), "--voxel-size", "0.25"]) == 0
    rows = [line.split(None, 1)[1] for line in capsys.readouterr().out.splitlines()[1:]]
    assert "(m)  60 x 60 x 18.25 at 0.25 m" in rows


def test_an_extent_in_metres_is_written_as_people_write_it():
    from ladartui.number_text import extent_metres

    assert extent_metres((1500, 1501, 73), 0.1) == "150 x 150.1 x 7.3"  # not 150.00000000000003
    assert extent_metres((3, 2_000_000, 2**31 - 1), 50.0) == "150 x 100000000 x 1.074e+11"


def test_info_without_target_file(tmp_path, capsys):
    (tmp_path / "lonely.txt").write_text("1,1,1\n")
    assert main(["info", str(tmp_path / "lonely.txt")]) == 0
    out = capsys.readouterr().out
    assert "none (lonely_Target.txt not found)" in out
    (tmp_path / "lonely_Target.txt").mkdir()  # it was said 'not found' too
    assert main(["info", str(tmp_path / "lonely.txt")]) == 0
    assert "none (lonely_Target.txt is a folder" in capsys.readouterr().out
    (tmp_path / "lonely_Target.txt").rmdir()
    pytest.importorskip("ladartui.scene.occupancy")
    assert "(1 brick, 1 tile, 1 region)" in out  # not "1 bricks, 1 tiles, 1 regions"
    (tmp_path / "lonely_Target.txt").write_text("1,1,1\n")
    assert main(["info", str(tmp_path / "lonely.txt")]) == 0
    assert "lonely_Target.txt: 1 voxel, 1 of them in the scene" in capsys.readouterr().out


def test_info_on_a_target_model_looks_for_no_target_model_of_it(tmp_path, capsys):
    """It said "target  none (lonely_Target_Target.txt not found)"."""
    (tmp_path / "lonely_Target.txt").write_text("1,1,1,1\n2,1,1,2\n")
    assert main(["info", str(tmp_path / "lonely_Target.txt")]) == 0
    rows = {line.split()[0]: line for line in capsys.readouterr().out.splitlines()[1:]}
    assert "target" not in rows and rows["targets"].split(None, 1)[1] == "2 targets (ids 1, 2)"


def test_info_reads_x_y_z_id_lines_as_a_target_model_whatever_its_name(tmp_path, capsys):
    """voxelize MESH truck.txt --id 7 writes x,y,z,id lines; info on it said 'truck.txt:1: 4
    comma-separated values in '0,0,0,7'; expected three non-negative integers x,y,z'."""
    (tmp_path / "truck.txt").write_text("0,0,0,7\n1,0,0,7\n")
    assert main(["info", str(tmp_path / "truck.txt")]) == 0
    rows = {line.split()[0]: line for line in capsys.readouterr().out.splitlines()[1:]}
    assert rows["voxels"].split(None, 1)[1] == "2"
    assert "target" not in rows and rows["targets"].split(None, 1)[1] == "1 target (id 7)"
    (tmp_path / "bad.txt").write_text("0,0,0,7\n1,0,0\n")  # nor a target model
    assert main(["info", str(tmp_path / "bad.txt")]) == 2
    said = one_error_line(capsys).removeprefix("ladartui: error: ")
    assert said.startswith(f"{tmp_path / 'bad.txt'}:1: 4 comma-separated values in '0,0,0,7'")


def test_info_on_a_runs_outputs_says_they_are_a_runs_outputs(tmp_path, capsys):
    """S_Scene.txt was said to have no target model (S_Scene_Target.txt not found), and
    S_Target.txt, the voxels the target-only run saw, was read as a target model."""
    (tmp_path / "S_Run.toml").write_text("# ladartui run record: the settings that made ...\n")
    (tmp_path / "S_Scene.txt").write_text("1,1,1\n2,2,2\n")
    (tmp_path / "S_Target.txt").write_text("1,1,1\n")
    assert main(["info", str(tmp_path / "S_Scene.txt")]) == 0
    rows = {line.split()[0]: line.split(None, 1)[1] for line in capsys.readouterr().out.splitlines()[1:]}
    assert "target" not in rows
    assert (
        rows["output"]
        == "the scene run's returns of a run of S.toml (S_Run.toml); S_Target.txt: the target run's"
    )
    assert main(["info", str(tmp_path / "S_Target.txt")]) == 0
    rows = {line.split()[0]: line.split(None, 1)[1] for line in capsys.readouterr().out.splitlines()[1:]}
    assert "targets" not in rows
    assert (
        rows["output"]
        == "the target run's returns of a run of S.toml (S_Run.toml); S_Scene.txt: the scene run's"
    )


def test_info_on_a_run_output_changed_since_the_run_does_not_claim_it_as_validate(tmp_path, capsys):
    """An output changed after its run (a line appended) was still 'the scene run's
    returns of a run of S.toml' in info, while validate said it was not the run's output."""
    from ladartui.simulation import simulate
    from test_output_set import make_scenario

    scenario = make_scenario(tmp_path)
    simulate(scenario)
    with open(scenario.scene_output, "a", encoding="utf-8") as handle:
        handle.write("1,2,3\n")

    def output_row(path):
        assert main(["info", str(path)]) == 0
        rows = capsys.readouterr().out.splitlines()[1:]
        return next(row.split(None, 1)[1] for row in rows if row.split()[0] == "output")

    assert output_row(scenario.scene_output) == (
        "changed since the run of S.toml wrote it (S_Run.toml): it is not the run's output"
    )
    # nor does info on the other output vouch for this one
    assert output_row(scenario.target_output) == (
        "the target run's returns of a run of S.toml (S_Run.toml); S_Scene.txt, the scene run's, "
        "changed since"
    )
    assert main(["validate", str(scenario.path)]) == 0
    assert "last run   S_Scene.txt changed since the run wrote it: it is not the run's output" in (
        capsys.readouterr().out.splitlines()
    )


def test_a_missing_voxel_list_is_said_missing_without_the_line_format(tmp_path, capsys):
    """'nothere.txt: no such file; expected three non-negative integers x,y,z ...': the
    format of lines of a file that is not there."""
    for name in ("nothere.txt", "nothere_Target.txt"):
        assert main(["info", str(tmp_path / name)]) == 2
        assert (
            one_error_line(capsys)
            == f"ladartui: error: {tmp_path / name}: no such file; expected a voxel-list file"
        )


def test_info_bad_file_is_one_line(tmp_path, capsys):
    (tmp_path / "bad.txt").write_text("1,2,3\n1,2\n")
    assert main(["info", str(tmp_path / "bad.txt")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"ladartui: error: {tmp_path / 'bad.txt'}:2: 2 comma-separated values")
    assert err.count("\n") == 1
    assert main(["info"]) == 2
    assert "needs a FILE" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["truck.obj", "truck.STL", "truck.ply"])
def test_info_on_a_mesh_says_what_it_takes_and_how_a_mesh_is_voxelised(tmp_path, capsys, name):
    """An OBJ was read as a voxel list: "1 comma-separated values in 'v -1 -2.5 0'"."""
    mesh = tmp_path / name
    mesh.write_text("v -1 -2.5 0\nv 1 -2.5 0\nv 0 2.5 0\nf 1 2 3\n")
    assert main(["info", str(mesh)]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: {mesh}: a mesh ({mesh.suffix}); info takes a voxel list (.txt) or a "
        "scenario (.toml): voxelise the mesh first with 'ladartui voxelize MESH OUT --voxel-size V'"
    )


@pytest.mark.parametrize(
    ("name", "what"), [("S_Scene.laz", "a LAS point cloud (.laz)"), ("S.cmf", "a measures file (.cmf)")]
)
def test_info_on_a_point_cloud_or_measures_file_says_what_it_takes(tmp_path, capsys, name, what):
    """Outputs written beside the voxel lists were read as voxel lists: "S_Scene.laz:1:
    binary data, not text" and "S.cmf:1: 2 comma-separated values in '# ladartui ..."."""
    path = tmp_path / name
    path.write_bytes(
        b"LASF\x00\x01" if name.endswith(".laz") else b"# ladartui comparison measures, format cmf 2\n"
    )
    assert main(["info", str(path)]) == 2
    advice = (
        ": make a scene model of it with 'ladartui voxelize CLOUD OUT --voxel-size V'"
        if "LAS" in what
        else ""
    )
    assert one_error_line(capsys) == (
        f"ladartui: error: {path}: {what}; info takes a voxel list (.txt) or a scenario (.toml){advice}"
    )


def test_info_scenario_summary(tmp_path, capsys):
    scenario = pytest.importorskip("ladartui.scenario")
    generated = generate_scene("small", seed=0, trees=4)
    generated.write(tmp_path / "forest")
    path = tmp_path / "plan.toml"
    scenario.Scenario.new(path, tmp_path / "forest.txt", generated.voxel_size).save()
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert out.strip() == scenario.load_scenario(path).summary().strip()
    # a scenario gives its own voxel size: the option was ignored without a word
    assert main(["info", str(path), "--voxel-size", "0.5"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        "ladartui: error: --voxel-size = 0.5: expected no --voxel-size with a scenario: "
        "it gives its own (files.voxel_size); the option is for a voxel list"
    )


def test_a_voxel_size_with_no_voxel_list_is_refused(capsys, monkeypatch):
    """'info --backends --voxel-size 1' listed the backends and dropped the size without a word."""
    import ladartui.cli.info as info

    monkeypatch.setattr(info, "print_backends", lambda: print("backends"))
    assert main(["info", "--backends", "--voxel-size", "1"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == (
        "ladartui: error: --voxel-size = 1.0: expected a FILE too: it sets a voxel list's size\n"
    )


def test_info_backends_lists_each_backend(capsys):
    backend = pytest.importorskip("ladartui.tracing.backend")
    status = backend.backend_status()
    assert main(["info", "--backends"]) == 0
    out = capsys.readouterr().out
    for name, reason in status.items():
        assert re.search(rf"{name}\s+│ (available|unavailable)", out)
        if reason is None:
            first_key = next(iter(backend.get_backend(name).describe()))
            assert first_key in out
    # What auto traces with here, under the table.
    from ladartui.tracing import auto_summary

    assert f"auto: {auto_summary()}" in " ".join(out.split())


def test_info_takes_a_bundled_scenario_by_name(tmp_path, capsys, monkeypatch):
    """'info convoy' read the name as a voxel list: 'no such file; expected three
    non-negative integers'. run, validate and the TUI take the name."""
    monkeypatch.chdir(tmp_path)
    assert main(["info", "default"]) == 0
    out = capsys.readouterr().out
    assert "default_Scene.txt, default_Target.txt, default.cmf" in out, out


def test_info_and_validate_count_target_voxels_in_the_scene_by_sorted_keys(tmp_path, capsys, monkeypatch):
    """np.isin took 4.4 of info's 6 s on the 3.8-million-voxel reference scene (its hashed
    unique of both key arrays); the scene's keys sorted once and searched take 0.2 s."""
    import numpy as np

    from ladartui.scenario import Scenario

    save_voxels(tmp_path / "s.txt", np.array([[0, 0, 0], [1, 2, 3], [4, 4, 4]], np.int32))
    save_voxels(tmp_path / "s_Target.txt", np.array([[1, 2, 3], [9, 9, 9]], np.int32))
    Scenario.new(tmp_path / "plan.toml", tmp_path / "s.txt", 1.0).save()

    def slow(*args, **kwargs):
        raise AssertionError("np.isin")

    monkeypatch.setattr(np, "isin", slow)
    assert main(["info", str(tmp_path / "s.txt")]) == 0
    assert "s_Target.txt: 2 voxels, 1 of them in the scene" in capsys.readouterr().out
    assert main(["validate", str(tmp_path / "plan.toml")]) == 0
    assert "1 of 2 target voxels is not in the scene model s.txt" in capsys.readouterr().out
