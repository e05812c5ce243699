"""Scenario files given things they cannot hold: quoted keys, a pipe for a file, target
names that are no table. Each is one line naming the file and line, never a hang."""

from pathlib import Path

import pytest

from ladartui.errors import FieldError, InputFileError
from ladartui.scenario import load_scenario


@pytest.mark.parametrize("key", ['"a[b"', '"[bold red]key"', '"x.y"'])
def test_a_quoted_unknown_key_is_named_on_its_line_and_does_not_hang(tmp_path, key):
    """A quoted key holding '[' sent the line finder into an endless loop."""
    import threading

    orbit = Path(__file__).resolve().parent.parent / "scenarios" / "orbit.toml"
    path = tmp_path / "s.toml"
    text = orbit.read_text().replace("[simulation]\n", f"[simulation]\n{key} = 1\n", 1)
    path.write_text(text)
    line = text.splitlines().index(f"{key} = 1") + 1
    raised = []

    def load():
        try:
            load_scenario(path, check_files=False)
        except InputFileError as error:
            raised.append(str(error))

    worker = threading.Thread(target=load, daemon=True)
    worker.start()
    worker.join(20)
    assert not worker.is_alive(), "load_scenario hung"
    assert raised and raised[0].startswith(f"{path}:{line}: unknown key"), raised


def test_a_pipe_given_as_a_scenario_or_model_is_named_not_waited_on(tmp_path):
    """validate and info blocked for ever reading a FIFO; a FIFO scene said 'not found'."""
    import os
    import threading

    from ladartui.fileprobe import file_problem

    pipe = tmp_path / "s.toml"
    os.mkfifo(pipe)
    said = []

    def load():
        try:
            load_scenario(pipe)
        except InputFileError as error:
            said.append(str(error))

    worker = threading.Thread(target=load, daemon=True)
    worker.start()
    worker.join(10)
    assert not worker.is_alive(), "load_scenario waited on the pipe"
    assert said == [f"{pipe}: is not a regular file (a pipe or device); expected a scenario file (.toml)"]
    assert file_problem(pipe) == "is not a regular file (a pipe or device)"


@pytest.mark.parametrize("names", ['""', "[]", "3"])
def test_target_names_that_are_no_table_are_refused(tmp_path, names):
    """names = "" and names = [] passed validate as no names at all."""
    from tiny_sweep import write_tiny_scenario

    scenario = write_tiny_scenario(tmp_path)
    text = scenario.path.read_text(encoding="utf-8") + f"\n[targets]\nnames = {names}\n"
    scenario.path.write_text(text, encoding="utf-8")
    with pytest.raises(FieldError) as caught:
        load_scenario(scenario.path)
    line = text.splitlines().index(f"names = {names}") + 1
    assert str(caught.value).startswith(f"{scenario.path}:{line}: targets.names = ")


def test_a_flight_log_named_relative_to_the_working_folder_is_saved_where_it_lies(tmp_path, monkeypatch):
    """A LogSegment given 'log.csv' in a script was read from the working folder, but a
    scenario saved elsewhere wrote file = "log.csv", which reads from the scenario's
    folder: the saved file named a log that is not there."""
    from ladartui.flight import FlightPlan
    from ladartui.scenario import Scenario
    from ladartui.sensor import Sensor
    from ladartui.trajectory import LogSegment
    from scenario_support import write_models

    work = tmp_path / "work"
    work.mkdir()
    (work / "log.csv").write_text("time,x,y,z,heading\n0,0,0,50,90\n1,30,0,50,90\n")
    scene = write_models(tmp_path / "models")
    monkeypatch.chdir(work)
    segment = LogSegment("log.csv", rate=1.0)
    assert segment.file == str(work / "log.csv")
    scenario = Scenario(
        tmp_path / "plans" / "s.toml", scene, 1.0, Sensor(grid=4), FlightPlan(None, (segment,))
    )
    scenario.save()
    assert 'file = "../work/log.csv"' in scenario.path.read_text()
    monkeypatch.chdir(tmp_path)
    again = load_scenario(scenario.path)
    assert again.flight.segments[0].file == str(work / "log.csv")
    assert again.poses() == scenario.poses()


def test_a_model_file_named_in_other_unicode_code_points_is_pointed_to(tmp_path):
    """'scène.txt' in the scenario (é one code point), 'scène.txt' on disk copied from a
    Mac (e and a combining accent): 'not found' named a file ls shows right there."""
    import shutil
    import unicodedata

    orbit = Path(__file__).resolve().parent.parent / "scenarios" / "orbit.toml"
    text = orbit.read_text()
    start = text.index('scene = "') + len('scene = "')
    written = text[start : text.index('"', start)]
    path = tmp_path / "s.toml"
    path.write_text(text.replace(f'scene = "{written}"', 'scene = "scène.txt"', 1))
    decomposed = unicodedata.normalize("NFD", "scène.txt")
    assert decomposed != "scène.txt"
    shutil.copy(orbit, tmp_path / decomposed)
    with pytest.raises(InputFileError) as caught:
        load_scenario(path)
    said = str(caught.value)
    assert f"scene model file {tmp_path / 'scène.txt'} not found (files.scene)" in said
    assert (
        "\n" not in said
        and f"the folder holds {decomposed}, the same name in other Unicode code points" in said
    )
    (tmp_path / decomposed).unlink()
    with pytest.raises(InputFileError) as caught:
        load_scenario(path)
    assert "Unicode" not in str(caught.value)  # nothing like it there: not found, alone


def test_a_flight_log_or_scenario_file_named_in_other_unicode_code_points_is_pointed_to(tmp_path):
    """'vol-é.csv' in the scenario, copied from a Mac as e and a combining accent: the
    flight log, and the scenario file itself, said a bare 'not found' for a file that
    ls shows right there, where the scene model pointed to it."""
    import shutil
    import unicodedata

    from ladartui.scenario import scenario_from_toml

    folder = Path(__file__).resolve().parent.parent / "scenarios"
    decomposed = unicodedata.normalize("NFD", "vol-é.csv")
    assert decomposed != "vol-é.csv"
    shutil.copy(folder / "flight-log.csv", tmp_path / decomposed)
    shutil.copy(folder / "orbit.toml", tmp_path / unicodedata.normalize("NFD", "é.toml"))
    hint = "the same name in other Unicode code points"
    text = '[files]\nscene = "s.txt"\n[[flight.segments]]\nkind = "log"\nfile = "vol-é.csv"\nrate = 2.0\n'
    with pytest.raises(FieldError) as caught:
        scenario_from_toml(text, tmp_path / "s.toml")
    said = str(caught.value)
    assert "\n" not in said and "not found" in said and f"the folder holds {decomposed}, {hint}" in said
    with pytest.raises(InputFileError) as caught:
        load_scenario(tmp_path / "é.toml")
    said = str(caught.value)
    assert said.startswith(f"{tmp_path / 'é.toml'}: no such file; the folder holds ")
    assert "\n" not in said and hint in said and said.endswith("expected a scenario file (.toml)")
    (tmp_path / decomposed).unlink()
    with pytest.raises(FieldError) as caught:
        scenario_from_toml(text, tmp_path / "s.toml")
    assert "not found" in str(caught.value) and "Unicode" not in str(caught.value)
