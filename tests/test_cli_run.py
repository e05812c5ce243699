"""``ladartui run``: JSON and table output, --no-write, Ctrl-C, bad input."""

import json
import os

import numpy as np
import pytest

import ladartui.simulation as simulation
from cli_support import ctrl_c, one_error_line
from ladartui.cli import main
from ladartui.cmf import read_cmf
from ladartui.flight import FlightPlan, Manual, ScanPose, aim_at
from ladartui.scenario import Scenario
from ladartui.scene.voxels import save_voxels
from ladartui.sensor import Sensor


@pytest.fixture
def scenario(tmp_path):
    target = np.array(
        [(x, y, z) for x in range(8, 12) for y in range(8, 11) for z in range(2)], dtype=np.int32
    )
    canopy = np.array(
        [(x, y, 6) for x in range(6, 14) for y in range(6, 13) if (x + 2 * y) % 3], dtype=np.int32
    )
    save_voxels(tmp_path / "woods.txt", np.vstack([target, canopy]))
    save_voxels(tmp_path / "woods_Target.txt", target)
    poses = tuple(aim_at(ScanPose(x, y, 40.0), (9.5, 9.0, 0.5)) for x, y in [(9.5, -10.0), (29.5, 9.0)])
    return Scenario(
        tmp_path / "S.toml",
        "woods.txt",
        1.0,
        Sensor(grid=16, ray_grid=2, fov=20.0),
        FlightPlan(segments=[Manual(poses)]),
        backend="numba",
    ).save()


