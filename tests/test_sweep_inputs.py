"""Sweeps given inputs that changed or are wrong: an edited base or model, bad budgets,
ranges and keys, a file for a results folder (--show: test_sweep_show.py)."""

import math

import pytest

from cli_support import one_error_line
from ladartui.errors import FieldError, InputFileError
from ladartui.sweep import load_sweep_results, load_sweep_spec, run_sweep
from tiny_sweep import tiny_folder, write_spec, write_tiny_scenario


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    return tiny_folder(tmp_path_factory)


@pytest.mark.parametrize("model", ["tiny.txt", "tiny_Target.txt"])
def test_a_changed_model_file_runs_every_variant_again(tmp_path, model):
    """A resumed sweep reused rows made from an earlier scene or target model: the
    check read the scene's name and size only, and no part of the target model."""
    write_tiny_scenario(tmp_path)  # its own models: this test changes one
    spec = write_spec(tmp_path, "[grid]\nradius = [20.0, 30.0]\n", name="models.toml")
    out = tmp_path / "out"
    assert run_sweep(spec, serial=True, out=out).ran == 2
    path = tmp_path / model
    text = path.read_text(encoding="utf-8")
    assert "\n14,15,1\n" in text
    # the same size, another voxel: one of the vehicle's raised by two
    path.write_text(text.replace("\n14,15,1\n", "\n14,15,3\n"), encoding="utf-8")
    again = run_sweep(spec, serial=True, out=out)
    assert (again.ran, again.resumed) == (2, 0)


def test_a_range_of_too_many_values_is_refused_on_its_line_even_past_float_range(tmp_path):
    write_tiny_scenario(tmp_path)
    body = "[grid]\naltitude = { start = 0.0, stop = 1e300, step = 1e-300 }\n"
    spec = write_spec(tmp_path, body, name="huge.toml")
    with pytest.raises(InputFileError, match=r"huge\.toml:4: grid\.altitude: expected at most 100000 values"):
        load_sweep_spec(spec)


@pytest.mark.parametrize("budget", [-1.0, 0.0, math.nan, math.inf, "abc", True])
def test_run_sweep_refuses_a_budget_that_is_no_positive_number(tiny, tmp_path, budget):
    from ladartui.errors import FieldError

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="budget.toml")
    with pytest.raises(FieldError, match=r"^budget.*expected a flight-time budget in seconds, > 0"):
        run_sweep(spec, serial=True, out=tmp_path / "o", objective="coverage-within-budget", budget=budget)
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    "options, message",
    [
        ({"backend": "cuda"}, r"^simulation\.backend = 'cuda': expected one of"),
        ({"step": -1.0}, r"^simulation\.step = -1\.0: expected"),
        ({"write": True}, r"^simulate_options = \{'write': True\}: expected a dict of backend, method"),
        (["numba"], r"^simulate_options = \['numba'\]: expected a dict of backend, method"),
    ],
)
def test_run_sweep_refuses_bad_simulate_options_before_any_variant(tiny, tmp_path, options, message):
    """Every variant became an error row that a later sweep, with good options, skipped."""
    from ladartui.errors import FieldError

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="options.toml")
    with pytest.raises(FieldError, match=message):
        run_sweep(spec, serial=True, out=tmp_path / "o", simulate_options=options)
    assert not (tmp_path / "o").exists()
    assert run_sweep(spec, serial=True, out=tmp_path / "o", simulate_options={"backend": "numba"}).ran == 1


@pytest.mark.parametrize(
    "arguments, message",
    [
        (dict(progress=3), r"^progress = 3: expected a function"),
        (dict(cancel=True), r"^cancel = True: expected"),
    ],
)
def test_run_sweep_refuses_a_progress_or_cancel_of_the_wrong_kind_first(tiny, tmp_path, arguments, message):
    from ladartui.errors import FieldError

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="callbacks.toml")
    with pytest.raises(FieldError, match=message):
        run_sweep(spec, serial=True, out=tmp_path / "o", **arguments)
    assert not (tmp_path / "o").exists()


def test_a_numpy_number_is_a_budget():
    import numpy as np

    from ladartui.sweep.execute import checked_budget

    assert checked_budget(np.int64(30)) == 30.0 and checked_budget(np.float32(2.5)) == 2.5


def test_run_sweep_names_a_file_given_as_its_results_folder(tiny, tmp_path):
    from ladartui.errors import OutputFileError

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="outfile.toml")
    with pytest.raises(OutputFileError, match="is a file, expected a folder"):
        run_sweep(spec, serial=True, out=spec)


