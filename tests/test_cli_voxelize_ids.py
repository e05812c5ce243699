"""``ladartui voxelize --id``: target models with a target id, and insertion keeping the ids."""

import numpy as np
import pytest
import trimesh

from cli_support import one_error_line
from ladartui.cli import main
from ladartui.scene.model import Scene
from ladartui.scene.target_model import load_target
from ladartui.scene.voxelize import Placement, load_mesh, voxelize
from ladartui.scene.voxels import load_voxels, save_voxels

SIZE = 0.5


@pytest.fixture
def box(tmp_path):
    """A closed 1 x 1 x 1 m box: 2 x 2 x 2 voxels at 0.5 m."""
    path = tmp_path / "box.stl"
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(path)
    return path


def field(tmp_path, target, ids=None):
    """A 20 x 20 ground at 0.5 m with ``target`` (and ids) as its target model."""
    ground = [(i, j, 0) for i in range(20) for j in range(20)]
    save_voxels(tmp_path / "field.txt", np.array(ground + [tuple(v) for v in target]))
    save_voxels(tmp_path / "field_Target.txt", np.array(target), ids=ids)
    return tmp_path / "field.txt"


def vehicle_at(box, x, y):
    """The box inserted at (x, y) m: resting on the field's ground, on top of layer 0."""
    return voxelize(load_mesh(box), SIZE, Placement(x, y, 0.0, 0.0), solid=True).voxels + [0, 0, 1]


def test_id_writes_a_four_column_target_model_that_loads_back(tmp_path, box, capsys):
    out = tmp_path / "box_Target.txt"
    assert main(["voxelize", str(box), str(out), "--voxel-size", str(SIZE), "--solid", "--id", "7"]) == 0
    voxels, ids = load_target(out)
    np.testing.assert_array_equal(voxels, voxelize(load_mesh(box), SIZE, solid=True).voxels)
    assert len(voxels) == 8 and ids.tolist() == [7] * 8
    assert all(line.count(",") == 3 and line.endswith(",7") for line in out.read_text().splitlines())
    assert f"wrote {out} (target 7)" in capsys.readouterr().out


def test_into_a_three_column_target_keeps_it_as_target_1_and_adds_the_new_id(tmp_path, box, capsys):
    old = [(2, 2, 1), (3, 2, 1)]
    scene_path = field(tmp_path, old)
    args = ["voxelize", str(box), str(tmp_path / "out"), "--voxel-size", str(SIZE), "--solid"]
    assert main([*args, "--at", "7,7", "--into", str(scene_path), "--id", "4"]) == 0
    scene = Scene.load(tmp_path / "out.txt", SIZE)
    vehicle = vehicle_at(box, 7.0, 7.0)
    assert scene.target_id_list == [1, 4]
    assert sorted(map(tuple, scene.target[scene.target_ids == 1].tolist())) == old
    assert sorted(map(tuple, scene.target[scene.target_ids == 4].tolist())) == sorted(
        map(tuple, vehicle.tolist())
    )
    assert "the vehicle is target 4, one of 2 targets" in capsys.readouterr().out
    # A second vehicle with another id keeps all three, and the earlier ids are untouched.
    assert main([*args, "--at", "3,7", "--into", str(tmp_path / "out.txt"), "--id", "2"]) == 0
    again = Scene.load(tmp_path / "out.txt", SIZE)
    assert again.target_id_list == [1, 2, 4]
    assert np.array_equal(again.target_ids_of(vehicle), np.full(len(vehicle), 4))


def test_without_id_a_one_target_model_stays_three_columns(tmp_path, box):
    scene_path = field(tmp_path, [(2, 2, 1)])
    args = ["voxelize", str(box), str(scene_path), "--voxel-size", str(SIZE), "--solid", "--at", "7,7"]
    assert main([*args, "--into", str(scene_path)]) == 0
    lines = (tmp_path / "field_Target.txt").read_text().splitlines()
    assert len(lines) == 1 + len(vehicle_at(box, 7.0, 7.0))
    assert all(line.count(",") == 2 for line in lines)


def test_without_id_a_model_of_several_targets_gives_the_next_free_id(tmp_path, box):
    scene_path = field(tmp_path, [(2, 2, 1), (18, 18, 1)], ids=[3, 5])
    args = ["voxelize", str(box), str(scene_path), "--voxel-size", str(SIZE), "--solid", "--at", "7,7"]
    assert main([*args, "--into", str(scene_path)]) == 0
    assert Scene.load(scene_path, SIZE).target_id_list == [3, 5, 6]


def test_a_clash_of_ids_or_voxels_is_one_line_and_nothing_written(tmp_path, box, capsys):
    scene_path = field(tmp_path, [(2, 2, 1), (14, 14, 1)], ids=[1, 2])
    before = (tmp_path / "field_Target.txt").read_text()
    args = ["voxelize", str(box), str(scene_path), "--voxel-size", str(SIZE), "--solid"]
    assert main([*args, "--at", "7,7", "--into", str(scene_path), "--id", "2"]) == 2
    assert one_error_line(capsys).endswith(
        "--id = 2: expected a target id not yet in field_Target.txt (it has 1, 2)"
    )
    # The box at (7, 7) m covers voxels 14..15: target 2's voxel 14,14,1 among them.
    assert main([*args, "--at", "7,7", "--into", str(scene_path), "--id", "3"]) == 2
    line = one_error_line(capsys)  # named in the file that holds the targets
    assert f"{tmp_path / 'field_Target.txt'}: 1 of the vehicle's voxels are already target voxels " in line
    assert "(voxel 14,14,1 is target 2)" in line
    assert main([*args, "--id", "0"]) == 2
    assert "--id = 0: expected a target id from 1 to 65535" in one_error_line(capsys)
    assert (tmp_path / "field_Target.txt").read_text() == before
    assert len(load_voxels(scene_path)) == 402
