"""``ladartui voxelize``: target models from meshes, inserted into scene models, and its errors."""

import warnings

import numpy as np
import pytest
import trimesh

from cli_support import file_size_limit, one_error_line
from ladartui.cli import main
from ladartui.scene.model import Scene
from ladartui.scene.voxelize import Placement, load_mesh, merge_voxels, voxelize
from ladartui.scene.voxels import load_voxels, save_voxels


@pytest.fixture
def truck(tmp_path):
    """A closed 2 x 4 x 1.5 m box, as an STL file."""
    path = tmp_path / "truck.stl"
    trimesh.creation.box(extents=(2.0, 4.0, 1.5)).export(path)
    return path


@pytest.fixture
def forest(tmp_path):
    """A 6 x 6 m scene at 0.1 m (scattered plant voxels, a corner post) with a one-voxel target."""
    rng = np.random.default_rng(5)
    plants = rng.integers(0, 60, size=(400, 3))
    plants[:, 2] = rng.integers(10, 40, size=400)
    scene = np.vstack([plants, [[59, 59, 0], [0, 0, 0], [5, 55, 0]]])
    save_voxels(tmp_path / "forest.txt", scene)
    save_voxels(tmp_path / "forest_Target.txt", [[5, 55, 0]])
    return tmp_path / "forest.txt"


def test_writes_a_target_model_that_loads_back(tmp_path, truck, capsys):
    out = tmp_path / "models" / "truck_Target.txt"
    assert main(["voxelize", str(truck), str(out), "--voxel-size", "0.1", "--solid"]) == 0
    voxels = load_voxels(out)
    assert len(voxels) == 20 * 40 * 15  # faces on voxel boundaries: exactly the box
    np.testing.assert_array_equal(voxels, voxelize(load_mesh(truck), 0.1, solid=True).voxels)
    text = capsys.readouterr().out
    assert "12 triangles, closed; solid model of 12,000 voxels at 0.1 m" in text
    assert "voxels x 0..19, y 0..39, z 0..14 (2 x 4 x 1.5 m)" in text
    assert f"wrote {out}" in text


def test_adds_the_suffix_and_writes_surface_models(tmp_path, truck):
    assert main(["voxelize", str(truck), str(tmp_path / "shell"), "--voxel-size", "0.1"]) == 0
    assert len(load_voxels(tmp_path / "shell.txt")) == 20 * 40 * 15 - 18 * 38 * 13


def test_inserts_a_turned_vehicle_into_a_scene_and_its_target(tmp_path, truck, forest, capsys):
    before = load_voxels(forest)
    out = tmp_path / "with_truck"
    args = ["voxelize", str(truck), str(out), "--voxel-size", "0.1", "--solid"]
    assert main([*args, "--at", "3,2.9", "--heading", "30", "--into", str(forest)]) == 0
    vehicle = voxelize(load_mesh(truck), 0.1, Placement(3.0, 2.9, 0.0, 30.0), solid=True).voxels
    scene = Scene.load(tmp_path / "with_truck.txt", 0.1)  # the scene and target loaders
    np.testing.assert_array_equal(scene.voxels, merge_voxels(before, vehicle))
    np.testing.assert_array_equal(scene.target, merge_voxels([[5, 55, 0]], vehicle))
    # The turned vehicle keeps its voxel count within rounding: the box grown by a
    # voxel's reach in plan (a b + 1 + (a + b)(cos + sin) cells a layer, 15 layers).
    grown = (20 * 40 + 1 + 60 * (np.cos(np.pi / 6) + np.sin(np.pi / 6))) * 15
    assert abs(len(vehicle) - grown) / grown < 0.01
    # Same x-y location in both models: every target voxel is in the scene.
    assert {tuple(v) for v in scene.target.tolist()} <= {tuple(v) for v in scene.voxels.tolist()}
    occupied = len(before) + len(vehicle) - len(scene.voxels)
    text = capsys.readouterr().out
    assert f"({len(scene.voxels):,} voxels, {len(vehicle) - occupied:,} new)" in text
    assert np.array_equal(load_voxels(forest), before)  # the input scene is untouched


def test_insertion_in_place_replaces_both_files(tmp_path, truck, forest):
    args = ["voxelize", str(truck), str(forest), "--voxel-size", "0.1", "--at", "3.05,3.05"]
    assert main([*args, "--into", str(forest)]) == 0
    assert len(load_voxels(tmp_path / "forest_Target.txt")) == 1 + 20 * 40 * 15 - 18 * 38 * 13
    assert sorted(p.name for p in tmp_path.iterdir()) == ["forest.txt", "forest_Target.txt", "truck.stl"]