def test_the_cli_refuses_an_infinite_budget_before_running(tiny, tmp_path, capsys):
    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="inf.toml")
    args = ["sweep", str(spec), "--serial", "--objective", "coverage-within-budget", "--budget", "inf"]
    assert main([*args, "--json", "--out", str(tmp_path / "o")]) == 2
    assert "--budget" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    "text, line",
    [
        ('[sweep]\nscenario = "base.toml"\n[grid]\n\'radius\' = [20.0, "x"]\n', 4),  # single-quoted
        ('[sweep]\nscenario = "base.toml"\n[grid]\n"radius" = [20.0, "x"]\n', 4),
        ('grid.radius = [20.0, "x"]\n[sweep]\nscenario = "base.toml"\n', 1),  # dotted, before any table
    ],
)
def test_a_bad_value_is_named_on_its_own_line_however_its_key_is_written(tmp_path, text, line):
    write_tiny_scenario(tmp_path)
    spec = tmp_path / "keys.toml"
    spec.write_text(text, encoding="utf-8")
    with pytest.raises(InputFileError, match=rf"keys\.toml:{line}: grid\.radius"):
        load_sweep_spec(spec)


def test_a_bad_value_after_a_comment_holding_a_line_separator_is_named_on_its_own_line(tmp_path):
    """U+2028 in a comment counted as a line break: the error named line 5 for line 4."""
    write_tiny_scenario(tmp_path)
    spec = tmp_path / "spec.toml"
    spec.write_text('[sweep]  # radius\u2028sweep\nscenario = "base.toml"\n[grid]\nradius = [20.0, "x"]\n')
    with pytest.raises(InputFileError, match=r"spec\.toml:4: grid\.radius"):
        load_sweep_spec(spec)


def test_a_variant_refused_by_this_machines_limits_runs_again_on_resume(tmp_path, monkeypatch):
    """A ray limit refusal was stored as an impossible value ('error'), never run again,
    though the limit belongs to the machine, not to the variant."""
    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nscans = [2, 40]\n", name="limits.toml")
    monkeypatch.setenv("LADARTUI_MAX_RAYS", "5000")  # the base: 2,048 rays; 40 scans: 20,480
    first = run_sweep(spec, serial=True, out=tmp_path / "o")
    refused = [row for row in first.rows if row["status"] != "ok"]
    assert len(refused) == 1 and refused[0]["status"] == "failed" and "limit" in refused[0]["error"]
    # the advice a sweep can follow: it has no --max-rays, its workers read the variable
    assert "--max-rays" not in refused[0]["error"] and "LADARTUI_MAX_RAYS" in refused[0]["error"]
    assert not first.impossible
    monkeypatch.delenv("LADARTUI_MAX_RAYS")
    again = run_sweep(spec, serial=True, out=tmp_path / "o")
    assert (again.ran, again.resumed) == (1, 1) and all(row["status"] == "ok" for row in again.rows)


def test_a_base_over_the_ray_limit_can_be_swept_down_to_variants_under_it(tmp_path, monkeypatch):
    """The base was refused for the limit before any variant was built, though no
    variant flies the base's own 4 scans: the limit is each variant's."""
    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nscans = [2, 3]\n", name="down.toml")
    monkeypatch.setenv("LADARTUI_MAX_RAYS", "1300")  # 256 rays a scan, two runs: 2 scans 1,024
    result = run_sweep(spec, serial=True, out=tmp_path / "o")
    status = {row["scans"]: (row["status"], row["error"]) for row in result.rows}
    assert status[2][0] == "ok"
    assert (
        status[3][0] == "failed" and "1.54e+03 rays" in status[3][1] and "LADARTUI_MAX_RAYS" in status[3][1]
    )


def test_a_spec_refused_for_the_ray_limit_says_so_when_other_variants_are_impossible(tmp_path, monkeypatch):
    """Of 'sensor_grid = [0, 64]' over the limit, the refusal named the impossible 0 alone:
    dropping it, the analyst met the limit that had stopped the 64 all along."""
    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nsensor_grid = [0, 64]\n", name="mixed.toml")
    monkeypatch.setenv("LADARTUI_MAX_RAYS", "5000")  # 64 x 64 detectors, 4 scans: 131,072 rays
    with pytest.raises(InputFileError) as refused:
        run_sweep(spec, serial=True, out=tmp_path / "o")
    message = str(refused.value)
    assert "mixed.toml:4: grid.sensor_grid: no variant can run: " in message
    assert "1.31e+05 rays" in message and "LADARTUI_MAX_RAYS" in message
    assert "sensor_grid = 0" not in message and not (tmp_path / "o").exists()


