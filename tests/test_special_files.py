"""Named pipes and devices given to a command as input or output: refused in one line.

Opening a pipe waits for a writer (or a reader), so every command with a pipe
for a file hung until killed; a pipe given as an output was replaced by a file.
"""

import os
import re
import stat
import subprocess
import sys
import threading

import numpy as np
import pytest
import trimesh

from cli_support import one_error_line
from ladartui.cli import main
from ladartui.fileprobe import SPECIAL_FILE
from tiny_sweep import write_spec, write_tiny_scenario

WAIT = 60  # seconds before a command counts as waiting on a pipe

# (arguments, the pipe named in the refusal); {d} is the case's folder, and every
# name starting "pipe" is made a pipe there
INPUTS = [
    ("trace --scene {d}/tiny.txt --rays {d}/pipe.npy --out {d}/h.npy", "pipe.npy"),
    ("trace --scene {d}/pipe.txt --rays {d}/rays.npy --out {d}/h.npy", "pipe.txt"),
    ("info {d}/pipe.txt", "pipe.txt"),
    ("info {d}/pipe_Target.txt", "pipe_Target.txt"),
    ("info {d}/pipe.toml", "pipe.toml"),
    ("study --chart-from {d}/pipe.json --out {d}/st", "pipe.json"),
    ("voxelize {d}/truck.obj {d}/v.txt --voxel-size 0.25 --at 10,10 --into {d}/pipe.txt", "pipe.txt"),
    ("voxelize {d}/pipe.obj {d}/v.txt --voxel-size 0.25", "pipe.obj"),
    ("validate {d}/pipe.toml", "pipe.toml"),
    ("run {d}/pipe.toml", "pipe.toml"),
    ("pulses {d}/pipe.toml", "pipe.toml"),
    ("sweep {d}/pipe.toml", "pipe.toml"),
    ("sweep {d}/spec.toml --serial --out {d}/sw", "pipe.toml"),
    ("sweep {d}/ok.toml --show --out {d}/sw", "sw/results.csv"),
    ("tui {d}/pipe.toml", "pipe.toml"),
]
OUTPUTS = [
    ("trace --scene {d}/tiny.txt --rays {d}/rays.npy --out {d}/pipe.npy", "pipe.npy"),
    ("generate small {d}/pipe --trees 3", "pipe.txt"),
    ("generate small {d}/forest --trees 3", "forest_Target.txt"),
    ("voxelize {d}/truck.obj {d}/pipe.txt --voxel-size 0.25", "pipe.txt"),
    ("voxelize {d}/truck.obj {d}/pipe --voxel-size 1 --at 15,15 --into {d}/tiny.txt", "pipe.txt"),
    ("run {d}/base.toml --chart {d}/pipe.svg", "pipe.svg"),
    ("run {d}/base.toml", "base.cmf"),
    ("study --quick --out {d}/st", "st/study.json"),  # refused before the study, not after it
] + [  # a sweep's own files in its results folder: refused before any variant runs
    ("sweep {d}/ok.toml --serial --out {d}/sw", f"sw/{name}")
    for name in ("results.csv", ".lock", "ranking.csv", "ok-best.toml", "pareto.svg", "pareto.png")
]


def _free(folder) -> None:
    """Open the other end of every pipe in ``folder`` and below, ending a wait on it."""
    for parent, _, names in os.walk(folder):
        for name in names:
            path = os.path.join(parent, name)
            if not stat.S_ISFIFO(os.stat(path).st_mode):
                continue
            for flags in (os.O_RDONLY | os.O_NONBLOCK, os.O_WRONLY | os.O_NONBLOCK):
                try:  # a writer end opens only while a reader waits (ENXIO otherwise)
                    os.close(os.open(path, flags))
                except OSError:
                    pass


def _main_watched(argv, folder) -> tuple[int, bool]:
    """``main(argv)`` and whether it waited on a pipe: after WAIT seconds the pipes'
    other ends are opened, so a command that hangs fails the test, not the suite."""
    done = threading.Event()
    waited = []

    def watch():
        if done.wait(WAIT):
            return
        waited.append(True)
        while not done.wait(0.2):
            _free(folder)

    watchdog = threading.Thread(target=watch, daemon=True)
    watchdog.start()
    try:
        return main(argv), bool(waited)
    finally:
        done.set()
        watchdog.join()


@pytest.fixture
def folder(tmp_path):
    write_tiny_scenario(tmp_path)
    trimesh.creation.box(extents=(2.0, 4.0, 1.5)).export(tmp_path / "truck.obj")
    np.save(tmp_path / "rays.npy", np.array([[15.5, 15.5, 20.0, 0.0, 0.0, -1.0]]))
    write_spec(tmp_path, "[grid]\nradius = [20.0, 25.0]\n", scenario="pipe.toml")
    write_spec(tmp_path, "[grid]\nradius = [20.0, 25.0]\n", name="ok.toml")
    for name in ("pipe.npy", "pipe.txt", "pipe_Target.txt", "pipe.toml", "pipe.json", "pipe.obj"):
        os.mkfifo(tmp_path / name)
    return tmp_path


@pytest.mark.parametrize(("command", "pipe"), INPUTS + OUTPUTS, ids=[c for c, _ in INPUTS + OUTPUTS])
def test_a_pipe_for_a_file_is_refused_not_waited_on(folder, capsys, command, pipe):
    if not (folder / pipe).exists():  # an output's pipe
        (folder / pipe).parent.mkdir(exist_ok=True)
        os.mkfifo(folder / pipe)
    status, waited = _main_watched(command.format(d=folder).split(), folder)
    assert not waited, f"waited on the pipe {pipe}"
    assert status == 2
    error = one_error_line(capsys)  # "PIPE: is not ...", or a flag's or a spec's line naming PIPE
    assert str(folder / pipe) in error and SPECIAL_FILE in error
    assert stat.S_ISFIFO(os.stat(folder / pipe).st_mode), "the pipe was replaced"


