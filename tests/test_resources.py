"""The resource guard: memory and work estimated up front, refused with one line."""

import numpy as np
import pytest

from cli_support import one_error_line
from ladartui.cli import main
from ladartui.errors import ResourceLimitError
from ladartui.resources import gib, occupancy_bytes, set_max_rays
from ladartui.scene.occupancy import Occupancy
from ladartui.scene.voxels import save_voxels


@pytest.mark.parametrize("far", ["2147483647,2147483647,0", "300000000,0,300000000"])
def test_two_voxels_far_apart_are_refused_not_allocated(tmp_path, capsys, far):
    """Where even the root grid (4 bytes a 512-voxel cell of the box) cannot fit; two
    voxels 10^6 apart on x and y fit in a few MiB since their column tops are left out
    (test_occupancy)."""
    path = tmp_path / "f.txt"
    path.write_text(f"0,0,0\n{far}\n")
    assert main(["info", str(path)]) == 2
    err = one_error_line(capsys)
    assert "f.txt: 2 voxels spanning" in err and "GiB" in err and "available" in err


def test_memory_limit_is_configurable(tmp_path, monkeypatch):
    voxels = np.array([(x, y, 0) for x in range(0, 200, 7) for y in range(0, 200, 7)], np.int32)
    need = occupancy_bytes(voxels.min(0), voxels.max(0) + 1, len(voxels))
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(need - 1))
    with pytest.raises(ResourceLimitError, match=r"woods.txt: 841 voxels .* more than the"):
        Occupancy.build(voxels, source="woods.txt")
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(need))
    assert Occupancy.build(voxels).count == len(voxels)


def test_a_memory_limit_of_one_byte_is_said_in_the_singular(tmp_path, capsys, monkeypatch):
    """LADARTUI_MAX_MEMORY=1 read 'more than the 1 bytes of memory available'."""
    path = tmp_path / "f.txt"
    path.write_text("0,0,0\n1,1,1\n")
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", "1")
    assert main(["info", str(path)]) == 2
    assert one_error_line(capsys).endswith("more than the 1 byte of memory available")
    assert [gib(n) for n in (0, 2, 1023, 1024)] == ["0 bytes", "2 bytes", "1,023 bytes", "1 KiB"]
    # a box far too large read '6.55e+04 GiB'
    assert [gib(n) for n in (999 * 2**30, 2**46, 2**60)] == ["999 GiB", "64 TiB", "1,048,576 TiB"]


@pytest.mark.parametrize(
    "voxels",
    [
        [(x, y, z) for x in range(0, 64, 3) for y in range(0, 40, 5) for z in range(3)],
        [(0, 0, 0), (700, 300, 20)],
    ],
)
def test_estimate_covers_what_the_build_holds(voxels):
    voxels = np.array(voxels, np.int32)
    occupancy = Occupancy.build(voxels)
    estimate = occupancy_bytes(voxels.min(0), voxels.max(0) + 1, len(voxels))
    assert occupancy.nbytes <= estimate <= 40 * occupancy.nbytes + 2**20


def write_big_scenario(folder, grid, ray_grid, scans):
    save_voxels(folder / "s.txt", np.zeros((1, 3), np.int32))
    save_voxels(folder / "s_Target.txt", np.zeros((1, 3), np.int32))
    path = folder / "big.toml"
    path.write_text(
        f'[files]\nscene = "s.txt"\n[sensor]\ngrid = {grid}\nray_grid = {ray_grid}\n'
        '[[flight.segments]]\nkind = "orbit"\ncentre = [0, 0, 0]\nradius = 100\n'
        f"altitude = 100\nscans = {scans}\n"
    )
    return path


