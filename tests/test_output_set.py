"""All-or-nothing output sets: checks before tracing, rollback, the lock, stale temporaries."""

import errno
import os
from pathlib import Path

import numpy as np
import pytest

import ladartui.outputset as outputset
from cli_support import one_error_line
from ladartui.cli import main
from ladartui.errors import OutputFileError
from ladartui.flight import FlightPlan, Manual, ScanPose, aim_at
from ladartui.scenario import Scenario
from ladartui.scene.voxels import save_voxels
from ladartui.sensor import Sensor
from ladartui.simulation import _output_set, simulate


def make_scenario(folder):
    target = np.array(
        [(x, y, z) for x in range(8, 12) for y in range(8, 11) for z in range(2)], dtype=np.int32
    )
    canopy = np.array(
        [(x, y, 6) for x in range(6, 14) for y in range(6, 13) if (x + 2 * y) % 3], dtype=np.int32
    )
    folder.mkdir(parents=True, exist_ok=True)
    save_voxels(folder / "woods.txt", np.vstack([target, canopy]))
    save_voxels(folder / "woods_Target.txt", target)
    poses = tuple(aim_at(ScanPose(x, y, 40.0), (9.5, 9.0, 0.5)) for x, y in [(9.5, -10.0), (29.5, 9.0)])
    return Scenario(
        folder / "S.toml",
        "woods.txt",
        1.0,
        Sensor(grid=16, ray_grid=2, fov=20.0),
        FlightPlan(segments=[Manual(poses)]),
        backend="numba",
    ).save()


def outputs_of(scenario):
    return [scenario.scene_output, scenario.target_output, scenario.measures_file]


def write_old_set(scenario):
    for index, path in enumerate(outputs_of(scenario)):
        path.write_text(f"old {index}\n")
    return snapshot(scenario)


def snapshot(scenario):
    return [p.read_bytes() if p.is_file() else None for p in outputs_of(scenario)]


