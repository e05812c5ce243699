"""The synthetic forest generator: determinism, target placement, foliage, options."""

import math

import numpy as np
import pytest

from ladartui.errors import FieldError, OutputFileError
from ladartui.scene.generate import generate_scene, output_paths, scene_params
from ladartui.scene.model import Scene
from temporaries import record_temporaries


def as_set(voxels):
    return set(map(tuple, np.asarray(voxels).tolist()))


@pytest.fixture(scope="module")
def small():
    return generate_scene("small", seed=0)


def test_writing_to_a_stem_that_is_no_path_is_a_field_error(small):
    # It raised TypeError from pathlib.
    with pytest.raises(FieldError) as caught:
        small.write(None)
    assert str(caught.value) == (
        "stem is not set: expected the scene's file stem, dir/name or dir/name.txt (str or pathlib.Path)"
    )


def test_same_seed_same_scene_other_seed_other_scene(small):
    again = generate_scene("small", seed=0)
    np.testing.assert_array_equal(again.voxels, small.voxels)
    np.testing.assert_array_equal(again.target, small.target)
    other = generate_scene("small", seed=1)
    assert as_set(other.voxels) != as_set(small.voxels)


def test_lists_are_unique_int32_and_inside_the_shape(small):
    for voxels in (small.voxels, small.target):
        assert voxels.dtype == np.int32 and voxels.ndim == 2 and voxels.shape[1] == 3
        assert len(np.unique(voxels, axis=0)) == len(voxels)
        assert voxels.min() >= 0 and np.all(voxels.max(axis=0) < np.array(small.shape))
    assert small.shape[:2] == (240, 240)  # 60 m at 0.25 m
    assert small.voxel_size == 0.25


def test_target_is_in_the_scene_at_the_same_place(small):
    assert len(small.target) > 0
    assert as_set(small.target) <= as_set(small.voxels)
    centre = small.target.mean(axis=0) * small.voxel_size
    np.testing.assert_allclose(small.target_centre, centre)
    # At the scene centre, on the ground (the ground plane is the bottom of layer 0).
    assert abs(centre[0] - 30.0) < 0.5 and abs(centre[1] - 30.0) < 0.5
    assert small.target[:, 2].min() == 0


def test_vehicle_has_the_requested_size_and_is_solid(small):
    vs = small.voxel_size
    xy = small.target[:, :2].astype(float) * vs
    xy -= xy.mean(axis=0)
    _, vectors = np.linalg.eigh(np.cov(xy.T))
    along = xy @ vectors[:, 1]
    across = xy @ vectors[:, 0]
    assert abs(np.ptp(along) + vs - 5.0) <= 2 * vs
    assert abs(np.ptp(across) + vs - 2.5) <= 2 * vs
    assert abs((small.target[:, 2].max() + 1) * vs - 2.2) <= vs
    volume = len(small.target) * vs**3
    assert 0.4 * 5 * 2.5 * 2.2 < volume < 5 * 2.5 * 2.2


def test_target_is_under_canopy(small):
    scene = as_set(small.voxels)
    target = as_set(small.target)
    columns = {(x, y) for x, y, _ in target}
    top_of_target = small.target[:, 2].max()
    covered = sum(
        1 for x, y in columns if any((x, y, z) in scene for z in range(top_of_target + 1, small.shape[2]))
    )
    assert covered / len(columns) > 0.5


def test_crowns_are_clumped_shells_with_gaps(small):
    vs = small.voxel_size
    v = small.voxels
    canopy = v[v[:, 2] * vs > 6.0]  # well above the vehicle and the lowest crown bases
    assert len(canopy) > 1000
    # Mostly air: a dense-crowned forest volume would be solid.
    lo, hi = canopy.min(axis=0), canopy.max(axis=0) + 1
    assert len(canopy) / np.prod(hi - lo) < 0.1
    # Gaps seen from above inside the canopy's own footprint.
    heights = np.full(small.shape[:2], -1)
    np.maximum.at(heights, (v[:, 0], v[:, 1]), v[:, 2])
    window = heights[100:140, 100:140]  # 10 m x 10 m round the vehicle
    assert 0.02 < np.mean(window < 0) < 0.9
    # Clumped: occupied voxels share 8x8x8 bricks (a tracer's memory depends on it).
    bricks = np.unique(v >> 3, axis=0)
    assert len(v) / len(bricks) > 8


