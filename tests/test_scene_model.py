"""Scene: loading X.txt with X_Target.txt, shape, centre, height map, occupancy."""

import threading

import numpy as np
import pytest

from ladartui.errors import FieldError, InputFileError, LadarError
from ladartui.scene.model import Scene, target_path_for, top_height_map

SCENE = np.array([[0, 0, 0], [4, 1, 2], [4, 1, 7], [2, 3, 5], [9, 0, 1]], dtype=np.int32)
TARGET = np.array([[4, 1, 2], [2, 3, 5]], dtype=np.int32)


def write_pair(folder, name="forest"):
    (folder / f"{name}.txt").write_text("".join(f"{x},{y},{z}\n" for x, y, z in SCENE))
    (folder / f"{name}_Target.txt").write_text("".join(f"{x},{y},{z}\n" for x, y, z in TARGET))
    return folder / f"{name}.txt"


def test_load_reads_scene_and_target(tmp_path):
    scene = Scene.load(write_pair(tmp_path), 0.5)
    np.testing.assert_array_equal(scene.voxels, SCENE)
    np.testing.assert_array_equal(scene.target, TARGET)
    assert scene.voxels.dtype == np.int32 and scene.target.dtype == np.int32
    assert scene.voxel_size == 0.5
    assert scene.shape == (10, 4, 8)
    assert scene.name == "forest"
    assert scene.path == tmp_path / "forest.txt"
    assert scene.target_path == tmp_path / "forest_Target.txt"


def test_target_path_follows_table_2_naming(tmp_path):
    assert target_path_for(tmp_path / "ExampleScene.txt") == tmp_path / "ExampleScene_Target.txt"
    assert target_path_for("a/b.c.txt") == target_path_for("a/b.c.txt").parent / "b.c_Target.txt"


def test_missing_target_names_the_expected_file(tmp_path):
    path = write_pair(tmp_path)
    (tmp_path / "forest_Target.txt").unlink()
    with pytest.raises(InputFileError) as caught:
        Scene.load(path, 0.5)
    assert str(caught.value) == (
        f"{tmp_path / 'forest_Target.txt'}: target model not found; expected it beside the "
        "scene model forest.txt (named forest_Target.txt)"
    )


def test_missing_scene_is_named(tmp_path):
    with pytest.raises(InputFileError, match=r"nothing\.txt: no such file"):
        Scene.load(tmp_path / "nothing.txt", 0.5)