def hidden(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


@pytest.fixture
def scenario(tmp_path):
    return make_scenario(tmp_path)


def test_target_output_a_folder_is_refused_before_tracing(scenario, capsys, monkeypatch):
    old = write_old_set(scenario)
    scenario.target_output.unlink()
    scenario.target_output.mkdir()
    traced = []
    monkeypatch.setattr("ladartui.simulation._ScanRunner.scan", lambda *a: traced.append(a))
    assert main(["run", str(scenario.path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "S_Target.txt" in err and "is a folder" in err
    assert traced == []
    assert snapshot(scenario)[0::2] == old[0::2]  # S.cmf and S_Scene.txt untouched


def test_failed_write_replaces_nothing(scenario, capsys, monkeypatch):
    old = write_old_set(scenario)
    real = Path.write_bytes

    def disk_full(path, data):  # the set's writers put each output's bytes in its temporary
        if ".S_Target.txt." in str(path):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(path, data)

    monkeypatch.setattr(Path, "write_bytes", disk_full)
    assert main(["run", str(scenario.path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]  # after the progress bar
    assert err.startswith("ladartui: error:") and "S_Target.txt" in err and "no space left" in err
    assert "earlier outputs are unchanged" in err
    assert snapshot(scenario) == old
    assert hidden(scenario.path.parent) == []


def test_failure_during_the_swap_rolls_back(scenario, monkeypatch):
    old = write_old_set(scenario)
    real = os.rename
    moved = []

    def failing(src, dst):
        if str(src).endswith(".tmp"):
            moved.append(dst)
            if len(moved) == 2:  # the first new file is already in place
                raise OSError(errno.EIO, "Input/output error")
        return real(src, dst)

    monkeypatch.setattr(outputset.os, "rename", failing)
    with pytest.raises(OutputFileError, match="S_Target.txt: could not be replaced"):
        simulate(scenario)
    assert snapshot(scenario) == old
    assert hidden(scenario.path.parent) == []


def test_an_output_that_cannot_be_moved_aside_is_one_line(scenario, capsys, monkeypatch):
    """An earlier output the folder will not let go (immutable, or another user's in a
    sticky folder) ended the run in a PermissionError traceback from the swap."""
    old = write_old_set(scenario)
    real = os.rename

    def refused(src, dst):
        if str(src) == str(scenario.target_output):
            raise PermissionError(errno.EPERM, "Operation not permitted", str(src), str(dst))
        return real(src, dst)

    monkeypatch.setattr(outputset.os, "rename", refused)
    assert main(["run", str(scenario.path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]  # after the progress bar
    assert err == (
        f"ladartui: error: {scenario.target_output}: could not be replaced (operation not "
        "permitted); nothing was replaced, earlier outputs are unchanged"
    )
    assert snapshot(scenario) == old
    assert hidden(scenario.path.parent) == []


def test_a_commit_that_cannot_remove_its_journal_is_said_as_such(scenario, capsys, monkeypatch):
    """The journal's removal (the commit point) refused read "…outputs.lock.journal: could
    not be replaced", of a file that is no output."""
    from ladartui.outputset import journal_path
    from ladartui.simulation import output_lock

    old = write_old_set(scenario)
    journal = journal_path(output_lock(scenario))
    real, refusals = os.unlink, []

    def refused(path, *args, **kwargs):
        if str(path) == str(journal) and not refusals:  # the commit; the roll back may
            refusals.append(path)
            raise PermissionError(errno.EPERM, "Operation not permitted", str(path))
        return real(path, *args, **kwargs)

    monkeypatch.setattr(outputset.os, "unlink", refused)
    assert main(["run", str(scenario.path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err == (
        f"ladartui: error: {journal}: could not be removed (operation not permitted); nothing "
        "was replaced, earlier outputs are unchanged"
    )
    assert snapshot(scenario) == old


def test_a_full_disk_at_the_lock_names_it_and_replaces_nothing(scenario, capsys):
    """The lock's pid was the first byte written: on a full disk the run said only "could
    not write the output", and simulate raised a bare OSError."""
    from cli_support import file_size_limit
    from ladartui.simulation import output_lock

    old = write_old_set(scenario)
    with file_size_limit(0):
        assert main(["run", str(scenario.path)]) == 2
        with pytest.raises(OutputFileError, match=".S.outputs.lock: could not be written"):
            simulate(scenario)
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1] == (
        f"ladartui: error: {output_lock(scenario)}: could not be written (file too large); "
        "nothing was replaced, earlier outputs are unchanged"
    )
    assert snapshot(scenario) == old
    assert hidden(scenario.path.parent) == []


def test_no_room_for_a_temporary_names_the_output_in_one_line(scenario, capsys, monkeypatch):
    """A folder out of inodes (or over an inode quota) let the run's checks through, then
    refused a temporary beside an output: a traceback ending in tempfile's OSError."""
    import tempfile

    old = write_old_set(scenario)
    real = tempfile.mkstemp

    def over_quota(suffix=None, prefix=None, dir=None, text=False):
        if prefix == ".S_Target.txt." and suffix == ".tmp":  # the set's temporary, not the check's probe
            path = os.path.join(dir, prefix + "abcdefgh" + suffix)
            raise OSError(errno.EDQUOT, "Disk quota exceeded", path)
        return real(suffix, prefix, dir, text)

    monkeypatch.setattr(tempfile, "mkstemp", over_quota)
    assert main(["run", str(scenario.path)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1] == (
        f"ladartui: error: {scenario.target_output}: could not be written (disk quota exceeded); "
        "nothing was replaced, earlier outputs are unchanged"
    )
    assert snapshot(scenario) == old
    assert hidden(scenario.path.parent) == []


def test_a_full_disk_at_the_journal_names_it_and_replaces_nothing(scenario, capsys, monkeypatch):
    import json
    from types import SimpleNamespace

    old = write_old_set(scenario)

    def disk_full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(outputset, "json", SimpleNamespace(dump=disk_full, loads=json.loads))
    assert main(["run", str(scenario.path)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1] == (
        f"ladartui: error: {scenario.path.parent / '.S.outputs.lock.journal'}: could not be "
        "written (no space left on device); nothing was replaced, earlier outputs are unchanged"
    )
    assert snapshot(scenario) == old
    assert hidden(scenario.path.parent) == []


def test_second_writer_is_refused(scenario, capsys):
    old = write_old_set(scenario)
    with _output_set(scenario, las=False):
        assert main(["run", str(scenario.path)]) == 75  # another writes it: try again later
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "another run" in err and f"pid {os.getpid()}" in err and err.startswith("ladartui: error")
    assert snapshot(scenario) == old
    assert main(["run", str(scenario.path)]) == 0  # the lock is let go
    assert hidden(scenario.path.parent) == []


def test_a_folder_where_the_lock_goes_is_one_line(scenario, capsys):
    """A folder of the set's lock file's name (.S.outputs.lock) ended a run in an
    IsADirectoryError traceback, from os.open."""
    from ladartui.simulation import output_lock

    lock = output_lock(scenario)
    lock.mkdir()
    assert main(["run", str(scenario.path)]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: {lock}: is a folder, expected the lock file of this set of outputs "
        "(made while they are written): remove the folder"
    )
    assert snapshot(scenario) == [None] * len(snapshot(scenario))
    assert main(["validate", str(scenario.path)]) == 1  # the summary, then what a run would refuse
    last = capsys.readouterr().out.splitlines()[-1]
    assert last.startswith("next run   .S.outputs.lock: is a folder, expected the lock file")


def test_stale_temporaries_are_removed_by_the_next_run(scenario):
    folder = scenario.path.parent
    for name in (
        ".S_Scene.txt.k1ll3d.tmp",
        "..S_Target.txt.x.tmp.y.tmp",
        ".S.cmf.123.old",
        ".S.outputs.lock.journal.tmp",
    ):
        (folder / name).write_text("stale")
    (folder / ".other.tmp").write_text("not ours")
    simulate(scenario)
    assert hidden(folder) == [".other.tmp"]


def test_half_done_swap_is_rolled_back(scenario, tmp_path):
    old = write_old_set(scenario)
    paths = outputs_of(scenario)
    lock = scenario.path.with_name(".S.outputs.lock")
    journal = lock.with_name(lock.name + ".journal")
    entries = []
    for path in paths:
        entries.append(
            {"path": str(path), "backup": str(path.with_name(f".{path.name}.1.old")), "existed": True}
        )
    outputset._write_journal(journal, entries)
    # As a kill between renames leaves it: the first file new, the second in its backup.
    os.rename(paths[0], entries[0]["backup"])
    paths[0].write_text("new 0\n")
    os.rename(paths[1], entries[1]["backup"])
    with _output_set(scenario, las=False):
        assert snapshot(scenario) == old
    assert hidden(scenario.path.parent) == []


@pytest.mark.parametrize(
    "problem, expected",
    [
        (lambda p: p.mkdir(), "is a folder"),
        (lambda p: None, None),
    ],
)
def test_output_problem(tmp_path, problem, expected):
    path = tmp_path / "out.txt"
    problem(path)
    assert outputset.output_problem(path) == expected or expected in outputset.output_problem(path)


def test_output_problem_names_unwritable_places(tmp_path):
    (tmp_path / "file").write_text("x")
    assert "is a file, not a folder" in outputset.output_problem(tmp_path / "file" / "out.txt")
    assert "cannot be written" in outputset.output_problem("/proc/x")
    assert "name too long" in outputset.output_problem(tmp_path / ("n" * 5000))
    with pytest.raises(OutputFileError, match="out.txt: is a folder"):
        (tmp_path / "out.txt").mkdir()
        outputset.check_writable(tmp_path / "ok.txt", tmp_path / "out.txt")


def last_error_line(capsys):
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0, err  # refused before any work or progress
    return err


def test_trace_out_a_folder_is_refused_before_tracing(tmp_path, capsys):
    rays = tmp_path / "rays.npy"
    np.save(rays, np.array([[0, 0, 5, 0, 0, -1.0]]))
    save_voxels(tmp_path / "v.txt", np.zeros((1, 3), np.int32))
    (tmp_path / "hits.npy").mkdir()
    assert (
        main(
            [
                "trace",
                "--scene",
                str(tmp_path / "v.txt"),
                "--rays",
                str(rays),
                "--out",
                str(tmp_path / "hits.npy"),
            ]
        )
        == 2
    )
    assert last_error_line(capsys) == (
        f"ladartui: error: --out = '{tmp_path / 'hits.npy'}': expected a file name, not a folder"
    )


def test_trace_of_an_empty_npy_is_one_line(tmp_path, capsys):
    (tmp_path / "rays.npy").write_bytes(b"")
    save_voxels(tmp_path / "v.txt", np.zeros((1, 3), np.int32))
    assert (
        main(
            [
                "trace",
                "--scene",
                str(tmp_path / "v.txt"),
                "--rays",
                str(tmp_path / "rays.npy"),
                "--out",
                str(tmp_path / "hits.npy"),
            ]
        )
        == 2
    )
    assert "rays.npy: empty or cut short" in last_error_line(capsys)


def test_generate_into_proc_is_refused(capsys):
    assert main(["generate", "small", "/proc/x"]) == 2
    err = last_error_line(capsys)
    assert "/proc/x.txt: cannot be written" in err


def test_sweep_out_an_existing_file_is_refused(tmp_path, capsys):
    from tiny_sweep import write_tiny_scenario

    write_tiny_scenario(tmp_path)
    spec = tmp_path / "spec.toml"
    spec.write_text('[sweep]\nscenario = "base.toml"\n[grid]\nscans = [2, 3]\n', encoding="utf-8")
    (tmp_path / "results").write_text("a file")
    assert main(["sweep", str(spec), "--serial", "--out", str(tmp_path / "results")]) == 2
    assert "results: is a file, expected a folder" in last_error_line(capsys)


@pytest.mark.parametrize("length", [220, 233, 236, 248])
def test_a_scenario_name_too_long_for_its_outputs_is_refused_before_tracing(tmp_path, capsys, length):
    """Names the outputs, their hidden temporaries, the lock and its journal take past
    the system's limit: refused after tracing, or a traceback, depending on the length."""
    scenario = make_scenario(tmp_path)
    long = tmp_path / ("m" * length + ".toml")
    long.write_bytes(scenario.path.read_bytes())  # as cp makes it
    for command in ("run", "validate"):
        assert main([command, str(long)]) == 2, command
        err = last_error_line(capsys)
        assert "name too long for this system" in err and "Traceback" not in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["S.toml", "woods.txt", "woods_Target.txt", long.name]
    )


def test_names_are_measured_with_what_each_file_writes_beside_it(tmp_path, capsys):
    """A chart has one temporary (14 bytes more than its name), not an output set's
    two (28), and is not a scenario name; a stem whose outputs fit is not refused for
    its lock (12 more)."""
    scenario = make_scenario(tmp_path)
    chart = tmp_path / ("c" * 235 + ".svg")
    assert main(["run", str(scenario.path), "--no-write", "--chart", str(chart)]) == 0
    assert chart.is_file()
    capsys.readouterr()
    fits = tmp_path / ("m" * 216 + ".toml")  # its longest output: 216 + len("_Target.txt") + 28 = 255
    fits.write_bytes(scenario.path.read_bytes())
    assert main(["validate", str(fits)]) == 0
    capsys.readouterr()
    # The limit is the folder's own (255 here): a name that fits with its hidden companion's
    # 14 bytes more passes, one byte longer is refused, saying both lengths.
    most = os.pathconf(tmp_path, "PC_NAME_MAX")
    assert outputset.name_problem(tmp_path / ("c" * (most - 14)), extra=14) is None
    assert outputset.name_problem(tmp_path / ("c" * (most - 13)), extra=14) == (
        f"name too long for this system ({most - 13} bytes, and {most + 1} for the hidden file "
        f"written beside it; at most {most} a name)"
    )
    assert "scenario" not in outputset.output_problem(tmp_path / ("c" * 242))


def test_a_scenario_name_that_is_not_utf8_is_refused_before_tracing(tmp_path, capsys):
    """A scenario copied from a Latin-1 system ('plan\\xe9.toml') traced the whole run,
    then ended in a UnicodeEncodeError traceback writing its run record, a UTF-8 file
    that names the outputs after the scenario. Its folder may hold such bytes."""
    scenario = make_scenario(tmp_path / os.fsdecode(b"lat\xe9"))
    latin = scenario.path.with_name(os.fsdecode(b"plan\xe9.toml"))
    latin.write_bytes(scenario.path.read_bytes())
    for command in ("run", "validate"):
        assert main([command, str(latin)]) == 2, command
        err = last_error_line(capsys)
        assert (
            "Traceback" not in err
            and "plan\\udce9_Scene.txt: its name is not UTF-8 text (the byte 0xe9)" in err
        ), err
        assert "rename the scenario" in err, err
    assert sorted(p.name for p in latin.parent.iterdir()) == sorted(
        ["S.toml", "woods.txt", "woods_Target.txt", latin.name]
    )
    assert main(["run", str(scenario.path)]) == 0  # the folder's own byte is no matter
    assert scenario.run_record.is_file()
