"""Inserting a vehicle rests it on the scene's ground under its footprint (``--at X,Y``)."""

import numpy as np
import pytest
import trimesh

from ladartui.cli import main
from ladartui.scene.generate import generate_scene
from ladartui.scene.insertion import insert_vehicle
from ladartui.scene.voxelize import Placement, load_mesh, merge_voxels, voxelize
from ladartui.scene.voxels import load_voxels, save_voxels


@pytest.fixture
def truck(tmp_path):
    """A closed 2 x 4 x 1.5 m box, as an STL file: 4 x 8 x 3 voxels at 0.5 m."""
    path = tmp_path / "truck.stl"
    trimesh.creation.box(extents=(2.0, 4.0, 1.5)).export(path)
    return path


def slope(size=81, rise=True):
    """A surveyed ground 40 x 40 m at 0.5 m: a ramp east to layer 20 (z 10 m) at x 10 m, then
    rising gently (a layer every 6 m: layer 20 at x 19.5..20 m, 21 at x 20.5..25.5 m)."""
    xs, ys = np.meshgrid(np.arange(size), np.arange(size), indexing="ij")
    zs = np.where(xs < 29, np.minimum(xs, 20), 20 + (xs - 29) // 12) if rise else 0 * xs
    return np.column_stack([xs.ravel(), ys.ravel(), zs.ravel()]).astype(np.int32)


def test_a_vehicle_rests_on_sloped_ground_not_under_it(tmp_path, truck, capsys):
    save_voxels(tmp_path / "survey.txt", slope())
    (tmp_path / "survey_Target.txt").write_text("")
    args = ["voxelize", str(truck), str(tmp_path / "out"), "--voxel-size", "0.5", "--solid"]
    assert main([*args, "--at", "20.25,20.25", "--into", str(tmp_path / "survey.txt")]) == 0
    target = load_voxels(tmp_path / "out_Target.txt")
    # Footprint x 39..42: ground layers 20, 20, 21, 21; the highest's top is z 10.75 m
    assert target[:, 0].min() == 39 and target[:, 0].max() == 42
    assert target[:, 2].min() == 22 and target[:, 2].max() == 24
    text = " ".join(capsys.readouterr().out.split())
    assert "resting on the ground under its footprint at z 10.75 m" in text
    assert "ground voxels there span z 9.75..10.75 m" in text
    assert "voxels x 39..42, y 37..44, z 22..24" in text
    assert "warning" not in text


def test_z_is_the_height_above_that_ground(tmp_path, truck):
    save_voxels(tmp_path / "survey.txt", slope())
    args = ["voxelize", str(truck), str(tmp_path / "out"), "--voxel-size", "0.5", "--solid"]
    assert main([*args, "--at", "20.25,20.25,1", "--into", str(tmp_path / "survey.txt")]) == 0
    assert load_voxels(tmp_path / "out_Target.txt")[:, 2].min() == 24  # 1 m (2 layers) higher


def test_a_footprint_with_no_scene_voxels_keeps_the_floor_and_says_so(tmp_path, truck, capsys):
    scene = slope()
    scene = scene[(scene[:, 0] < 20) | (scene[:, 0] > 60)]  # a gap 10 m wide either side
    save_voxels(tmp_path / "survey.txt", scene)
    args = ["voxelize", str(truck), str(tmp_path / "out"), "--voxel-size", "0.5", "--solid"]
    assert main([*args, "--at", "20.25,20.25", "--into", str(tmp_path / "survey.txt")]) == 0
    assert load_voxels(tmp_path / "out_Target.txt")[:, 2].min() == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "no ground found under the vehicle's footprint (0 of its 32 columns)" in text
    assert "give its height with --at X,Y,Z" in text
    assert "on the scene's floor at z -0.25 m" in text
    # given a height, that is where it goes, and the line says so
    out = str(tmp_path / "lifted")
    assert (
        main([*args[:2], out, *args[3:], "--at", "20.25,20.25,2", "--into", str(tmp_path / "survey.txt")])
        == 0
    )
    assert load_voxels(tmp_path / "lifted_Target.txt")[:, 2].min() == 4  # 2 m (4 layers) up
    text = " ".join(capsys.readouterr().out.split())
    assert "it is set 2 m above the scene's floor (z -0.25 m, the bottom of voxel layer 0)" in text
    assert "give its height" not in text


def test_a_vehicle_covered_from_above_is_warned_of(tmp_path, truck, capsys):
    ground = slope(rise=False)
    roof = ground.copy()
    roof[:, 2] = 5  # a flat layer 2 m over the vehicle's ground: its top is layer 3
    save_voxels(tmp_path / "cave.txt", np.vstack([ground, roof]))
    args = ["voxelize", str(truck), str(tmp_path / "out"), "--voxel-size", "0.5", "--solid"]
    assert main([*args, "--at", "20.25,20.25", "--into", str(tmp_path / "cave.txt")]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if "warning" in line]
    assert len(lines) == 1
    assert "32 of its 32 footprint columns" in lines[0]


@pytest.mark.parametrize("preset", ["small"])
def test_generated_scenes_place_vehicles_exactly_as_before(tmp_path, truck, preset):
    """A generated scene's ground is the floor (no ground voxels): a vehicle set anywhere clear of
    the scene's own vehicles keeps the placement on the floor, under trees too."""
    generated = generate_scene(preset, seed=1)
    vs = generated.voxel_size
    mesh = load_mesh(truck)
    taken = {(int(x), int(y)) for x, y in generated.target[:, :2]}
    empty = np.zeros((0, 3), dtype=np.int32)
    checked = 0
    for x in np.arange(3.0, 57.0, 3.0):
        for y in np.arange(3.0, 57.0, 3.0):
            vehicle = voxelize(mesh, vs, Placement(float(x), float(y)), solid=True).voxels
            if any((int(a), int(b)) in taken for a, b in vehicle[:, :2]):
                continue
            done = insert_vehicle(generated.voxels, empty, vehicle, vs)
            np.testing.assert_array_equal(done.target, vehicle)
            assert done.resting.lift == 0
            np.testing.assert_array_equal(done.scene, merge_voxels(generated.voxels, vehicle))
            checked += 1
    assert checked > 250


def test_a_vehicle_under_sparse_survey_ground_is_warned_of_and_told_its_height(tmp_path, truck, capsys):
    """A survey with a ground return in one column in eight (too few to rest on) keeps the
    vehicle on the floor, ten metres under that ground: the command says the ground it found
    and the --at height that sets the vehicle on it."""
    scene = slope()
    scene = scene[(scene[:, 0] + 3 * scene[:, 1]) % 8 == 0]
    save_voxels(tmp_path / "survey.txt", scene)
    args = ["voxelize", str(truck), str(tmp_path / "out"), "--voxel-size", "0.5", "--solid"]
    assert main([*args, "--at", "20.25,20.25", "--into", str(tmp_path / "survey.txt")]) == 0
    assert load_voxels(tmp_path / "out_Target.txt")[:, 2].min() == 0
    lines = [" ".join(line.split()) for line in capsys.readouterr().out.splitlines()]
    text = " ".join(lines)
    assert "no ground found" not in text
    assert "too little ground under the vehicle's footprint to rest on (4 of its 32 columns" in text
    warnings = [line for line in lines if line.startswith("warning")]
    assert len(warnings) == 1
    assert "ground found under it (z 9.75..10.75 m) lies above the vehicle's top (z 1.25 m)" in warnings[0]
    assert "--at 20.25,20.25,11 sets it on that ground" in warnings[0]
    # The height it gives does set it there, with no warning.
    assert main([*args, "--at", "20.25,20.25,11", "--into", str(tmp_path / "survey.txt")]) == 0
    assert load_voxels(tmp_path / "out_Target.txt")[:, 2].min() == 22
    assert "warning" not in capsys.readouterr().out
