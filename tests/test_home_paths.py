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


def no_home(monkeypatch, tmp_path):
    """A process with no HOME whose user id the password database does not know (a
    container or batch job started with a bare user id): no home folder at all."""
    import pwd

    def unknown(uid):
        raise KeyError(f"getpwuid(): uid not found: {uid}")

    monkeypatch.chdir(tmp_path)
    for name in ("HOME", "LADARTUI_HOME", "XDG_DATA_HOME", "XDG_CONFIG_HOME"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setattr(pwd, "getpwuid", unknown)


@pytest.mark.parametrize("command", [["validate", "default"], ["run", "convoy", "--no-write"]])
def test_no_home_folder_is_said_in_one_line(tmp_path, capsys, monkeypatch, command):
    """'ladartui validate default' with no home folder ended in pathlib's RuntimeError
    traceback ('Could not determine home directory.')."""
    no_home(monkeypatch, tmp_path)
    assert main(command) == 2
    line = one_error_line(capsys)
    assert "no home folder" in line and "set LADARTUI_HOME" in line, line
    assert list(tmp_path.iterdir()) == []  # no folder named ~ made here


def test_no_home_folder_leaves_the_settings_unread_not_in_a_folder_named_tilde(tmp_path, monkeypatch):
    """platformdirs put the settings under './~/.config/ladartui' in the current folder."""
    from ladartui.errors import LadarError
    from ladartui.user_data import config_folder

    no_home(monkeypatch, tmp_path)
    with pytest.raises(LadarError, match="no home folder"):
        config_folder()
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "h"))  # the way out it names
    assert config_folder() == tmp_path / "h" / "config"