def test_a_scene_without_a_target_model_gets_one(tmp_path, truck, forest, capsys):
    (tmp_path / "forest_Target.txt").unlink()
    out = tmp_path / "new"
    args = ["voxelize", str(truck), str(out), "--voxel-size", "0.1", "--at", "3.05,3.05"]
    assert main([*args, "--into", str(forest)]) == 0
    assert len(load_voxels(tmp_path / "new_Target.txt")) == 20 * 40 * 15 - 18 * 38 * 13
    assert "a new target model" in capsys.readouterr().out


def test_a_vehicle_past_the_scene_edge_is_refused_and_nothing_written(tmp_path, truck, forest, capsys):
    args = ["voxelize", str(truck), str(tmp_path / "out"), "--voxel-size", "0.1", "--into", str(forest)]
    assert main([*args, "--at", "5.5,3"]) == 2
    line = one_error_line(capsys)
    assert line == (
        f"ladartui: error: {forest}: the vehicle would reach x = 6.550 m, past the scene's edge at "
        "x = 5.95 m; place it inside the scene"
    )
    assert not (tmp_path / "out.txt").exists() and not (tmp_path / "out_Target.txt").exists()


def test_open_mesh_in_solid_mode_is_one_line(tmp_path, capsys):
    shape = trimesh.creation.box(extents=(1, 1, 1))
    shape.faces = shape.faces[:-2]
    mesh = tmp_path / "open.obj"
    shape.export(mesh)
    assert main(["voxelize", str(mesh), str(tmp_path / "t"), "--voxel-size", "0.1", "--solid"]) == 2
    line = one_error_line(capsys)
    assert line.startswith(f"ladartui: error: {mesh}: not a closed mesh: 4 edges border only one triangle")
    assert "leave out --solid" in line
    assert not (tmp_path / "t.txt").exists()
    assert main(["voxelize", str(mesh), str(tmp_path / "t"), "--voxel-size", "0.1"]) == 0  # surface is fine


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("bad.obj", "v 0 0 0\nv 1 0\nf 1 2 3\n", "bad.obj:2: vertex 'v 1 0': expected x, y, z"),
        ("bad.ply", "ply\nformat nonsense\n", "bad.ply: not a readable PLY mesh"),
        ("empty.stl", "", "empty.stl: holds no triangles; expected a triangle mesh"),
    ],
)
def test_malformed_mesh_is_one_line(tmp_path, capsys, name, content, message):
    (tmp_path / name).write_text(content)
    assert main(["voxelize", str(tmp_path / name), str(tmp_path / "t"), "--voxel-size", "0.1"]) == 2
    line = one_error_line(capsys)
    assert line.startswith(f"ladartui: error: {tmp_path}/{message}")
    assert not (tmp_path / "t.txt").exists()


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--at", "1,x"], "--at = '1,x': expected X,Y or X,Y,Z in metres"),
        (["--heading", "30"], "--heading = 30.0: expected --at X,Y too"),
        (["--into", "scene.txt"], "--into = 'scene.txt': expected --at X,Y too"),
        (["--voxel-size", "-1"], "--voxel-size = -1.0: expected a number of metres from 0.001 to 100"),
        # the scene's voxel size: at most what a scenario takes
        (["--voxel-size", "1e308"], "--voxel-size = 1e+308: expected a number of metres from 0.001 to 100"),
        (["--at", "0.5,5"], "--at = '0.5,5': expected a position keeping the mesh inside the scene"),
        (["--at", "5,5,-1"], "--at = '5,5,-1': expected a height of 0 m or more above the ground"),
        # 1e23 degrees was taken: at that size a float holds no angle
        (["--at", "5,5", "--heading", "1e23"], "--heading = 1e+23: expected degrees clockwise from north, "),
    ],
)
def test_bad_flags_are_one_line(tmp_path, truck, capsys, extra, message):
    assert main(["voxelize", str(truck), str(tmp_path / "t"), "--voxel-size", "0.1", *extra]) == 2
    assert message in one_error_line(capsys)
    assert not (tmp_path / "t.txt").exists()


