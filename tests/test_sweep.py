"""Sweeps without a cluster: ranking, parameters applied to the base, serial runs,
resume, the best scenario file, a column's decimals (specs and variant ids:
test_sweep_spec.py; the command and its folder lock: test_sweep_cli.py; the result
table itself: test_sweep_table.py)."""

import math
import random
import subprocess
import sys
import threading
from dataclasses import replace

import pytest

from ladartui.errors import Cancelled, FieldError
from ladartui.sweep import (
    apply_parameters,
    load_sweep_results,
    pareto_front,
    rank_rows,
    read_table,
    run_sweep,
)
from tiny_sweep import CENTRE, tiny_folder, write_spec, write_tiny_scenario

# Columns that depend on where and when a variant ran, not on what it computed.
VOLATILE = {"run_time_s", "worker"}


TINY_GRID = """
[grid]
radius = [10.0, 20.0]
scans = [2, 4]
sensor_grid = [8, 0]
"""


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    return tiny_folder(tmp_path_factory)


# -- ranking -------------------------------------------------------------------------


def _dominated(p, q):
    return q[0] <= p[0] and q[1] >= p[1] and q != p


def test_pareto_front_matches_a_brute_force_check():
    rng = random.Random(3)
    for _ in range(200):
        points = [(float(rng.randint(0, 5)), float(rng.randint(0, 5))) for _ in range(rng.randint(0, 12))]
        points.append(None)
        expected = [
            p is not None and not any(q is not None and _dominated(p, q) for q in points) for p in points
        ]
        assert pareto_front(points, ("min", "max")) == expected


def _row(variant, coverage, length, time, status="ok"):
    return {
        "variant": variant,
        "status": status,
        "obscured_coverage": coverage,
        "path_length_m": length,
        "flight_time_s": time,
    }


def test_objectives_rank_by_coverage_per_km_and_within_budget():
    rows = [
        _row("a", 0.5, 2000.0, 100.0),
        _row("b", 0.4, 500.0, 25.0),
        _row("c", 0.9, 9000.0, 450.0),
        _row("d", None, None, None, status="error"),
        _row("e", 0.3, 0.0, 0.0),
    ]
    per_km = rank_rows(rows, "coverage-per-km")
    assert [(r.row["variant"], r.rank) for r in per_km] == [
        ("b", 1),
        ("a", 2),
        ("c", 3),
        ("e", None),
        ("d", None),
    ]
    assert per_km[0].value == pytest.approx(0.4 / 0.5)
    budget = rank_rows(rows, "coverage-within-budget", budget=120.0)
    assert [r.row["variant"] for r in budget if r.rank] == ["a", "b", "e"]
    best = rank_rows(rows, "obscured-coverage")
    assert best[0].row["variant"] == "c"
    # Pareto front (time against coverage): e (0 s), b, a and c each buy more coverage.
    assert {r.row["variant"] for r in best if r.pareto} == {"e", "b", "a", "c"}
    with pytest.raises(FieldError) as caught:
        rank_rows(rows, "speed")
    assert str(caught.value).startswith("objective = 'speed': expected one of obscured-coverage, ")


# -- applying parameters -------------------------------------------------------------


def _bearing(pose, centre):
    return math.degrees(math.atan2(pose.x - centre[0], pose.y - centre[1])) % 360.0


def test_parameters_reshape_the_base_flight_and_sensor(tiny):
    from ladartui.scenario import load_scenario

    base = load_scenario(tiny / "base.toml")
    scenario = apply_parameters(
        base,
        {"radius": 12.0, "altitude": 30.0, "scans": 6, "heading_offset": 90.0, "fov": 15.0, "sensor_grid": 4},
    )
    poses = scenario.poses()
    assert len(poses) == 6
    for pose in poses:
        assert math.hypot(pose.x - CENTRE[0], pose.y - CENTRE[1]) == pytest.approx(12.0)
        assert pose.z == pytest.approx(30.0)
    assert _bearing(poses[0], CENTRE) == pytest.approx(180.0 + 90.0)
    assert (scenario.sensor.fov, scenario.sensor.grid) == (15.0, 4)
    assert scenario.sensor.ray_grid == base.sensor.ray_grid