def test_a_spec_over_the_ray_limit_is_named_on_what_makes_its_rays(tmp_path, monkeypatch):
    """Over the ray limit, 'grid.radius: no variant can run' blamed the first parameter
    written, which adds no ray; the sensor grid does."""
    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [20.0, 30.0]\nsensor_grid = [64]\n", name="rays.toml")
    monkeypatch.setenv("LADARTUI_MAX_RAYS", "5000")
    with pytest.raises(InputFileError) as refused:
        run_sweep(spec, serial=True, out=tmp_path / "o")
    assert "rays.toml:5: grid.sensor_grid: no variant can run: " in str(refused.value)


def test_a_spec_file_name_that_cannot_name_the_best_path_file_asks_for_sweep_name(tmp_path):
    """'my sweep.toml' was refused as 'sweep.name: ... (got 'my sweep')', a key not in the
    file: the default comes from the file name, which the message now says."""
    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nscans = [2]\n", name="my sweep.toml")
    with pytest.raises(InputFileError) as caught:
        load_sweep_spec(spec)
    assert str(caught.value) == (
        f"{spec}:1: sweep.name: expected a file-name stem of letters, digits, '.', '_' or '-' to "
        "name the best-path scenario file: the spec's file name 'my sweep' is not one, so set sweep.name"
    )
    spec.write_text(spec.read_text().replace("[grid]", 'name = "my-sweep"\n[grid]'), encoding="utf-8")
    assert load_sweep_spec(spec).name == "my-sweep"
    spec.write_text(spec.read_text().replace('"my-sweep"', '"../up"'), encoding="utf-8")
    with pytest.raises(InputFileError, match=r":3: sweep\.name: .* \(got '\.\./up'\)$"):
        load_sweep_spec(spec)


@pytest.mark.parametrize("mode", ["--serial", "--show"])
def test_a_budget_for_an_objective_that_uses_none_is_refused(tiny, tmp_path, capsys, mode):
    """--budget 5 under coverage-per-km was taken and ignored: that ranking has no budget."""
    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="budget.toml")
    args = ["sweep", str(spec), mode, "--objective", "coverage-per-km", "--budget", "5"]
    assert main([*args, "--out", str(tmp_path / "o")]) == 2
    assert one_error_line(capsys) == (
        "ladartui: error: --budget = 5.0: expected no --budget with objective 'coverage-per-km' "
        "(only coverage-within-budget and identified-within-budget use a budget)"
    )
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("flag", "value", "expected"),
    [
        ("--objective", "coverage", "one of obscured-coverage, coverage-per-km, "),
        ("--cost", "miles", "one of flight-time, distance"),
    ],
)
def test_a_bad_objective_or_cost_flag_is_named_as_the_flag(tiny, tmp_path, capsys, flag, value, expected):
    """The errors said 'objective = ...' and 'cost = ...', a key the spec has, not the flag typed."""
    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="flags.toml")
    assert main(["sweep", str(spec), "--serial", flag, value, "--out", str(tmp_path / "o")]) == 2
    assert one_error_line(capsys).startswith(f"ladartui: error: {flag} = {value!r}: expected {expected}")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: load_sweep_spec(None), "path is not set: expected a sweep spec file's path"),
        (lambda: load_sweep_spec(123), "path = 123: expected a sweep spec file's path"),
        (
            lambda: run_sweep(None, serial=True),
            "spec is not set: expected a SweepSpec or a sweep spec file's path",
        ),
        (
            lambda: load_sweep_results(None),
            "path is not set: expected a sweep's results folder or its results.csv",
        ),
    ],
)
def test_a_path_that_is_no_path_is_a_field_error(call, message):
    # They raised TypeError from pathlib.
    with pytest.raises(FieldError) as caught:
        call()
    assert str(caught.value) == f"{message} (str or pathlib.Path)"


def _straight_base(folder):
    """The tiny scenario flown along a straight line: no orbit, fly-past or standoff to vary."""
    from ladartui.flight import FlightPlan, ScanPose, Straight

    base = write_tiny_scenario(folder)
    start = ScanPose(0.0, 15.5, 20.0, heading=90.0, depression=45.0)
    flight = FlightPlan(start=start, segments=(Straight(distance=30.0, scans=3),))
    return base.with_changes(flight=flight).save()


