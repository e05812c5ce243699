"""Sweeps over a two-target scene: per-target columns, objectives over all targets, the
recommended path's targets, and bundled base scenarios by name."""

import pytest

from ladartui.sweep import rank_rows, read_table, run_sweep
from ladartui.sweep.columns import target_values
from ladartui.sweep.ranking import levels_text
from tiny_sweep import write_two_target_spec


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    folder = tmp_path_factory.mktemp("two")
    spec = write_two_target_spec(folder, "time-to-identify")
    return run_sweep(spec, serial=True, out=folder / "out")


def by_path(result):
    return {(r["altitude"], r["radius"]): r for r in result.rows}


def test_rows_hold_each_targets_figures_and_levels(sweep):
    rows = by_path(sweep)
    assert all(r["status"] == "ok" and r["targets.ids"] == [1, 2] for r in rows.values())
    low, high = rows[(2.0, 30.0)], rows[(40.0, 5.0)]
    assert (low["target.1.name"], low["target.2.name"]) == ("open", "roofed")
    assert low["targets.count"] == 2 and low["target.1.target_voxels"] == 18
    # Looking down, the roof hides the roofed target entirely; the open one is seen.
    assert high["target.2.obscured_coverage"] == 0.0
    assert high["target.2.levels.detect.reached"] is False
    assert high["target.1.levels.identify.reached"] is True
    assert high["targets.worst.obscured_coverage"] == 0.0
    assert high["targets.mean.obscured_coverage"] == pytest.approx(high["target.1.obscured_coverage"] / 2)
    assert "targets.per_target" not in low  # no JSON cell of every target's measures
    assert target_values(low, "obscured_coverage") == [11 / 18, 9 / 18]


def test_the_table_reads_back_the_per_target_columns(sweep):
    rows, header = read_table(sweep.results_path)
    assert "target.2.levels.identify.scan" in header and "targets.ids" in header
    for row in rows:
        written = next(r for r in sweep.rows if r["variant"] == row["variant"])
        for column in header:
            if column.startswith(("target.", "targets.")):
                assert row[column] == written[column], column


def test_time_to_identify_all_targets_is_the_last_targets_identification(sweep):
    rows = by_path(sweep)
    ranking = rank_rows(sweep.rows, "time-to-identify")
    order = [((r.row["altitude"], r.row["radius"]), r.rank) for r in ranking]
    # The high paths never see the roofed target: not ranked, though they identify the open one.
    assert order[:2] == [((2.0, 5.0), 1), ((2.0, 30.0), 2)]
    assert {p for p, rank in order[2:] if rank is None} == {(40.0, 5.0), (40.0, 30.0)}
    close, wide = rows[(2.0, 5.0)], rows[(2.0, 30.0)]
    # Close orbit: roofed at scan 2, open only at the last scan 4: the whole flight.
    assert (close["target.1.levels.identify.scan"], close["target.2.levels.identify.scan"]) == (4, 2)
    assert ranking[0].value == close["flight_time_s"]
    # Wide orbit: both at scan 2 of 4, a third of the flight.
    assert ranking[1].value == pytest.approx(wide["flight_time_s"] / 3)
    distance = rank_rows(sweep.rows, "distance-to-identify")
    assert distance[0].value == pytest.approx(close["path_length_m"])


def test_worst_target_coverage_is_the_lowest_targets_coverage(sweep):
    ranking = rank_rows(sweep.rows, "worst-target-coverage")
    assert [((r.row["altitude"], r.row["radius"]), r.value) for r in ranking[:2]] == [
        ((2.0, 30.0), 9 / 18),
        ((2.0, 5.0), 6 / 18),
    ]
    assert [r.value for r in ranking[2:]] == [0.0, 0.0]


def test_targets_identified_within_budget_count_and_the_earlier_time_breaks_ties(sweep):
    ranking = rank_rows(sweep.rows, "identified-within-budget", budget=2.0)
    assert [((r.row["altitude"], r.row["radius"]), r.value) for r in ranking] == [
        ((2.0, 5.0), 2.0),  # both by 0.8 s
        ((2.0, 30.0), 2.0),  # both by 1.6 s
        ((40.0, 5.0), 1.0),  # the open one at 0.5 s
        ((40.0, 30.0), 1.0),  # the open one at 1.6 s
    ]
    short = rank_rows(sweep.rows, "identified-within-budget", budget=1.0)
    assert [r.value for r in short] == [2.0, 1.0, None, None]


