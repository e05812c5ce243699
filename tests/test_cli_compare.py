"""``ladartui compare``: several runs' measures side by side, as the TUI's Compare shows them."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_support import one_error_line
from ladartui import cli
from ladartui.measures import compute_measures


def box(nx, ny, nz):
    return np.array([(i, j, k) for i in range(nx) for j in range(ny) for k in range(nz)], np.int32)


def write_run(path, seen_layers: int, scans: int):
    """A .cmf of a 4 x 4 x 4 target of which the top ``seen_layers`` layers were seen,
    over ``scans`` scans; the path flown is 100 m a scan."""
    target = box(4, 4, 4)
    seen = target[target[:, 2] >= 4 - seen_layers]
    measures = compute_measures(
        target,
        seen,
        seen,
        scene_per_scan=[seen] * scans,
        target_per_scan=[seen] * scans,
        path_length_m=100.0 * scans,
        flight_time_s=4.0 * scans,
    )
    path.write_text(measures.to_cmf())
    return measures


def test_two_runs_side_by_side_with_the_best_and_worst_named(tmp_path, capsys):
    orbit = write_run(tmp_path / "orbit.cmf", seen_layers=3, scans=12)
    flypast = write_run(tmp_path / "flypast.cmf", seen_layers=1, scans=6)
    assert cli.main(["compare", str(tmp_path / "orbit.cmf"), str(tmp_path / "flypast.cmf"), "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    assert said["columns"] == ["orbit", "flypast"]
    rows = {row["measure"]: row for row in said["measures"]}
    coverage = rows["Obscured target coverage"]
    assert coverage["values"] == [orbit.obscured_coverage, flypast.obscured_coverage] == [48 / 64, 16 / 64]
    assert coverage["text"] == ["75.0%", "25.0%"] and coverage["differ"]
    assert (coverage["best"], coverage["worst"]) == (["orbit"], ["flypast"])
    path = rows["Path length (m)"]  # shorter is better
    assert path["values"] == [1200.0, 600.0] and (path["best"], path["worst"]) == (["flypast"], ["orbit"])
    target = rows["Target voxels"]  # the same in both: no best, no worst
    assert target["values"] == [64, 64] and not target["differ"] and target["best"] == target["worst"] == []
    assert rows["Scans"]["values"] == [12, 6] and rows["Scans"]["best"] == []  # no better way


def test_the_table_names_its_columns_apart_and_reads_in_percent(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "120")
    write_run(tmp_path / "a.cmf", seen_layers=2, scans=3)
    (tmp_path / "other").mkdir()
    write_run(tmp_path / "other" / "a.cmf", seen_layers=4, scans=3)
    assert cli.main(["compare", str(tmp_path / "a.cmf"), str(tmp_path / "other" / "a.cmf")]) == 0
    out = capsys.readouterr().out
    # two files of one name are told apart by their folders
    header = next(line for line in out.splitlines() if "┃ Measure " in line)
    assert f"{tmp_path.name}/a" in header and "other/a" in header
    line = next(line for line in out.splitlines() if "Obscured target coverage" in line)
    assert [cell.strip() for cell in line.split("│")[2:4]] == ["50.0%", "100.0%"]


def test_a_scenario_is_compared_by_the_measures_its_run_wrote(tmp_path, capsys):
    from scenario_support import BASE, write_scenario

    write_scenario(tmp_path, BASE, "orbit.toml")  # its run wrote orbit.cmf beside it
    write_run(tmp_path / "orbit.cmf", seen_layers=3, scans=10)
    write_run(tmp_path / "flypast.cmf", seen_layers=2, scans=10)
    files = [str(tmp_path / "orbit.toml"), str(tmp_path / "flypast.cmf"), "--json"]
    assert cli.main(["compare", *files]) == 0
    said = json.loads(capsys.readouterr().out)
    assert said["columns"] == ["orbit", "flypast"]
    assert said["measures"][2]["measure"] == "Obscured target coverage"
    assert said["measures"][2]["values"] == [0.75, 0.5]


@pytest.mark.parametrize(
    ("files", "said"),
    [
        (["one.cmf"], "FILE = 'one.cmf': expected two or more files to compare"),
        (["one.cmf", "gone.cmf"], "gone.cmf: measures file not found"),
        (["one.cmf", "."], ".: is a folder; expected a .cmf measures file or a scenario (.toml)"),
        (["one.cmf", ""], "FILE = '': expected a measures file (.cmf) or a scenario (.toml)"),
        (["one.cmf", "never.toml"], "never.cmf: measures file of never.toml not found: run it first"),
        (["one.cmf", "gone.toml"], "gone.toml: scenario not found"),
        (
            ["one.cmf", "never.toml", "--json"],
            "never.cmf: measures file of never.toml not found: run it first",
        ),
    ],
)
def test_what_cannot_be_compared_is_said_in_one_line(tmp_path, capsys, monkeypatch, files, said):
    from scenario_support import write_scenario

    monkeypatch.chdir(tmp_path)
    write_run(tmp_path / "one.cmf", seen_layers=1, scans=1)
    write_scenario(tmp_path, name="never.toml")  # never run: no never.cmf
    assert cli.main(["compare", *files]) == 2
    assert one_error_line(capsys).endswith(said)


def test_columns_of_one_name_are_told_apart_in_the_table_and_the_json(tmp_path, capsys):
    """'compare a.cmf a.cmf' headed both columns 'a', and a scenario beside its own
    measures file both 'orbit': the JSON's best and worst named no column."""
    from scenario_support import BASE, write_scenario

    write_scenario(tmp_path, BASE, "orbit.toml")
    write_run(tmp_path / "orbit.cmf", seen_layers=3, scans=10)
    for files, columns in (
        (["orbit.cmf", "orbit.cmf"], ["orbit", "orbit (2)"]),
        (["orbit.cmf"] * 3, ["orbit", "orbit (2)", "orbit (3)"]),  # the third was 'orbit (2)' again
        (["orbit.toml", "orbit.cmf"], ["orbit.toml", "orbit.cmf"]),
    ):
        assert cli.main(["compare", *(str(tmp_path / f) for f in files), "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["columns"] == columns


def test_bundled_scenarios_are_compared_by_name_as_run_takes_them(tmp_path, capsys, monkeypatch):
    """'ladartui run convoy' then 'ladartui compare convoy default' said convoy was not found."""
    from ladartui.user_data import data_home
    from scenario_support import write_scenario

    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    monkeypatch.chdir(tmp_path)
    for name, layers in (("default", 3), ("convoy", 1)):
        folder = data_home() / name
        folder.mkdir(parents=True)
        write_scenario(folder, name=f"{name}.toml")
        write_run(folder / f"{name}.cmf", seen_layers=layers, scans=2)
    assert cli.main(["compare", "convoy", "default.toml", "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    assert said["columns"] == ["convoy", "default"]
    assert said["measures"][2]["values"] == [0.25, 0.75]
    (tmp_path / "convoy.cmf").write_text((data_home() / "default" / "default.cmf").read_text())
    assert cli.main(["compare", "convoy.cmf", "convoy", "--json"]) == 0  # a file here is that file
    assert json.loads(capsys.readouterr().out)["measures"][2]["values"] == [0.75, 0.25]


def test_a_bundled_scenario_never_made_is_told_to_run_first_and_not_made(tmp_path, capsys, monkeypatch):
    from ladartui.user_data import data_home

    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    monkeypatch.chdir(tmp_path)
    write_run(tmp_path / "one.cmf", seen_layers=1, scans=1)
    assert cli.main(["compare", "one.cmf", "convoy"]) == 2
    assert one_error_line(capsys).endswith("convoy.cmf: measures file of convoy.toml not found: run it first")
    assert not (data_home() / "convoy").exists()  # no scene generated only to say so


def test_geiger_runs_are_compared_by_their_detection_figures_too(tmp_path, capsys):
    """A 10-pulse and a 100-pulse run differ most in their false alarms, which their .cmf
    files hold: compare showed their coverages alone, as if the sensor were the same."""
    import dataclasses

    from ladartui.detection.measures import DetectionMeasures

    def geiger(measures, pulses, false_alarms, detection):
        figures = DetectionMeasures(
            pulses=pulses,
            coincidence=max(1, pulses // 10),
            seed=0,
            declared_points=1000 + false_alarms,
            declared_per_look=(1000 + false_alarms) / 10,
            false_alarms=false_alarms,
            false_alarms_per_look=false_alarms / 10,
            false_alarm_probability=false_alarms / 1e6,
            target_detection=detection,
            ideal_obscured_coverage=0.75,
            ideal_unobscured_coverage=0.75,
        )
        return dataclasses.replace(measures, detection=figures)

    ten = geiger(write_run(tmp_path / "ten.cmf", seen_layers=3, scans=10), 10, 6908, 0.924)
    (tmp_path / "ten.cmf").write_text(ten.to_cmf())
    hundred = geiger(write_run(tmp_path / "hundred.cmf", seen_layers=3, scans=10), 100, 0, 0.898)
    (tmp_path / "hundred.cmf").write_text(hundred.to_cmf())
    write_run(tmp_path / "ideal.cmf", seen_layers=3, scans=10)
    files = [str(tmp_path / f"{name}.cmf") for name in ("ten", "hundred", "ideal")]
    assert cli.main(["compare", *files, "--json"]) == 0
    rows = {row["measure"]: row for row in json.loads(capsys.readouterr().out)["measures"]}
    alarms = rows["False alarms"]
    assert alarms["values"] == [6908, 0, None] and alarms["text"] == ["6,908", "0", "ideal sensor"]
    assert (alarms["best"], alarms["worst"]) == (["hundred"], ["ten"])  # fewer is better
    detected = rows["P_d of target voxels"]
    assert detected["text"] == ["92.4%", "89.8%", "ideal sensor"] and detected["best"] == ["ten"]
    assert rows["Pulses per look"]["values"] == [10, 100, None]
    assert rows["Coincidence k"]["values"] == [1, 10, None]
    assert rows["Declared points"]["values"] == [7908, 1000, None]
    assert rows["Declared points per look"]["values"] == [790.8, 100.0, None]
    assert rows["Random seed"]["values"] == [0, 0, None]  # the docs list it among what is compared
    ideal = rows["Ideal sensor: obscured coverage"]  # an ideal run's is its own coverage
    assert ideal["values"] == [0.75, 0.75, 0.75] and ideal["text"] == ["75.0%"] * 3
    # ideal runs alone have no such rows
    assert cli.main(["compare", files[2], files[2], "--json"]) == 0
    said = json.loads(capsys.readouterr().out)["measures"]
    assert not any(row["measure"] == "False alarms" for row in said)


def test_compare_offers_the_runs_beside_a_scenario_that_read(tmp_path):
    """Compare (F10) filled its list with every .cmf of the folder, so one that could not
    be read opened it on that file's error and no table; it offers the scenario's own
    run first, then the others that read, four at most."""
    from ladartui.measures_compare import measures_files_to_offer

    own = tmp_path / "plan.cmf"
    write_run(own, seen_layers=2, scans=2)
    for name in ("a", "c", "d", "e"):
        write_run(tmp_path / f"{name}.cmf", seen_layers=1, scans=1)
    (tmp_path / "b.cmf").write_text("not a measures file\n")
    (tmp_path / "cut.cmf").write_text((tmp_path / "a.cmf").read_text()[:200])
    assert [p.name for p in measures_files_to_offer(own)] == ["plan.cmf", "a.cmf", "c.cmf", "d.cmf"]
    own.unlink()  # not run yet: the others alone
    assert [p.name for p in measures_files_to_offer(own)] == ["a.cmf", "c.cmf", "d.cmf", "e.cmf"]


def test_the_voxels_seen_obscured_alone_are_compared_as_run_shows_them(tmp_path, capsys):
    """run's table gives 'Seen obscured but not unobscured'; compare, which says it
    shows every measure, left it out."""
    target = box(2, 2, 1)
    for name, extra in (("a", 1), ("b", 0)):
        obscured = target[: 2 + extra]  # what the scene run saw: one voxel the target-alone run missed
        compute_measures(target, obscured, target[:2]).write_cmf(tmp_path / f"{name}.cmf")
    assert cli.main(["compare", str(tmp_path / "a.cmf"), str(tmp_path / "b.cmf"), "--json"]) == 0
    rows = {row["measure"]: row for row in json.loads(capsys.readouterr().out)["measures"]}
    assert rows["Seen obscured but not unobscured"]["values"] == [1, 0]


def test_a_false_alarm_chance_too_small_for_six_decimals_is_not_shown_as_none():
    """Chances of 2e-7 and 4e-9 per bin both read '0.000000', one painted best, the other
    worst; run's table writes such a chance with its exponent."""
    from ladartui.measures_compare import format_value

    assert format_value(2e-7, "prob") == "2.00e-07" and format_value(4e-9, "prob") == "4.00e-09"
    assert format_value(0.0, "prob") == "0.000000" and format_value(0.0123, "prob") == "0.012300"


def test_a_scenario_edited_since_its_run_is_compared_with_a_note_naming_what_changed(tmp_path, capsys):
    """'compare orbit.toml flypast.cmf' after the orbit's radius was changed and not run
    again showed the old run's path length and coverage under 'orbit' without a word,
    where validate says the outputs came from other settings."""
    from tiny_sweep import write_tiny_scenario

    pytest.importorskip("numba")
    scenario = write_tiny_scenario(tmp_path, "orbit.toml")
    assert cli.main(["run", str(scenario.path)]) == 0
    write_run(tmp_path / "flypast.cmf", seen_layers=2, scans=10)
    text = scenario.path.read_text()
    scenario.path.write_text(text.replace("radius = 20.0", "radius = 35.0"))
    capsys.readouterr()
    for extra in ([], ["--json"]):
        assert cli.main(["compare", str(scenario.path), str(tmp_path / "flypast.cmf"), *extra]) == 0
        err = capsys.readouterr().err.strip()
        assert err == (
            f"note: {scenario.path}: its measures are its last run's, made with other settings "
            "than this file: flight.segments[0].radius 20 (here 35); run it again to compare these"
        )
    scenario.path.write_text(text)  # as it ran: nothing to say
    assert cli.main(["compare", str(scenario.path), str(tmp_path / "flypast.cmf")]) == 0
    assert capsys.readouterr().err == ""