def test_density_controls_foliage():
    sparse = generate_scene("small", seed=4, density=0.3)
    dense = generate_scene("small", seed=4, density=0.9)
    assert dense.parts["foliage"] > 2 * sparse.parts["foliage"]

    def empty_columns(g):
        heights = np.full(g.shape[:2], -1)
        np.maximum.at(heights, (g.voxels[:, 0], g.voxels[:, 1]), g.voxels[:, 2])
        return np.mean(heights < 0)

    assert empty_columns(dense) < empty_columns(sparse)


def test_no_target():
    scene = generate_scene("small", seed=2, vehicles=0)
    assert len(scene.target) == 0 and scene.target_centre is None
    assert "vehicles" in scene.parts and scene.parts["vehicles"] == 0


def test_several_vehicles_are_all_target():
    scene = generate_scene("small", seed=2, vehicles=3)
    single = generate_scene("small", seed=2, vehicles=1)
    assert len(scene.target) > 2.5 * len(single.target)
    assert as_set(scene.target) <= as_set(scene.voxels)


def test_terrain_is_a_watertight_skin_under_everything():
    scene = generate_scene("small", seed=5, terrain=True, terrain_relief=2.0)
    v = scene.voxels
    nx, ny = scene.shape[:2]
    lowest = np.full((nx, ny), np.iinfo(np.int32).max)
    np.minimum.at(lowest, (v[:, 0], v[:, 1]), v[:, 2])
    assert (lowest < np.iinfo(np.int32).max).all()  # every column has ground
    assert lowest.max() - lowest.min() >= round(2.0 / scene.voxel_size) - 1
    # The vehicle stands on the ground: under each of its lowest voxels, the layer below is terrain.
    t = scene.target
    base = t[:, 2].min()
    assert base > 0
    occupied = as_set(v)
    under = [(x, y, base - 1) for x, y, z in t.tolist() if z == base]
    assert sum(p in occupied for p in under) >= 0.5 * len(under)


def test_camouflage_net_is_scene_only_and_above_the_target():
    plain = generate_scene("small", seed=6)
    netted = generate_scene("small", seed=6, camouflage=True)
    np.testing.assert_array_equal(plain.target, netted.target)
    extra = as_set(netted.voxels) - as_set(plain.voxels)
    assert netted.parts["net"] > 0 and len(extra) > 0
    assert not extra & as_set(netted.target)
    columns = {(x, y) for x, y, _ in netted.target.tolist()}
    top = netted.target[:, 2].max()
    over = {(x, y) for x, y, z in extra if (x, y) in columns and z > top}
    # Patchy: covers a good share of the vehicle, not all of it.
    assert 0.2 < len(over) / len(columns) < 0.95


def test_write_creates_the_table_2_pair(tmp_path, small):
    scene_path, target_path = small.write(tmp_path / "sub" / "forest.txt")
    assert scene_path == tmp_path / "sub" / "forest.txt"
    assert target_path == tmp_path / "sub" / "forest_Target.txt"
    loaded = Scene.load(scene_path, small.voxel_size)
    np.testing.assert_array_equal(loaded.voxels, small.voxels)
    np.testing.assert_array_equal(loaded.target, small.target)
    np.testing.assert_allclose(loaded.target_centre_m(), small.target_centre)
    assert output_paths(tmp_path / "x") == (tmp_path / "x.txt", tmp_path / "x_Target.txt")


