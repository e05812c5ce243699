"""Every command in the CLI's table has its module: none can vanish quietly."""

from __future__ import annotations

import importlib

import pytest

from cli_support import one_error_line
from ladartui import cli


def test_every_command_module_exists_and_adds_its_parser():
    parser = cli.build_parser()
    choices = next(a for a in parser._actions if a.dest == "command").choices
    assert set(choices) == set(cli.COMMANDS)


def test_a_missing_command_module_is_an_error_not_a_missing_command(monkeypatch):
    monkeypatch.setitem(cli.COMMANDS, "ghost", "ghost_command_that_does_not_exist")
    with pytest.raises(ModuleNotFoundError):
        cli.build_parser()


def test_the_study_package_offers_only_names_that_resolve():
    study = importlib.import_module("ladartui.study")
    for name in study.__all__:
        assert getattr(study, name) is not None, name


def test_a_mistyped_command_is_named_not_taken_for_a_scenario(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["valdiate", "x.toml"]) == 2
    assert capsys.readouterr().err == (
        "ladartui: error: unknown command 'valdiate'; did you mean 'validate'? (see 'ladartui -h')\n"
    )
    assert cli.main(["bogus"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ladartui: error: unknown command 'bogus'; expected one of run, trace, ")
    assert err.endswith(", or a scenario file (.toml) (see 'ladartui -h')\n")


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (
            ["bench", "--bogus"],
            "ladartui bench: error: unrecognized arguments: --bogus (see 'ladartui bench -h')\n",
        ),
        (
            ["info", "--backends", "--json"],
            "ladartui info: error: unrecognized arguments: --json (see 'ladartui info -h')\n",
        ),
        # before the command: the top level's, not the command's
        (
            ["--bogus", "run", "x.toml"],
            "ladartui: error: unrecognized arguments: --bogus (see 'ladartui -h')\n",
        ),
    ],
)
def test_a_flag_a_command_lacks_points_at_that_command_s_help(capsys, argv, said):
    """'ladartui bench --bogus' said to see 'ladartui -h', which lists no flag of bench."""
    with pytest.raises(SystemExit) as stop:
        cli.main(argv)
    assert stop.value.code == 2
    assert capsys.readouterr().err == said


def test_the_terminal_ui_on_a_folder_names_it_a_folder(tmp_path, capsys):
    """'ladartui tui FOLDER' said 'no such file', where run says 'is a folder'."""
    assert cli.main(["tui", str(tmp_path)]) == 2
    assert capsys.readouterr().err == (
        f"ladartui: error: {tmp_path}: is a folder; expected a scenario file (.toml)\n"
    )


def test_ctrl_c_while_the_commands_load_is_one_line(monkeypatch, capsys):
    def interrupted():
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "build_parser", interrupted)
    assert cli.main(["run", "default"]) == 130
    assert capsys.readouterr().err == "ladartui: interrupted\n"


def test_ctrl_c_inside_an_extension_module_s_start_is_one_line(monkeypatch, capsys):
    """A Ctrl-C as 'study' imported matplotlib ended in a traceback: CPython turns a
    KeyboardInterrupt inside an extension module's start into 'ImportError:
    initialization failed' (its cause the interrupt), which no handler took."""

    def importing():
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as interrupt:
            raise ImportError("initialization failed") from interrupt

    monkeypatch.setattr(cli, "build_parser", importing)
    assert cli.main(["study", "--quick"]) == 130
    assert capsys.readouterr().err == "ladartui: interrupted\n"


def test_an_import_that_fails_for_another_reason_is_not_taken_for_a_ctrl_c(monkeypatch):
    def importing():
        raise ImportError("libGL.so.1: cannot open shared object file")

    monkeypatch.setattr(cli, "build_parser", importing)
    with pytest.raises(ImportError, match="libGL"):
        cli.main(["study", "--quick"])


