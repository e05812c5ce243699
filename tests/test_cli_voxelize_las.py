"""``ladartui voxelize SURVEY.las OUT``: a scene model from a point cloud, and the steps after it."""

import numpy as np
import pytest
import trimesh

from cli_support import ctrl_c, one_error_line
from ladartui.cli import main
from ladartui.scene.voxelize import Placement, load_mesh, voxelize
from ladartui.scene.voxels import load_voxels, save_voxels

laspy = pytest.importorskip("laspy")

from ladartui.scene.las import import_las  # noqa: E402

EAST, NORTH, HEIGHT = 500100.0, 4100200.0, 120.0  # the survey's lowest corner, UTM metres


def _write_cloud(path, x, y, z, classification=None, crs=None):
    header = laspy.LasHeader(version="1.4", point_format=6)
    header.scales, header.offsets = [0.01] * 3, [500000.0, 4100000.0, 0.0]
    if crs is not None:
        header.offsets = [0.0] * 3
        header.add_crs(crs)
    cloud = laspy.LasData(header)
    cloud.x, cloud.y, cloud.z = np.asarray(x, float), np.asarray(y, float), np.asarray(z, float)
    if classification is not None:
        cloud.classification = np.asarray(classification)
    cloud.write(path)
    return path


def _forest_points():
    """Ground every metre over 20 x 15 m rising 0.1 m a metre eastward, and two trees 9 m tall."""
    gx, gy = np.meshgrid(np.arange(20.0), np.arange(15.0), indexing="ij")
    ground = np.column_stack([gx.ravel(), gy.ravel(), 0.1 * gx.ravel()])
    heights = np.arange(0.0, 9.0, 0.5)
    trees = np.vstack(
        [np.column_stack([np.full(18, cx), np.full(18, cy), heights]) for cx, cy in ((5, 4), (14, 10))]
    )
    points = np.vstack([ground, trees])
    return points + [EAST, NORTH, HEIGHT]


@pytest.fixture
def survey(tmp_path):
    points = _forest_points()
    return _write_cloud(tmp_path / "survey.las", *points.T)


@pytest.fixture
def truck(tmp_path):
    path = tmp_path / "truck.stl"
    trimesh.creation.box(extents=(2.0, 4.0, 1.5)).export(path)
    return path


def _sorted(voxels):
    voxels = np.asarray(voxels)
    return voxels[np.lexsort(voxels.T[::-1])]


@pytest.mark.parametrize("suffix", [".las", ".LAZ"])
def test_a_survey_makes_a_scene_model_and_an_empty_target_model(tmp_path, capsys, suffix):
    """'voxelize survey.las forest --voxel-size 1' said "unsupported mesh type '.las';
    expected .obj, .stl or .ply": a scene from a survey needed Python."""
    points = _forest_points()
    path = tmp_path / f"survey{suffix}"
    with open(path, "wb") as stream:  # the suffix in capitals: LAZ is chosen by the stream
        header = laspy.LasHeader(version="1.4", point_format=6)
        header.scales, header.offsets = [0.01] * 3, [500000.0, 4100000.0, 0.0]
        cloud = laspy.LasData(header)
        cloud.x, cloud.y, cloud.z = points.T
        cloud.write(stream, do_compress=suffix == ".LAZ")
    out = tmp_path / "forest"
    assert main(["voxelize", str(path), str(out), "--voxel-size", "1"]) == 0
    voxels = load_voxels(tmp_path / "forest.txt")
    expected, origin = import_las(path, 1.0)
    np.testing.assert_array_equal(voxels, _sorted(expected))  # sorted, as the project writes models
    np.testing.assert_allclose(origin, [EAST, NORTH, HEIGHT])
    # ground 20 x 15 columns; the ground rises 1.9 m (z 0..2), the trees to 8.5 m (z 0..9)
    assert voxels.max(axis=0).tolist() == [19, 14, 9]
    assert (tmp_path / "forest_Target.txt").read_bytes() == b""  # a scene with no vehicle yet
    lines = capsys.readouterr().out.splitlines()
    assert lines == [
        f"wrote {out}.txt ({len(voxels):,} voxels, 20 x 15 x 10 m at 1 m) and {out}_Target.txt "
        f"(empty: no vehicle yet); voxel 0,0,0 is centred at x 500100.000, y 4100200.000, "
        f"z 120.000 m in the coordinates of {path} (scene metres count from there)"
    ]