def test_to_scene_keeps_the_grid(small):
    scene = small.to_scene()
    assert scene.shape == small.shape and scene.voxel_size == small.voxel_size
    np.testing.assert_allclose(scene.target_centre_m(), small.target_centre)


@pytest.mark.parametrize(
    "overrides, message",
    [
        ({"density": 1.5}, "density = 1.5: expected a number from 0 to 0.99"),
        ({"trees": -1}, "trees = -1: expected a whole number, 0 or more"),
        ({"voxel_size": 0}, "voxel_size = 0: expected a positive number"),
        ({"crown_radius": (4.0, 2.0)}, "crown_radius = (4.0, 2.0): expected (low, high) positive"),
        ({"leaves": 3}, "leaves = 3: expected a scene parameter: "),
        ({"width": 5.0}, "width = 5.0: expected room for the vehicle"),
        # a vehicle lost at 30 m voxels ('no target'), nothing left at 1000 m (a traceback)
        ({"voxel_size": 30.0}, "voxel_size = 30.0: expected at most 1.1 m (half the vehicle's"),
        ({"voxel_size": 1000.0, "vehicles": 0}, "voxel_size = 1000.0: expected at most 7.5 m (an eighth"),
        # 1 mm over the reference area said only 'a size giving at most 1e8 ground cells'
        (
            {"voxel_size": 0.001},
            "voxel_size = 0.001: expected a size giving at most 1e8 ground cells "
            "(0.001 m gives 3.6e+09 over 60 x 60 m)",
        ),
        # any text was true: terrain = "false" made terrain
        ({"terrain": "false"}, "terrain = 'false': expected True or False"),
        ({"camouflage": 1}, "camouflage = 1: expected True or False"),
        ({"density": float("nan")}, "density = nan: expected a number from 0 to 0.99"),
    ],
)
def test_bad_overrides_name_the_field(overrides, message):
    with pytest.raises(FieldError) as caught:
        scene_params("small", **overrides)
    assert str(caught.value).startswith(message)


def test_unknown_preset_and_bad_seed():
    with pytest.raises(FieldError, match="preset = 'huge': expected one of small, reference"):
        generate_scene("huge")
    with pytest.raises(FieldError, match="seed = -3"):
        generate_scene("small", seed=-3)
    with pytest.raises(FieldError, match=r"^progress = 3: expected a function"):
        generate_scene("small", progress=3)
    with pytest.raises(FieldError, match=r"^cancel = True: expected a threading\.Event"):
        generate_scene("small", cancel=True)


def packed(voxels, shift=0):
    """One int64 per voxel (or per 2**shift cell), for fast set operations."""
    v = np.asarray(voxels).astype(np.int64) >> shift
    return (v[:, 0] << 42) | (v[:, 1] << 21) | v[:, 2]


def count_cells(voxels, shift):
    keys = np.sort(packed(voxels, shift))
    return int(np.count_nonzero(np.diff(keys)) + 1)


@pytest.mark.slow
def test_reference_preset_matches_the_reports_figure_11_scale():
    scene = generate_scene("reference", seed=0)
    assert scene.shape == (1500, 1500, 900)
    assert math.isclose(scene.voxel_size, 0.1)
    assert 3.4e6 < len(scene.voxels) < 4.2e6
    assert np.isin(packed(scene.target), packed(scene.voxels)).all()
    # Sparse structure estimate: 64 B per 8^3 brick, 2 KiB per 64^3 tile and 512^3 region.
    nbytes = (
        count_cells(scene.voxels, 3) * 64
        + (count_cells(scene.voxels, 6) + count_cells(scene.voxels, 9)) * 2048
    )
    assert nbytes < 32 * 2**20