@pytest.mark.parametrize(
    "flags", [["--at", "-5,-5"], ["--at", "1,1", "--heading", "-1e1"], ["--at", "-.5,5"]]
)
def test_a_negative_value_is_taken_as_the_value_of_its_flag(tmp_path, truck, capsys, flags):
    """--at -5,-5 and --heading -1e1 stopped in argparse with 'argument --at: expected one
    argument' (only -5 and -0.5 read as numbers); --at=-5,-5 reached the command."""
    args = ["voxelize", str(truck), str(tmp_path / "t"), "--voxel-size", "0.25"]
    joined = [f"{flag}={value}" for flag, value in zip(flags[::2], flags[1::2])]
    assert main([*args, *joined]) == 2
    with_equals = one_error_line(capsys)
    assert main([*args, *flags]) == 2
    assert one_error_line(capsys) == with_equals
    assert with_equals.startswith("ladartui: error: --at = ") and "expected a position" in with_equals


@pytest.mark.parametrize("empty", ["SOURCE", "OUT", "--into"])
def test_an_empty_path_names_its_argument(tmp_path, truck, forest, capsys, monkeypatch, empty):
    """An empty OUT ended in a ValueError traceback; an empty SOURCE (MESH) was '.: is a folder' and
    an empty --into was taken as no --into."""
    monkeypatch.chdir(tmp_path)
    mesh, out = ("" if empty == "SOURCE" else str(truck)), ("" if empty == "OUT" else "t")
    into = "" if empty == "--into" else str(forest)
    assert main(["voxelize", mesh, out, "--voxel-size", "0.1", "--at", "3,3", "--into", into]) == 2
    assert one_error_line(capsys) == f"ladartui: error: {empty} = '': expected a file name"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["forest.txt", "forest_Target.txt", "truck.stl"]


def test_a_scene_named_as_a_target_model_is_refused(tmp_path, truck, forest, capsys):
    """OUT forest_Target.txt wrote the scene over forest.txt's target model (and its own target
    as forest_Target_Target.txt); --into forest_Target.txt took the target model as a scene."""
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    target = str(tmp_path / "forest_Target.txt")
    args = ["voxelize", str(truck), "--voxel-size", "0.1", "--at", "3,3"]
    assert main([*args, target, "--into", str(forest)]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: OUT = {target!r}: expected the scene's stem, such as forest "
        "(it writes forest.txt and forest_Target.txt), not a target model's name"
    )
    assert main([*args, str(tmp_path / "out"), "--into", target]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: --into = {target!r}: expected a scene model, such as forest.txt "
        "(its target model forest_Target.txt is read beside it), not a target model"
    )
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_out_naming_a_scene_model_without_into_is_refused(tmp_path, truck, forest, capsys):
    """'voxelize truck.stl forest --at 3,3' (--into forgotten) wrote the vehicle's target
    model over the scene model forest.txt, and the forest was gone."""
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    args = ["voxelize", str(truck), "--voxel-size", "0.1", "--at", "3,3"]
    for out in (tmp_path / "forest", forest):
        assert main([*args, str(out)]) == 2
        assert one_error_line(capsys) == (
            f"ladartui: error: OUT = {str(out)!r}: expected a new target model's name, not the scene "
            f"model {forest.name} (its target model forest_Target.txt is beside it); to add the "
            f"vehicle to that scene, give --into {forest.name}"
        )
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    # a target model written again is replaced as before
    assert main([*args, str(tmp_path / "truck_model")]) == 0
    assert main([*args, str(tmp_path / "truck_model")]) == 0


