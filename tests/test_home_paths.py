"""A path that starts with ~ for a user this machine does not know: pathlib raises
RuntimeError ('Could not determine home directory.') where the shell and os.path leave
it as it is; ladartui reads it as a name like any other and says it is not there."""

from __future__ import annotations

import pytest

from cli_support import one_error_line
from ladartui.cli import main

UNKNOWN = "~no_such_user_here/plans"


@pytest.mark.parametrize(
    ("command", "said"),
    [
        (["validate", f"{UNKNOWN}/orbit.toml"], f"{UNKNOWN}/orbit.toml"),
        (["run", f"{UNKNOWN}/orbit.toml"], f"{UNKNOWN}/orbit.toml"),
        (["compare", f"{UNKNOWN}/a.cmf", f"{UNKNOWN}/b.cmf"], f"{UNKNOWN}/a.cmf: measures file not found"),
    ],
)
def test_a_home_of_an_unknown_user_is_a_name_not_a_crash(tmp_path, capsys, monkeypatch, command, said):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    assert main(command) == 2
    line = one_error_line(capsys)
    assert said in line and ("not found" in line or "no such file" in line)


def test_a_data_folder_under_an_unknown_users_home_is_named(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("LADARTUI_HOME", UNKNOWN)
    assert main(["validate", "default"]) == 0  # a folder of that name, made here
    err = capsys.readouterr().err
    assert "Traceback" not in err and "RuntimeError" not in err
    assert (tmp_path / UNKNOWN / "default" / "default.toml").is_file()
