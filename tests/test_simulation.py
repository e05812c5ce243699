"""The run end to end on tiny hand-made scenes: fusion, measures, outputs, progress, cancel."""

import threading

import numpy as np
import pytest

import ladartui.simulation as simulation
from ladartui.cmf import read_cmf
from ladartui.errors import Cancelled
from ladartui.flight import FlightPlan, Manual, ScanPose, aim_at
from ladartui.returns import fuse_scans
from ladartui.scenario import Scenario
from ladartui.scene.voxels import load_voxels, save_voxels
from ladartui.sensor import Sensor
from ladartui.simulation import simulate
from temporaries import record_temporaries

TARGET_CENTRE = (22.5, 21.5, 1.0)


def box(x0, x1, y0, y1, z0, z1):
    return np.array(
        [(x, y, z) for x in range(x0, x1) for y in range(y0, y1) for z in range(z0, z1)], dtype=np.int32
    )


def as_set(voxels):
    return {tuple(v) for v in np.asarray(voxels).tolist()}


def make_scenario(folder, scene, target, poses, sensor, name="S"):
    save_voxels(folder / "forest.txt", scene)
    save_voxels(folder / "forest_Target.txt", target)
    return Scenario(
        folder / f"{name}.toml",
        "forest.txt",
        1.0,
        sensor,
        FlightPlan(segments=[Manual(tuple(poses))]),
        speed=25.0,
        backend="numba",
    )


@pytest.fixture
def forest(tmp_path):
    """A 6 x 4 x 3 vehicle under a patchy canopy layer at z = 8, seen from four scans."""
    target = box(20, 26, 20, 24, 0, 3)
    canopy = np.array(
        [(x, y, 8) for x in range(16, 30) for y in range(16, 28) if (7 * x + 3 * y) % 4], dtype=np.int32
    )
    poses = [
        aim_at(ScanPose(x, y, 60.0), TARGET_CENTRE)
        for x, y in [(22.5, 0.0), (45.0, 21.5), (22.5, 21.5), (0.0, 21.5)]
    ]
    sensor = Sensor(grid=32, ray_grid=2, fov=20.0, depth_resolution=1.0)
    return make_scenario(tmp_path, np.vstack([target, canopy]), target, poses, sensor)


def test_forest_run_end_to_end(forest):
    reports = []
    result = simulate(forest, progress=reports.append)
    m = result.measures
    assert result.backend == "numba"
    assert result.scans == 4 and len(result.target_per_scan) == 4
    # Foliage can only take coverage away here.
    assert 0 < m.obscured_coverage <= m.unobscured_coverage <= m.maximum_coverage <= 1
    assert m.scans == 4 and m.obscured_after_scan[-1] == pytest.approx(m.obscured_coverage)
    # The fused output is the union of the scans' returns.
    assert as_set(result.scene_output) == set().union(*map(as_set, result.scene_per_scan))
    assert as_set(result.target_output) == set().union(*map(as_set, result.target_per_scan))
    # The target-only run sees nothing but target voxels and ground.
    target = as_set(load_voxels(forest.target_file))
    assert all(v in target or v[2] == 0 for v in as_set(result.target_output))
    # Outputs on disk are the fused lists and the measures.
    assert as_set(load_voxels(forest.scene_output)) == as_set(result.scene_output)
    assert as_set(load_voxels(forest.target_output)) == as_set(result.target_output)
    assert read_cmf(forest.measures_file) == m
    assert m.path_length_m == pytest.approx(forest.path_length())
    assert m.flight_time_s == pytest.approx(forest.path_length() / 25.0)
    # Progress: both runs, fractions rising to 1, one report with returns per scan.
    fractions = [p.fraction for p in reports]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    assert [(p.run, p.scan) for p in reports if p.returns is not None] == [
        (run, scan) for scan in (1, 2, 3, 4) for run in ("scene", "target")
    ]
    assert reports[-1].rays_done == reports[-1].rays_total == 2 * 4 * 64 * 64


def test_fusion_over_scans_equals_union_of_single_scan_runs(forest, tmp_path):
    poses = forest.poses()
    whole = simulate(forest, write=False)
    singles = [
        simulate(forest.with_changes(flight=FlightPlan(segments=[Manual((pose,))])), write=False)
        for pose in poses
    ]
    assert as_set(whole.scene_output) == set().union(*(as_set(r.scene_output) for r in singles))
    for fused, single in zip(whole.scene_per_scan, singles):
        assert as_set(fused) == as_set(single.scene_output)
    assert as_set(fuse_scans(whole.scene_per_scan)) == as_set(whole.scene_output)


