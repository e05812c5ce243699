"""The run record: a run writes the settings that made its outputs beside them.

``S_Run.toml`` is part of the output set (written with the outputs or not at
all). It says which settings made the outputs even when they were never saved
(a TUI run of unsaved edits, ``ladartui run --method``), so the TUI can tell
whether the outputs it opens match the scenario.
"""

from __future__ import annotations

import pytest

from ladartui.cli import main
from ladartui.errors import LadarError
from ladartui.run_record import RECORD_HEADER, read_run_record
from ladartui.scenario import load_scenario
from ladartui.simulation import simulate
from ladartui.tui import bridge
from test_output_set import make_scenario, snapshot


@pytest.fixture
def scenario(tmp_path):
    return make_scenario(tmp_path)


def test_a_run_records_the_settings_it_ran_with_overrides_included(scenario):
    result = simulate(scenario, method="march", step=0.25)
    record = scenario.path.with_name("S_Run.toml")
    assert result.outputs["record"] == str(record)
    assert record.read_text(encoding="utf-8").startswith(RECORD_HEADER)
    ran = read_run_record(scenario)
    assert ran is not None and ran.method == "march" and ran.step == 0.25
    # everything else is the scenario's, so the record says exactly what made the outputs
    assert ran.same_outputs(scenario.with_changes(method="march", step=0.25))
    assert not ran.same_outputs(scenario)
    # the scenario file is left as it was
    assert load_scenario(scenario.path).method == scenario.method


def test_the_record_of_an_unsaved_scenario_is_what_ran_not_what_is_saved(scenario):
    edited = scenario.with_changes(sensor=scenario.sensor.__class__(grid=12, ray_grid=1, fov=20.0))
    simulate(edited)
    ran = read_run_record(scenario)
    assert ran is not None and ran.sensor == edited.sensor and ran.same_outputs(edited)
    assert not ran.same_outputs(load_scenario(scenario.path))


def test_no_record_before_a_first_run_and_an_older_set_is_not_incomplete(scenario):
    assert read_run_record(scenario) is None
    simulate(scenario)
    scenario.path.with_name("S_Run.toml").unlink()  # a set written before records existed
    assert read_run_record(scenario) is None
    assert bridge.missing_outputs(scenario) == []


def test_a_users_own_file_of_that_name_is_never_overwritten(scenario, capsys):
    theirs = scenario.path.with_name("S_Run.toml")
    theirs.write_text("# my own notes\n", encoding="utf-8")
    before = snapshot(scenario)
    assert main(["run", str(scenario.path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "S_Run.toml" in err and "not a run record" in err
    assert theirs.read_text(encoding="utf-8") == "# my own notes\n"
    assert snapshot(scenario) == before  # nothing was written


def test_a_damaged_record_is_reported_naming_the_file(scenario):
    simulate(scenario)
    record = scenario.path.with_name("S_Run.toml")
    record.write_text(RECORD_HEADER + "\n[sensor\n", encoding="utf-8")
    with pytest.raises(LadarError) as caught:
        read_run_record(scenario)
    assert "S_Run.toml" in str(caught.value)
