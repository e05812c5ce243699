"""Sweep objectives on levels: time / distance to identify, worst-target coverage,
targets identified within a budget, and the recommended path's levels text."""

import pytest

from ladartui.errors import FieldError, InputFileError
from ladartui.sweep import load_sweep_results, load_sweep_spec, rank_rows, write_table
from ladartui.sweep.ranking import levels_text, objective_value


def row(variant, coverage, identify=None, recognise=None, status="ok", flight_time=10.0, scans=6):
    """A result row as the sweep writes it: levels flattened as levels.<level>.<field>."""
    out = {
        "variant": variant,
        "status": status,
        "obscured_coverage": coverage,
        "flight_time_s": flight_time,
        "path_length_m": 30.0 * flight_time,
        "levels.scans": scans,
    }
    for level, at in (("detect", recognise or identify), ("recognise", recognise), ("identify", identify)):
        scan, time = at if at is not None else (None, None)
        out[f"levels.{level}.reached"] = at is not None
        out[f"levels.{level}.scan"] = scan
        out[f"levels.{level}.flight_time_s"] = time
        out[f"levels.{level}.distance_m"] = None if time is None else 30.0 * time
    return out


ROWS = [
    row("a", 0.9, identify=(4, 6.0), recognise=(2, 2.0)),
    row("b", 0.6, identify=(2, 2.0), recognise=(1, 0.0), flight_time=12.0),
    row("c", 0.95, recognise=(3, 4.0)),  # best coverage, never identified
    row("d", 0.7, identify=(3, 4.0), recognise=(2, 2.0), flight_time=8.0),
    row("e", None, status="error"),
]


def order(ranking):
    return [(r.row["variant"], r.rank) for r in ranking]


def test_time_to_identify_ranks_the_earliest_identification_first_and_unidentified_last():
    ranking = rank_rows(ROWS, "time-to-identify")
    assert order(ranking) == [("b", 1), ("d", 2), ("a", 3), ("c", None), ("e", None)]
    assert [r.value for r in ranking[:3]] == [2.0, 4.0, 6.0]
    distance = rank_rows(ROWS, "distance-to-identify")
    assert [r.value for r in distance[:3]] == [60.0, 120.0, 180.0]


def test_ties_in_time_to_identify_go_to_the_cheaper_path():
    rows = [
        row("x", 0.5, identify=(2, 2.0), flight_time=9.0),
        row("y", 0.5, identify=(2, 2.0), flight_time=7.0),
    ]
    assert order(rank_rows(rows, "time_to_identify")) == [("y", 1), ("x", 2)]


def test_worst_target_coverage_is_the_target_coverage_with_one_target():
    ranking = rank_rows(ROWS, "worst-target-coverage")
    assert order(ranking)[:4] == [("c", 1), ("a", 2), ("d", 3), ("b", 4)]
    assert [r.value for r in ranking[:4]] == [0.95, 0.9, 0.7, 0.6]


def test_identified_within_budget_counts_targets_and_prefers_the_earlier_identification():
    ranking = rank_rows(ROWS, "identified-within-budget", budget=5.0)
    # a identifies at 6 s: over the budget, like c (never) and e (failed).
    assert order(ranking) == [("b", 1), ("d", 2), ("a", None), ("c", None), ("e", None)]
    assert [r.value for r in ranking[:2]] == [1.0, 1.0]
    # a value never given is said to be missing, not "= None"
    with pytest.raises(FieldError, match="^budget is not set: expected a flight-time budget"):
        objective_value(ROWS[0], "identified-within-budget")


def test_levels_text_says_which_level_the_path_reaches_and_when():
    assert levels_text(ROWS[0]) == "reaches identify at scan 4 of 6 (6.0 s, 180.0 m from the first scan)"
    assert levels_text(ROWS[2]) == (
        "reaches recognise at scan 3 of 6 (4.0 s, 120.0 m from the first scan); identify not reached"
    )
    assert levels_text(row("n", 0.0)) == "reaches no level (not detected)"
    # every level above the one reached is named ('identify not reached' left recognise out)
    detected = row("t", 0.1)
    detected.update({"levels.detect.reached": True, "levels.detect.scan": 1})
    detected.update({"levels.detect.flight_time_s": 0.0, "levels.detect.distance_m": 0.0})
    assert levels_text(detected) == (
        "reaches detect at scan 1 of 6 (0.0 s, 0.0 m from the first scan); recognise, identify not reached"
    )
    assert levels_text({"variant": "old", "status": "ok", "obscured_coverage": 0.5}) == "levels unknown"