@pytest.mark.parametrize(
    ("body", "key", "line"),
    [
        ("[grid]\naltitude = [40.0, 50.0]\n", "grid.altitude", 4),
        ("[random]\nsamples = 2\nradius = { min = 5.0, max = 9.0 }\n", "random.radius", 5),
        ('[grid]\npreset = ["orbit"]\nradius = [9.0]\n', "grid.preset", 4),
        ("[grid]\nsensor_grid = [0]\n", "grid.sensor_grid", 4),
    ],
)
def test_a_spec_no_variant_of_which_can_run_is_refused_before_anything_runs(tmp_path, body, key, line):
    """Flight parameters over a base with nothing to vary made every variant an error
    row, after a cluster started; docs/sweeps.md promises a refusal on the key's line."""
    _straight_base(tmp_path)
    spec = write_spec(tmp_path, body)
    with pytest.raises(InputFileError) as refused:
        run_sweep(spec, serial=True, out=tmp_path / "out")
    message = str(refused.value)
    assert f"spec.toml:{line}: {key}: no variant can run: " in message
    assert "\n" not in message and not (tmp_path / "out").exists()


def test_a_spec_whose_some_variants_are_impossible_still_runs(tiny, tmp_path):
    spec = write_spec(tiny, "[grid]\nsensor_grid = [0, 4]\n", name="some.toml")
    result = run_sweep(spec, serial=True, out=tmp_path / "out")
    assert sorted(r["status"] for r in result.rows) == ["error", "ok"]


def test_the_cli_refuses_a_spec_no_variant_of_which_can_run_before_its_progress(tmp_path, capsys):
    from ladartui.cli import main

    _straight_base(tmp_path)
    spec = write_spec(tmp_path, "[grid]\naltitude = [40.0, 50.0]\n")
    assert main(["sweep", str(spec), "--serial"]) == 2
    out, err = capsys.readouterr()
    assert "spec.toml:4: grid.altitude: no variant can run" in err and "sweep of" not in out + err


def test_a_refusal_for_a_field_the_spec_does_not_name_blames_the_parameter_varied(tmp_path):
    """An aim point above every altitude tried was blamed on sweep.scenario (line 2)."""
    from ladartui.flight import FlightPlan, Orbit

    base = write_tiny_scenario(tmp_path)
    orbit = Orbit(centre=(15.5, 15.5, 0.5), radius=20.0, altitude=20.0, scans=4, aim_at=(15.5, 15.5, 10.0))
    base.with_changes(flight=FlightPlan(segments=(orbit,))).save()
    spec = write_spec(tmp_path, "[grid]\naltitude = [5.0, 8.0]\n")
    with pytest.raises(InputFileError) as refused:
        run_sweep(spec, serial=True, out=tmp_path / "out")
    assert "spec.toml:4: grid.altitude: no variant can run: " in str(refused.value)


def test_a_preset_over_a_scene_without_a_target_names_its_target_model(tmp_path):
    """It read 'no variant can run: scene 'base' has no target voxels', naming the base
    scenario as a scene; the scene is tiny.txt and its empty target model tiny_Target.txt."""
    _straight_base(tmp_path)
    (tmp_path / "tiny_Target.txt").write_text("", encoding="utf-8")
    spec = write_spec(tmp_path, '[grid]\npreset = ["orbit"]\nradius = [9.0]\naltitude = [20.0]\n')
    with pytest.raises(InputFileError) as refused:
        run_sweep(spec, serial=True, out=tmp_path / "out")
    assert str(refused.value) == (
        f"{spec}:4: grid.preset: no variant can run: scene 'tiny' has no target voxels "
        f"({tmp_path / 'tiny_Target.txt'} is empty)"
    )


def test_the_check_reads_the_target_model_not_the_scene(tmp_path, monkeypatch):
    """The CLI's check loaded the whole scene again for each variant that failed, and a
    good spec's scene twice."""
    from ladartui.cli import main
    from ladartui.scenario import Scenario

    _straight_base(tmp_path)
    loads = []
    real = Scenario.load_scene
    monkeypatch.setattr(Scenario, "load_scene", lambda self: loads.append(1) or real(self))
    bad = write_spec(tmp_path, '[grid]\npreset = ["orbit", "flypast"]\nradius = [5.0, 6.0]\n')
    assert main(["sweep", str(bad), "--serial", "--out", str(tmp_path / "bad")]) == 2
    assert loads == []
    good = write_spec(
        tmp_path, '[grid]\npreset = ["orbit"]\nradius = [9.0]\naltitude = [20.0]\nscans = [2]\n', "good.toml"
    )
    assert main(["sweep", str(good), "--serial", "--out", str(tmp_path / "good"), "--json"]) == 0
    assert loads == [1]  # the sweep's own