def test_a_device_is_refused_as_a_voxel_list():
    """``info /dev/zero`` read zeros for ever (a process: nothing can end that read)."""
    done = subprocess.run(
        [sys.executable, "-m", "ladartui", "info", "/dev/zero"], capture_output=True, text=True, timeout=WAIT
    )
    assert done.returncode == 2
    assert done.stderr == f"ladartui: error: /dev/zero: {SPECIAL_FILE}; expected a voxel-list file\n"


@pytest.mark.parametrize("reader", ["read_cmf", "import_las", "load_flight_log", "read_config_table"])
def test_a_pipe_is_refused_by_the_readers_no_command_reaches(tmp_path, reader):
    """The measures, LAS, flight-log and settings readers waited on a pipe too."""
    from ladartui import cmf, toml_lines, trajectory
    from ladartui.scene import las

    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    calls = {
        "read_cmf": lambda: cmf.read_cmf(pipe),
        "import_las": lambda: las.import_las(pipe, 1.0),
        "load_flight_log": lambda: trajectory.load_flight_log(pipe),
        "read_config_table": lambda: toml_lines.read_config_table(pipe, "keys", "command id = key").problems,
    }
    waited, said = _call_watched(calls[reader], tmp_path)
    assert not waited, f"{reader} waited on the pipe"
    assert f"{pipe}: {SPECIAL_FILE}" in str(said)


def test_a_pipe_is_no_run_record_and_no_scenario_in_the_file_tree(tmp_path):
    """Both read the file's first line to tell, and waited on a pipe named S_Run.toml or S.toml."""
    from ladartui.scenario_file import is_record
    from ladartui.tui.file_tree import opens_table

    pipe = tmp_path / "S_Run.toml"
    os.mkfifo(pipe)
    assert _call_watched(lambda: is_record(pipe), tmp_path) == (False, False)
    assert _call_watched(lambda: opens_table(pipe, "[files]"), tmp_path) == (False, False)


def test_a_pipe_named_as_a_best_path_is_not_read_as_one(tmp_path):
    """Telling a sweep's best-path file from an edited one reads its first lines: a pipe
    named NAME-best.toml waited for ever (the sweep screen lists them)."""
    from ladartui.sweep.best_file import best_files, best_target

    os.mkfifo(tmp_path / "forest-best.toml")
    assert _call_watched(lambda: best_files(tmp_path), tmp_path) == (False, [])
    waited, target = _call_watched(lambda: best_target(tmp_path / "forest-best.toml"), tmp_path)
    assert not waited and target.path == tmp_path / "forest-best-2.toml"


def _call_watched(call, folder):
    """(whether ``call()`` waited WAIT seconds on a pipe in ``folder``, what it returned or
    the LadarError it raised, as text)."""
    from ladartui.errors import LadarError

    said = []

    def run():
        try:
            said.append(call())
        except LadarError as error:
            said.append(str(error))

    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    worker.join(WAIT)
    waited = worker.is_alive()
    _free(folder)  # ends the wait of a reader that hung
    worker.join(WAIT)
    return waited, said[0] if said else None


def test_the_terminal_ui_study_refuses_a_pipe_in_its_folder_before_it_runs(tmp_path, monkeypatch):
    """The study screen's job found a pipe among its outputs only once the study was done."""
    from ladartui.errors import OutputFileError
    from ladartui.study import run as study_run
    from ladartui.tui.study_screen import _study

    write_tiny_scenario(tmp_path)
    (tmp_path / "base-study").mkdir()
    os.mkfifo(tmp_path / "base-study" / "speed-accuracy.png")
    monkeypatch.setattr(study_run, "run_study", lambda *a, **k: pytest.fail("the study ran"))
    with pytest.raises(OutputFileError, match=re.escape(SPECIAL_FILE)):
        _study("quick", tmp_path / "base.toml", None, None, threading.Event(), lambda *a: None)


@pytest.mark.parametrize("command", ["validate", "run", "tui"])
def test_a_scenario_link_that_loops_is_named_as_such_not_as_missing(tmp_path, capsys, monkeypatch, command):
    """'validate loop.toml', a link to a link back to it, said 'no such file; expected a
    scenario file (.toml) or a bundled scenario' of a file that is there."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "loop.toml").symlink_to("back.toml")
    (tmp_path / "back.toml").symlink_to("loop.toml")
    assert main([command, "loop.toml"]) == 2
    said = one_error_line(capsys)
    assert re.fullmatch(
        r"ladartui: error: (\S*/)?loop\.toml: cannot (read the scenario file: |be read \()Too many "
        r"levels of symbolic links(\); expected a scenario file \(\.toml\))?",
        said,
    ), said


def test_a_link_to_a_missing_file_is_not_found_and_one_that_loops_cannot_be_read(tmp_path):
    """A link to a missing file read 'cannot be read (No such file or directory)' once
    links were looked into for loops; it is missing, as every reader says."""
    from ladartui.fileprobe import file_problem

    (tmp_path / "gone.txt").symlink_to(tmp_path / "nowhere.txt")
    (tmp_path / "loop.txt").symlink_to(tmp_path / "loop.txt")
    assert file_problem(tmp_path / "gone.txt") == "not found"
    assert file_problem(tmp_path / "loop.txt") == "cannot be read (Too many levels of symbolic links)"