def test_levels_text_writes_a_huge_time_with_an_exponent():
    """A speed of 1e-300 m/s printed the time to identify as 300 digits (run's table wrote 3.142e+301 s)."""
    slow = row("s", 0.9, identify=(4, 4e301), recognise=(2, 2e301))
    assert levels_text(slow) == "reaches identify at scan 4 of 6 (4e+301 s, 1.2e+303 m from the first scan)"


def test_objectives_survive_the_result_table(tmp_path):
    path = tmp_path / "results.csv"
    write_table(path, ROWS, [])
    result = load_sweep_results(path, objective="time-to-identify")
    assert order(result.ranking) == order(rank_rows(ROWS, "time-to-identify"))
    assert levels_text(result.ranking[0].row) == levels_text(ROWS[1])


def test_spec_objectives_and_their_budget(tmp_path):
    (tmp_path / "base.toml").write_text("")
    path = tmp_path / "s.toml"
    head = '[sweep]\nscenario = "base.toml"\nobjective = "{}"\n[grid]\nradius = [1.0]\n'
    path.write_text(head.format("time-to-identify"))
    assert load_sweep_spec(path).objective == "time-to-identify"
    path.write_text(head.format("identified-within-budget"))
    with pytest.raises(InputFileError, match="sweep.budget: expected a flight-time budget in seconds for "):
        load_sweep_spec(path)


