from pathlib import Path

import pytest

import ladartui
from ladartui.cli import main
from ladartui.textsafe import one_line

DEFAULT = (Path(ladartui.__file__).parent / "scenarios" / "default.toml").read_text(encoding="utf-8")


def _scenario_with_scene(tmp_path, scene_toml_string):
    path = tmp_path / "s.toml"
    path.write_text(DEFAULT.replace('scene = "small.txt"', f"scene = {scene_toml_string}"), encoding="utf-8")
    return path


def test_one_line_escapes_terminal_controls_and_line_breaks():
    text = "scene \x1b]0;PWNED\x07 a\r\nb\x9b"
    safe = one_line(text)
    assert "\x1b" not in safe and "\x07" not in safe and "\r" not in safe
    assert "\n" not in safe and "\x9b" not in safe
    assert safe == "scene \\x1b]0;PWNED\\x07 a\\x0d\\x0ab\\x9b"


def test_one_line_caps_length_and_says_how_much_was_cut():
    safe = one_line("x" * 10_000, limit=100)
    assert safe.startswith("x" * 100)
    assert safe.endswith("(9900 more characters)")
    assert len(safe) < 140


def test_cli_error_with_escape_in_scenario_value_reaches_terminal_escaped(tmp_path, capsys):
    scenario = _scenario_with_scene(tmp_path, '"\\u001b]0;PWNED\\u0007x.txt"')
    code = main(["validate", str(scenario)])
    err = capsys.readouterr().err
    assert code == 2
    assert "\x1b" not in err and "\x07" not in err
    assert "\\x1b]0;PWNED" in err
    assert err.count("\n") == 1


def test_cli_error_message_is_capped(tmp_path, capsys):
    scenario = _scenario_with_scene(tmp_path, '"' + "y" * 100_000 + '.txt"')
    assert main(["validate", str(scenario)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and len(err) < 1000


def test_scene_that_is_a_folder_is_not_reported_as_missing(tmp_path, capsys):
    (tmp_path / "forest.txt").mkdir()
    scenario = _scenario_with_scene(tmp_path, '"forest.txt"')
    assert main(["validate", str(scenario)]) == 2
    err = capsys.readouterr().err
    assert "is a folder, expected a file (files.scene)" in err and "not found" not in err


@pytest.mark.parametrize(
    "raw", ["\x1b[2J\x1b]0;PWNED\x07", "\nladartui: forged\n"], ids=["escapes", "newlines"]
)
def test_file_names_with_terminal_escapes_reach_the_terminal_escaped(tmp_path, capsys, raw):
    """Errors escaped them, but the lines of a command that worked printed them raw: a
    name holding ESC [2J cleared the screen; one holding a line break broke the line it
    was written on, and what followed it stood as a line of its own."""
    import shutil

    from tiny_sweep import write_tiny_scenario

    folder = tmp_path / f"d{raw}"
    folder.mkdir()
    base = write_tiny_scenario(folder, name=f"s{raw}.toml")
    shutil.copy(folder / "tiny.txt", folder / f"v{raw}.txt")
    commands = [
        ["validate", str(base.path)],
        ["info", str(base.path)],
        ["info", str(folder / f"v{raw}.txt")],
        ["run", str(base.path)],
        ["generate", "small", str(folder / f"g{raw}"), "--las"],
        ["sweep", str(_spec(folder, base.path.name)), "--serial"],
        [
            "trace",
            "--scene",
            str(folder / "tiny.txt"),
            "--rays",
            str(_rays(folder)),
            "--out",
            str(folder / f"h{raw}.npy"),
        ],
    ]
    for command in commands:
        assert main(command) == 0, command
        out, err = capsys.readouterr()
        assert "\x1b" not in out + err and "\x07" not in out + err, (command, out + err)
        assert not any(line.startswith("ladartui: forged") for line in (out + err).splitlines()), command
        assert f"\\x{ord(raw[0]):02x}" in out + err, command


def _spec(folder, scenario_name):
    import json

    spec = folder / "sweep.toml"
    spec.write_text(f"[sweep]\nscenario = {json.dumps(scenario_name)}\n[grid]\nradius = [20.0]\n")
    return spec


def _rays(folder):
    import numpy as np

    path = folder / "rays.npy"
    np.save(path, np.array([[5.0, 5.0, 30.0, 0.0, 0.0, -1.0]]))
    return path


def test_a_file_name_that_is_not_utf8_is_written_escaped(tmp_path, capsys):
    """Bytes of a file name that are not UTF-8 (b'\\xff', a lone surrogate in Python) reached
    standard output as they were: where its encoding is strict (an en_US.UTF-8 locale,
    PYTHONIOENCODING=utf-8), validate ended in a UnicodeEncodeError traceback. (Such a
    scenario is refused, its run record being UTF-8 text: the refusal names it escaped.)"""
    import os

    from tiny_sweep import write_tiny_scenario

    base = write_tiny_scenario(tmp_path, name="bad\udcffname.toml")
    assert main(["validate", os.fsdecode(base.path)]) == 2
    err = capsys.readouterr().err
    err.encode("utf-8")  # strict: no lone surrogate left
    assert "bad\\udcffname_Scene.txt: its name is not UTF-8 text" in err
    assert one_line("a\udcffb") == "a\\udcffb"