def test_validate_says_when_the_scene_and_target_together_pass_the_memory(tmp_path, capsys, monkeypatch):
    """Each tracing structure is checked alone; validate printed a need above the memory
    available ('about 3.41 MiB ... (3.15 MiB available)') as if that were fine."""
    path = write_big_scenario(tmp_path, 16, 1, 4)  # one-voxel scene and target
    one = occupancy_bytes(np.zeros(3, np.int64), np.ones(3, np.int64), 1)
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(one))  # each fits, the two do not
    assert main(["validate", str(path)]) == 0
    line = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("memory"))
    assert line.endswith("available): more than this machine has; a run may fail for want of memory")
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(4 * one))
    assert main(["validate", str(path)]) == 0
    line = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("memory"))
    assert line.endswith("available)")


def test_a_run_over_the_ray_limit_is_a_next_run_line_after_the_summary(tmp_path, capsys, monkeypatch):
    """validate gave one error line and exit 2, naming 'big.toml:' without its folder,
    though its --help promises a sound scenario a run would refuse before tracing its
    summary, a 'next run' line saying why, and exit 1."""
    path = write_big_scenario(tmp_path, 1024, 16, 10000)
    assert main(["validate", str(path)]) == 1
    out, err = capsys.readouterr()
    assert err == "" and out.startswith(f"scenario   {path}\n")
    assert (
        "\nrays       268,435,456 per scan, 2,684,354,560,000 in all; 5,368,709,120,000 traced with "
        "the target-alone run\n"
    ) in out
    assert out.splitlines()[-1] == (
        f"next run   {path}: sensor.grid = 1024, sensor.ray_grid = 16, 10,000 scans x 2 runs "
        "(the scene run and the target-alone run): about 5.37e+12 "
        "rays to trace, more than the limit of 2e+09 (raise it with LADARTUI_MAX_RAYS or run's "
        "--max-rays if this is meant); the run is refused before it traces"
    )
    monkeypatch.setenv("LADARTUI_MAX_RAYS", "6e12")
    assert main(["validate", str(path)]) == 0
    assert "next run" not in capsys.readouterr().out
    # a run still refuses it, in one line naming the file with its folder
    monkeypatch.delenv("LADARTUI_MAX_RAYS")
    assert main(["run", str(path), "--no-write"]) == 2
    assert one_error_line(capsys).startswith(f"ladartui: error: {path}: sensor.grid = 1024,")


def test_max_rays_flag(tmp_path, capsys):
    path = write_big_scenario(tmp_path, 16, 2, 4)  # 2 x 1024 x 4 = 8192 rays
    try:
        assert main(["run", str(path), "--no-write", "--max-rays", "8000"]) == 2
        assert "8.19e+03 rays to trace, more than the limit of 8e+03" in one_error_line(capsys)
        assert main(["run", str(path), "--no-write", "--max-rays", "0"]) == 2
        assert "--max-rays = 0: expected" in one_error_line(capsys)
    finally:
        set_max_rays(None)


def test_huge_sweep_and_generate_are_refused(tmp_path, capsys):
    spec = tmp_path / "sp.toml"
    spec.write_text(
        '[sweep]\nscenario = "default"\n[random]\nsamples = 1000000000000\nseed = 1\n'
        "radius = {min = 1, max = 2}\n"
    )
    assert main(["sweep", str(spec), "--serial"]) == 2
    assert "1,000,000,000,000 variants" in one_error_line(capsys)
    spec.write_text(
        '[sweep]\nscenario = "default"\n[grid]\n'
        + "".join(
            f"{name} = [{', '.join(str(v) for v in range(1, 101))}]\n"
            for name in ("radius", "altitude", "scans")
        )
    )
    assert main(["sweep", str(spec), "--serial"]) == 2
    assert "1,000,000 variants (100 radius x 100 altitude x 100 scans)" in one_error_line(capsys)
    # each list's length written as the total is: '2,000 radius', not '2000 radius'
    spec.write_text(
        '[sweep]\nscenario = "default"\n[grid]\nradius = { start = 1, stop = 2000, step = 1 }\n'
        "altitude = { start = 1, stop = 100, step = 1 }\n"
    )
    assert main(["sweep", str(spec), "--serial"]) == 2
    assert "200,000 variants (2,000 radius x 100 altitude)" in one_error_line(capsys)
    assert main(["generate", "small", str(tmp_path / "x"), "--trees", "100000000"]) == 2
    assert "trees = 100000000: expected at most 100,000 trees" in one_error_line(capsys)