def test_more_vehicles_than_the_scene_holds_apart_are_refused_not_overlapped():

    with pytest.raises(FieldError) as caught:
        generate_scene("small", seed=2, vehicles=1000)
    message = str(caught.value)
    assert message.startswith("vehicles = 1000: expected at most ")
    assert message.endswith(" m between centres) in a 60 x 60 m scene")
    most = int(message.split("at most ")[1].split()[0])
    scene = generate_scene("small", seed=2, vehicles=most)
    assert len(np.unique(scene.target_ids)) == most  # every one kept, none overwritten


def test_progress_names_each_stage_in_order_and_cancel_stops_between_them():
    """A --trees 100000 scene took two minutes without a word (generate_scene had no progress)."""
    import threading

    from ladartui.errors import Cancelled

    seen = []
    generate_scene("small", seed=0, trees=5, progress=lambda *step: seen.append(step))
    stages = [stage for stage, _, _ in seen]
    assert stages[0] == "ground" and "foliage" in stages and stages[-1] == "merging"
    assert [done for _, done, _ in seen] == list(range(1, len(seen) + 1))
    assert {total for _, _, total in seen} == {len(seen)}

    cancel = threading.Event()

    def stop_at_foliage(stage, done, total):
        if stage == "foliage":
            cancel.set()

    with pytest.raises(Cancelled):
        generate_scene("small", seed=0, trees=5, progress=stop_at_foliage, cancel=cancel)


def test_a_cancel_during_the_foliage_stops_it_before_its_end(monkeypatch):
    """Ctrl-C was seen only as the next stage started: the foliage of 100,000 trees
    took about a minute first. Clump groups are now stamped one by one, each after a
    check; the same seed still gives the same scene."""
    import threading

    from ladartui.errors import Cancelled
    from ladartui.scene import trees

    cancel = threading.Event()
    stamped = []
    real_template = trees._clump_template

    def template_then_cancel(radius, rng):  # a Ctrl-C as the first group is stamped
        stamped.append(radius)
        if len(stamped) == 1:
            cancel.set()
        return real_template(radius, rng)

    monkeypatch.setattr(trees, "_clump_template", template_then_cancel)
    with pytest.raises(Cancelled):
        generate_scene("small", seed=0, trees=40, cancel=cancel)
    assert len(set(stamped)) == 1  # stopped within the first size class
    stamped.clear()
    checked = generate_scene("small", seed=0, trees=40, cancel=threading.Event())
    assert len(set(stamped)) > 1  # (uncancelled, the foliage has several)
    monkeypatch.setattr(trees, "_clump_template", real_template)
    assert np.array_equal(checked.voxels, generate_scene("small", seed=0, trees=40).voxels)


def test_write_replaces_both_files_or_neither(tmp_path, small, monkeypatch):
    """The pair was written one file after the other: a failure between left a new scene
    beside an old target model."""
    from ladartui.scene import model_files

    scene_path, target_path = small.write(tmp_path / "forest")
    before = scene_path.read_bytes(), target_path.read_bytes()
    other = generate_scene("small", seed=1, trees=5)
    real = model_files.write_voxel_lines
    calls = []

    def fail_on_second(path, voxels, *rest, **options):
        calls.append(path)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        real(path, voxels, *rest, **options)

    monkeypatch.setattr(model_files, "write_voxel_lines", fail_on_second)
    with pytest.raises(OutputFileError):
        other.write(tmp_path / "forest")
    assert (scene_path.read_bytes(), target_path.read_bytes()) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["forest.txt", "forest_Target.txt"]


def test_a_scene_too_large_for_the_memory_is_refused_before_its_trees_are_made(monkeypatch):
    """--trees 100000 ran past 8 GB (about 11 GB at its peak) with no estimate."""
    from ladartui.errors import ResourceLimitError
    from ladartui.scene import trees

    made = []
    monkeypatch.setattr(trees, "foliage_voxels", lambda *a: made.append(1))
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(200 * 2**20))
    with pytest.raises(ResourceLimitError) as caught:
        generate_scene("small", trees=5000)
    message = str(caught.value)
    assert (
        message.startswith("generating 5,000 trees (about ")
        and "more than the 0.195 GiB of memory" in message
    )
    assert made == []
    generate_scene("small", trees=20)  # a small one fits