def test_the_next_steps_take_the_scene_vehicle_scenario_validate_run(tmp_path, survey, truck, capsys):
    """Survey -> scene -> a vehicle put in with --into -> a scenario -> validate -> run."""
    assert main(["voxelize", str(survey), str(tmp_path / "forest"), "--voxel-size", "0.5"]) == 0
    scenario = tmp_path / "plan.toml"
    scenario.write_text(
        '[files]\nscene = "forest.txt"\nvoxel_size = 0.5\n\n[sensor]\ngrid = 16\nray_grid = 1\n\n'
        "[flight]\nspeed_mps = 20.0\n\n[[flight.segments]]\n"
        'kind = "orbit"\ncentre = [10.0, 7.0, 0.0]\nradius = 30.0\naltitude = 60.0\nscans = 2\n'
    )
    capsys.readouterr()
    assert main(["validate", str(scenario)]) == 0  # a scene without a vehicle plans too
    assert "forest_Target.txt holds no voxels" in capsys.readouterr().out
    args = ["voxelize", str(truck), str(tmp_path / "forest"), "--voxel-size", "0.5", "--solid"]
    assert main([*args, "--at", "10,7,1", "--into", str(tmp_path / "forest.txt")]) == 0
    said = capsys.readouterr().out
    assert f"wrote {tmp_path / 'forest.txt'}" in said and "a new target model" not in said
    vehicle = voxelize(load_mesh(truck), 0.5, Placement(10.0, 7.0, 1.0), solid=True).voxels
    # 1 m above the ground under it: the survey's ground at x 9..11 m is z 0.9..1.1 m, in voxel
    # layer 2, so the vehicle goes up 3 layers from the floor (the bottom of layer 0)
    assert "resting on the ground under its footprint at z 1.25 m" in " ".join(said.split())
    vehicle = vehicle + [0, 0, 3]
    np.testing.assert_array_equal(load_voxels(tmp_path / "forest_Target.txt"), vehicle)
    assert main(["validate", str(scenario)]) == 0
    assert "holds no voxels" not in capsys.readouterr().out
    assert main(["run", str(scenario), "--no-write"]) == 0


def test_a_survey_in_feet_gives_its_origin_in_feet_and_the_scene_in_metres(tmp_path, capsys):
    import pyproj

    foot = 1200 / 3937  # metres in a US survey foot
    feet = np.array([1000.0, 1010.0, 1020.0, 1030.0])
    path = _write_cloud(
        tmp_path / "ft.las", feet, feet * 0 + 2000.0, feet - 900.0, crs=pyproj.CRS("EPSG:2263")
    )
    assert main(["voxelize", str(path), str(tmp_path / "scene"), "--voxel-size", "1"]) == 0
    assert load_voxels(tmp_path / "scene.txt").tolist() == [[0, 0, 0], [3, 0, 3], [6, 0, 6], [9, 0, 9]]
    line = capsys.readouterr().out.strip()
    assert "(4 voxels, 10 x 1 x 10 m at 1 m)" in line
    assert line.endswith(
        f"voxel 0,0,0 is centred at x 1000.000, y 2000.000, z 100.000 US survey feet ({foot:.7g} m) "
        f"in the coordinates of {path} (scene metres count from there)"
    )
    # heights in metres under feet across (NAVD88 height in metres): each axis its unit
    mixed = _write_cloud(
        tmp_path / "mixed.las",
        feet,
        feet * 0 + 2000.0,
        (feet - 900.0) * foot,
        crs=pyproj.CRS("EPSG:2263+5703"),
    )
    assert main(["voxelize", str(mixed), str(tmp_path / "mixed"), "--voxel-size", "1"]) == 0
    assert load_voxels(tmp_path / "mixed.txt").tolist() == [[0, 0, 0], [3, 0, 3], [6, 0, 6], [9, 0, 9]]
    assert f"x 1000.000, y 2000.000 US survey feet ({foot:.7g} m), z {100 * foot:.3f} m in" in (
        capsys.readouterr().out
    )