def test_the_cli_checks_the_variants_and_loads_the_base_once(tiny, tmp_path, monkeypatch):
    """The CLI loaded the base and checked the spec's variants before the cluster
    started, and run_sweep did both again."""
    from ladartui import scenario as scenario_module
    from ladartui.cli import main
    from ladartui.sweep import base, execute

    checks, loads = [], []
    real_check, real_load = base.check_some_variant_runs, scenario_module.load_scenario

    def check(spec, scenario):
        checks.append(spec.path)
        return real_check(spec, scenario)

    def load(path, *args, **options):
        loads.append(path)
        return real_load(path, *args, **options)

    monkeypatch.setattr(base, "check_some_variant_runs", check)
    monkeypatch.setattr(execute, "check_some_variant_runs", check, raising=False)
    monkeypatch.setattr(scenario_module, "load_scenario", load)
    spec = write_spec(tiny, "[grid]\nradius = [20.0, 30.0]\n", name="once.toml")
    assert main(["sweep", str(spec), "--serial", "--out", str(tmp_path / "out"), "--json"]) == 0
    assert checks == [spec]
    assert loads.count(tiny / "base.toml") == 1


def test_the_cli_exits_non_zero_when_no_variant_finished(tmp_path, monkeypatch, capsys):
    """Every variant failed (its backend unavailable): an empty ranking, exit 0. A spec
    whose every variant is over the ray limit is refused first, with a sweep's advice."""
    from ladartui import simulation
    from ladartui.cli import main
    from ladartui.errors import BackendUnavailable

    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nscans = [40, 41]\n", name="none.toml")
    monkeypatch.setenv("LADARTUI_MAX_RAYS", "5000")
    assert main(["sweep", str(spec), "--serial"]) == 2
    err = capsys.readouterr().err
    assert "no variant can run" in err and "--max-rays" not in err and "LADARTUI_MAX_RAYS" in err
    monkeypatch.delenv("LADARTUI_MAX_RAYS")

    def unavailable(*args, **options):
        raise BackendUnavailable("backend 'wgpu' is unavailable: no adapter")

    monkeypatch.setattr(simulation, "simulate", unavailable)
    assert main(["sweep", str(spec), "--serial"]) == 1
    assert "ladartui: no variant finished (2 failed)" in capsys.readouterr().err


def test_the_tui_sweep_job_reads_and_hashes_the_base_once(tmp_path, monkeypatch):
    """The TUI's sweep job hashed the base's models for its stored rows, then run_sweep
    read, checked and hashed them again."""
    from ladartui.sweep import base
    from ladartui.tui.sweep_jobs import StoredRows, sweep_job

    write_tiny_scenario(tmp_path)
    spec = load_sweep_spec(write_spec(tmp_path, "[grid]\nscans = [2, 3]\n"))
    from ladartui.sweep import execute

    real_digest, digests = base.base_digest, []

    def counted_digest(*args):
        digests.append(1)
        return real_digest(*args)

    for module in (base, execute):  # wherever the name is imported
        monkeypatch.setattr(module, "base_digest", counted_digest, raising=False)
    reports = []
    args = ("", None, True, "obscured-coverage", "flight-time", None, 5.0, None)
    result = sweep_job(spec, *args, lambda fraction, text, report=None, keep=False: reports.append(report))
    assert result.ran == 2 and len(digests) == 1
    assert isinstance(reports[0], StoredRows) and reports[0].rows == []
    digests.clear()
    again = sweep_job(spec, *args, lambda fraction, text, report=None, keep=False: reports.append(report))
    assert again.resumed == 2 and len(digests) == 1


def test_more_local_workers_than_the_machine_can_hold_are_refused(tiny, tmp_path, capsys, monkeypatch):
    """--workers 99999999999999999999999 started worker processes until the command was killed."""
    import os

    import ladartui.sweep.execute as execute
    from ladartui.cli import main

    def refuse(workers=None):
        raise AssertionError("a cluster was started")

    monkeypatch.setattr(execute, "local_client", refuse)
    limit = 4 * (os.cpu_count() or 1)
    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="workers.toml")
    assert main(["sweep", str(spec), "--workers", str(limit + 1), "--out", str(tmp_path / "o")]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: --workers = {limit + 1}: expected at most {limit} local worker processes "
        f"(4 per core of this machine's {os.cpu_count()})"
    )
    assert not (tmp_path / "o").exists()
    # with --serial no worker runs at all: that is what is wrong, not their number
    assert main(["sweep", str(spec), "--serial", "--workers", str(limit + 1)]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: --workers = {limit + 1}: expected no --workers with --serial "
        "(one process runs every variant)"
    )