def test_solid_box_from_straight_above(tmp_path):
    # Nadir over the centre of a 4 x 4 x 3 box, no foliage: diverging rays from
    # above can only enter the roof, so coverage is the top layer's share and
    # the mean direction points straight up.
    target = box(10, 14, 10, 14, 0, 3)
    pose = ScanPose(12.0, 12.0, 50.0, depression=90.0)
    sensor = Sensor(grid=32, ray_grid=2, fov=10.0, depth_resolution=0.5)
    scenario = make_scenario(tmp_path, target, target, [pose], sensor)
    m = simulate(scenario, write=False).measures
    assert m.unobscured_coverage == pytest.approx(16 / 48)
    assert m.obscured_coverage == pytest.approx(16 / 48)
    assert m.unobscured_directions.mean_direction == pytest.approx((0.0, 0.0, 1.0), abs=1e-9)
    assert m.direction_shift_rad == pytest.approx(0.0, abs=1e-6)


def write_earlier_outputs(scenario):
    earlier = {}
    for path, text in (
        (scenario.scene_output, "1,2,3\n"),
        (scenario.target_output, "4,5,6\n"),
        (scenario.measures_file, "earlier measures\n"),
    ):
        path.write_bytes(text.encode())
        earlier[path] = text.encode()
    return earlier


def assert_untouched(scenario, earlier):
    for path, data in earlier.items():
        assert path.read_bytes() == data
    leftovers = [p.name for p in scenario.path.parent.iterdir() if p.name.startswith(".")]
    assert leftovers == []


def test_cancel_mid_run_writes_nothing(forest, monkeypatch):
    # Small chunks, so a scan is traced in several parts and cancel lands inside one.
    monkeypatch.setattr(simulation, "_FIRST_CHUNK_RAYS", 512)
    monkeypatch.setattr(simulation, "_next_chunk", lambda chunk, traced, elapsed: chunk)
    earlier = write_earlier_outputs(forest)
    cancel = threading.Event()
    seen = []

    def progress(p):
        seen.append(p)
        if p.run == "target" and p.scan == 2 and p.returns is None:
            cancel.set()

    with pytest.raises(Cancelled):
        simulate(forest, progress=progress, cancel=cancel)
    # It stopped at the next chunk, not at the end of the scan.
    assert seen[-1].run == "target" and seen[-1].scan == 2 and seen[-1].returns is None
    assert_untouched(forest, earlier)


def test_failed_run_leaves_earlier_outputs(forest):
    earlier = write_earlier_outputs(forest)

    def progress(p):
        if p.run == "target" and p.scan == 4 and p.returns is not None:
            raise RuntimeError("viewer crashed")

    with pytest.raises(RuntimeError):
        simulate(forest, progress=progress)
    assert_untouched(forest, earlier)


def test_no_write_writes_nothing(forest):
    result = simulate(forest, write=False)
    assert result.outputs == {}
    assert not forest.scene_output.exists() and not forest.measures_file.exists()


def test_bad_arguments_are_field_errors_before_anything_runs(forest):
    """A bool cancel, a number as progress or scenario, or another scene failed deep
    inside the run with an AttributeError or TypeError, or scored the other scene."""
    from ladartui.errors import FieldError
    from ladartui.scene.model import Scene

    other = Scene(box(0, 2, 0, 2, 0, 2), box(0, 1, 0, 1, 0, 1), 0.5)
    cases = [
        (dict(cancel=True), r"^cancel = True: expected a threading\.Event"),
        (dict(progress=3), r"^progress = 3: expected a function"),
        (dict(scene="forest.txt"), r"^scene = 'forest.txt': expected the scenario's Scene"),
        (dict(scene=other), r"^scene\.voxel_size = 0\.5: expected the scenario's voxel size \(1\.0\)"),
        # a string is true: write="no" wrote the outputs
        (dict(write="no"), r"^write = 'no': expected True or False"),
        (dict(las="no"), r"^las = 'no': expected True or False"),
    ]
    for arguments, message in cases:
        with pytest.raises(FieldError, match=message):
            simulate(forest, **arguments)
    with pytest.raises(FieldError, match=r"^scenario = 42: expected a Scenario or a scenario file's path"):
        simulate(42)
    assert not forest.scene_output.exists() and not forest.measures_file.exists()