def test_the_commands_load_without_numba_or_dask():
    import subprocess
    import sys

    # `ladartui --help` and a mistyped flag answer at once: loading numba alone took 0.7 s
    code = (
        "import sys; from ladartui.cli import build_parser; build_parser(); "
        "print(sorted(m for m in ('numba', 'distributed') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("command", [["info"], ["run", "--no-write"]])
def test_output_into_a_closed_pipe_ends_quietly(tmp_path, command):
    # `ladartui info S.toml | head -1`: the reader goes before the writer has written;
    # run's measures table is written by rich, which exited with status 1 there
    import subprocess
    import sys

    from tui_support import make_scenario

    scene = tmp_path / "s.txt"
    scene.write_text("0,0,0\n1,1,0\n", encoding="utf-8")
    (tmp_path / "s_Target.txt").write_text("0,0,0\n", encoding="utf-8")
    scenario = make_scenario(tmp_path, (scene, (0.5, 0.5, 0.5), 1.0))
    child = subprocess.Popen(
        [sys.executable, "-m", "ladartui", command[0], str(scenario.path), *command[1:]],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    child.stdout.close()
    err = child.stderr.read().decode()
    assert child.wait(timeout=120) == 141  # as a shell reports SIGPIPE
    assert "Traceback" not in err and "rror" not in err  # said nothing of it (run: its progress)


@pytest.mark.parametrize("command", ["run", "validate", "pulses", "study"])
def test_a_mistyped_bundled_name_names_the_bundled_scenarios(tmp_path, capsys, monkeypatch, command):
    """'run defualt' said only 'no such file; expected a scenario file (.toml)'."""
    monkeypatch.chdir(tmp_path)
    assert cli.main([command, "defualt"]) == 2
    assert capsys.readouterr().err == (
        f"ladartui: error: {tmp_path / 'defualt'}: no such file; "
        "expected a scenario file (.toml) or a bundled scenario: default, convoy\n"
    )


@pytest.mark.parametrize("argument", ["./convoy", "./convoy.toml"])
def test_a_path_with_a_folder_is_never_a_bundled_name(tmp_path, capsys, monkeypatch, argument):
    """'validate ./convoy', a path to no file, opened the bundled convoy scenario."""
    monkeypatch.chdir(tmp_path)
    assert cli.main(["validate", argument]) == 2
    assert capsys.readouterr().err == (
        f"ladartui: error: {tmp_path / argument[2:]}: no such file; expected a scenario file (.toml)\n"
    )


BUNDLED = "a scenario file (.toml) or a bundled scenario: default, convoy"


@pytest.mark.parametrize(
    "command, name, expected",
    [
        (["run", ""], "SCENARIO", BUNDLED),
        (["validate", ""], "SCENARIO", BUNDLED),
        (["tui", ""], "SCENARIO", BUNDLED),
        ([""], "SCENARIO", BUNDLED),
        (["info", ""], "FILE", "a voxel list (.txt) or a scenario (.toml)"),
        (["pulses", ""], "SCENARIO", BUNDLED),
        (["study", ""], "SCENARIO", BUNDLED),
        (["study", "--chart-from", ""], "--chart-from", "a study.json written by 'ladartui study'"),
        (["sweep", ""], "SPEC", "a sweep spec (.toml)"),
        (["certs", ""], "DIR", "a folder name, such as certs"),
        (["sweep", "sp.toml", "--out", ""], "--out", "a folder name, such as sp-results"),
        (["sweep", "sp.toml", "--show", "--out", ""], "--out", "a folder name, such as sp-results"),
    ],
)
def test_an_empty_path_is_refused_naming_its_argument(tmp_path, capsys, monkeypatch, command, name, expected):
    """An empty path was the current folder ('/cwd: is a folder', '.: is a folder'), or no
    path at all: pulses '' and study '' took their default scenes, study --chart-from ''
    ran a whole new study, and sweep --out '' wrote its results into the current folder."""
    import ladartui.detection.pulses as pulses_module
    from ladartui.study import inputs as study_inputs

    def refuse(*args, **kwargs):
        raise AssertionError("the work started")

    monkeypatch.setattr(pulses_module, "pulse_study", refuse)
    monkeypatch.setattr(study_inputs, "generated_inputs", refuse)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sp.toml").write_text('[sweep]\nscenario = "default"\n[grid]\nscans = [2]\n')
    assert cli.main(command) == 2
    assert one_error_line(capsys) == f"ladartui: error: {name} = '': expected {expected}"
    assert [p.name for p in tmp_path.iterdir()] == ["sp.toml"]


def test_a_closed_standard_output_is_a_failure_said_on_standard_error(tmp_path, capsys, monkeypatch):
    """'ladartui info v.txt >&-' wrote nothing and exited 0: Python sets sys.stdout to
    None, and print() then drops what it is given."""
    import sys

    (tmp_path / "v.txt").write_text("1,2,3\n")
    monkeypatch.setattr(sys, "stdout", None)
    assert cli.main(["info", str(tmp_path / "v.txt")]) == 1
    assert one_error_line(capsys) == (
        "ladartui: error: standard output is closed; expected it open (> /dev/null drops the output)"
    )


def test_output_that_cannot_be_written_is_one_line_not_a_traceback(tmp_path, capsys, monkeypatch):
    """'ladartui run S.toml --json > out.json' on a full disk (or '> /dev/full') ended in an
    OSError traceback from print()."""
    import errno
    import io
    import sys

    class Full(io.StringIO):
        def write(self, text):
            raise OSError(errno.ENOSPC, "No space left on device")

    (tmp_path / "v.txt").write_text("1,2,3\n")
    monkeypatch.setattr(sys, "stdout", Full())
    assert cli.main(["info", str(tmp_path / "v.txt")]) == 1
    assert one_error_line(capsys) == "ladartui: error: could not write the output: No space left on device"


def test_a_full_disk_under_numbas_cache_is_not_called_the_output(tmp_path, capsys, monkeypatch):
    """A first run's kernels written to numba's cache on a full disk said 'could not write
    the output', with --no-write too."""
    import errno
    import os

    import numba

    import ladartui.cli.info as info

    numba_code = compile(  # code that names itself numba's own cache module
        "def save(*args, **kwargs):\n    raise OSError(errno.EFBIG, 'File too large')\n",
        os.path.join(os.path.dirname(numba.__file__), "core", "caching.py"),
        "exec",
    )
    space = {"errno": errno}
    exec(numba_code, space)
    monkeypatch.setattr(info, "print_voxel_list", space["save"])
    (tmp_path / "v.txt").write_text("1,2,3\n")
    assert cli.main(["info", str(tmp_path / "v.txt")]) == 1
    assert one_error_line(capsys) == (
        "ladartui: error: could not write numba's cache of the compiled kernels: File too large"
    )


def test_certs_that_cannot_be_written_leave_no_lock_behind(tmp_path, capsys):
    """A failed write left an empty DIR/.certs.lock: the lock's own write failed after
    the file was made, before the set held it to remove it."""
    from cli_support import file_size_limit

    folder = tmp_path / "certs"
    with file_size_limit(0):  # no byte can be written: the lock's pid first
        assert cli.main(["certs", str(folder)]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: {folder / '.certs.lock'}: could not be written (file too large); "
        "nothing was replaced, earlier outputs are unchanged"
    )
    assert list(folder.iterdir()) == []
    assert cli.main(["certs", str(folder)]) == 0  # and a second try writes them
    assert sorted(p.name for p in folder.iterdir()) == ["ca.pem", "cluster-key.pem", "cluster.pem"]


@pytest.mark.parametrize("status", [0, 3])
def test_a_ctrl_c_as_a_finished_command_exits_keeps_its_status(status):
    """'ladartui run --json' ended as killed by SIGINT (-2 to the script that ran it, 130
    in a shell) when a Ctrl-C came while Python shut down after the command: its outputs
    written and said, its status a failure. Shutting down is made slow here."""
    import signal
    import subprocess
    import sys
    import time

    slow_teardown = (  # an object torn down with the modules, slowly
        "    import time\n"
        "    class Slow:\n"
        "        def __del__(self):\n"
        "            time.sleep(1.5)\n"
        "    global keep\n"
        "    keep = Slow()\n"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", _entry_script(status, slow_teardown)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert child.stdout.readline() == "done\n"
    time.sleep(0.5)  # shutting down
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=60)
    assert (child.returncode, out, err) == (status, "", "")


def test_the_ladartui_command_and_python_m_go_through_entry():
    """The exit a Ctrl-C cannot turn into a failure is entry's: main alone does not give it."""
    import tomllib
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    scripts = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["project"]["scripts"]
    assert scripts == {"ladartui": "ladartui.cli:entry"}
    assert (root / "src" / "ladartui" / "__main__.py").read_text(encoding="utf-8").split() == [
        "from",
        "ladartui.cli",
        "import",
        "entry",
        "entry()",
    ]


def _entry_script(status: int, body: str = "") -> str:
    """A child that runs cli.entry over a command that does ``body``, prints a line and
    returns ``status``."""
    return (
        "import ladartui.cli as cli\n"
        "def finished(argv=None):\n"
        f"{body}"
        "    print('done', flush=True)\n"
        f"    return {status}\n"
        "cli.main = finished\n"
        "cli.entry()\n"
    )


@pytest.mark.parametrize("closed", [1, 2])
def test_entry_with_standard_output_or_error_closed_keeps_the_status(closed):
    """With stdout closed ('>&-') entry's flush raised AttributeError after the command's
    own one-line error; with stderr closed ('2>&-') a finished command exited 1."""
    import os
    import subprocess
    import sys

    child = subprocess.run(
        [sys.executable, "-c", _entry_script(0).replace("print('done', flush=True)", "pass")],
        capture_output=True,
        text=True,
        timeout=60,
        preexec_fn=lambda: os.close(closed),
    )
    assert child.returncode == 0 and "Traceback" not in child.stderr and "Error" not in child.stderr, (
        child.stderr
    )


def test_a_slow_exit_handler_still_ends_at_a_ctrl_c_with_the_status():
    """The handler that ignores Ctrl-C ran first of the exit handlers: a slow clean-up
    registered during the command (a cluster's close) could not be stopped."""
    import signal
    import subprocess
    import sys
    import time

    body = "    import atexit, time\n    atexit.register(time.sleep, 30)\n"
    child = subprocess.Popen(
        [sys.executable, "-c", _entry_script(3, body)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert child.stdout.readline() == "done\n"
    time.sleep(0.5)  # in the exit handler's sleep
    started = time.monotonic()
    child.send_signal(signal.SIGINT)
    child.communicate(timeout=60)
    assert child.returncode == 3 and time.monotonic() - started < 10


def test_only_numbas_own_frames_blame_its_kernel_cache():
    """Any frame under a folder named numba counted, so a checkout in ~/work/numba/ said
    "could not write numba's cache of the compiled kernels" of every full disk."""
    import os

    import numba

    from ladartui.cli import _in_numba

    def raised_in(filename: str) -> OSError:
        try:
            exec(compile("raise OSError(28, 'No space left on device')", filename, "exec"))
        except OSError as error:
            return error
        raise AssertionError("nothing raised")

    ours = os.path.join(os.sep, "home", "u", "work", "numba", "ladartui", "cli", "run.py")
    assert not _in_numba(raised_in(ours))
    assert _in_numba(raised_in(os.path.join(os.path.dirname(numba.__file__), "core", "caching.py")))