def test_sparse_huge_voxel_file_is_refused_before_reading(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(16 * 2**30))
    path = tmp_path / "sparse.txt"
    with open(path, "wb") as handle:  # 50 GB on paper, nothing on disk
        handle.truncate(50 * 10**9)
    assert main(["info", str(path)]) == 2
    err = one_error_line(capsys)
    assert "sparse.txt: a voxel list of 46.6 GiB needs about 93.1 GiB to read, more than the 16 GiB" in err


@pytest.mark.parametrize("value", ["abc", "-1", "0", "nan"])
def test_a_bad_limit_in_the_environment_is_named_not_ignored(monkeypatch, value):
    from ladartui.resources import available_memory, max_rays

    monkeypatch.setenv("LADARTUI_MAX_RAYS", value)
    with pytest.raises(ResourceLimitError) as rays:
        max_rays()
    assert str(rays.value) == f"LADARTUI_MAX_RAYS = {value!r}: expected a number of rays >= 1"
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", value)
    with pytest.raises(ResourceLimitError) as memory:
        available_memory()
    assert str(memory.value) == f"LADARTUI_MAX_MEMORY = {value!r}: expected a number of bytes >= 1"


def test_a_ray_limit_names_how_its_caller_raises_it_and_a_sweep_its_own_way(monkeypatch):
    """A sweep's advice was made by replacing text in the message: a reworded message
    would have kept advising --max-rays, which a sweep does not have."""
    import pickle

    from ladartui.resources import RAISE_RAYS, SWEEP_RAISE_RAYS, RayLimitError, check_rays, sweep_advice

    with pytest.raises(RayLimitError) as command:
        check_rays(3e6, "s.toml", limit=1e6)
    assert str(command.value) == (
        f"s.toml: about 3e+06 rays to trace, more than the limit of 1e+06 (raise it with {RAISE_RAYS} "
        "if this is meant)"
    )
    with pytest.raises(RayLimitError) as own:
        check_rays(3e6, "s.toml", limit=1e6, raise_with=SWEEP_RAISE_RAYS)
    assert sweep_advice(command.value) == str(own.value) != str(command.value)
    assert "--max-rays" not in str(own.value) and SWEEP_RAISE_RAYS in str(own.value)
    assert str(pickle.loads(pickle.dumps(own.value))) == str(own.value)
    other = ResourceLimitError(f"x.txt: too big; use {RAISE_RAYS}")  # not a ray limit: as it is
    assert sweep_advice(other) == str(other)