def test_cli_sweep_says_which_level_the_recommended_path_reaches(tmp_path, capsys):
    import json

    from ladartui.cli import main
    from tiny_sweep import write_tiny_scenario

    write_tiny_scenario(tmp_path)
    spec = tmp_path / "spec.toml"
    spec.write_text(
        '[sweep]\nscenario = "base.toml"\nobjective = "time-to-identify"\n[grid]\nradius = [20.0, 30.0]\n'
    )
    assert main(["sweep", str(spec), "--serial"]) == 0
    text = capsys.readouterr().out
    assert "identify s" in text
    line = next(s for s in text.splitlines() if s.startswith("best path "))
    assert line.startswith("best path reaches identify at scan ") and "from the first scan)" in line
    assert main(["sweep", str(spec), "--show", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert "best path " + out["best_levels"] == line
    best = out["top"][0]
    assert best["levels"][0]["identify"]["reached"] is True
    assert best["objective"] == best["levels"][0]["identify"]["flight_time_s"]
    late = [
        r
        for r in load_sweep_results(tmp_path / "spec-results").rows
        if r["levels.identify.flight_time_s"] > 1e-9
    ]
    assert late  # some variant identifies after its first scan
    assert (
        main(["sweep", str(spec), "--show", "--objective", "identified-within-budget", "--budget", "1e-9"])
        == 0
    )
    text = capsys.readouterr().out
    said = f"{len(late)} finished {'variant' if len(late) == 1 else 'variants'} not ranked"
    assert f"{said} (no target identified within the budget)" in text


def two_target_row(variant, identify_times, coverages, names=("truck", "van")):
    """A row whose ``targets.per_target`` cell holds each target's measures (as a run writes)."""
    per_target = []
    for i, (time, coverage, name) in enumerate(zip(identify_times, coverages, names), start=1):
        levels = {"scans": 6}
        for level in ("detect", "recognise", "identify"):
            reached = time is not None
            levels[level] = {
                "reached": reached,
                "scan": 3 if reached else None,
                "flight_time_s": time,
                "distance_m": None if time is None else 30.0 * time,
            }
        per_target.append(
            {"id": i, "name": name, "measures": {"obscured_coverage": coverage, "levels": levels}}
        )
    out = row(variant, sum(coverages) / len(coverages), identify=(3, min(t or 99.0 for t in identify_times)))
    out["targets.per_target"] = per_target
    return out


TWO_TARGETS = [
    two_target_row("p", (2.0, 9.0), (0.8, 0.5)),  # both identified, the last at 9 s
    two_target_row("q", (4.0, 5.0), (0.6, 0.55)),  # both by 5 s: first on time to identify all
    two_target_row("r", (1.0, None), (0.9, 0.2)),  # the van never: unranked on time, worst 0.2
]


def test_objectives_over_several_targets_read_each_target():
    from ladartui.sweep.ranking import identified_within, time_to_identify, worst_target_coverage

    assert [time_to_identify(r) for r in TWO_TARGETS] == [9.0, 5.0, None]
    assert [worst_target_coverage(r) for r in TWO_TARGETS] == [0.5, 0.55, 0.2]
    assert [identified_within(r, 4.5) for r in TWO_TARGETS] == [(1, 2.0), (1, 4.0), (1, 1.0)]
    assert order(rank_rows(TWO_TARGETS, "time-to-identify")) == [("q", 1), ("p", 2), ("r", None)]
    assert order(rank_rows(TWO_TARGETS, "worst-target-coverage")) == [("q", 1), ("p", 2), ("r", 3)]
    # within 4.5 s each identifies one target; the earliest identification wins the tie
    ranked = order(rank_rows(TWO_TARGETS, "identified-within-budget", budget=4.5))
    assert ranked == [("r", 1), ("p", 2), ("q", 3)]
    text = levels_text(TWO_TARGETS[2])
    assert text.startswith("identifies 1 of 2 targets: truck reaches identify at scan 3")
    assert "van reaches no level" in text


def test_several_targets_survive_the_result_table(tmp_path):
    path = tmp_path / "results.csv"
    write_table(path, TWO_TARGETS, [])
    result = load_sweep_results(path, objective="time-to-identify")
    again = sorted((r.row for r in result.ranking), key=lambda r: r["variant"])
    assert [r["targets.per_target"] for r in again] == [r["targets.per_target"] for r in TWO_TARGETS]
    assert order(result.ranking) == [("q", 1), ("p", 2), ("r", None)]


def test_cli_sweep_prints_paths_with_markup_as_they_are(tmp_path, capsys):
    from ladartui.cli import main
    from tiny_sweep import write_tiny_scenario

    folder = tmp_path / "a[" / "bold]s"  # the path holds "[/bold]": a closing tag to rich
    folder.mkdir(parents=True)
    write_tiny_scenario(folder)
    spec = folder / "spec.toml"
    spec.write_text('[sweep]\nscenario = "base.toml"\n[grid]\nradius = [20.0, 30.0]\n')
    assert main(["sweep", str(spec), "--serial"]) == 0
    text = capsys.readouterr().out.replace("\n", "")
    assert f"results  {folder}" in text


def test_cli_sweep_table_folds_headers_never_values_in_a_narrow_terminal(tmp_path, capsys, monkeypatch):
    from ladartui.cli import main
    from tiny_sweep import write_tiny_scenario

    write_tiny_scenario(tmp_path)
    spec = tmp_path / "spec.toml"
    spec.write_text(
        '[sweep]\nscenario = "base.toml"\n[grid]\nradius = [20.0, 30.123]\naltitude = [30.0, 40.5]\n'
        "scans = [3, 4]\n"
    )
    assert main(["sweep", str(spec), "--serial"]) == 0
    capsys.readouterr()
    monkeypatch.setenv("COLUMNS", "60")
    assert main(["sweep", str(spec), "--show"]) == 0
    lines = capsys.readouterr().out.splitlines()
    rows = [r for r in (line.split() for line in lines) if len(r) > 2 and r[0].isdigit() and len(r[1]) == 8]
    assert len(rows) == 8 and all(len(line) <= 60 for line in lines)
    assert {r[2] for r in rows} == {"20.00", "30.12"} and {r[3] for r in rows} == {
        "30.00",
        "40.50",
    }  # decimals shared
    assert not any("…" in cell for r in rows for cell in r)


def test_targets_identified_are_shown_as_a_count(tmp_path, capsys):
    """The ranking's 'identified' column read 1.000 for one target."""
    from ladartui.cli import main
    from tiny_sweep import write_spec, write_tiny_scenario

    write_tiny_scenario(tmp_path)
    body = 'objective = "identified-within-budget"\nbudget = 1000.0\n[grid]\nradius = [20.0, 30.0]\n'
    assert main(["sweep", str(write_spec(tmp_path, body)), "--serial"]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()]
    ranked = [row for row in rows if row[:1] in (["1"], ["2"]) and row[1] != "variants"]
    assert ranked and all(row[3] == "1" for row in ranked), ranked