@pytest.mark.parametrize("mode", [[], ["--serial"], ["--workers", "1"]])
def test_a_connect_timeout_without_a_scheduler_is_refused(tiny, tmp_path, capsys, mode):
    """--connect-timeout 5 on a local sweep was taken and ignored: only a connection to a
    scheduler waits for it."""
    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="timeout.toml")
    args = ["sweep", str(spec), *mode, "--connect-timeout", "5", "--out", str(tmp_path / "o")]
    assert main(args) == 2
    assert one_error_line(capsys) == (
        "ladartui: error: --scheduler is not set: expected an address with --connect-timeout "
        "(only a connection to a scheduler waits for it)"
    )
    assert not (tmp_path / "o").exists()  # refused before anything ran


@pytest.mark.parametrize(
    "body,made,sizes",
    [
        (
            "[grid]\nradius = { start = 1, stop = 401, step = 1 }\n"
            "altitude = { start = 1, stop = 301, step = 1 }\n",
            "[grid] makes 120,701",
            "401 radius x 301 altitude",
        ),
        (
            "[random]\nsamples = 200000\nradius = { min = 10, max = 90 }\n",
            "[random] makes 200,000",
            "200,000 random draws",
        ),
        (
            "[grid]\nradius = [10, 20, 30]\n[random]\nsamples = 50000\naltitude = { min = 50, max = 90 }\n",
            "[grid] and [random] make 150,000",
            "3 radius x 50,000 random draws",
        ),
    ],
)
def test_too_many_variants_names_the_spec_line_and_the_sizes(tmp_path, body, made, sizes):
    """The limit of 100,000 variants named the file but no line."""
    from ladartui.errors import ResourceLimitError

    spec = write_spec(tmp_path, body)
    with pytest.raises(ResourceLimitError) as caught:
        load_sweep_spec(spec)
    assert str(caught.value) == (
        f"{spec}:3: {made} variants ({sizes}), more than the limit of 100,000; use fewer values or samples"
    )
    assert made.split()[0] == spec.read_text(encoding="utf-8").splitlines()[2]  # line 3, the table's


@pytest.mark.parametrize("value", ["inf", "nan", "1e300", "0", "-5"])
def test_a_connect_timeout_beyond_a_day_or_not_finite_is_refused(tiny, tmp_path, capsys, value):
    """--connect-timeout inf ended in dask's KeyError traceback ('Invalid time unit: infs');
    1e300 waited for ever."""
    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="timeout.toml")
    args = ["sweep", str(spec), "--scheduler", "tcp://127.0.0.1:1", "--connect-timeout", value]
    assert main([*args, "--out", str(tmp_path / "o")]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: --connect-timeout = {float(value)!r}: expected a number of seconds "
        "greater than 0 and at most 86400"
    )
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("variable", "expected"),
    [("LADARTUI_MAX_RAYS", "a number of rays >= 1"), ("LADARTUI_MAX_BIN_VISITS", "a number of visits >= 1")],
)
def test_a_mistyped_limit_is_named_alone_not_on_a_spec_line(
    tmp_path, capsys, monkeypatch, variable, expected
):
    """LADARTUI_MAX_RAYS=abc read 'spec.toml:5: grid.radius: no variant can run: ...'."""
    from ladartui.cli import main

    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [20.0]\n", name="limit.toml")
    monkeypatch.setenv(variable, "abc")
    assert main(["sweep", str(spec), "--serial"]) == 2
    assert capsys.readouterr().err.strip() == f"ladartui: error: {variable} = 'abc': expected {expected}"


def test_a_spec_naming_itself_as_its_scenario_is_told_on_that_line(tmp_path, capsys):
    """It read 'self.toml:1: a sweep spec ([sweep]), not a scenario', the key unnamed."""
    from ladartui.cli import main

    spec = write_spec(tmp_path, "[grid]\nradius = [20.0]\n", name="self.toml", scenario="self.toml")
    assert main(["sweep", str(spec), "--serial"]) == 2
    assert capsys.readouterr().err.strip() == (
        f"ladartui: error: {spec}:2: sweep.scenario: expected the base scenario's file; "
        "'self.toml' is this sweep spec"
    )
