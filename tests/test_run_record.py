"""The run record: a run writes the settings that made its outputs beside them.

``S_Run.toml`` is part of the output set (written with the outputs or not at
all). It says which settings made the outputs even when they were never saved
(a TUI run of unsaved edits, ``ladartui run --method``), so the TUI can tell
whether the outputs it opens match the scenario.
"""

from __future__ import annotations

import os

import pytest

from ladartui.cli import main
from ladartui.errors import LadarError
from ladartui.run_record import RECORD_HEADER, missing_outputs, read_run_record, setting_changes
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
    assert missing_outputs(scenario) == []


def test_a_users_own_file_of_that_name_is_never_overwritten(scenario, capsys):
    theirs = scenario.path.with_name("S_Run.toml")
    theirs.write_text("# my own notes\n", encoding="utf-8")
    before = snapshot(scenario)
    assert main(["run", str(scenario.path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "S_Run.toml" in err and "not a run record" in err
    assert theirs.read_text(encoding="utf-8") == "# my own notes\n"
    assert snapshot(scenario) == before  # nothing was written


def test_a_folder_of_the_records_name_is_called_a_folder(scenario, capsys):
    """It was said to be a file that 'is not a run record', to be renamed."""
    record = scenario.path.with_name("S_Run.toml")
    record.mkdir()
    assert main(["run", str(scenario.path)]) == 2
    assert capsys.readouterr().err == (
        f"ladartui: error: {record}: is a folder, expected a file name (a run writes its settings there)\n"
    )
    assert main(["validate", str(scenario.path)]) == 1  # the summary, then why a run is refused
    assert capsys.readouterr().out.splitlines()[-1] == (
        "next run   S_Run.toml: is a folder, expected a file name (a run writes its settings there); "
        "the run is refused before it traces"
    )


def test_a_damaged_record_is_reported_naming_the_file(scenario):
    simulate(scenario)
    record = scenario.path.with_name("S_Run.toml")
    record.write_text(RECORD_HEADER + "\n[sensor\n", encoding="utf-8")
    with pytest.raises(LadarError) as caught:
        read_run_record(scenario)
    assert "S_Run.toml" in str(caught.value)


def test_the_settings_that_differ_are_named_with_both_values(scenario):
    simulate(scenario, method="march", step=0.25)
    ran = read_run_record(scenario)
    assert setting_changes(ran, scenario) == ["simulation.method march (here exact)"]
    # the step only counts for the march; in a run of it, it does
    marched = scenario.with_changes(method="march")
    assert setting_changes(ran, marched) == ["simulation.step 0.25 (here 0.5)"]
    assert setting_changes(ran, scenario.with_changes(method="march", step=0.25, backend="auto")) == []
    wider = scenario.with_changes(sensor=scenario.sensor.__class__(grid=16, ray_grid=2, fov=25.0))
    assert "sensor.fov_deg 20 (here 25)" in setting_changes(ran, wider)


def test_validate_says_whether_the_outputs_came_from_this_file(scenario, capsys):
    assert main(["validate", str(scenario.path)]) == 0
    assert "last run" not in capsys.readouterr().out  # nothing run yet
    assert main(["run", str(scenario.path), "--method", "march"]) == 0
    capsys.readouterr()
    assert main(["validate", str(scenario.path)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("last run"))
    assert line == (
        "last run   made the outputs with other settings than this file: "
        "simulation.method march (here exact); they are in S_Run.toml"
    )
    assert main(["run", str(scenario.path)]) == 0
    capsys.readouterr()
    assert main(["validate", str(scenario.path)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("last run"))
    assert line == "last run   made the outputs with this file's settings (S_Run.toml)"
    # a set with a file gone is said to be incomplete (the line was left out)
    scenario.measures_file.unlink()
    assert main(["validate", str(scenario.path)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("last run"))
    assert line == "last run   outputs incomplete: S.cmf missing; a run writes the whole set again"


def test_validate_names_an_output_a_run_would_refuse_to_write(scenario, capsys):
    """An S.cmf folder was 'outputs incomplete: S.cmf missing; a run writes the whole set
    again', and a run refused it; before a first run, an S_Scene.txt folder went unsaid."""
    scenario.scene_output.mkdir()
    assert main(["validate", str(scenario.path)]) == 1
    lines = [x for x in capsys.readouterr().out.splitlines() if x.startswith(("last run", "next run"))]
    assert lines == [
        "next run   S_Scene.txt is a folder, expected a file name: it is refused before it traces"
    ]
    scenario.scene_output.rmdir()
    assert main(["run", str(scenario.path)]) == 0
    scenario.measures_file.unlink()
    scenario.measures_file.mkdir()
    capsys.readouterr()
    assert main(["validate", str(scenario.path)]) == 1
    lines = [x for x in capsys.readouterr().out.splitlines() if x.startswith(("last run", "next run"))]
    assert lines == [
        "last run   outputs incomplete: S.cmf missing",
        "next run   S.cmf is a folder, expected a file name: it is refused before it traces",
    ]
    assert main(["run", str(scenario.path)]) == 2
    assert "S.cmf: is a folder, expected a file name" in capsys.readouterr().err


def test_validate_says_whether_outputs_it_cannot_replace_are_up_to_date(scenario, capsys, monkeypatch):
    """An output a run cannot write (a read-only folder) was said in place of whether the
    outputs on disk came from this file's settings, which still matters to read them."""
    from ladartui import outputset

    assert main(["run", str(scenario.path)]) == 0
    capsys.readouterr()
    real = outputset.output_problem
    monkeypatch.setattr(
        outputset,
        "output_problem",
        lambda path: "cannot be written (permission denied)" if path.name == "S_Scene.txt" else real(path),
    )
    assert main(["validate", str(scenario.path)]) == 1
    lines = [x for x in capsys.readouterr().out.splitlines() if x.startswith(("last run", "next run"))]
    assert lines == [
        "last run   made the outputs with this file's settings (S_Run.toml)",
        "next run   S_Scene.txt cannot be written (permission denied): it is refused before it traces",
    ]
    scenario.measures_file.unlink()  # incomplete: but a run would not write the set again
    assert main(["validate", str(scenario.path)]) == 1
    lines = [x for x in capsys.readouterr().out.splitlines() if x.startswith(("last run", "next run"))]
    assert lines == [
        "last run   outputs incomplete: S.cmf missing",
        "next run   S_Scene.txt cannot be written (permission denied): it is refused before it traces",
    ]


def test_validate_reports_a_file_in_the_run_records_place_and_goes_on(scenario, capsys):
    """A file of the run record's name that is not one stopped validate with exit 2 and no
    summary, though the scenario is sound: only the next run is refused for it."""
    assert main(["run", str(scenario.path)]) == 0
    scenario.run_record.write_text("garbage [")
    capsys.readouterr()
    assert main(["validate", str(scenario.path)]) == 1
    out = capsys.readouterr().out
    assert out.startswith("scenario   ") and "memory     about" in out
    lines = [x for x in out.splitlines() if x.startswith(("last run", "next run"))]
    assert lines[0].startswith("last run   settings not read: ")
    assert lines[1:] == [
        "next run   S_Run.toml: exists and is not a run record of S.toml (a run writes its settings "
        "there): rename that file; the run is refused before it traces"
    ]


def test_a_step_flag_on_an_exact_run_does_not_make_its_outputs_out_of_date(scenario):
    simulate(scenario, step=0.25)  # the exact method takes no step
    ran = read_run_record(scenario)
    assert ran.same_outputs(scenario) and setting_changes(ran, scenario) == []
    marched = read_run_record(scenario).with_changes(method="march")
    assert not marched.same_outputs(scenario.with_changes(method="march"))


def test_no_save_replaces_a_run_record_and_a_record_saved_elsewhere_is_a_plain_scenario(scenario):
    from ladartui.errors import OutputFileError
    from ladartui.run_record import is_record

    simulate(scenario)
    record = scenario.path.with_name("S_Run.toml")
    before = record.read_bytes()
    with pytest.raises(OutputFileError) as caught:
        scenario.save(record)  # Save As onto the record: the next run would be refused
    assert "S_Run.toml" in str(caught.value) and "run record" in str(caught.value)
    ran = read_run_record(scenario)
    with pytest.raises(OutputFileError):
        ran.save()  # a record opened and saved in place would say what never ran
    assert record.read_bytes() == before
    copy = ran.save(scenario.path.with_name("T.toml"))
    assert not is_record(copy.path) and load_scenario(copy.path).same_outputs(scenario)


def test_validate_says_what_a_run_would_refuse_and_exits_1(scenario, capsys):
    theirs = scenario.path.with_name("S_Run.toml")
    theirs.write_text("# my own notes\n", encoding="utf-8")
    assert main(["validate", str(scenario.path)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[-1].startswith("next run   S_Run.toml: exists and is not a run record of S.toml")


def test_the_new_dialog_names_the_record_and_will_not_make_one_a_new_scenario(scenario):
    from ladartui.errors import FieldError

    simulate(scenario)
    names = dict(bridge.derived_names(scenario.path.with_name("N.toml"), scenario.scene_file))
    assert names["Run record (its settings)"] == "N_Run.toml"
    with pytest.raises(FieldError) as caught:
        bridge.new_scenario(scenario.path.with_name("S_Run.toml"), scenario.scene_file)
    assert "is a run record" in str(caught.value)


def test_validate_reports_a_damaged_record_on_its_line_and_still_passes(scenario, capsys):
    simulate(scenario)
    record = scenario.path.with_name("S_Run.toml")
    record.write_text(RECORD_HEADER + "\n[sensor\n", encoding="utf-8")
    assert main(["validate", str(scenario.path)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("last run"))
    assert line.startswith("last run   settings not read: ") and "S_Run.toml" in line
    record.unlink()  # removed since, or a set written before records existed: either may be
    assert main(["validate", str(scenario.path)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("last run"))
    assert line == (
        "last run   settings not recorded: no S_Run.toml beside the outputs "
        "(removed since, or written before runs kept records)"
    )


def test_validate_says_which_las_files_an_earlier_run_left(scenario, capsys):
    """run --las, then a run without: the LAS files beside the new set were the first
    run's, and nothing said so."""
    assert main(["run", str(scenario.path), "--las"]) == 0
    capsys.readouterr()
    assert main(["validate", str(scenario.path)]) == 0
    assert "LAS" not in capsys.readouterr().out  # this run's own
    assert main(["run", str(scenario.path), "--method", "march"]) == 0
    capsys.readouterr()
    assert main(["validate", str(scenario.path)]) == 0
    lines = [x for x in capsys.readouterr().out.splitlines() if x.startswith("last run")]
    assert lines[-1] == (
        "last run   wrote no LAS: S_Scene.las and S_Target.las are from an earlier run (run --las "
        "writes them again)"
    )


def test_a_segment_is_named_as_errors_name_it(scenario):
    """The record named the first segment 'flight.segments.1', errors 'flight.segments[0]'."""
    from ladartui.flight import FlightPlan, Manual

    simulate(scenario)
    ran = read_run_record(scenario)
    first = scenario.flight.segments[0]
    fewer = scenario.with_changes(flight=FlightPlan(segments=[Manual(first.poses[:1])]))
    changes = setting_changes(ran, fewer)
    assert changes and all(change.startswith("flight.segments[0].poses[1].") for change in changes), changes


def test_validate_says_a_set_a_killed_run_left_half_replaced(scenario, capsys):
    """With the swap's journal on disk the next run rolls the files back; validate
    described those files as the last run's."""
    from ladartui.simulation import output_lock

    assert main(["run", str(scenario.path)]) == 0
    lock = output_lock(scenario)
    lock.with_name(lock.name + ".journal").write_text("[]")
    capsys.readouterr()
    assert main(["validate", str(scenario.path)]) == 0
    lines = [x for x in capsys.readouterr().out.splitlines() if x.startswith("last run")]
    assert lines == [
        "last run   was stopped while it replaced the outputs: the next run puts the earlier set "
        "back first, so the files now on disk are not to be read"
    ]


def test_validate_says_a_run_is_writing_the_set_now(scenario, capsys):
    """While a run held the set (the TUI's or another ``ladartui run``), validate said
    nothing of it and exited 0, though a run started then is refused; and it told of
    that run's swap under way as of a run stopped part-way."""
    from ladartui.simulation import _output_set, output_lock

    assert main(["run", str(scenario.path)]) == 0
    capsys.readouterr()
    writing = f"another run (pid {os.getpid()}) is writing this output set now"
    with _output_set(scenario, las=False):
        assert main(["validate", str(scenario.path)]) == 1  # as for any run bound to be refused
        out = capsys.readouterr().out.splitlines()
        assert out[-1] == f"next run   {writing}: a run is refused until it ends"
        # the files on disk are still the earlier run's, and said as such
        assert "last run   made the outputs with this file's settings (S_Run.toml)" in out
        journal = output_lock(scenario).with_name(output_lock(scenario).name + ".journal")
        journal.write_text("[]")  # its swap under way
        assert main(["validate", str(scenario.path)]) == 1
        out = capsys.readouterr().out.splitlines()
        assert [x for x in out if x.startswith("last run")] == [
            f"last run   {writing}: until it ends the files on disk are part earlier, part new"
        ]
        journal.unlink()
    assert _last_run_lines(capsys, scenario) == [
        "last run   made the outputs with this file's settings (S_Run.toml)"
    ]


def test_the_look_at_a_runs_lock_never_waits_on_a_pipe(tmp_path):
    """validate asked whether a run held the set by opening its lock file to read: a
    pipe there left it waiting for ever after its summary."""
    import threading

    from ladartui.outputset import lock_holder

    pipe = tmp_path / ".case.outputs.lock"
    os.mkfifo(pipe)
    said = []
    looking = threading.Thread(target=lambda: said.append(lock_holder(pipe)), daemon=True)
    looking.start()
    looking.join(10)
    if looking.is_alive():  # (let the thread go: a writer ends its wait)
        os.close(os.open(pipe, os.O_WRONLY | os.O_NONBLOCK))
    assert said == [None]


@pytest.mark.parametrize("left", ["", "12345"])
def test_a_run_is_not_refused_for_a_look_at_its_lock(scenario, left):
    """validate's look takes the lock shared for a moment: a run that came to lock it
    then was refused as 'another run (pid ?) is writing this output set', and as 'pid
    12345' where a killed run had left its pid in the file."""
    import fcntl
    import threading

    from ladartui.simulation import _output_set, output_lock

    lock = output_lock(scenario)
    lock.parent.mkdir(parents=True, exist_ok=True)
    lock.write_text(left)
    fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)  # as the look finds it
    fcntl.flock(fd, fcntl.LOCK_SH)
    letting_go = threading.Timer(0.02, lambda: fcntl.flock(fd, fcntl.LOCK_UN))
    letting_go.start()
    try:
        with _output_set(scenario, las=False):
            assert lock.read_text() == str(os.getpid())
    finally:
        letting_go.join()
        os.close(fd)


def _last_run_lines(capsys, scenario) -> list[str]:
    capsys.readouterr()
    assert main(["validate", str(scenario.path)]) == 0
    return [x for x in capsys.readouterr().out.splitlines() if x.startswith("last run")]


def test_validate_names_a_model_file_changed_since_the_run(scenario, capsys):
    """The record held settings only: a scene model regenerated after the run still
    read 'made with this file's settings'."""
    simulate(scenario)
    assert _last_run_lines(capsys, scenario) == [
        "last run   made the outputs with this file's settings (S_Run.toml)"
    ]
    scene_model = scenario.scene_file
    scene_model.write_text(scene_model.read_text() + "0,0,9\n")
    assert _last_run_lines(capsys, scenario)[1:] == [
        "last run   the scene model woods.txt changed since the run"
    ]
    simulate(scenario)  # the next run records the file as it is now
    target_model = scenario.target_file
    target_model.write_text(target_model.read_text().replace("8,8,0\n", ""))
    assert _last_run_lines(capsys, scenario)[1:] == [
        "last run   the target model woods_Target.txt changed since the run"
    ]


def test_validate_names_a_flight_log_changed_since_the_run(scenario, capsys):
    from ladartui.flight import FlightPlan
    from ladartui.trajectory import LogSegment

    log = scenario.path.with_name("pass.csv")
    log.write_text("time,x,y,z,heading\n0,0,9,40,90\n2,20,9,40,90\n", encoding="utf-8")
    segment = LogSegment(file=str(log), times=(1.0,), aim_at=(9.5, 9.0, 0.5))
    flown = scenario.with_changes(flight=FlightPlan(segments=[*scenario.flight.segments, segment])).save()
    simulate(flown)
    assert _last_run_lines(capsys, flown) == [
        "last run   made the outputs with this file's settings (S_Run.toml)"
    ]
    log.write_text("time,x,y,z,heading\n0,0,9,40,90\n2,24,9,40,90\n", encoding="utf-8")
    assert _last_run_lines(capsys, flown)[1:] == ["last run   the flight log pass.csv changed since the run"]


def test_validate_names_an_output_changed_since_the_run_wrote_it(scenario, capsys):
    """Outputs overwritten after their run (echo x > S.cmf) still read 'made the outputs
    with this file's settings': the record fingerprinted the files read, not written."""
    import hashlib

    from ladartui.run_record import recorded_outputs

    simulate(scenario)
    recorded = {entry.role: entry for entry in recorded_outputs(scenario)}
    assert set(recorded) == {"scene output", "target output", "measures"}
    for entry in recorded.values():
        data = entry.path.read_bytes()
        assert (entry.fingerprint.size, entry.fingerprint.sha256) == (
            len(data),
            hashlib.sha256(data).hexdigest(),
        )
    assert _last_run_lines(capsys, scenario) == [
        "last run   made the outputs with this file's settings (S_Run.toml)"
    ]
    scenario.measures_file.write_text("x\n")
    scenario.scene_output.write_text("1,1,1\n")
    assert _last_run_lines(capsys, scenario)[1:] == [
        "last run   S_Scene.txt changed since the run wrote it: it is not the run's output",
        "last run   S.cmf changed since the run wrote it: it is not the run's output",
    ]
    simulate(scenario)  # the next run's are its own
    assert _last_run_lines(capsys, scenario)[1:] == []
    # one gone is missing (said as such), not 'changed since the run wrote it'
    from ladartui.run_record import outputs_changed

    scenario.target_output.unlink()
    assert outputs_changed(scenario) == []


def test_a_record_older_than_model_fingerprints_is_read_and_says_so(scenario, capsys):
    simulate(scenario)
    record = scenario.path.with_name("S_Run.toml")
    text = record.read_text(encoding="utf-8")
    record.write_text(text[: text.index("\n# The files the run read")] + "\n", encoding="utf-8")
    assert read_run_record(scenario).same_outputs(scenario)
    assert _last_run_lines(capsys, scenario) == [
        "last run   made the outputs with this file's settings (S_Run.toml)",
        "last run   the record does not say which model files the run read (written before records did)",
    ]


def test_the_record_fingerprints_the_bytes_the_run_read(scenario):
    """Size and SHA-256 of each model file as loaded: a scene loaded before the file
    changed is what the run used, so the record must not hash the file anew."""
    import hashlib

    from ladartui.run_record import recorded_inputs

    scene = scenario.load_scene()
    before = scenario.scene_file.read_bytes()
    scenario.scene_file.write_text(before.decode() + "0,0,9\n")
    simulate(scenario, scene=scene)
    read = {entry.role: entry for entry in recorded_inputs(scenario)}
    assert sorted(read) == ["scene model", "target model"]
    assert read["scene model"].path == scenario.scene_file
    assert read["scene model"].fingerprint.size == len(before)
    assert read["scene model"].fingerprint.sha256 == hashlib.sha256(before).hexdigest()


def test_only_a_record_may_hold_the_files_its_run_read(scenario):
    simulate(scenario)
    record = scenario.path.with_name("S_Run.toml").read_text(encoding="utf-8")
    scenario.path.write_text(record.split("\n", 1)[1], encoding="utf-8")  # without the record's first line
    with pytest.raises(LadarError, match=r"unknown section \[run\]"):
        load_scenario(scenario.path)