def test_a_scenario_over_the_ray_limit_opens_and_only_work_on_it_is_refused(tmp_path, monkeypatch):
    """Reading a scenario over the limit was refused, so the TUI could not open it to cut
    it down, nor a script shrink it: the limit is the work's, checked where work starts."""
    from ladartui import load_scenario, simulate
    from ladartui.detection.pulses import pulse_study
    from ladartui.flight import FlightPlan, Orbit
    from ladartui.resources import RayLimitError
    from tiny_sweep import CENTRE, write_tiny_scenario

    path = write_tiny_scenario(tmp_path).path  # 8 x 8 detectors, 2 x 2 rays each: 256 rays a scan
    monkeypatch.setenv("LADARTUI_MAX_RAYS", "2000")  # two runs of 4 scans: 2,048
    scenario = load_scenario(path)
    with pytest.raises(RayLimitError) as refused:
        simulate(scenario)
    assert str(refused.value).startswith(
        f"{path}: sensor.grid = 8, sensor.ray_grid = 2, 4 scans x 2 runs "
        "(the scene run and the target-alone run): "
        "about 2.05e+03 rays to trace"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["base.toml", "tiny.txt", "tiny_Target.txt"]
    three = scenario.with_changes(
        flight=FlightPlan(segments=(Orbit(centre=CENTRE, radius=20.0, altitude=20.0, scans=3),))
    )
    assert len(simulate(three, write=False).measures.obscured_after_scan) == 3
    monkeypatch.setenv("LADARTUI_MAX_RAYS", "1000")  # a pulse study traces each scan once: 1,024
    with pytest.raises(RayLimitError, match=r"about 1\.02e\+03 rays to trace, more than the limit of 1e\+03"):
        pulse_study(scenario, [1])
    assert pulse_study(three, [1])[1][0].pulses == 1  # 768 rays


def test_a_study_over_the_ray_limit_is_refused_before_it_traces(tmp_path, monkeypatch):
    """A study's traces were not counted: one over a scenario of a large sensor ran on
    until Ctrl-C (and one over a scenario whose own run was over the limit was refused
    though it traces a few of its scans)."""
    from ladartui.resources import RayLimitError
    from ladartui.study.inputs import scenario_inputs
    from ladartui.study.run import run_study
    from ladartui.study.settings import Setting, reference_setting
    from tiny_sweep import write_tiny_scenario

    inputs = scenario_inputs(write_tiny_scenario(tmp_path).path, scans=2)  # 64 detectors
    march = Setting("numba", "march", "f64", 0.5, 1)
    # the reference at ray grids 1 and 2, a march at 1; each 2 scans, 1 warm-up, 3 repeats
    # of the first scan (runs=5): 64 x 6 + 256 x 6 + 64 x 5 + the march's warm-up, 64 rays
    rays = 64 * 6 + 256 * 6 + 64 * 5 + 64
    monkeypatch.setenv("LADARTUI_MAX_RAYS", str(rays - 1))
    import ladartui.study.run as study_run

    traced, real = [], study_run._trace
    monkeypatch.setattr(study_run, "_trace", lambda *args: traced.append(args) or real(*args))
    with pytest.raises(RayLimitError) as refused:
        run_study(inputs, [march, reference_setting(2)], runs=5, warmup=1)
    assert f"about {rays:.3g} rays to trace" in str(refused.value) and traced == []
    assert "LADARTUI_MAX_RAYS if" in str(refused.value) and "--max-rays" not in str(refused.value)
    monkeypatch.setenv("LADARTUI_MAX_RAYS", str(rays))  # exactly the count: it runs
    result = run_study(inputs, [march, reference_setting(2)], runs=5, warmup=1)
    assert traced and all(row.status == "ok" for row in result.rows)


def test_the_tui_study_says_how_to_raise_the_ray_limit_as_its_run_does(tmp_path, monkeypatch):
    """The study screen said "raise it with LADARTUI_MAX_RAYS if this is meant", the
    command's advice; F5 says the variable is set before ladartui starts."""
    from ladartui.resources import RAISE_IN_TUI, RayLimitError
    from ladartui.tui.study_screen import _study
    from tiny_sweep import write_tiny_scenario

    path = write_tiny_scenario(tmp_path).path
    monkeypatch.setenv("LADARTUI_MAX_RAYS", "1000")
    with pytest.raises(RayLimitError) as refused:
        _study("quick", path, 2, 3, None, lambda *args: None)
    assert f"(raise it with {RAISE_IN_TUI} if this is meant)" in str(refused.value)


def _address_space_in_use() -> int:
    with open("/proc/self/status", encoding="ascii") as status:
        line = next(line for line in status if line.startswith("VmSize:"))
    return int(line.split()[1]) * 1024


def test_an_address_space_limit_bounds_the_memory_available(tmp_path, capsys, monkeypatch):
    """Under `ulimit -v 4000000` a trace of 30 million rays, estimated at 7.1 GiB, was
    checked against the 22 GiB the kernel had free, read its rays, traced for 80 s and
    ended in a MemoryError traceback; the limit left to the process is what it has."""
    import resource

    from numpy.lib import format as npy

    from ladartui.resources import available_memory

    room = 100 * 2**20
    limit = _address_space_in_use() + room
    real = resource.getrlimit
    monkeypatch.setattr(
        resource, "getrlimit", lambda which: (limit, limit) if which == resource.RLIMIT_AS else real(which)
    )
    assert available_memory() <= room
    rays = tmp_path / "rays.npy"
    with open(rays, "wb") as handle:  # a million rays on paper
        npy.write_array_header_1_0(handle, {"descr": "<f8", "fortran_order": False, "shape": (10**6, 6)})
    assert main(["trace", "--scene", str(tmp_path / "s.txt"), "--rays", str(rays), "--out", "h.npy"]) == 2
    err = one_error_line(capsys)
    assert "rays.npy: 1,000,000 rays need about" in err and "MiB of memory available" in err


@pytest.mark.parametrize("version", [1, 2])
def test_a_memory_cgroup_limit_bounds_the_memory_available(tmp_path, monkeypatch, version):
    """In a container or a batch job limited to 2 GiB the host's free memory was taken as
    what a run may allocate; the cgroup's limit less its use (page cache aside) is."""
    from ladartui import resources

    proc = tmp_path / "cgroup"
    if version == 2:
        proc.write_text("0::/job/7\n")
        folder, names, prefix = tmp_path / "job" / "7", ("memory.max", "memory.current"), ""
    else:
        proc.write_text("5:cpu:/x\n4:memory:/job/7\n")
        folder = tmp_path / "memory"  # the container's own group, at the root of the mount
        names, prefix = ("memory.limit_in_bytes", "memory.usage_in_bytes"), "total_"
    folder.mkdir(parents=True)
    (folder / names[0]).write_text(f"{2 * 2**30}\n")
    (folder / names[1]).write_text(f"{2**30 + 300 * 2**20}\n")
    (folder / "memory.stat").write_text(
        f"{prefix}inactive_file {200 * 2**20}\n{prefix}active_file {100 * 2**20}\n"
    )
    monkeypatch.setattr(resources, "_PROC_CGROUP", str(proc))
    monkeypatch.setattr(resources, "_CGROUP_ROOT", str(tmp_path))
    monkeypatch.setattr(resources, "_free_memory", lambda: 64 * 2**30)
    monkeypatch.setattr(resources, "_address_space_left", lambda: None)
    assert resources.available_memory() == 2**30
    (folder / names[0]).write_text("max\n" if version == 2 else f"{2**63 - 4096}\n")
    assert resources.available_memory() == 64 * 2**30


@pytest.mark.parametrize("version", [1, 2])
def test_a_limit_on_a_parent_cgroup_bounds_the_memory_available(tmp_path, monkeypatch, version):
    """A batch scheduler limits its job's cgroup and leaves the task's own unlimited
    (job_1 at 1 GiB, job_1/step_0/task_0 at 'max'): the host's free memory was taken."""
    from ladartui import resources

    proc = tmp_path / "cgroup"
    if version == 2:
        proc.write_text("0::/job_1/step_0/task_0\n")
        mount, names, unlimited = tmp_path, ("memory.max", "memory.current"), "max"
    else:
        proc.write_text("4:memory:/job_1/step_0/task_0\n")
        mount = tmp_path / "memory"
        names, unlimited = ("memory.limit_in_bytes", "memory.usage_in_bytes"), str(2**63 - 4096)
    job = mount / "job_1"
    task = job / "step_0" / "task_0"
    task.mkdir(parents=True)
    for folder, limit, used in ((job, str(2**30), 300 * 2**20), (task, unlimited, 100 * 2**20)):
        (folder / names[0]).write_text(limit + "\n")
        (folder / names[1]).write_text(f"{used}\n")
    monkeypatch.setattr(resources, "_PROC_CGROUP", str(proc))
    monkeypatch.setattr(resources, "_CGROUP_ROOT", str(tmp_path))
    monkeypatch.setattr(resources, "_free_memory", lambda: 64 * 2**30)
    monkeypatch.setattr(resources, "_address_space_left", lambda: None)
    assert resources.available_memory() == 2**30 - 300 * 2**20  # the job's room, not the host's
    (task / names[0]).write_text(f"{200 * 2**20}\n")  # a tighter limit below it wins
    assert resources.available_memory() == 100 * 2**20