def test_preset_builds_a_flypast_or_standoff_around_the_base_target(tiny):
    from ladartui.scenario import load_scenario

    base = load_scenario(tiny / "base.toml")
    flypast = apply_parameters(base, {"preset": "flypast", "standoff": 8.0, "scans": 5})
    poses = flypast.poses()
    closest = min(math.hypot(p.x - CENTRE[0], p.y - CENTRE[1]) for p in poses)
    assert closest == pytest.approx(8.0)
    # The base orbit starts due south of the target: the fly-past passes there.
    assert _bearing(poses[2], CENTRE) == pytest.approx(180.0)
    assert math.hypot(poses[2].x - CENTRE[0], poses[2].y - CENTRE[1]) == pytest.approx(8.0)
    assert all(p.z == pytest.approx(20.0) for p in poses)  # the base orbit's altitude
    standoff = apply_parameters(base, {"preset": "standoff", "standoff": 30.0, "scans": 3})
    distances = [math.hypot(p.x - CENTRE[0], p.y - CENTRE[1]) for p in standoff.poses()]
    assert distances == pytest.approx([30.0, 20.0, 10.0])
    turned = apply_parameters(
        base, {"preset": "standoff", "standoff": 30.0, "scans": 3, "heading_offset": -90.0}
    )
    assert all(_bearing(p, CENTRE) == pytest.approx(90.0) for p in turned.poses())


def test_a_base_standoff_turned_about_its_target_turns_the_heading_it_gives(tiny):
    """A standoff with its own heading (0, flying north along a line from the east)
    turned 90 degrees kept heading 0, so the best path written flew across its line."""
    from ladartui.flight import FlightPlan, Standoff
    from ladartui.scenario import load_scenario

    line = Standoff(target=CENTRE, standoffs=(40.0, 20.0), altitude=25.0, bearing=90.0, heading=270.0)
    base = load_scenario(tiny / "base.toml").with_changes(flight=FlightPlan(segments=(line,)))
    turned = apply_parameters(base, {"heading_offset": 90.0}).flight.segments[0]
    assert (turned.bearing, turned.heading) == (180.0, 0.0)  # still flying in towards the target
    assert all(
        _bearing(p, CENTRE) == pytest.approx(180.0)
        for p in apply_parameters(base, {"heading_offset": 90.0}).poses()
    )
    unset = apply_parameters(
        base.with_changes(flight=FlightPlan(segments=(replace(line, heading=None),))),
        {"heading_offset": 90.0},
    ).flight.segments[0]
    assert unset.heading is None  # towards the target, whatever the bearing


def test_a_base_standoff_keeps_its_spacing_scaled_to_the_new_standoff(tiny):
    from ladartui.flight import FlightPlan, Standoff
    from ladartui.scenario import load_scenario

    base = load_scenario(tiny / "base.toml").with_changes(
        flight=FlightPlan(
            segments=(Standoff(target=CENTRE, standoffs=(40.0, 20.0, 10.0), altitude=25.0, bearing=90.0),)
        )
    )
    scenario = apply_parameters(base, {"standoff": 80.0})
    distances = [math.hypot(p.x - CENTRE[0], p.y - CENTRE[1]) for p in scenario.poses()]
    assert distances == pytest.approx([80.0, 40.0, 20.0])
    assert all(_bearing(p, CENTRE) == pytest.approx(90.0) for p in scenario.poses())
    more = apply_parameters(base, {"scans": 4})  # a new count: even spacing from the farthest
    distances = [math.hypot(p.x - CENTRE[0], p.y - CENTRE[1]) for p in more.poses()]
    assert distances == pytest.approx([40.0, 30.0, 20.0, 10.0])


