"""A study of a scenario traces the scans that scenario's runs trace."""

from __future__ import annotations

import dataclasses

import pytest

from tiny_sweep import write_tiny_scenario


@pytest.mark.parametrize("mount", ["stabilised", "body-fixed"])
def test_a_study_of_a_scenario_scores_the_coverage_its_run_scores(tmp_path, mount):
    """A study of a body-fixed sensor's scenario (scenarios/realism.toml) traced every scan
    as if stabilised: exact m=2 over its 19 scans scored 39.6 % where its run, on the
    same rays, scored 25.2 % (the orbit's banked looks miss the target)."""
    from ladartui.scenario import load_scenario
    from ladartui.simulation import simulate
    from ladartui.study.inputs import scenario_inputs
    from ladartui.study.run import run_study
    from ladartui.study.settings import reference_setting

    pytest.importorskip("numba")
    scenario = write_tiny_scenario(tmp_path)
    scenario = dataclasses.replace(scenario, sensor=dataclasses.replace(scenario.sensor, mount=mount)).save()
    run = simulate(load_scenario(scenario.path), write=False)
    inputs = scenario_inputs(scenario.path, None)
    study = run_study(inputs, [reference_setting(scenario.sensor.ray_grid)], runs=1, warmup=0)
    (row,) = study.rows
    assert row.scans == run.scans == 4
    assert row.coverage == pytest.approx(run.measures.obscured_coverage)


def _bearings(poses, centre):
    """Each pose's bearing from ``centre``, degrees clockwise from north (+y)."""
    import math

    return [math.degrees(math.atan2(p.x - centre[0], p.y - centre[1])) % 360.0 for p in poses]


def _gaps(bearings):
    """The gaps between neighbouring bearings around the circle, degrees."""
    ordered = sorted(bearings)
    return [(b - a) % 360.0 for a, b in zip(ordered, ordered[1:] + ordered[:1])]


@pytest.mark.parametrize("scans, picked", [(24, 3), (24, 8), (36, 5)])
def test_a_study_spreads_its_scans_around_a_closed_orbit(tmp_path, scans, picked):
    """A full orbit's last scan is one step before its first: a study of 3 of the default
    orbit's 24 scans traced the scans at 0, 180 and 345 degrees, two of them 15 degrees
    apart, where 0, 120 and 240 are the three spread around it."""
    from ladartui.flight import FlightPlan, Orbit
    from ladartui.study.inputs import scenario_inputs
    from tiny_sweep import CENTRE

    scenario = write_tiny_scenario(tmp_path)
    orbit = Orbit(centre=CENTRE, radius=20.0, altitude=20.0, scans=scans)
    scenario = dataclasses.replace(scenario, flight=FlightPlan(segments=(orbit,))).save()
    inputs = scenario_inputs(scenario.path, picked)
    assert len(inputs.poses) == picked
    assert inputs.notes == [
        f"{picked} of the scenario's {scans} scans traced "
        "(evenly spread around its orbit; --scans changes this)."
    ]
    gaps = _gaps(_bearings(inputs.poses, CENTRE))
    step = 360.0 / scans
    assert max(gaps) - min(gaps) <= step + 1e-9  # as even as whole scans allow
    assert sum(gaps) == pytest.approx(360.0)


def test_a_study_of_an_open_arc_keeps_both_its_ends(tmp_path):
    from ladartui.flight import FlightPlan, Orbit
    from ladartui.study.inputs import scenario_inputs
    from tiny_sweep import CENTRE

    scenario = write_tiny_scenario(tmp_path)
    orbit = Orbit(centre=CENTRE, radius=20.0, altitude=20.0, scans=13, arc=120.0)
    scenario = dataclasses.replace(scenario, flight=FlightPlan(segments=(orbit,))).save()
    every = scenario_inputs(scenario.path, None).poses
    picked_inputs = scenario_inputs(scenario.path, 3)
    picked = picked_inputs.poses
    assert picked_inputs.notes == [
        "3 of the scenario's 13 scans traced (evenly spread; --scans changes this)."
    ]
    assert [picked[0], picked[-1]] == [every[0], every[-1]]
    assert _bearings(picked[1:2], CENTRE) == pytest.approx(_bearings(every[6:7], CENTRE))


def test_a_study_of_the_generated_scene_spreads_its_scans_around_the_default_orbit(monkeypatch, tmp_path):
    from ladartui.defaults import target_centre
    from ladartui.scenario import load_scenario
    from ladartui.study import inputs as study_inputs

    scene = load_scenario(write_tiny_scenario(tmp_path).path).load_scene()
    monkeypatch.setattr(study_inputs, "cached_scene", lambda preset, progress=None: scene)
    inputs = study_inputs.generated_inputs("reference", 3)
    centre = target_centre(scene.target, scene.voxel_size)
    assert _gaps(_bearings(inputs.poses, centre)) == pytest.approx([120.0] * 3)
