"""``ladartui study``'s flags: refused before any scene is loaded or file written."""

from __future__ import annotations

import pytest

from ladartui.cli import main
from ladartui.study import inputs as study_inputs


@pytest.fixture
def no_scene(monkeypatch):
    """A study that got past its flags would load a scene: fail loudly instead."""

    def refuse(*args, **kwargs):
        raise AssertionError("a scene was loaded")

    monkeypatch.setattr(study_inputs, "cached_scene", refuse)
    monkeypatch.setattr(study_inputs, "generated_inputs", refuse)


@pytest.mark.parametrize("out", ["", "  "])
def test_an_empty_out_is_refused_and_nothing_is_written_here(tmp_path, monkeypatch, capsys, no_scene, out):
    """'study --quick --out ""' wrote its five files into the current folder."""
    monkeypatch.chdir(tmp_path)
    assert main(["study", "--quick", "--out", out]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"ladartui: error: --out = {out!r}: expected a folder name, such as study-results"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "flag, value, expected",
    [
        ("--runs", "100000", "a whole number from 1 to 1000"),
        ("--runs", "0", "a whole number from 1 to 1000"),
        ("--warmup", "100000", "a whole number from 0 to 1000"),
        ("--warmup", "-1", "a whole number from 0 to 1000"),
    ],
)
def test_runs_and_warmup_have_the_bench_limits(tmp_path, capsys, no_scene, flag, value, expected):
    """'--warmup 100000' and '--runs 100000' were taken: the study ran until Ctrl-C."""
    assert main(["study", "--quick", flag, value, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"ladartui: error: {flag} = {value}: expected {expected}"


def test_more_scans_than_the_default_orbit_has_are_refused_before_the_scene_loads(
    tmp_path, monkeypatch, capsys
):
    """'--scans 100000' was cut to 24 in silence, said only by the last line."""

    def refuse(*args, **kwargs):
        raise AssertionError("a scene was loaded")

    monkeypatch.setattr(study_inputs, "cached_scene", refuse)
    assert main(["study", "--quick", "--scans", "100000", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "ladartui: error: --scans = 100000: expected at most 24: the default orbit has 24 scans"


def test_more_scans_than_a_scenario_has_are_refused_naming_its_count(tmp_path, monkeypatch, capsys):
    from ladartui.scenario import Scenario, load_scenario
    from ladartui.user_data import default_scenario_path

    path = default_scenario_path()
    available = len(load_scenario(path).poses())

    def refuse(self):
        raise AssertionError("the scene was loaded")

    monkeypatch.setattr(Scenario, "load_scene", refuse)
    asked = available + 1
    assert main(["study", str(path), "--scans", str(asked), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        f"ladartui: error: --scans = {asked}: expected at most {available}: "
        f"the flight of {path} has {available} scans"
    )


def test_a_bundled_scenario_is_taken_by_name_as_run_takes_it(tmp_path, monkeypatch, capsys):
    """'study convoy' said '/cwd/convoy: no such file', where 'run convoy' runs it."""
    from ladartui.scenario import Scenario
    from ladartui.user_data import bundled_scenario_path

    path = bundled_scenario_path("convoy")

    def refuse(self):
        raise AssertionError("the scene was loaded")

    monkeypatch.setattr(Scenario, "load_scene", refuse)
    monkeypatch.chdir(tmp_path)
    assert main(["study", "convoy", "--scans", "1000", "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.strip() == (
        f"ladartui: error: --scans = 1000: expected at most 24: the flight of {path} has 24 scans"
    )


def test_the_scans_a_flight_has_are_all_taken_and_a_default_above_them_is_not_refused(tmp_path):
    from ladartui.scenario import load_scenario
    from ladartui.user_data import default_scenario_path

    path = default_scenario_path()
    available = len(load_scenario(path).poses())
    assert len(study_inputs.scenario_inputs(path, available, refuse_as="--scans").poses) == available
    # the study screen and a default count keep taking what the flight has
    assert len(study_inputs.scenario_inputs(path, available + 5).poses) == available


@pytest.mark.parametrize("signum, status", [(2, 130), (15, 143)], ids=["Ctrl-C", "SIGTERM"])
def test_a_stopped_study_says_nothing_was_written(tmp_path, monkeypatch, capsys, signum, status):
    """A Ctrl-C said only 'study cancelled', not whether the earlier study in --out was kept,
    and SIGTERM ended the command without a word."""
    import types

    import numpy as np

    import ladartui.study.run as study_run
    from cli_support import ctrl_c
    from ladartui.errors import Cancelled

    inputs = types.SimpleNamespace(
        name="tiny",
        scene=types.SimpleNamespace(voxels=np.zeros((1, 3)), shape=(1, 1, 1)),
        poses=[None],
        sensor=types.SimpleNamespace(grid=4),
    )
    monkeypatch.setattr(study_inputs, "generated_inputs", lambda *a, **k: inputs)
    monkeypatch.setattr(study_run, "backend_reasons", lambda backends: {})

    def stopped(*args, cancel, **kwargs):
        assert ctrl_c(cancel, signum=signum), "the stop did not cancel the study"  # the key, or `kill`
        raise Cancelled("study cancelled")

    monkeypatch.setattr(study_run, "run_study", stopped)
    out = tmp_path / "results"
    assert main(["study", "--quick", "--out", str(out)]) == status
    assert (
        capsys.readouterr().err.splitlines()[-1] == f"ladartui: study cancelled; nothing was written to {out}"
    )
    out.mkdir(exist_ok=True)
    (out / "study.csv").write_text("earlier")
    assert main(["study", "--quick", "--out", str(out)]) == status
    assert capsys.readouterr().err.splitlines()[-1] == (
        f"ladartui: study cancelled; nothing was written, the earlier study in {out} is unchanged"
    )
    assert [p.name for p in out.iterdir()] == ["study.csv"] and (out / "study.csv").read_text() == "earlier"


def test_a_folder_where_the_lock_goes_is_refused_before_the_study(tmp_path, capsys, no_scene):
    """It ended the study, after all its tracing, in an IsADirectoryError traceback."""
    (tmp_path / ".study.outputs.lock").mkdir(parents=True)
    assert main(["study", "--quick", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(
        f"ladartui: error: {tmp_path / '.study.outputs.lock'}: is a folder, expected the lock file"
    )