@pytest.mark.parametrize("given", [".", "/"])
def test_a_folder_without_a_name_given_as_the_scene_is_named_a_folder(tmp_path, monkeypatch, given):
    """Scene.load(".") failed with ValueError: PosixPath('.') has an empty name, making the
    name of a target model beside it."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputFileError) as caught:
        Scene.load(given, 1.0)
    assert str(caught.value) == f"{given}: is a folder; expected a voxel-list file"


def test_empty_target_loads_but_has_no_centre(tmp_path):
    path = write_pair(tmp_path)
    (tmp_path / "forest_Target.txt").write_text("")
    scene = Scene.load(path, 0.5)
    assert scene.target.shape == (0, 3) and scene.shape == (10, 4, 8)
    with pytest.raises(LadarError) as caught:
        scene.target_centre_m()
    assert str(caught.value) == (
        f"scene 'forest' has no target voxels ({tmp_path / 'forest_Target.txt'} is empty)"
    )


def test_the_bounds_of_an_empty_target_say_it_has_none(tmp_path):
    # It raised KeyError: True.
    path = write_pair(tmp_path)
    (tmp_path / "forest_Target.txt").write_text("")
    scene = Scene.load(path, 0.5)
    assert scene.bounds()[1].tolist() == [9, 3, 7]
    with pytest.raises(LadarError) as caught:
        scene.bounds(target=True)
    assert str(caught.value) == (
        f"scene 'forest' has no target voxels ({tmp_path / 'forest_Target.txt'} is empty)"
    )
    with pytest.raises(LadarError, match=r"^scene 'empty' has no voxels$"):
        Scene(np.zeros((0, 3), np.int32), np.zeros((0, 3), np.int32), 1.0, name="empty").bounds()


def test_target_ids_of_voxels_of_another_shape_is_a_field_error():
    # It raised numpy's 'cannot reshape array of size 1 into shape (3)'.
    scene = Scene(SCENE, TARGET, 0.5)
    assert scene.target_ids_of(np.array([[2, 3, 5], [0, 0, 0]])).tolist() == [1, 0]
    with pytest.raises(FieldError, match=r"^voxels is not set: expected an \(N, 3\)"):
        scene.target_ids_of(None)
    with pytest.raises(FieldError, match=r"^voxels = \[1, 2\]: expected an \(N, 3\)"):
        scene.target_ids_of([1, 2])


def test_shape_covers_both_lists_and_can_be_larger():
    target = np.array([[20, 1, 1]])
    assert Scene(SCENE, target, 1.0).shape == (21, 4, 8)
    assert Scene(SCENE, TARGET, 1.0, shape=(10, 4, 900)).shape == (10, 4, 900)
    expected = r"shape = \(9, 4, 8\): expected \(nx, ny, nz\) at least \(10, 4, 8\)"
    with pytest.raises(FieldError, match=expected):
        Scene(SCENE, TARGET, 1.0, shape=(9, 4, 8))


@pytest.mark.parametrize(
    ("shape", "shown"),
    [
        ("abc", "'abc'"),
        (12, "12"),
        ((None, 4, 8), r"\(None, 4, 8\)"),
        ((float("nan"), 4, 8), r"\(nan, 4, 8\)"),
        ((10.5, 4, 8), r"\(10.5, 4, 8\)"),
        ((10, 4), r"\(10, 4\)"),
    ],
)
def test_a_shape_that_is_no_three_whole_numbers_is_a_field_error(shape, shown):
    """shape="abc" or (None, 4, 8) raised ValueError or TypeError from int(), and
    (10.5, 4, 8) was cut to (10, 4, 8) without a word."""
    expected = rf"^shape = {shown}: expected \(nx, ny, nz\) at least \(10, 4, 8\)$"
    with pytest.raises(FieldError, match=expected):
        Scene(SCENE, TARGET, 1.0, shape=shape)


def test_a_shape_of_numpy_integers_is_taken():
    assert Scene(SCENE, TARGET, 1.0, shape=np.array([10, 4, 9])).shape == (10, 4, 9)
    assert Scene(SCENE, TARGET, 1.0, shape=(np.int64(10), np.int32(4), 8)).shape == (10, 4, 8)


@pytest.mark.parametrize("size", [0, -1.0, "big", float("nan"), True, np.True_, "0.25"])
def test_voxel_size_must_be_a_positive_number(size, tmp_path):
    """True was taken as 1 m, and the text "0.25" as a number, by the API's Scene, trace(),
    voxelize and LAS import alike; a scenario file or compute_measures refused them."""
    from ladartui.scene.las import export_las, import_las
    from ladartui.scene.occupancy import Occupancy
    from ladartui.scene.voxelize import grid_triangles
    from ladartui.tracing import trace

    said = f"voxel_size = {size!r}: expected a positive number of metres"
    with pytest.raises(FieldError) as refused:
        Scene(SCENE, TARGET, size)
    assert str(refused.value) == said
    ray = np.array([[0.5, 0.5, 9.0]]), np.array([[0.0, 0.0, -1.0]])
    for call in (
        lambda: trace(Occupancy.build(SCENE), *ray, voxel_size=size),
        lambda: grid_triangles(None, size),  # refused before the mesh is read
        lambda: import_las(tmp_path / "none.las", size),  # before the file is
        lambda: export_las(tmp_path / "out.las", SCENE, size),
    ):
        with pytest.raises(FieldError) as refused:
            call()
        assert str(refused.value) == said


def test_target_centre_is_the_centroid_in_metres():
    scene = Scene(SCENE, TARGET, 0.25)
    np.testing.assert_allclose(
        scene.target_centre_m(), [(4 + 2) / 2 * 0.25, (1 + 3) / 2 * 0.25, (2 + 5) / 2 * 0.25]
    )
    with pytest.raises(LadarError, match="^scene 'scene' has no target voxels$"):
        Scene(SCENE, np.zeros((0, 3), int), 0.25).target_centre_m()


def test_top_height_map_against_a_dense_grid():
    rng = np.random.default_rng(3)
    voxels = rng.integers(0, [30, 20, 15], size=(2000, 3))
    expected = np.full((30, 20), -1)
    dense = np.zeros((30, 20, 15), bool)
    dense[tuple(voxels.T)] = True
    for x in range(30):
        for y in range(20):
            filled = np.nonzero(dense[x, y])[0]
            if len(filled):
                expected[x, y] = filled.max()
    np.testing.assert_array_equal(top_height_map(voxels, 30, 20), expected)
    origin = (1000, 2000)
    shifted = voxels + [*origin, 0]
    np.testing.assert_array_equal(top_height_map(shifted, 30, 20, origin), expected)


def test_column_tops_span_the_voxels_own_columns():
    scene = Scene(SCENE, TARGET, 1.0)
    origin, heights = scene.column_tops()
    assert origin == (0, 0) and heights.shape == (10, 4)
    assert heights[4, 1] == 7 and heights[0, 0] == 0 and heights[1, 1] == -1
    origin, heights = scene.column_tops(target=True)  # columns x 2..4, y 1..3
    assert origin == (2, 1) and heights.shape == (3, 3)
    assert heights[2, 0] == 2 and heights[0, 2] == 5 and (heights >= 0).sum() == 2
    far = Scene(SCENE + [5_000_000, 9, 0], TARGET + [5_000_000, 9, 0], 1.0)
    origin, heights = far.column_tops()
    assert origin == (5_000_000, 9) and heights.shape == (10, 4) and heights[4, 1] == 7
    assert Scene(SCENE[:0], TARGET[:0], 1.0).column_tops()[1].tolist() == [[-1]]


def test_occupancy_is_built_once_and_matches_the_lists():
    pytest.importorskip("ladartui.scene.occupancy")
    scene = Scene(SCENE, TARGET, 1.0, shape=(10, 4, 900))
    results = []
    threads = [threading.Thread(target=lambda: results.append(scene.occupancy)) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert all(occ is results[0] for occ in results)
    occupancy = scene.occupancy
    assert occupancy.count == len(SCENE)
    assert tuple(occupancy.shape) == (10, 4, 900)
    assert occupancy.contains(SCENE).all()
    assert not occupancy.contains(np.array([[1, 1, 1], [4, 1, 3]])).any()
    target = scene.target_occupancy
    assert target is scene.target_occupancy
    assert target.count == len(TARGET) and tuple(target.shape) == (10, 4, 900)
    assert target.contains(TARGET).all() and not target.contains(np.array([[0, 0, 0]])).any()


def test_bad_arrays_are_field_errors_naming_the_argument():
    with pytest.raises(FieldError, match=r"^voxels\[1\] = \(0, -1, 0\): expected non-negative"):
        Scene(np.array([[0, 0, 0], [0, -1, 0]]), TARGET, 1.0)
    with pytest.raises(FieldError, match=r"^target is an array of shape \(1, 2\): expected an \(N, 3\)"):
        Scene(SCENE, np.array([[0, 1]]), 1.0)
    with pytest.raises(FieldError, match=r"^voxels is an array of float64: expected .*integer"):
        Scene(np.array([[0.5, 1, 1]]), TARGET, 1.0)
    with pytest.raises(FieldError, match=r"^target_ids = \[1, 2\]: expected"):
        Scene(SCENE, TARGET[:1], 1.0, target_ids=[1, 2])
    with pytest.raises(FieldError, match=r"^target_ids\[0\] = 0: expected a target id from 1 to 65535"):
        Scene(SCENE, TARGET[:2], 1.0, target_ids=[0, 1])


def test_scene_survives_pickling():
    import pickle

    scene = Scene(SCENE, TARGET, 0.5, shape=(10, 4, 20), name="p")
    copy = pickle.loads(pickle.dumps(scene))
    np.testing.assert_array_equal(copy.voxels, SCENE)
    np.testing.assert_array_equal(copy.target, TARGET)
    assert (copy.shape, copy.voxel_size, copy.name) == ((10, 4, 20), 0.5, "p")
    np.testing.assert_array_equal(copy.column_tops()[1], scene.column_tops()[1])


def test_a_scenes_bounds_are_found_once_however_many_ask(monkeypatch):
    """Opening a scene passed over its voxels for their bounds three times: the memory
    check, the views' memory check and the height map; building its occupancy, once more."""
    import ladartui.scene.model as model
    import ladartui.scene.occupancy as occupancy

    passes = []
    real = model.column_bounds
    counted = lambda voxels: passes.append(len(voxels)) or real(voxels)  # noqa: E731
    monkeypatch.setattr(model, "column_bounds", counted)
    monkeypatch.setattr(occupancy, "column_bounds", counted)
    voxels = np.array([(5, 6, 1), (9, 2, 4), (7, 7, 0)], np.int32)
    scene = model.Scene(voxels, voxels[:1], 1.0)
    scene.tracing_bytes()
    origin, heights = scene.column_tops()
    assert scene.bounds()[0].tolist() == [5, 2, 0] and origin == (5, 2) and heights.shape == (5, 6)
    built = scene.occupancy, scene.target_occupancy  # (nor for the tracing structures)
    assert [(b.bbox_lo.tolist(), b.bbox_hi.tolist()) for b in built] == [
        ([5, 2, 0], [10, 8, 5]),
        ([5, 6, 1], [6, 7, 2]),
    ]
    assert sorted(passes) == [1, 3]  # the voxels once, the target once
