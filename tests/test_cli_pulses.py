"""``ladartui pulses``: JSON rows, the terminal chart, the scenario's settings, Ctrl-C."""

import json

import numpy as np
import pytest

import ladartui.detection.pulses as pulses_module
from cli_support import ctrl_c
from ladartui.cli import main
from ladartui.cli.pulses import chart_text
from ladartui.detection.pulses import PulseRow
from ladartui.detection.settings import DetectionSettings
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
    poses = tuple(
        aim_at(ScanPose(x, y, 40.0), (9.5, 9.0, 0.5)) for x, y in [(9.5, -10.0), (29.5, 9.0), (9.5, 30.0)]
    )
    return Scenario(
        tmp_path / "S.toml",
        "woods.txt",
        1.0,
        Sensor(grid=16, ray_grid=2, fov=20.0),
        FlightPlan(segments=[Manual(poses)]),
        backend="numba",
        detection=DetectionSettings(pulses=20, coincidence=4, solar_rate_hz=2e7, seed=3),
    ).save()


def test_json_rows_use_the_scenario_settings(scenario, capsys):
    assert main(["pulses", str(scenario.path), "--pulses", "1,5,20", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["settings"]["seed"] == 3 and out["settings"]["model"] == "geiger"
    rows = out["rows"]
    assert [r["pulses"] for r in rows] == [1, 5, 20]
    assert [r["threshold"] for r in rows] == [1, 1, 4]  # the scenario's k share, 4 of 20
    assert 0 < out["ideal_obscured_coverage"] <= 1
    assert all(r["obscured_coverage"] <= out["ideal_obscured_coverage"] for r in rows)
    # k = 1: every noise fire is a false alarm, so five pulses see more than one.
    assert rows[1]["false_alarms"] > rows[0]["false_alarms"] > 0


def test_pulse_counts_are_traced_once_each_in_increasing_order(scenario, capsys):
    # A repeated or out-of-order list made repeated rows and a chart line that doubled back.
    assert main(["pulses", str(scenario.path), "--pulses", "20,1,5,1", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert [r["pulses"] for r in rows] == [1, 5, 20]


def test_table_and_chart(scenario, capsys):
    assert main(["pulses", str(scenario.path), "--pulses", "1,20", "--seed", "5"]) == 0
    out = capsys.readouterr().out
    assert "ideal model: obscured coverage" in out
    assert "pulses per look" in out and "false alarms (right)" in out


def test_chart_text_draws_both_series():
    rows = [PulseRow(1, 1, 0.2, 100, 40, 0.5), PulseRow(100, 10, 0.35, 90, 0, 0.9)]
    text = chart_text(0.4, rows, width=60, height=15, color=False)
    assert "obscured coverage % (Geiger)" in text and "obscured coverage % (ideal)" in text
    assert "40" in text  # the false-alarm axis reaches the largest count
    assert "\x1b[" not in text


def test_bad_flag_names_the_flag(scenario, capsys):
    assert main(["pulses", str(scenario.path), "--n-ref", "-1"]) == 2
    assert capsys.readouterr().err.strip() == (
        "ladartui: error: --n-ref = -1.0: expected a number greater than 0 and at most 1000000"
    )
    # a bad backend is named before any tracing: no progress drawn on stderr
    assert main(["pulses", str(scenario.path), "--backend", "abacus"]) == 2
    assert capsys.readouterr().err == (
        "ladartui: error: --backend = 'abacus': expected one of 'auto', 'numba', 'wgpu'\n"
    )


def test_ctrl_c_cancels_with_a_truthful_message(scenario, capsys, monkeypatch):
    real = pulses_module.pulse_study

    def interrupted(*args, progress=None, cancel=None, **kwargs):
        def report(p):
            progress(p)
            if p.stage == "trace" and p.done == 2:
                assert ctrl_c(cancel), "Ctrl-C did not set the cancel event"

        return real(*args, progress=report, cancel=cancel, **kwargs)

    monkeypatch.setattr(pulses_module, "pulse_study", interrupted)
    assert main(["pulses", str(scenario.path), "--pulses", "1,20"]) == 130
    captured = capsys.readouterr()
    assert "pulse study cancelled after tracing 2 of 3 scans; no results" in captured.err
    assert "ideal model" not in captured.out


def test_ctrl_c_during_a_pulse_count_shows_the_rows_finished(scenario, capsys, monkeypatch):
    """The rows finished were thrown away ('no results'), and the bar named the count
    finished, not the one being fired, until that one's first scan was done."""
    real = pulses_module.pulse_study
    seen = []

    def interrupted(*args, progress=None, cancel=None, **kwargs):
        def report(p):
            progress(p)
            seen.append((p.stage, p.done, len(p.rows)))
            if p.stage == "pulses" and p.done == 2:
                assert ctrl_c(cancel), "Ctrl-C did not set the cancel event"

        return real(*args, progress=report, cancel=cancel, **kwargs)

    monkeypatch.setattr(pulses_module, "pulse_study", interrupted)
    assert main(["pulses", str(scenario.path), "--pulses", "1,20", "--no-chart"]) == 130
    captured = capsys.readouterr()
    assert ("pulses", 1, 0) in seen and seen[-1] == ("pulses", 2, 1)  # told at once, row 1 done
    assert captured.err.strip().endswith(
        "pulse study cancelled after tracing every scan, during pulse count 2 of 2; the 1 row "
        "finished is above, and this command writes no files"
    )
    lines = captured.out.splitlines()
    assert lines[0].startswith("ideal model: obscured coverage 0.") and len(lines) == 3
    assert lines[2].split()[:2] == ["1", "1"]  # 1 pulse, k = 1


def test_a_bundled_scenario_is_taken_by_name_as_run_takes_it(tmp_path, capsys, monkeypatch):
    """'pulses convoy' said '/cwd/convoy: no such file', where 'run convoy' runs it."""
    from ladartui.user_data import bundled_scenario_path

    studied = []

    def study(scenario, *args, **kwargs):
        studied.append(scenario.path)
        return 0.5, []

    monkeypatch.setattr(pulses_module, "pulse_study", study)
    monkeypatch.chdir(tmp_path)
    assert main(["pulses", "convoy", "--pulses", "1", "--json"]) == 0
    assert studied == [bundled_scenario_path("convoy")]


def test_work_beyond_the_memory_limit_is_refused_up_front(scenario, capsys, monkeypatch):
    """The Geiger model's limit ignored LADARTUI_MAX_MEMORY, which the README says sets the
    memory limit, and said a small need as "about 0.0 GiB ... more than the 0.0 GiB"."""
    from ladartui.errors import ResourceLimitError
    from ladartui.simulation import _ScanRunner, simulate

    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(1 << 16))
    traced = []
    monkeypatch.setattr("ladartui.tracing.trace", lambda *a, **k: traced.append(1))
    assert main(["pulses", str(scenario.path), "--pulses", "1"]) == 2
    err = capsys.readouterr().err
    assert (  # 3 x 1,024 rays x 110 bytes
        "the Geiger-mode model would need about 330 KiB for 3 scans of 1,024 rays, more than the "
        "64 KiB it may use here: use fewer scans" in err
    )
    assert not traced
    # A run of the same scenario refuses before its first scan: one scan's rays held in both
    # runs, 2 x 1,024 rays x 110 bytes, are more than the 64 KiB allowed.
    monkeypatch.setattr(_ScanRunner, "scan", lambda *a, **k: traced.append(1))
    with pytest.raises(ResourceLimitError) as caught:
        simulate(scenario.with_changes(detection=DetectionSettings(model="geiger")))
    assert str(caught.value) == (
        "the Geiger-mode model would need about 220 KiB for one scan's 1,024 rays in two runs, more "
        "than the 64 KiB it may use here: use a smaller sensor grid or fewer rays per detector"
    )
    assert not traced and not scenario.scene_output.exists() and not scenario.measures_file.exists()


def test_the_geiger_memory_limit_is_what_the_memory_cgroup_has_left(scenario, capsys, monkeypatch):
    """The Geiger model allowed half the machine's physical memory whatever a container's
    or a batch job's memory cgroup had left, so a study past that limit was killed by the
    kernel rather than refused, where the README says the least of them is the limit."""
    import ladartui.resources as resources

    monkeypatch.delenv("LADARTUI_MAX_MEMORY", raising=False)
    monkeypatch.setattr(resources, "_cgroup_left", lambda: 1 << 17)
    traced = []
    monkeypatch.setattr("ladartui.tracing.trace", lambda *a, **k: traced.append(1))
    assert main(["pulses", str(scenario.path), "--pulses", "1"]) == 2
    assert (  # 3 x 1,024 rays x 110 bytes
        "the Geiger-mode model would need about 330 KiB for 3 scans of 1,024 rays, more than the "
        "128 KiB it may use here" in capsys.readouterr().err
    )
    assert not traced


def test_geiger_markers_stay_visible_where_they_meet_the_ideal_line():
    # coverage a hair under the ideal: on the same character row as its line
    rows = [PulseRow(m, 1, 0.2499, 100, 0, 0.5) for m in (1, 10, 30, 100)]
    text = chart_text(0.25, rows, width=60, height=15, color=False)
    plot = [line.split("┤", 1)[1].split("├", 1)[0] for line in text.splitlines() if "┤" in line]
    markers = sum(row.count("o") for row in plot if "obscured coverage" not in row)
    assert markers >= len(rows)


def test_the_chart_fits_a_narrow_terminal_and_keeps_its_title(scenario, capsys, monkeypatch):
    """The chart was 78 columns whatever the width: on a 60-column terminal every line
    wrapped onto the next, and at 60 plotext dropped the title, too long to fit."""
    monkeypatch.setenv("COLUMNS", "60")
    assert main(["pulses", str(scenario.path), "--pulses", "1,20"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines and max(len(line) for line in lines) <= 60
    assert any("false alarms against pulses per look" in line for line in lines)
    monkeypatch.setenv("COLUMNS", "200")  # wider: the chart as drawn before
    assert main(["pulses", str(scenario.path), "--pulses", "1,20"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert max(len(line) for line in lines) == 78
    assert any("Geiger-mode: coverage and false alarms against pulses per look" in line for line in lines)


def test_the_table_writes_counts_with_thousands_separators(scenario, capsys, monkeypatch):
    """'declared' and 'false' were bare digits (195447), where every other count has commas."""
    rows = [
        PulseRow(1, 1, 0.4, 93_376, 7_066, 0.674),
        PulseRow(100_000, 10, 0.41, 12_345_678, 1_234_567, 0.9),
    ]
    monkeypatch.setattr(pulses_module, "pulse_study", lambda *a, **k: (0.41, rows))
    assert main(["pulses", str(scenario.path), "--pulses", "1,100000", "--no-chart"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1:] == [
        " pulses     k  coverage    declared      false P_d(target)",
        "      1     1    0.4000      93,376      7,066       0.674",
        "100,000    10    0.4100  12,345,678  1,234,567       0.900",
    ]


def test_coverage_of_a_target_model_with_no_voxels_is_undefined(scenario, capsys):
    """A target model holding no voxels read as 0.0000 coverage (none of it seen), where
    a run's measures call it undefined; the false alarms are still counted."""
    (scenario.path.parent / "woods_Target.txt").write_text("", encoding="utf-8")
    assert main(["pulses", str(scenario.path), "--pulses", "1,20", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["ideal_obscured_coverage"] is None
    assert [r["obscured_coverage"] for r in out["rows"]] == [None, None]
    assert out["rows"][0]["false_alarms"] > 0
    assert main(["pulses", str(scenario.path), "--pulses", "1,20"]) == 0
    out = capsys.readouterr().out
    assert "ideal model: obscured coverage undefined (the target model holds no voxels)" in out
    assert out.splitlines()[2].split()[2] == "undefined"  # the first row's coverage column
    assert "false alarms (right)" in out and "obscured coverage % (Geiger)" not in out


def _count_visits(monkeypatch):
    """Record the detector range-bin visits each firing makes (detectors x bins x pulses)."""
    import ladartui.detection.look as look

    visits = []
    real = look.fire_counts

    def counting(mean, pulses, *args, **kwargs):
        visits.append(np.asarray(mean).size * pulses)
        return real(mean, pulses, *args, **kwargs)

    monkeypatch.setattr(look, "fire_counts", counting)
    return visits


def test_firing_beyond_the_work_limit_is_refused_before_a_pulse(scenario, capsys, monkeypatch):
    """100,000 pulses per look on a large sensor fired for hours; the estimate after
    tracing is exactly the work the firing does, and over the limit nothing is fired."""
    visits = _count_visits(monkeypatch)
    assert main(["pulses", str(scenario.path), "--pulses", "5,20", "--json"]) == 0
    capsys.readouterr()
    work = sum(visits)
    assert work > 0
    visits.clear()
    monkeypatch.setenv("LADARTUI_MAX_BIN_VISITS", str(work - 1))
    assert main(["pulses", str(scenario.path), "--pulses", "5,20"]) == 2
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and not visits
    assert len(err.splitlines()) == 1  # the tracing's bar is gone: the work was refused
    assert err.startswith(f"ladartui: error: {scenario.path}: about {work:.3g} detector range-bin visits")
    assert "25 pulses in all on each of 3 looks" in err and "LADARTUI_MAX_BIN_VISITS" in err
    monkeypatch.setenv("LADARTUI_MAX_BIN_VISITS", str(work))
    assert main(["pulses", str(scenario.path), "--pulses", "5,20", "--json"]) == 0
    assert sum(visits) == work
    monkeypatch.setenv("LADARTUI_MAX_BIN_VISITS", "1")
    assert main(["pulses", str(scenario.path), "--pulses", "1"]) == 2
    assert "1 pulse in all on each of 3 looks" in capsys.readouterr().err  # not '1 pulses'


def test_a_geiger_run_beyond_the_work_limit_is_refused_before_its_first_pulse(scenario, capsys, monkeypatch):
    visits = _count_visits(monkeypatch)
    monkeypatch.setenv("LADARTUI_MAX_BIN_VISITS", "1000")
    geiger = scenario.with_changes(detection=DetectionSettings(model="geiger", pulses=20, coincidence=4))
    geiger.save()
    assert main(["run", str(scenario.path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and not visits
    assert (
        "detector range-bin visits to fire" in err.splitlines()[-1] and "20 pulses on each of 3 looks" in err
    )
    assert not scenario.scene_output.exists() and not scenario.target_output.exists()
    # a first look that misses everything fires nothing: the next one is checked
    away = ScanPose(500.0, 500.0, 40.0, depression=90.0)
    poses = (away, *geiger.flight.segments[0].poses)
    geiger.with_changes(flight=FlightPlan(segments=[Manual(poses)])).save()
    assert main(["run", str(scenario.path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and not visits
    assert "20 pulses on each of 4 looks, those to come taken as look 2's" in err.splitlines()[-1]
    monkeypatch.setenv("LADARTUI_MAX_BIN_VISITS", "a lot")
    assert main(["run", str(scenario.path)]) == 2
    assert "LADARTUI_MAX_BIN_VISITS = 'a lot': expected a number of visits >= 1" in capsys.readouterr().err


def test_a_scene_model_refused_in_setting_up_leaves_no_progress_line(scenario, capsys):
    """A bad line in the scene model printed 'scan 1  0.0 %' above the error, as run did."""
    from cli_support import one_error_line

    with open(scenario.scene_file, "a", encoding="utf-8") as handle:
        handle.write("1,2\n")
    assert main(["pulses", str(scenario.path), "--pulses", "1"]) == 2
    assert "expected three non-negative integers" in one_error_line(capsys)


def test_validate_names_a_mistyped_firing_limit_of_a_geiger_scenario(scenario, capsys, monkeypatch):
    """validate passed a Geiger scenario with LADARTUI_MAX_BIN_VISITS=abc, which run refused."""
    from cli_support import one_error_line

    monkeypatch.setenv("LADARTUI_MAX_BIN_VISITS", "abc")
    scenario.with_changes(detection=DetectionSettings(model="geiger", pulses=20, coincidence=4)).save()
    assert main(["validate", str(scenario.path)]) == 2
    assert one_error_line(capsys).endswith(
        "LADARTUI_MAX_BIN_VISITS = 'abc': expected a number of visits >= 1"
    )


@pytest.mark.parametrize(
    "pulse_counts, shown",
    [
        ([2.5], "[2.5]"),  # was studied as 2 pulses in a row that read 2.5
        ([10, 0], "[10, 0]"),  # was a ValueError from deep in the firing
        ([200_000], "[200000]"),  # was fired past the scenario's and the command's limit
        (10, "10"),  # was a TypeError: 'int' object is not iterable
        ("10", "'10'"),  # was a TypeError from dividing text
    ],
)
def test_pulse_study_refuses_pulse_counts_the_command_refuses(scenario, pulse_counts, shown, monkeypatch):
    from ladartui.errors import FieldError

    traced = []
    monkeypatch.setattr("ladartui.tracing.trace", lambda *a, **k: traced.append(1))
    with pytest.raises(FieldError) as caught:
        pulses_module.pulse_study(scenario, pulse_counts)
    assert str(caught.value) == (
        f"pulses_list = {shown}: expected a list of pulse counts, whole numbers from 1 to 100000"
    )
    assert not traced  # refused before any tracing


def test_pulse_study_names_a_scenario_or_settings_of_the_wrong_kind(scenario, monkeypatch):
    """A scenario's path and a dict of settings ended in AttributeError ('str' object
    has no attribute 'detection', 'dict' object has no attribute 'bin_width')."""
    from ladartui.errors import FieldError

    monkeypatch.setattr("ladartui.tracing.trace", lambda *a, **k: pytest.fail("traced"))
    with pytest.raises(FieldError) as caught:
        pulses_module.pulse_study(scenario, [10], settings={"pulses": 10})
    assert str(caught.value) == (
        "settings = {'pulses': 10}: expected a DetectionSettings (or None: the scenario's)"
    )
    with pytest.raises(FieldError) as caught:
        pulses_module.pulse_study(str(scenario.path), [10])
    assert str(caught.value) == (
        f"scenario = {str(scenario.path)!r}: expected a Scenario "
        "(ladartui.load_scenario reads one from a file)"
    )


@pytest.mark.parametrize(
    ("env", "coloured"), [({}, True), ({"NO_COLOR": "1"}, False), ({"TERM": "dumb"}, False)]
)
def test_the_chart_on_a_terminal_is_coloured_unless_no_color_or_a_dumb_terminal(
    scenario, capsys, monkeypatch, env, coloured
):
    """NO_COLOR=1 (and TERM=dumb, which shows escapes as text) still got the chart's ANSI
    colours: it asked only whether standard output was a terminal."""
    import sys

    monkeypatch.delenv("NO_COLOR", raising=False)
    monkeypatch.delenv("FORCE_COLOR", raising=False)
    monkeypatch.setenv("TERM", "xterm-256color")
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    monkeypatch.setattr(sys.stdout, "isatty", lambda: True)  # a terminal
    assert main(["pulses", str(scenario.path), "--pulses", "1,2"]) == 0
    out = capsys.readouterr().out
    assert ("\x1b[" in out) is coloured, out[-400:]
    assert "obscured coverage % (ideal)" in out
