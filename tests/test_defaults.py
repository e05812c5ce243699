"""The built-in default scenario: where it lives, its scene, and that it makes a sensible run."""

import math
import os
from pathlib import Path

import numpy as np
import pytest

from ladartui import user_data as defaults
from ladartui.scenario import load_scenario, scenario_from_toml
from ladartui.sensor import pose_rotation


def test_data_home_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "xdg"))
    assert defaults.default_folder() == tmp_path / "home" / "default"
    monkeypatch.delenv("LADARTUI_HOME")
    assert defaults.default_folder() == tmp_path / "xdg" / "ladartui" / "default"
    monkeypatch.delenv("XDG_DATA_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "user"))
    user_share = tmp_path / "user" / ".local" / "share"
    assert defaults.default_folder() == user_share / "ladartui" / "default"


@pytest.mark.parametrize(("variable", "home"), [("LADARTUI_HOME", "file"), ("XDG_DATA_HOME", "file")])
def test_a_data_folder_that_cannot_be_made_is_one_line_naming_its_variable(
    monkeypatch, tmp_path, capsys, variable, home
):
    """'run default' with LADARTUI_HOME naming a file ended in a NotADirectoryError traceback."""
    from cli_support import one_error_line
    from ladartui.cli import main

    (tmp_path / "file").write_text("")
    monkeypatch.delenv("LADARTUI_HOME")
    monkeypatch.setenv(variable, str(tmp_path / home))
    data = tmp_path / "file" if variable == "LADARTUI_HOME" else tmp_path / "file" / "ladartui"
    for argv in (["run", "default", "--no-write"], ["bench", "--quick"]):
        assert main(argv) == 2
        line = one_error_line(capsys)
        assert line.startswith(f"ladartui: error: {data}/") and ": cannot be made (not a directory); " in line
        assert line.endswith(f"it is in the user data folder {data}, set by {variable}")


def test_packaged_default_is_an_orbit_with_a_relative_scene(tmp_path):
    scenario = scenario_from_toml(defaults.default_scenario_text(), tmp_path / "default.toml")
    assert scenario.scene_file == tmp_path / "small.txt"
    assert [s.kind for s in scenario.flight.segments] == ["orbit"]
    assert 12 <= len(scenario.poses()) <= 36
    assert scenario.sensor.grid in (64, 128)


@pytest.fixture(scope="module")
def materialised(tmp_path_factory):
    pytest.importorskip("ladartui.scene.generate")
    home = tmp_path_factory.mktemp("ladartui-home")
    old = os.environ.get("LADARTUI_HOME")
    os.environ["LADARTUI_HOME"] = str(home)
    try:
        path = defaults.default_scenario_path()
        yield home, path
    finally:
        if old is None:
            del os.environ["LADARTUI_HOME"]
        else:
            os.environ["LADARTUI_HOME"] = old


def read_voxels(path):
    return np.loadtxt(path, delimiter=",", dtype=np.int64, ndmin=2)


def test_first_use_writes_scenario_and_scene_in_the_data_folder(materialised):
    home, path = materialised
    assert path == home / "default" / "default.toml"
    scenario = load_scenario(path)  # checks both model files exist
    assert scenario.scene_file == home / "default" / "small.txt"
    assert scenario.target_file.is_file()
    assert not (Path(defaults.__file__).parent / "scenarios" / "small.txt").exists()


def test_second_use_is_idempotent(materialised):
    home, path = materialised
    stamps = {p: p.stat().st_mtime_ns for p in (home / "default").iterdir()}
    assert defaults.default_scenario_path() == path
    assert {p: p.stat().st_mtime_ns for p in (home / "default").iterdir()} == stamps


@pytest.mark.parametrize("lost", ["small.txt", "small_Target.txt"])
def test_a_lost_scene_is_made_again_and_the_users_edits_kept(tmp_path, monkeypatch, lost):
    """With a model file gone, the whole folder was made again: the scenario file, with
    the user's edits, was replaced by the packaged one without a word."""
    pytest.importorskip("ladartui.scene.generate")
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path))
    path = defaults.default_scenario_path()
    made = (path.parent / lost).read_bytes()
    edited = path.read_text().replace("scans = 24", "scans = 12") + "# my notes\n"
    assert edited != path.read_text() + "# my notes\n"  # the edit changed a setting
    path.write_text(edited)
    (path.parent / lost).unlink()
    assert defaults.default_scenario_path() == path
    assert path.read_text() == edited
    assert (path.parent / lost).read_bytes() == made  # the same scene: the same generator


def test_default_orbit_circles_the_generated_target_and_keeps_it_in_view(materialised):
    _, path = materialised
    scenario = load_scenario(path)
    target = read_voxels(scenario.target_file) * scenario.voxel_size
    centre = target.mean(axis=0)
    orbit = scenario.flight.segments[0]
    half_fov = math.radians(scenario.sensor.fov / 2)
    for pose in scenario.poses():
        assert math.dist((pose.x, pose.y), centre[:2]) == pytest.approx(orbit.radius, abs=0.02)
        # Every target voxel lies inside the field of view, with a margin.
        local = (target - pose.position) @ pose_rotation(pose)  # scene -> sensor frame
        assert (local[:, 2] < 0).all()
        angle_x = np.abs(np.arctan(local[:, 0] / -local[:, 2]))
        angle_y = np.abs(np.arctan(local[:, 1] / -local[:, 2]))
        assert max(angle_x.max(), angle_y.max()) < 0.8 * half_fov
    # Rays are fine enough to sample every voxel: several per voxel at the target.
    slant = math.dist(scenario.poses()[0].position, centre)
    spacing = slant * math.radians(scenario.sensor.fov) / (scenario.sensor.grid * scenario.sensor.ray_grid)
    assert spacing < scenario.voxel_size / 2


def test_load_scenario_takes_a_bundled_name_as_the_commands_do(materialised, tmp_path, monkeypatch):
    """`ladartui run default` ran, but ladartui.load_scenario("default") said no such file."""
    import ladartui
    from ladartui.errors import InputFileError

    load_scenario = ladartui.load_scenario
    _, path = materialised
    monkeypatch.chdir(tmp_path)
    assert load_scenario("default").path == path
    assert load_scenario("default.toml").path == path
    # A file of that name here wins, as with the commands.
    (tmp_path / "default.toml").write_text(path.read_text(encoding="utf-8"), encoding="utf-8")
    assert load_scenario("default.toml", check_files=False).path == tmp_path / "default.toml"
    # A folder of that name (a run's own, say) is no scenario file: the bundled one is meant
    # ('validate default' said '.../default: is a folder', with no way to reach it from here).
    (tmp_path / "default").mkdir()
    assert load_scenario("default").path == path
    with pytest.raises(InputFileError) as caught:
        load_scenario("defualt")
    assert str(caught.value) == (
        f"{tmp_path / 'defualt'}: no such file; expected a scenario file (.toml) "
        "or a bundled scenario: default, convoy"
    )