@pytest.mark.parametrize("slash", ["", "/"])
def test_a_folder_as_out_is_refused(tmp_path, truck, forest, capsys, slash):
    """OUT naming a folder ('models' or 'models/') wrote models.txt beside it, and with --into
    models.txt and models_Target.txt: the folder was taken as a file's stem."""
    (tmp_path / "models").mkdir()
    before = sorted(p.name for p in tmp_path.iterdir())
    out = str(tmp_path / "models") + slash
    args = ["voxelize", str(truck), out, "--voxel-size", "0.1", "--at", "3,3"]
    assert main(args) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: OUT = {out!r}: expected a target model's file name (X.txt), not a folder"
    )
    assert main([*args, "--into", str(forest)]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: OUT = {out!r}: expected the scene's stem (X writes X.txt and X_Target.txt), "
        "not a folder"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == before and not any((tmp_path / "models").iterdir())


@pytest.mark.parametrize("name", ["truck.las", "truck.LAZ", "truck.toml", "truck.cmf"])
@pytest.mark.parametrize("into", [False, True])
def test_out_named_as_another_kind_of_file_is_refused(tmp_path, truck, forest, capsys, name, into):
    """'truck.las' wrote truck.las.txt (with --into, truck.las.txt and truck.las_Target.txt):
    a voxel list under the name of a point cloud, as generate refuses."""
    before = sorted(p.name for p in tmp_path.iterdir())
    out = str(tmp_path / name)
    args = ["voxelize", str(truck), out, "--voxel-size", "0.1", "--at", "3,3"]
    assert main([*args, "--into", str(forest)] if into else args) == 2
    wanted = (
        "the scene's stem (X writes X.txt and X_Target.txt)" if into else "a voxel-list name ending in .txt"
    )
    suffix = name[name.index(".") :]
    assert (
        one_error_line(capsys)
        == f"ladartui: error: OUT = {out!r}: expected {wanted}, not a {suffix} file name"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_one_voxel_is_said_in_the_singular(tmp_path, truck, capsys):
    """A voxel as large as the truck: '1 voxels'."""
    assert main(["voxelize", str(truck), str(tmp_path / "t"), "--voxel-size", "5"]) == 0
    out = capsys.readouterr().out
    assert "surface model of 1 voxel at 5 m (1 on the surface)" in out


def test_memory_beyond_the_machine_is_refused_with_its_estimate(tmp_path, truck, capsys, monkeypatch):
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(64 * 2**20))
    assert main(["voxelize", str(truck), str(tmp_path / "t"), "--voxel-size", "0.005", "--solid"]) == 2
    line = one_error_line(capsys)
    assert "voxel size 0.005 m makes a 401 x 801 x 301 voxel box needing about" in line
    assert "more than the 64 MiB of memory available" in line


def test_unwritable_output_is_refused_before_the_work(tmp_path, truck, forest, capsys):
    (tmp_path / "out_Target.txt").mkdir()
    args = ["voxelize", str(truck), str(tmp_path / "out"), "--voxel-size", "0.1", "--at", "3,3"]
    assert main([*args, "--into", str(forest)]) == 2
    assert "out_Target.txt: is a folder" in one_error_line(capsys)
    assert not (tmp_path / "out.txt").exists()


def test_a_failed_write_names_the_file_as_with_into(tmp_path, truck, forest, capsys):
    """A target model that could not be written said only 'could not write the output:
    File too large', exit 1; with --into the file was named."""
    out = tmp_path / "truck_Target.txt"
    args = ["voxelize", str(truck), str(out), "--voxel-size", "0.1", "--solid", "--at", "3,3"]
    into = [*args[:2], str(tmp_path / "out"), *args[3:], "--into", str(forest)]
    assert main(args) == main(into) == 0  # the earlier files, the kernels compiled
    capsys.readouterr()
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with file_size_limit(20_000):  # 12,000 voxels: about 100 kB of lines
        assert main(args) == 2
        assert one_error_line(capsys) == f"ladartui: error: {out}: cannot be written (file too large)"
        assert main(into) == 2
        assert one_error_line(capsys).startswith(
            f"ladartui: error: {tmp_path / 'out.txt'}: could not be written"
        )
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_missing_scene_is_said_missing_without_the_line_format(tmp_path, truck, capsys):
    """--into naming no file was told the format of a voxel list's lines."""
    scene = tmp_path / "nothere.txt"
    args = ["voxelize", str(truck), str(tmp_path / "out"), "--voxel-size", "0.1", "--at", "3,3"]
    assert main([*args, "--into", str(scene)]) == 2
    assert one_error_line(capsys) == f"ladartui: error: {scene}: no such file; expected a voxel-list file"
    assert not (tmp_path / "out.txt").exists()


def test_a_bad_scene_file_is_one_line_naming_its_line(tmp_path, truck, forest, capsys):
    forest.write_text("1,2,3\n4,five,6\n")
    args = ["voxelize", str(truck), str(tmp_path / "out"), "--voxel-size", "0.1", "--at", "3,3"]
    assert main([*args, "--into", str(forest)]) == 2
    assert one_error_line(capsys).startswith(f"ladartui: error: {forest}:2: y = 'five' is not a whole number")
    assert not (tmp_path / "out.txt").exists()


def test_cancelled_writes_leave_the_earlier_files(tmp_path, forest, monkeypatch):
    import threading

    from ladartui.errors import Cancelled
    from ladartui.scene import insertion as module
    from ladartui.scene import model_files

    monkeypatch.setattr(model_files, "WRITE_ROWS", 100)
    vehicle = np.array([[i, j, 0] for i in range(20, 40) for j in range(20, 40)], dtype=np.int32)
    scene, target, _, had = module.load_scene_model(forest)
    inserted = module.insert_vehicle(scene, target, vehicle, 0.1, had)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    cancel = threading.Event()
    stages = []

    def cancel_on_second_chunk(stage, done, total):
        stages.append((stage, done, total))
        if len(stages) == 2:
            cancel.set()

    with pytest.raises(Cancelled):
        module.write_scene_model(forest, inserted, cancel, cancel_on_second_chunk)
    with pytest.raises(Cancelled):
        model_files.save_model(tmp_path / "forest_Target.txt", vehicle, cancel)
    assert stages[:2] == [("writing", 100, len(inserted.scene)), ("writing", 200, len(inserted.scene))]
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before  # no temporaries left either
    cancel.clear()
    module.write_scene_model(forest, inserted, cancel)
    np.testing.assert_array_equal(load_voxels(forest), inserted.scene)
    np.testing.assert_array_equal(load_voxels(tmp_path / "forest_Target.txt"), inserted.target)


def test_a_mesh_too_large_for_the_grid_is_blamed_in_one_line(tmp_path, capsys):
    """A vertex at 1e30 printed numpy's cast warning from the mesh reader, then blamed
    --voxel-size, whose value was fine for the mesh meant."""
    far = tmp_path / "far.obj"
    far.write_text("v 1e30 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert main(["voxelize", str(far), str(tmp_path / "o"), "--voxel-size", "0.25"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Warning" not in err, err
    assert err.startswith(f"ladartui: error: {far}: the mesh spans 1e+30 x 1 x 0 m")
    assert "2147483647" in err and "--scale" in err


def test_a_placement_off_the_grid_is_blamed_on_at_not_the_mesh(tmp_path, capsys):
    tri = tmp_path / "tri.obj"
    tri.write_text("v 0 0 0\nv 3 0 0\nv 0 3 2\nf 1 2 3\n")
    code = main(["voxelize", str(tri), str(tmp_path / "o"), "--voxel-size", "0.5", "--at", "1e12,5"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1
    assert err.startswith("ladartui: error: --at = ") and "2147483647" in err and "the mesh spans" not in err


@pytest.mark.parametrize(
    ("mesh", "extra", "starts"),
    [
        ("cube", ["--scale", "1e308"], "{mesh}: the mesh spans 1e+308 x 1e+308 x 1e+308 m"),
        ("cube", ["--scale", "1e308", "--at", "5,5"], "{mesh}: the mesh spans 1e+308 x 1e+308 x 1e+308 m"),
        ("cube", ["--scale", "1e300", "--at", "5,5", "--heading", "30"], "{mesh}: the mesh spans 1e+300"),
        ("huge", ["--at", "5,5"], "{mesh}: the mesh spans "),
        ("huge", ["--scale", "2"], "{mesh}: scaled by 2 its vertices pass the largest number"),
        ("cube", ["--at", "1e308,5"], "--at = '1e308,5': expected a position within the scene's grid"),
        ("cube", ["--at", "5,-1e308"], "--at = '5,-1e308': expected a position within the scene's grid"),
    ],
)
def test_absurd_sizes_and_places_are_one_line(tmp_path, capsys, mesh, extra, starts):
    """--scale 1e308 and --at 1e308,0 printed numpy's overflow warnings before the error; a
    mesh spanning 1e308 m placed --at 5,5 blamed --at with a 300-digit distance."""
    files = {
        "cube": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
        "huge": "v -1e308 -1e308 0\nv 1e308 -1e308 0\nv 0 1e308 1\nf 1 2 3\n",
    }
    path = tmp_path / f"{mesh}.obj"
    path.write_text(files[mesh])
    with warnings.catch_warnings(record=True) as caught:  # printed on stderr outside pytest
        warnings.simplefilter("always")
        assert main(["voxelize", str(path), str(tmp_path / "o"), "--voxel-size", "0.5", *extra]) == 2
    assert not caught, [str(w.message) for w in caught]
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert err.startswith("ladartui: error: " + starts.format(mesh=path)), err
    assert len(err) < 400