@pytest.mark.parametrize(
    "arguments, message",
    [
        # step=50 traced every scan, then the record of the run could not be written
        (dict(method="march", step=50), r"^step = 50: expected a number from 0\.001 to 10$"),
        (dict(method="march", step=True), r"^step = True: expected a number from 0\.001 to 10$"),
        (dict(method="marsh"), r"^method = 'marsh': expected one of 'exact', 'march'$"),
        (dict(precision="f16"), r"^precision = 'f16': expected one of 'f64', 'f32'$"),
    ],
)
def test_overrides_the_scenario_would_refuse_are_refused_before_any_tracing(
    forest, monkeypatch, arguments, message
):
    from ladartui.errors import FieldError
    from ladartui.scene.model import Scene

    loads = []
    monkeypatch.setattr(Scene, "load", lambda *args, **kwargs: loads.append(args))
    write_earlier_outputs(forest)
    earlier = {path: path.read_bytes() for path in simulation.output_paths(forest).values() if path.exists()}
    for write in (True, False):
        with pytest.raises(FieldError, match=message):
            simulate(forest, write=write, **arguments)
    assert loads == []
    assert {path: path.read_bytes() for path in earlier} == earlier


def test_a_scene_loaded_from_another_file_is_refused(forest, tmp_path):
    """simulate(scenario, scene=...) with the Scene of another scene model ran on it and
    scored that scene as the scenario's, without a word."""
    from ladartui.errors import FieldError
    from ladartui.scene.model import Scene

    save_voxels(tmp_path / "elsewhere.txt", box(0, 4, 0, 4, 0, 4))
    save_voxels(tmp_path / "elsewhere_Target.txt", box(0, 1, 0, 1, 0, 1))
    elsewhere = Scene.load(tmp_path / "elsewhere.txt", forest.voxel_size)
    with pytest.raises(FieldError) as caught:
        simulate(forest, scene=elsewhere, write=False)
    assert str(caught.value) == (
        f"scene is the scene of {tmp_path / 'elsewhere.txt'}: expected the scenario's Scene, "
        f"of {forest.scene_file} (scenario.load_scene())"
    )
    # the scenario's own, and one made in memory from its voxels, run
    own = forest.load_scene()
    assert simulate(forest, scene=own, write=False).measures is not None
    in_memory = Scene(own.voxels, own.target, own.voxel_size, target_ids=own.target_ids)
    assert in_memory.path is None and simulate(forest, scene=in_memory, write=False).measures is not None


def test_las_outputs_hold_the_fused_voxels(forest):
    from ladartui.scene.las import import_las

    result = simulate(forest, las=True)
    for run, fused in (("scene", result.scene_output), ("target", result.target_output)):
        path = forest.path.with_name(f"S_{run.capitalize()}.las")
        assert result.outputs[f"{run}_las"] == str(path)
        voxels, _ = import_las(path, 1.0, origin=(0.0, 0.0, 0.0))
        assert as_set(voxels) == as_set(fused)


def test_las_outputs_are_written_straight_into_the_sets_temporaries(forest, monkeypatch):
    """Each .las output went to a temporary of the set's temporary: the exporter, atomic
    itself, made a second one beside the first and renamed it over."""
    import laspy

    made = record_temporaries(monkeypatch)
    simulate(forest, las=True)
    assert sorted(prefix for prefix in made if ".las" in prefix) == [".S_Scene.las.", ".S_Target.las."]
    with laspy.open(forest.path.with_name("S_Scene.las")) as reader:
        assert not reader.header.are_points_compressed  # a .las name: plain LAS


def test_every_available_backend_gives_the_same_run(forest):
    from ladartui.tracing import backend_status

    available = [name for name, reason in backend_status().items() if reason is None]
    if len(available) < 2:
        pytest.skip(f"only {available} available here")
    results = {name: simulate(forest, backend=name, write=False) for name in available}
    expected = results.pop("numba")
    for name, result in results.items():
        assert result.backend == name
        assert as_set(result.scene_output) == as_set(expected.scene_output), name
        assert as_set(result.target_output) == as_set(expected.target_output), name
        assert result.measures == expected.measures