def test_json_output_and_files(scenario, capsys):
    assert main(["run", str(scenario.path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["backend"] == "numba" and out["scans"] == 2
    assert out["rays_per_scan"] == 32 * 32
    assert set(out["outputs"]) == {"scene", "target", "measures", "record"}
    measures = read_cmf(scenario.measures_file)
    assert out["measures"] == json.loads(json.dumps(measures.to_dict()))
    assert scenario.scene_output.is_file() and scenario.target_output.is_file()


def test_table_output_and_no_write(scenario, capsys):
    assert main(["run", str(scenario.path), "--no-write", "--method", "march", "--step", "0.25"]) == 0
    out = capsys.readouterr().out
    assert "Target coverage" in out and "Shift in mean direction" in out
    assert "numba (march, f64)" in out and "no scenario outputs written (--no-write)" in out
    assert not scenario.scene_output.exists() and not scenario.measures_file.exists()
    assert not scenario.path.with_name("S_Run.toml").exists()


def test_no_write_with_a_chart_says_truly_what_was_written(scenario, capsys):
    """It said 'wrote chart: c.svg' and then 'nothing written (--no-write)'."""
    chart = scenario.path.with_name("c.svg")
    assert main(["run", str(scenario.path), "--no-write", "--chart", str(chart)]) == 0
    out, err = capsys.readouterr()
    # with the run's other lines on stdout (it was on stderr), after what the run wrote
    assert out.endswith(f"no scenario outputs written (--no-write)\nwrote chart: {chart}\n")
    assert chart.is_file() and "chart" not in err
    assert "nothing written" not in out + err
    # --json keeps stdout JSON: the chart's line goes to stderr
    assert main(["run", str(scenario.path), "--no-write", "--json", "--chart", str(chart)]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["outputs"] == {} and err.endswith(f"wrote chart: {chart}\n")
    assert json.loads(out)["chart"] == str(chart)  # a script reads what was written from the JSON
    assert main(["run", str(scenario.path), "--no-write", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["chart"] is None
    assert not scenario.measures_file.exists()


def test_ctrl_c_cancels_and_keeps_earlier_outputs(scenario, capsys, monkeypatch):
    assert main(["run", str(scenario.path), "--json"]) == 0
    capsys.readouterr()
    files = [scenario.scene_output, scenario.target_output, scenario.measures_file]
    earlier = [p.read_bytes() for p in files]
    real_simulate = simulation.simulate

    def interrupted(*args, progress=None, cancel=None, **kwargs):
        def report(p):
            progress(p)
            if p.run == "target" and p.returns is not None:
                assert ctrl_c(cancel), "Ctrl-C did not set the cancel event"

        return real_simulate(*args, progress=report, cancel=cancel, **kwargs)

    monkeypatch.setattr(simulation, "simulate", interrupted)
    # A different method would change the outputs if they were written.
    assert main(["run", str(scenario.path), "--method", "march", "--step", "1.0"]) == 130
    assert "cancelled" in capsys.readouterr().err
    assert [p.read_bytes() for p in files] == earlier


def test_bad_input_is_one_line(tmp_path, capsys):
    assert main(["run", str(tmp_path / "missing.toml")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "missing.toml" in err and "no such file" in err


def test_bad_backend_is_one_line(scenario, capsys):
    assert main(["run", str(scenario.path), "--backend", "abacus", "--no-write"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "ladartui: error: --backend = 'abacus': expected one of 'auto', 'numba', 'wgpu'"


def test_bad_step_names_the_flag(scenario, capsys):
    for step in ("0", "1e-9"):  # (a march that fine ran without end)
        assert main(["run", str(scenario.path), "--step", step, "--no-write"]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1
        assert err.startswith(f"ladartui: error: --step = {float(step)!r}: expected")


def test_ctrl_c_after_the_run_wrote_its_outputs_says_what_it_wrote(scenario, capsys, monkeypatch):
    import ladartui.cli.run as cli_run

    real_show = cli_run.show_result

    def interrupted_while_showing(console, result, **options):
        real_show(console, result)
        raise KeyboardInterrupt  # as a Ctrl-C landing once the run had finished

    monkeypatch.setattr(cli_run, "show_result", interrupted_while_showing)
    assert main(["run", str(scenario.path)]) == 130
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err == (
        "ladartui: interrupted after the run had finished; it wrote "
        f"{scenario.scene_output}, {scenario.target_output}, {scenario.measures_file}, "
        f"{scenario.path.with_name('S_Run.toml')}"
    )
    assert scenario.measures_file.is_file()


def test_an_unwritable_chart_is_refused_before_anything_runs(scenario, capsys, tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    assert main(["run", str(scenario.path), "--chart", str(blocker / "c.svg")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"ladartui: error: --chart = '{blocker / 'c.svg'}': expected a writable path")
    assert not scenario.measures_file.exists() and not scenario.scene_output.exists()


@pytest.mark.parametrize("name", [".svg", "c.svg/.png", ".PNG"])
def test_a_chart_name_with_no_suffix_is_refused_before_anything_runs(scenario, capsys, tmp_path, name):
    """'.svg' ends in .svg but is a name with no suffix: the run traced and replaced its
    outputs, then the chart died with a ValueError traceback."""
    chart = tmp_path / name
    chart.parent.mkdir(exist_ok=True)
    for write in ([], ["--no-write"]):
        assert main(["run", str(scenario.path), "--chart", str(chart), *write]) == 2
        err = one_error_line(capsys)
        assert err == (
            f"ladartui: error: --chart = '{chart}': expected a file name ending in .svg or .png, "
            "a name before it"
        )
    assert not scenario.measures_file.exists() and not scenario.scene_output.exists()
    assert not chart.exists()


def test_a_name_the_fonts_cannot_draw_is_one_note_not_matplotlibs_warnings(
    scenario, capsys, tmp_path, recwarn
):
    """A CJK target name printed matplotlib's raw warnings with its source paths on
    stderr ('UserWarning: Glyph 28450 ... missing from font(s) DejaVu Sans.')."""
    target = np.loadtxt(tmp_path / "woods_Target.txt", delimiter=",", dtype=np.int32)
    save_voxels(tmp_path / "woods_Target.txt", target, ids=np.where(target[:, 0] < 10, 1, 2))
    with open(scenario.path, "a", encoding="utf-8") as handle:  # none of the chart's fonts has them
        handle.write('\n[targets]\nnames = { 1 = "\u6f22\u5b57", 2 = "truck B" }\n')
    chart = tmp_path / "c.png"
    assert main(["run", str(scenario.path), "--no-write", "--chart", str(chart)]) == 0
    out = capsys.readouterr().out
    # (pytest records warnings rather than print them: none recorded is none printed)
    assert chart.is_file() and [str(warning.message) for warning in recwarn] == []
    note = out.splitlines()[-1]
    assert note == "note: the chart draws a box for each of \u6f22, \u5b57: no font here has them"


def test_a_chart_in_a_missing_folder_is_refused_as_trace_refuses_its_out(scenario, capsys, tmp_path):
    """run --chart made the folders of a mistyped path (trace --out refuses it)."""
    chart = tmp_path / "chrats" / "c.svg"
    assert main(["run", str(scenario.path), "--chart", str(chart)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"ladartui: error: --chart = '{chart}': expected a file in an existing folder"
    assert not chart.parent.exists() and not scenario.measures_file.exists()


def test_a_chart_that_fails_after_the_run_says_the_outputs_were_written(scenario, capsys, monkeypatch):
    """A full disk at the chart said only '--chart: expected a writable path', with the
    run's four outputs already replaced and its measures never shown."""
    from ladartui import charts

    def full(figure, path):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(charts, "save_figure", full)
    chart = scenario.path.with_name("c.svg")
    assert main(["run", str(scenario.path), "--chart", str(chart)]) == 2
    captured = capsys.readouterr()
    assert "obscured" in captured.out.lower()  # the measures are shown
    err = captured.err.strip().splitlines()[-1]
    assert err.startswith(f"ladartui: error: {chart}: the chart was not written (no space left on device);")
    assert f"the run wrote {scenario.scene_output}" in err and scenario.measures_file.is_file()


def test_paths_with_markup_are_printed_as_they_are(tmp_path, capsys):
    from ladartui.flight import FlightPlan, Manual, ScanPose, aim_at

    folder = tmp_path / "a["
    folder.mkdir()
    target = np.array([(x, y, 0) for x in range(8, 12) for y in range(8, 11)], dtype=np.int32)
    save_voxels(folder / "woods.txt", target)
    save_voxels(folder / "woods_Target.txt", target)
    poses = (aim_at(ScanPose(9.5, -10.0, 40.0), (9.5, 9.0, 0.5)),)
    scenario = Scenario(
        folder / "bold]b.toml",  # the path holds "[/bold]": a closing tag to rich
        "woods.txt",
        1.0,
        Sensor(grid=8, ray_grid=1, fov=20.0),
        FlightPlan(segments=[Manual(poses)]),
        backend="numba",
    ).save()
    assert main(["run", str(scenario.path)]) == 0
    out = capsys.readouterr().out
    assert f"wrote measures: {scenario.measures_file}" in out.replace("\n", "")


def test_las_outputs_are_named_in_words(scenario, capsys):
    assert main(["run", str(scenario.path), "--las"]) == 0
    out = capsys.readouterr().out.replace("\n", "")
    assert f"wrote scene LAS: {scenario.scene_output.with_suffix('.las')}" in out
    assert f"wrote target LAS: {scenario.target_output.with_suffix('.las')}" in out


def test_a_run_without_las_names_the_las_copies_an_earlier_run_left(scenario, capsys):
    """Validate said the LAS copies were from an earlier run; the run that made them so did not."""
    assert main(["run", str(scenario.path), "--las"]) == 0
    capsys.readouterr()
    assert main(["run", str(scenario.path)]) == 0
    out = capsys.readouterr().out
    stem = scenario.path.stem
    assert out.splitlines()[-1] == (
        f"note: {stem}_Scene.las and {stem}_Target.las are from an earlier run, not this one "
        "(run --las writes them again)"
    )
    assert main(["run", str(scenario.path), "--las"]) == 0
    assert "earlier run" not in capsys.readouterr().out


def test_flags_the_run_would_ignore_or_round_are_refused(scenario, capsys):
    """--las with --no-write wrote nothing without a word; --max-rays 1.5 became 'the
    limit of 1'."""
    assert main(["run", str(scenario.path), "--las", "--no-write"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ladartui: error: --las: ") and "--no-write" in err
    assert main(["run", str(scenario.path), "--max-rays", "1.5"]) == 2
    assert "--max-rays = 1.5: expected a whole number of rays >= 1" in capsys.readouterr().err
    assert main(["run", str(scenario.path), "--max-rays", "-1"]) == 2  # not '-1.0'
    assert "--max-rays = -1: expected a whole number of rays >= 1" in capsys.readouterr().err
    assert not scenario.measures_file.exists()


def test_a_step_an_exact_run_would_ignore_is_refused(scenario, capsys):
    """--step 3 on an exact scenario traced exactly, without a word, and its record kept the
    step (trace refuses the same flags)."""
    assert main(["run", str(scenario.path), "--step", "3"]) == 2
    assert capsys.readouterr().err == (
        "ladartui: error: --step 3 sets the march's step, and this run is exact (the scenario's "
        "simulation.method): add --method march, or drop --step\n"
    )
    assert main(["run", str(scenario.path), "--method", "exact", "--step", "3"]) == 2
    assert "and this run is --method exact: add --method march" in capsys.readouterr().err
    assert not scenario.measures_file.exists()


def test_a_one_scan_run_and_its_summary_say_one_scan(scenario, capsys):
    """They said "1 scans x 1,024 rays" and "flight     1 scans: manual (1)"."""
    first = scenario.flight.segments[0].poses[:1]
    one = scenario.with_changes(flight=FlightPlan(segments=[Manual(first)])).save()
    assert main(["run", str(one.path), "--no-write"]) == 0
    assert "; 1 scan x 1,024 rays, two runs, in " in capsys.readouterr().out
    assert main(["validate", str(one.path)]) == 0
    assert "\nflight     1 scan: manual (1)\n" in capsys.readouterr().out


def test_a_precision_the_backend_lacks_is_named_in_the_summary_and_json(scenario, capsys):
    """--precision f32 on numba (no f32 kernels) traced in f64 and said only 'numba (exact)';
    the JSON had no precision (trace says 'f64, not the f32 asked for')."""
    assert main(["run", str(scenario.path), "--no-write", "--precision", "f32"]) == 0
    assert "backend: numba (exact, f64, not the f32 asked for); 2 scans x" in capsys.readouterr().out
    assert main(["run", str(scenario.path), "--no-write", "--precision", "f32", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["precision"] == "f64"
    assert main(["run", str(scenario.path), "--no-write"]) == 0
    assert "backend: numba (exact, f64); 2 scans x" in capsys.readouterr().out
    # an f32 run said only "wgpu (exact)", as if it were the default f64
    assert main(["run", str(scenario.path), "--no-write", "--backend", "wgpu", "--precision", "f32"]) == 0
    assert "backend: wgpu (exact, f32); 2 scans x" in capsys.readouterr().out


def test_the_bar_names_compiling_only_when_the_cache_lacks_the_kernels(scenario, monkeypatch):
    """Every run's bar said 'compiling kernels on a first run' until its first scan,
    with the kernels cached too."""
    from rich.progress import Progress

    from ladartui import precompile
    from ladartui.cli.progress import FIRST_SCAN, first_scan

    assert main(["run", str(scenario.path), "--no-write"]) == 0  # the kernels are cached now
    started = []
    real = Progress.add_task

    def add_task(self, description, *args, **kwargs):
        started.append(description)
        return real(self, description, *args, **kwargs)

    monkeypatch.setattr(Progress, "add_task", add_task)
    assert main(["run", str(scenario.path), "--no-write"]) == 0
    assert started == ["scan 1"]  # what the bar says until the first scan is done
    monkeypatch.setattr(precompile, "kernels_cached", lambda scenario: False)
    assert first_scan(scenario) == FIRST_SCAN == "scan 1 (compiling kernels on a first run)"


def test_a_scene_model_refused_in_setting_up_leaves_no_progress_line(scenario, capsys):
    """A bad line in the scene model printed 'scan 1  0.0 %' above the error."""
    with open(scenario.scene_file, "a", encoding="utf-8") as handle:
        handle.write("1,2\n")
    assert main(["run", str(scenario.path)]) == 2
    err = one_error_line(capsys)
    assert "1,2" in err and "expected three non-negative integers" in err


@pytest.mark.parametrize("refusal", ["another run", "bad model line"])
def test_a_run_refused_while_another_writes_the_set_says_one_line_alone(scenario, capsys, refusal):
    """Two runs of one scenario from a batch script, stderr to a log: the one refused
    wrote a blank line (the hidden bar's last frame) above its error, as did a run
    refused for its scene model's bad line."""
    from ladartui.simulation import _output_set

    if refusal == "bad model line":
        with open(scenario.scene_file, "a", encoding="utf-8") as handle:
            handle.write("1,2\n")
        assert main(["run", str(scenario.path), "--json"]) == 2
        said = "expected three non-negative integers"
    else:
        with _output_set(scenario, False):  # 75, EX_TEMPFAIL: a script may try again later
            assert main(["run", str(scenario.path), "--json"]) == 75
        said = "is writing this output set"
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("ladartui: error: "), repr(captured.err)
    assert captured.err.count("\n") == 1 and said in captured.err


def test_a_run_of_a_set_being_written_is_refused_before_compiling_or_loading(scenario, capsys, monkeypatch):
    """A second run of one scenario compiled the kernels (minutes on a fresh clone) and
    loaded the scene before it was told another run was writing the set."""
    from ladartui import precompile
    from ladartui.simulation import _output_set

    started = []
    monkeypatch.setattr(precompile, "compile_ahead", lambda *args, **kwargs: started.append(args))
    with _output_set(scenario, False):
        assert main(["run", str(scenario.path), "--json"]) == 75
    err = one_error_line(capsys)
    assert err.endswith("is writing this output set; wait for it to finish") and not started
    assert f"another run (pid {os.getpid()})" in err


def _aimed_away(scenario):
    """The scenario with a lone tree 50 m from the target, its two scans aimed at it."""
    import dataclasses

    from ladartui.scene.voxels import load_voxels

    scene = load_voxels(scenario.scene_file)
    save_voxels(scenario.scene_file, np.vstack([scene, np.array([(60, 60, 6)], np.int32)]))
    poses = tuple(aim_at(ScanPose(x, 50.0, 40.0), (60.5, 60.5, 6.5)) for x in (58.0, 62.0))
    return dataclasses.replace(scenario, flight=FlightPlan(segments=[Manual(poses)])).save()


def test_a_run_whose_scans_never_look_at_the_target_says_so(scenario, capsys):
    """Such a run printed 0.0 % coverage and nothing more; validate said why, run did not."""
    from ladartui.view_reach import reach_notes

    scenario = _aimed_away(scenario)
    (expected,) = reach_notes(scenario, scenario.load_scene())
    assert "at the target" in expected
    assert main(["run", str(scenario.path), "--no-write"]) == 0
    said = capsys.readouterr()
    assert f"note: {expected}" in " ".join((said.out + said.err).split())


def test_a_json_run_gives_its_notes_and_keeps_stdout_json(scenario, capsys):
    from ladartui.view_reach import reach_notes

    assert main(["run", str(scenario.path), "--json", "--no-write"]) == 0
    assert json.loads(capsys.readouterr().out)["notes"] == []  # its scans look at the target
    scenario = _aimed_away(scenario)
    assert main(["run", str(scenario.path), "--json", "--no-write"]) == 0
    said = capsys.readouterr()
    assert json.loads(said.out)["notes"] == reach_notes(scenario, scenario.load_scene())


def test_a_run_under_columns_0_still_shows_its_measures(tmp_path, capsys, monkeypatch):
    """COLUMNS=0 (exported where 0 is taken to mean no limit) made rich's width 0: the
    run printed nothing at all, not even its 'backend:' line, and exited 0."""
    from ladartui.cli.console import CliConsole

    monkeypatch.setenv("COLUMNS", "0")
    assert CliConsole().width == 80  # as rich takes a terminal that reports no size
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    assert main(["run", "default", "--no-write"]) == 0
    out = capsys.readouterr().out
    assert "Target coverage" in out and "backend: " in out and "no scenario outputs written" in out