def test_impossible_parameters_raise_naming_the_sweep_parameter(tiny):
    from ladartui.scenario import load_scenario

    base = load_scenario(tiny / "base.toml")
    with pytest.raises(FieldError) as caught:
        apply_parameters(base, {"sensor_grid": 0})
    assert str(caught.value) == "sensor_grid = 0: expected an integer from 1 to 1024"
    with pytest.raises(FieldError) as caught:
        apply_parameters(base, {"standoff": 5.0})  # the base flies an orbit, not a fly-past
    assert str(caught.value) == (
        "standoff = 5.0: expected a parameter of the base's orbit "
        "(altitude, arc, heading_offset, radius, scans)"
    )


# -- serial runs ---------------------------------------------------------------------


def _hand_built(base, radius, scans, grid):
    """The variant's scenario built directly from the flight and sensor classes."""
    from ladartui.flight import FlightPlan, Orbit

    flight = FlightPlan(segments=(Orbit(centre=CENTRE, radius=radius, altitude=20.0, scans=scans),))
    return base.with_changes(flight=flight, sensor=replace(base.sensor, grid=grid))


def comparable(row):
    return {k: v for k, v in row.items() if k not in VOLATILE}


def test_serial_sweep_rows_match_direct_simulations(tiny, tmp_path):
    from ladartui.scenario import load_scenario
    from ladartui.simulation import simulate

    spec = write_spec(tiny, TINY_GRID, name="serial.toml")
    result = run_sweep(spec, serial=True, out=tmp_path / "out")
    assert len(result.rows) == 8
    base = load_scenario(tiny / "base.toml")
    errors = [r for r in result.rows if r["status"] != "ok"]
    assert len(errors) == 4
    assert all(
        r["sensor_grid"] == 0 and "sensor_grid = 0" in r["error"] and "expected" in r["error"] for r in errors
    )
    for row in (r for r in result.rows if r["status"] == "ok"):
        expected = simulate(_hand_built(base, row["radius"], row["scans"], row["sensor_grid"]), write=False)
        measures = expected.measures
        assert row["obscured_coverage"] == measures.obscured_coverage
        assert row["unobscured_coverage"] == measures.unobscured_coverage
        assert row["obscured_after_scan"] == list(measures.obscured_after_scan)
        assert row["scan_count"] == row["scans"]
        assert row["path_length_m"] == pytest.approx(
            2 * math.pi * row["radius"] * (1 if row["scans"] == 1 else (row["scans"] - 1) / row["scans"])
        )
        assert row["flight_time_s"] == pytest.approx(row["path_length_m"] / base.speed)
    # The file holds the same rows, and the ranking and best scenario were written.
    stored, _ = read_table(tmp_path / "out" / "results.csv")
    assert sorted(map(repr, map(comparable, stored))) == sorted(map(repr, map(comparable, result.rows)))
    best = result.best.row
    assert best["obscured_coverage"] == max(
        r["obscured_coverage"] for r in result.rows if r["status"] == "ok"
    )
    saved = load_scenario(result.best_scenario_path)
    assert saved.flight.segments[0].radius == best["radius"]
    assert len(saved.poses()) == best["scans"]
    assert saved.scene_file == base.scene_file
    loaded = load_sweep_results(tmp_path / "out")
    assert [r.row["variant"] for r in loaded.ranking] == [r.row["variant"] for r in result.ranking]


def test_interrupted_sweep_resumes_with_only_the_missing_variants(tiny, tmp_path):
    spec = write_spec(tiny, TINY_GRID, name="resume.toml")
    out = tmp_path / "out"
    cancel = threading.Event()
    seen = []

    def stop_after_three(progress):
        seen.append(progress.done)
        if progress.done >= 3:
            cancel.set()

    with pytest.raises(Cancelled):
        run_sweep(spec, serial=True, out=out, progress=stop_after_three, cancel=cancel)
    first, _ = read_table(out / "results.csv")
    assert len(first) == 3
    reports = []
    result = run_sweep(spec, serial=True, out=out, progress=reports.append)
    assert (result.resumed, result.ran, len(result.rows)) == (3, 5, 8)
    assert reports[0].resumed == 3 and reports[-1].done == 8
    kept = {r["variant"]: r for r in result.rows}
    for row in first:  # untouched: same worker and run time as before
        assert {k: v for k, v in kept[row["variant"]].items() if v is not None} == {
            k: v for k, v in row.items() if v is not None
        }
    # Nothing left to do: a third run runs nothing.
    again = run_sweep(spec, serial=True, out=out)
    assert (again.resumed, again.ran) == (8, 0)