def test_a_fine_voxel_size_is_refused_before_the_vehicles_are_made(monkeypatch):
    """--voxel-size 0.01 spent 37 s and 4 GB making the vehicle (a 563 x 563 x 221
    voxel box, 60 bytes a cell) before the estimate, which counted the trees only,
    refused it; under a 3.5 GB address-space limit it died with a traceback."""
    from ladartui.errors import ResourceLimitError
    from ladartui.scene import generate

    made = []
    terrain = generate._terrain
    monkeypatch.setattr(generate, "vehicle_voxels", lambda *a: made.append(1))
    monkeypatch.setattr(generate, "_terrain", lambda *a: made.append(2))
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(3 * 2**30))
    with pytest.raises(ResourceLimitError) as caught:
        generate_scene("small", voxel_size=0.01)
    assert made == []
    message = str(caught.value)
    assert message.startswith("generating 1 vehicle at 0.01 m (a 563 x 563 x 221 voxel box) and the ground")
    assert "more than the 3 GiB of memory available" in message and "coarser voxel size" in message
    need = float(message.split("needs about ")[1].split(" GiB")[0])
    assert 4.0 < need < 6.0  # 4.2 GB measured at its peak (the vehicle, the ground's maps)
    monkeypatch.setattr(generate, "_terrain", terrain)
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(8 * 2**30))
    with pytest.raises(ResourceLimitError) as caught:  # the trees' estimate, still before the vehicle
        generate_scene("small", voxel_size=0.01)
    assert str(caught.value).startswith("generating 48 trees (about ")
    assert made == []