def test_the_recommended_path_names_the_targets_it_identifies_and_when(sweep):
    assert sweep.best.row["radius"] == 5.0 and sweep.best.row["altitude"] == 2.0
    text = levels_text(sweep.best.row)
    assert text.startswith("identifies all 2 targets: open reaches identify at scan 4 of 4 (0.8 s, ")
    assert "; roofed reaches identify at scan 2 of 4 (0.3 s, " in text
    high = by_path(sweep)[(40.0, 5.0)]
    assert levels_text(high) == (
        "identifies 1 of 2 targets: open reaches identify at scan 3 of 4 (0.5 s, 15.7 m from the "
        "first scan); roofed reaches no level (not detected)"
    )


def test_a_bundled_scenario_name_is_a_sweep_base(tmp_path):
    from ladartui.sweep.base import base_scenario_path
    from ladartui.sweep.spec import load_sweep_spec
    from ladartui.user_data import bundled_scenario_path

    spec = tmp_path / "spec.toml"
    spec.write_text('[sweep]\nscenario = "convoy"\n[grid]\nscans = [2, 3]\n', encoding="utf-8")
    path = base_scenario_path(load_sweep_spec(spec))
    assert path == bundled_scenario_path("convoy") and path.is_file()
    # A file of that name beside the spec wins over the bundled one.
    (tmp_path / "convoy").write_text(path.read_text(encoding="utf-8"), encoding="utf-8")
    assert base_scenario_path(load_sweep_spec(spec)) == tmp_path / "convoy"


def test_cli_sweep_shows_targets_identified_and_names_them(tmp_path, capsys):
    import json

    from ladartui.cli import main

    spec = write_two_target_spec(tmp_path, "time-to-identify")
    assert main(["sweep", str(spec), "--serial"]) == 0
    text = capsys.readouterr().out
    assert "targets id." in text and text.count(" 2/2 ") == 2  # the two ranked paths
    assert "2 finished variants not ranked (a target not identified)" in text
    line = next(s for s in text.splitlines() if s.startswith("best path "))
    assert line.startswith("best path identifies all 2 targets: open reaches identify at scan 4 of 4")
    assert main(["sweep", str(spec), "--show", "--json"]) == 0
    best = json.loads(capsys.readouterr().out)["top"][0]
    assert [(t["target"], t["name"]) for t in best["levels"]] == [(1, "open"), (2, "roofed")]
    assert best["objective"] == max(t["identify"]["flight_time_s"] for t in best["levels"])


def test_cli_sweep_names_the_target_no_path_identifies(tmp_path, capsys):
    from ladartui.cli import main

    spec = write_two_target_spec(tmp_path, "time-to-identify")
    spec.write_text(spec.read_text().replace("altitude = [2.0, 40.0]", "altitude = [40.0]"))
    assert main(["sweep", str(spec), "--serial"]) == 0
    text = capsys.readouterr().out
    assert "no variant identifies roofed" in text and "best path" not in text


def test_a_row_with_a_per_target_cell_reads_per_target(sweep):
    """Tables written with one JSON cell of every target's measures still rank per target."""
    from ladartui.sweep.columns import target_names
    from ladartui.sweep.ranking import time_to_identify, worst_target_coverage

    row = by_path(sweep)[(2.0, 5.0)]
    old = {k: v for k, v in row.items() if not k.startswith(("target.", "targets.ids"))}
    old["targets.per_target"] = [
        {
            "id": i,
            "name": row[f"target.{i}.name"],
            "measures": {
                "obscured_coverage": row[f"target.{i}.obscured_coverage"],
                "levels": {
                    "identify": {
                        f: row[f"target.{i}.levels.identify.{f}"]
                        for f in ("reached", "scan", "flight_time_s", "distance_m")
                    }
                },
            },
        }
        for i in (1, 2)
    ]
    assert target_names(old) == ["open", "roofed"]
    assert time_to_identify(old) == time_to_identify(row) == row["flight_time_s"]
    assert worst_target_coverage(old) == worst_target_coverage(row) == 6 / 18