def test_noise_is_left_out_unless_keep_noise_is_given(tmp_path, capsys):
    x, y, z = np.array([0.0, 1.0, 2.0, 3.0]), np.zeros(4), np.array([0.0, 1.0, 3000.0, 2.0])
    path = _write_cloud(tmp_path / "survey.las", x + EAST, y + NORTH, z, classification=[2, 5, 18, 5])
    args = ["voxelize", str(path), str(tmp_path / "scene"), "--voxel-size", "1"]
    assert main(args) == 0
    assert load_voxels(tmp_path / "scene.txt").tolist() == [[0, 0, 0], [1, 0, 1], [3, 0, 2]]
    out = capsys.readouterr().out
    assert "note: 1 of 4 points left out as noise or withheld (--keep-noise keeps them)" in out
    assert main([*args, "--keep-noise"]) == 0
    assert load_voxels(tmp_path / "scene.txt")[:, 2].max() == 3000
    assert "note:" not in capsys.readouterr().out
    path = _write_cloud(tmp_path / "noise.las", x, y, z, classification=[7, 7, 18, 7])
    assert main(["voxelize", str(path), str(tmp_path / "noise"), "--voxel-size", "1"]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: {path}: all 4 points are noise or withheld (ASPRS classes 7 and 18, or the "
        "withheld flag); expected ground, vegetation or object points (--keep-noise takes them)"
    )
    assert not (tmp_path / "noise.txt").exists()


@pytest.mark.parametrize(
    "flag", [["--at", "3,3"], ["--heading", "0"], ["--solid"], ["--scale", "1"], ["--up", "z"], ["--id", "2"]]
)
def test_a_mesh_flag_with_a_point_cloud_is_refused_naming_it(tmp_path, survey, capsys, flag):
    """Each would have been dropped without a word (a point cloud is placed as it was surveyed)."""
    args = ["voxelize", str(survey), str(tmp_path / "forest"), "--voxel-size", "1", *flag]
    assert main(args) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: {flag[0]} is for a mesh; {survey} is a point cloud, voxelised where it "
        f"was surveyed as a whole scene: drop {flag[0]}"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["survey.las"]


def test_a_point_cloud_into_a_scene_is_refused_and_a_mesh_takes_no_keep_noise(
    tmp_path, survey, truck, capsys
):
    save_voxels(tmp_path / "old.txt", [[0, 0, 0], [5, 5, 0]])
    save_voxels(tmp_path / "old_Target.txt", [[5, 5, 0]])
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    args = [
        "voxelize",
        str(survey),
        str(tmp_path / "new"),
        "--voxel-size",
        "1",
        "--into",
        str(tmp_path / "old.txt"),
    ]
    assert main(args) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: --into adds a mesh's vehicle to a scene; {survey} is a point cloud, "
        "voxelised as a scene of its own: drop --into, then add vehicles to that scene with "
        "'voxelize MESH OUT --into OUT.txt --at X,Y'"
    )
    assert main(["voxelize", str(truck), str(tmp_path / "t"), "--voxel-size", "1", "--keep-noise"]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: --keep-noise is for a point cloud (.las, .laz); {truck} is a mesh: "
        "drop --keep-noise"
    )
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_scene_from_a_survey_replaces_both_files_of_an_earlier_one(tmp_path, survey, capsys):
    """The earlier scene's target model (a vehicle) would not match the new scene."""
    save_voxels(tmp_path / "forest.txt", [[0, 0, 0], [5, 5, 0]])
    save_voxels(tmp_path / "forest_Target.txt", [[5, 5, 0]])
    assert main(["voxelize", str(survey), str(tmp_path / "forest.txt"), "--voxel-size", "1"]) == 0
    assert len(load_voxels(tmp_path / "forest.txt")) > 2
    assert (tmp_path / "forest_Target.txt").read_bytes() == b""
    target = str(tmp_path / "forest_Target.txt")
    assert main(["voxelize", str(survey), target, "--voxel-size", "1"]) == 2
    assert one_error_line(capsys).startswith(f"ladartui: error: OUT = {target!r}: expected the scene's stem")


def test_a_voxel_size_too_fine_for_the_survey_names_the_flag(tmp_path, survey, capsys, monkeypatch):
    import ladartui.scene.las as las

    monkeypatch.setattr(las, "MAX_INDEX", 9)  # a 10-voxel grid side for the test
    assert main(["voxelize", str(survey), str(tmp_path / "forest"), "--voxel-size", "1"]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: {survey}: --voxel-size = 1.0: expected at least 2 m for the cloud's "
        "extent (19 x 14 x 8.5 m; at most 10 voxels a side)"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["survey.las"]


def test_ctrl_c_while_a_survey_is_read_leaves_the_earlier_scene(tmp_path, survey, capsys, monkeypatch):
    """The cloud is read a chunk at a time, the cancel seen between chunks."""
    import ladartui.scene.las as las

    save_voxels(tmp_path / "forest.txt", [[0, 0, 0]])
    save_voxels(tmp_path / "forest_Target.txt", [[0, 0, 0]])
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    monkeypatch.setattr(las, "READ_POINTS", 100)
    seen, reads = {}, []
    real_check, real_read = las.check_cancelled, laspy.LasReader.read_points

    def check(cancel, message):
        seen["cancel"] = cancel
        real_check(cancel, message)

    def read_points(self, n):
        reads.append(n)
        if len(reads) == 2:
            assert ctrl_c(seen["cancel"])
        return real_read(self, n)

    monkeypatch.setattr(las, "check_cancelled", check)
    monkeypatch.setattr(laspy.LasReader, "read_points", read_points)
    assert main(["voxelize", str(survey), str(tmp_path / "forest"), "--voxel-size", "1"]) == 130
    assert capsys.readouterr().err.strip().endswith("ladartui: voxelisation cancelled; nothing was written")
    assert len(reads) == 2  # the other chunks were not read
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_import_las_reports_its_reading_in_chunks(tmp_path, survey, monkeypatch):
    import threading

    import ladartui.scene.las as las
    from ladartui.errors import Cancelled

    monkeypatch.setattr(las, "READ_POINTS", 100)
    stages = []
    voxels, _ = import_las(survey, 1.0, progress=lambda *stage: stages.append(stage))
    points = 300 + 36
    assert [s for s in stages if s[0] == "reading"] == [
        ("reading", 100, points),
        ("reading", 200, points),
        ("reading", 300, points),
        ("reading", points, points),
    ]
    cancel = threading.Event()

    def cancel_at_200(stage, done, total):
        if done == 200:
            cancel.set()

    with pytest.raises(Cancelled):
        import_las(survey, 1.0, progress=cancel_at_200, cancel=cancel)