def test_chunk_size_does_not_change_the_result(forest, monkeypatch):
    whole = simulate(forest, write=False)
    # Three detector rows (32 detectors x 4 rays each) per trace call: 11 calls a scan.
    monkeypatch.setattr(simulation, "_FIRST_CHUNK_RAYS", 3 * 128)
    monkeypatch.setattr(simulation, "_next_chunk", lambda chunk, traced, elapsed: chunk)
    reports = []
    rows = simulate(forest, write=False, progress=reports.append)
    assert sum(p.returns is None for p in reports) == 4 * (2 * 11 - 1)
    for a, b in zip(whole.scene_per_scan + whole.target_per_scan, rows.scene_per_scan + rows.target_per_scan):
        np.testing.assert_array_equal(a, b)
    assert rows.measures == whole.measures


def test_fast_chunks_grow_to_a_whole_object_order_scan():
    """Trace calls grow fourfold while fast, up to one object-order block (a 128 x 128
    sensor's whole scan with 4 x 4 rays, which object order takes in one call), and
    shrink at most fourfold after a slow one."""
    from ladartui.tracing.config import SCAN_BLOCK

    chunk, sizes = simulation._FIRST_CHUNK_RAYS, []
    for _ in range(4):
        chunk = simulation._next_chunk(chunk, chunk, 0.01)  # 10 ms a call: far under the goal
        sizes.append(chunk)
    assert sizes == [4 * simulation._FIRST_CHUNK_RAYS, SCAN_BLOCK, SCAN_BLOCK, SCAN_BLOCK]
    assert simulation._next_chunk(SCAN_BLOCK, SCAN_BLOCK, 10.0) == SCAN_BLOCK // 4


def test_simulate_takes_a_scenario_files_path_as_the_scenario_itself(tmp_path):
    """simulate('S.toml') failed with "'str' object has no attribute 'backend'"."""
    from tiny_sweep import write_tiny_scenario

    scenario = write_tiny_scenario(tmp_path)
    by_object = simulate(scenario, write=False).measures
    for given in (str(scenario.path), scenario.path):
        assert simulate(given, write=False).measures.to_dict() == by_object.to_dict()


def test_a_process_pools_refused_runs_come_back_as_their_errors(forest):
    """simulate over variants in a process pool: a variant refused in its worker (the set
    being written, a mistyped backend, a missing file) could not be unpickled, so
    ProcessPoolExecutor broke and lost every other variant, and Pool.map hung."""
    import multiprocessing
    import pickle
    from concurrent.futures import ProcessPoolExecutor

    from ladartui.errors import FieldError, InputFileError, OutputFileError

    missing = str(forest.path.with_name("missing.toml"))
    spawn = multiprocessing.get_context("spawn")
    with simulation._output_set(forest, False), ProcessPoolExecutor(1, mp_context=spawn) as pool:
        busy = pool.submit(simulate, forest)
        mistyped = pool.submit(simulate, forest, backend="gpu", write=False)
        absent = pool.submit(simulate, missing)
        ran = pool.submit(simulate, forest, write=False)
        with pytest.raises(OutputFileError, match="is writing this output set") as refused:
            busy.result(timeout=120)
        assert refused.value.path == str(forest.path.with_name(".S.outputs.lock"))
        with pytest.raises(FieldError, match="backend = 'gpu': expected one of") as field:
            mistyped.result(timeout=120)
        assert (field.value.field, field.value.value) == ("backend", "gpu")
        with pytest.raises(InputFileError, match="no such file") as file:
            absent.result(timeout=120)
        assert file.value.path == missing
        assert ran.result(timeout=120).scans == 4
    # a value that cannot cross (an Event given as progress) crosses as its description
    event = FieldError("progress", threading.Event(), "a function (or None)")
    again = pickle.loads(pickle.dumps(event))
    assert str(again) == str(event) and repr(again.value) == "an Event"
    error = FieldError("radius", -5.0, "a positive number", source="s.toml", limits=(0.0, None, True, True))
    again = pickle.loads(pickle.dumps(error))
    assert type(again) is FieldError and str(again) == str(error) and again.args == error.args
    assert (again.field, again.value, again.expected, again.limits) == (
        "radius",
        -5.0,
        "a positive number",
        error.limits,
    )