def test_las_copies_are_part_of_the_set(tmp_path, small, monkeypatch):
    """The .laz copies were written after the models, outside their set: a Ctrl-C there
    left new models beside old copies (and a killed run a temporary no run removed)."""
    laspy = pytest.importorskip("laspy")
    from ladartui.scene import las

    small.write(tmp_path / "forest", las=True)
    names = ["forest.laz", "forest.txt", "forest_Target.laz", "forest_Target.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == names
    with laspy.open(tmp_path / "forest.laz") as reader:
        assert reader.header.are_points_compressed and reader.header.point_count == len(small.voxels)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    real, calls = las.write_las, []

    def fail_on_second(*args, **options):
        calls.append(1)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        real(*args, **options)

    monkeypatch.setattr(las, "write_las", fail_on_second)
    with pytest.raises(OutputFileError):
        generate_scene("small", seed=3, trees=5).write(tmp_path / "forest", las=True)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_las_copies_are_written_straight_into_the_sets_temporaries(tmp_path, small, monkeypatch):
    """Each .laz copy went to a temporary of the set's temporary: the exporter, atomic
    itself, made a second one beside the first and renamed it over."""
    pytest.importorskip("laspy")
    made = record_temporaries(monkeypatch)
    small.write(tmp_path / "forest", las=True)
    assert sorted(prefix for prefix in made if ".laz" in prefix) == [".forest.laz.", ".forest_Target.laz."]


@pytest.mark.parametrize("radius", [0.5, 1.0, 1.5, 2.5, 4.0])
def test_the_memory_estimates_clump_size_is_the_stamped_clumps_mean_size(radius):
    """The estimate rebuilt the clump's shape beside the template's: had one changed,
    the memory estimate would have drifted from the trees it estimates."""
    from ladartui.scene.trees import _clump_chances, _clump_template, expected_clump_voxels

    rng = np.random.default_rng(7)
    draws = 4000
    sizes = [len(_clump_template(radius, rng)) for _ in range(draws)]
    chance = _clump_chances(radius)[1]
    spread = math.sqrt(float(np.sum(chance * (1 - chance))) / draws)  # of the mean of the draws
    assert abs(np.mean(sizes) - expected_clump_voxels(radius)) <= 4 * spread + 1e-9


def test_merging_by_flags_and_by_sorting_give_the_same_sorted_union(monkeypatch):
    """A merge whose box is no larger than its lists flags cells instead of sorting (9.3 s
    to sort 67 million voxels of a 30,000-tree scene); both give each voxel once, by x, y, z."""
    from ladartui.scene import generate

    rng = np.random.default_rng(7)
    lists = [rng.integers(0, (30, 20, 10), (n, 3)).astype(np.int32) for n in (5000, 3000, 0)]
    flagged = generate._merge(lists)
    monkeypatch.setattr(generate, "VOXEL_CHUNK", 333)  # flags set a chunk at a time
    flagged_in_chunks = generate._merge(lists)
    monkeypatch.setattr(generate, "DENSE_MERGE", 0)  # always sort
    sorted_ = generate._merge(lists)
    expected = np.unique(np.concatenate(lists), axis=0)  # (rows sorted by x, then y, then z)
    for merged in (flagged, flagged_in_chunks, sorted_):
        assert np.array_equal(merged, expected)
    assert len(expected) < 8000  # (repeats were there to drop)


def test_a_cancel_during_the_clearing_stops_it_before_its_end(monkeypatch):
    """Ctrl-C waited for the whole clearing stage (13 s for 30,000 trees): its plant
    voxels are now clipped and carved a chunk at a time, each after a check, and
    chunks of any size give the same scene."""
    import threading

    from ladartui.errors import Cancelled
    from ladartui.scene import generate

    whole = generate_scene("small", seed=3, trees=30, camouflage=True, vehicles=2)
    monkeypatch.setattr(generate, "VOXEL_CHUNK", 997)  # many chunks, none aligned to a part
    chunked = generate_scene("small", seed=3, trees=30, camouflage=True, vehicles=2)
    assert np.array_equal(chunked.voxels, whole.voxels)
    assert np.array_equal(chunked.target, whole.target)

    cancel = threading.Event()
    checks = []
    real_inside = generate._inside_and_clear

    def cancel_in_first_chunk(*args):
        checks.append(1)
        cancel.set()
        return real_inside(*args)

    monkeypatch.setattr(generate, "_inside_and_clear", cancel_in_first_chunk)
    with pytest.raises(Cancelled):
        generate_scene("small", seed=3, trees=30, vehicles=2, cancel=cancel)
    assert len(checks) == 1  # the chunk after it was never cleared


def test_a_cancel_during_the_merging_stops_it_before_its_end(monkeypatch):
    """The merging stage (8 s for 100,000 trees) ran as one step: its flags are now set
    a chunk of voxels at a time, each after the stage's cancel check."""
    from ladartui.errors import Cancelled
    from ladartui.scene import generate

    monkeypatch.setattr(generate, "VOXEL_CHUNK", 1000)
    rng = np.random.default_rng(9)
    lists = [rng.integers(0, (30, 20, 10), (n, 3)).astype(np.int32) for n in (5000, 3000)]
    keyed = []
    real_keys = generate._merge_keys
    monkeypatch.setattr(generate, "_merge_keys", lambda v, top: keyed.append(len(v)) or real_keys(v, top))

    def cancel_after(checks):
        def checkpoint():
            checks.append(1)
            if len(checks) > 1:
                raise Cancelled("generating cancelled")

        return checkpoint

    with pytest.raises(Cancelled):
        generate._merge(lists, cancel_after([]))
    assert keyed == [1000]  # of 8,000 voxels in eight chunks, one was keyed
    keyed.clear()
    monkeypatch.setattr(generate, "DENSE_MERGE", 0)  # the sorting way: checked before its sort
    with pytest.raises(Cancelled):
        generate._merge(lists, cancel_after([None]))
    assert keyed == [5000, 3000]