def test_editing_the_base_scenario_runs_every_variant_again(tmp_path):
    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nscans = [2, 3]\n")
    out = tmp_path / "out"
    assert run_sweep(spec, serial=True, out=out).ran == 2
    from ladartui.scenario import load_scenario

    base = load_scenario(tmp_path / "base.toml")
    base.with_changes(speed=60.0).save()
    result = run_sweep(spec, serial=True, out=out)
    assert (result.ran, result.resumed) == (2, 0)
    assert all(r["flight_time_s"] == pytest.approx(r["path_length_m"] / 60.0) for r in result.rows)


def test_the_sweep_core_and_command_import_without_textual_or_dask():
    code = (
        "import sys, ladartui.sweep, ladartui.cli.sweep; "
        "print(sorted(m for m in ('textual', 'distributed') if m in sys.modules))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert loaded == "[]"  # Dask loads only when a sweep runs on it


def test_the_best_scenario_file_does_not_carry_the_base_files_comments(tmp_path):
    from ladartui.scenario import load_scenario
    from ladartui.sweep.best_file import write_best_scenario

    base = write_tiny_scenario(tmp_path)
    text = base.path.read_text().replace("radius = 20.0", "radius = 20.0  # a tight orbit: 20 m")
    base.path.write_text("# Orbit: 4 looks at 20 m\n" + text)
    base = load_scenario(base.path)
    out = tmp_path / "out"
    out.mkdir()
    row = {"variant": "abc12345", "radius": 35.0}
    path = write_best_scenario(out / "base-best.toml", base, row, ["radius"], base.load_scene).path
    written = path.read_text()
    # the base's comments described the base's values: not this file's
    assert "20 m" not in written and "4 looks" not in written
    assert written.startswith(
        "# The best flight path of a sweep (variant abc12345): base.toml with radius = 35\n"
    )
    saved = load_scenario(path)
    assert saved.flight.segments[0].radius == 35.0 and saved.scene_file == base.scene_file


def test_a_columns_numbers_share_their_decimals():
    """The time column read '4', '8.029', '10.04': each cell to four significant figures,
    so the decimals wandered and whole numbers lost theirs."""
    from ladartui.sweep.table import column_format

    shown = column_format([4.0, 8.029, 10.04, None, 12])
    assert [shown(v) for v in (4.0, 8.029, 10.04, None, 12)] == ["4.00", "8.03", "10.04", "-", "12.00"]
    assert column_format([0.5, 0.25], 3)(0.25) == "0.250"  # a share: three figures of the largest
    # past what fixed decimals show well, each cell keeps its own figures
    assert [column_format([1e7, 3.5])(v) for v in (1e7, 3.5)] == ["1e+07", "3.5"]
    assert column_format([0.0001, 0.0002])(0.0001) == "0.0001"
    assert column_format([float("nan"), 2.5])(float("nan")) == "nan"
    assert column_format(["text", 1.5])("text") == "text"
    # whole numbers beside fractions take the decimals too
    assert [column_format([64, 128.5])(v) for v in (64, 128.5)] == ["64.0", "128.5"]
    # decimals that would show distinct values alike, or one as nought: each its own figures
    assert [column_format([0.25, 0.5, 1000.0])(v) for v in (0.25, 0.5, 1000.0)] == ["0.25", "0.5", "1000"]
    assert column_format([-0.0001, 0.5], 3)(-0.0001) == "-0.0001"
