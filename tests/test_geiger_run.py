"""The Geiger-mode model inside ``ladartui run``: declared points, measures, reproducibility."""

import json
import math

import numba
import numpy as np
import pytest

import ladartui.simulation as simulation
from ladartui.cli import main
from ladartui.cmf import read_cmf
from ladartui.detection.pulses import pulse_study
from ladartui.detection.settings import DetectionSettings
from ladartui.flight import FlightPlan, Manual, ScanPose, aim_at
from ladartui.scenario import Scenario
from ladartui.scene.voxels import save_voxels
from ladartui.sensor import Sensor
from ladartui.simulation import simulate


@pytest.fixture
def woods(tmp_path):
    target = np.array(
        [(x, y, z) for x in range(8, 12) for y in range(8, 11) for z in range(2)], dtype=np.int32
    )
    canopy = np.array(
        [(x, y, 6) for x in range(4, 16) for y in range(4, 15) if (x + 2 * y) % 3], dtype=np.int32
    )
    save_voxels(tmp_path / "woods.txt", np.vstack([target, canopy]))
    save_voxels(tmp_path / "woods_Target.txt", target)
    poses = tuple(
        aim_at(ScanPose(x, y, 40.0), (9.5, 9.0, 0.5)) for x, y in [(9.5, -10.0), (29.5, 9.0), (-5.0, 20.0)]
    )
    return Scenario(
        tmp_path / "S.toml",
        "woods.txt",
        1.0,
        Sensor(grid=16, ray_grid=2, fov=20.0),
        FlightPlan(segments=[Manual(poses)]),
        backend="numba",
    )


def _geiger(scenario, **settings):
    return scenario.with_changes(detection=DetectionSettings(model="geiger", **settings))


def _outputs(scenario):
    return [p.read_bytes() for p in (scenario.scene_output, scenario.target_output, scenario.measures_file)]


def test_certain_detection_gives_the_ideal_outputs(woods):
    ideal = simulate(woods, write=False)
    # Huge signal, no noise, a detector that re-arms after each bin: every return declared.
    certain = simulate(
        _geiger(
            woods, n_ref=1e6, dark_rate_hz=0.0, solar_rate_hz=0.0, dead_time_m=1.0, pulses=3, coincidence=3
        ),
        write=False,
    )
    np.testing.assert_array_equal(certain.scene_output, ideal.scene_output)
    np.testing.assert_array_equal(certain.target_output, ideal.target_output)
    d = certain.measures.detection
    assert d.false_alarms == 0 and d.target_detection == 1.0
    assert d.ideal_obscured_coverage == ideal.measures.obscured_coverage
    assert certain.measures.obscured_coverage == ideal.measures.obscured_coverage


def test_weak_signal_and_noise_lose_coverage_and_add_false_alarms(woods):
    ideal = simulate(woods, write=False)
    run = simulate(_geiger(woods, n_ref=0.5, solar_rate_hz=3e7, pulses=1, coincidence=1), write=False)
    d = run.measures.detection
    assert d.false_alarms > 0 and 0 < d.false_alarm_probability < 1
    assert d.target_detection < 1.0
    assert run.measures.obscured_coverage < ideal.measures.obscured_coverage
    # Noise never counts as coverage: every declared voxel is a voxel the ideal model returns.
    ideal_keys = {tuple(v) for v in ideal.scene_output}
    assert {tuple(v) for v in run.scene_output} <= ideal_keys


def test_false_alarm_probability_per_bin_is_the_noise_rates_poisson_share(woods):
    """One pulse, k = 1 and a detector that re-arms after each bin: a bin holding no return
    fires alone, with probability 1 - exp(-N), N = rate x 2 x bin width / c (3 sigma)."""
    from ladartui.detection import noise_per_bin

    rate, width = 4e7, 1.0  # N = 0.267 counts a bin
    assert woods.sensor.depth_resolution == width  # the default bin width
    run = simulate(
        _geiger(
            woods, n_ref=0.5, solar_rate_hz=rate, dark_rate_hz=0.0, dead_time_m=width, pulses=1, coincidence=1
        ),
        write=False,
    )
    d = run.measures.detection
    p = 1 - math.exp(-rate * 2 * width / 299_792_458.0)
    assert p == pytest.approx(1 - math.exp(-noise_per_bin(rate, width)))
    noise_bins = round(d.false_alarms / d.false_alarm_probability)
    assert noise_bins > 2000  # enough trials that 3 sigma is a few per cent of p
    sigma = math.sqrt(p * (1 - p) / noise_bins)
    assert abs(d.false_alarm_probability - p) <= 3 * sigma, (d.false_alarm_probability, p, sigma)
    # Per look: the false alarms over the run's three looks.
    assert d.false_alarms_per_look == pytest.approx(d.false_alarms / 3)


def test_run_agrees_with_the_pulse_study_row(woods):
    scenario = _geiger(woods, pulses=10, coincidence=2, solar_rate_hz=1e7, seed=4)
    run = simulate(scenario, write=False)
    ideal, (row,) = pulse_study(scenario, [10])
    d = run.measures.detection
    assert row.threshold == 2
    assert (row.obscured_coverage, row.false_alarms, row.declared_points) == (
        run.measures.obscured_coverage,
        d.false_alarms,
        d.declared_points,
    )
    assert row.target_detection == d.target_detection and ideal == d.ideal_obscured_coverage


def test_with_no_target_return_the_run_and_the_pulse_study_leave_p_d_undefined(woods, capsys):
    """The pulse study said P_d 0.000 (0.0 in its JSON) where the run said undefined."""
    away = aim_at(ScanPose(60.0, 60.0, 40.0), (70.0, 70.0, 0.0))  # sees only ground
    scenario = _geiger(woods, pulses=10, coincidence=2)
    scenario = scenario.with_changes(flight=FlightPlan(segments=[Manual((away,))])).save()
    d = simulate(scenario, write=False).measures.detection
    _, (row,) = pulse_study(scenario, [10])
    assert d.target_detection is None and row.target_detection is None
    assert main(["pulses", str(scenario.path), "--pulses", "10", "--no-chart"]) == 0
    assert capsys.readouterr().out.splitlines()[-1].split()[-1] == "undefined"


def test_cli_run_writes_and_reads_back_the_detection_measures(woods, capsys):
    scenario = _geiger(woods, pulses=5, coincidence=2).save()
    assert "[detection]" in scenario.path.read_text()
    assert main(["run", str(scenario.path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["measures"]["detection"]["pulses"] == 5
    measures = read_cmf(scenario.measures_file)
    assert measures.detection.coincidence == 2
    assert out["measures"] == json.loads(json.dumps(measures.to_dict()))
    assert main(["run", str(scenario.path), "--no-write"]) == 0
    assert "Geiger-mode detection: 5 pulses per look, k = 2" in capsys.readouterr().out


def test_same_seed_same_answer_over_threads_and_chunks(woods, monkeypatch):
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba runs one thread here")
    scenario = _geiger(woods, pulses=20, coincidence=3, solar_rate_hz=1e7, seed=123).save()
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        simulate(scenario)
        one = _outputs(scenario)
        numba.set_num_threads(2)
        simulate(scenario)
        assert _outputs(scenario) == one
    finally:
        numba.set_num_threads(before)
    monkeypatch.setattr(simulation, "_FIRST_CHUNK_RAYS", 256)
    monkeypatch.setattr(simulation, "_MAX_CHUNK_RAYS", 256)
    simulate(scenario)
    assert _outputs(scenario) == one
    other_seed = simulate(
        scenario.with_changes(
            detection=DetectionSettings(model="geiger", pulses=20, coincidence=3, solar_rate_hz=1e7, seed=124)
        ),
        write=False,
    )
    assert other_seed.measures.detection != read_cmf(scenario.measures_file).detection


def test_same_seed_same_answer_on_both_backends(woods, wgpu_backend):
    scenario = _geiger(woods, pulses=20, coincidence=3, solar_rate_hz=1e7, seed=9)
    on_numba = simulate(scenario, backend="numba", write=False)
    on_wgpu = simulate(scenario, backend="wgpu", write=False)
    assert on_wgpu.backend == "wgpu"
    np.testing.assert_array_equal(on_numba.scene_output, on_wgpu.scene_output)
    np.testing.assert_array_equal(on_numba.target_output, on_wgpu.target_output)
    assert on_numba.measures == on_wgpu.measures


@pytest.mark.parametrize("model", ['model = "ideal"\n', "# no model: ideal\n"])
def test_validate_notes_geiger_keys_that_the_ideal_model_does_not_use(woods, capsys, model):
    """[detection] model = "ideal" with pulses = 10 was taken without a word: a run
    used the ideal sensor and no pulses at all."""
    path = woods.save().path
    text = path.read_text(encoding="utf-8")
    line = text.count("\n") + 4  # pulses: after a blank line, the header and the model line
    path.write_text(text + f"\n[detection]\n{model}pulses = 10\nn_ref = 3.0\n", "utf-8")
    assert main(["validate", str(path)]) == 0
    default = "" if model.startswith("model") else " (the default)"
    assert (
        f"\nnote       {path}:{line}: detection.pulses, detection.n_ref: Geiger-mode keys that "
        f'model "ideal"{default} does not use (model = "geiger" runs them; ladartui pulses '
        "reads them as they are)\n"
    ) in capsys.readouterr().out
    path.write_text(text + '\n[detection]\nmodel = "geiger"\npulses = 10\n', "utf-8")
    assert main(["validate", str(path)]) == 0
    assert "note       " not in capsys.readouterr().out


@pytest.mark.parametrize(
    "probability, shown",
    [(3.2e-8, "3.20e-08"), (0.0, "0.000000"), (0.0123, "0.012300"), (None, "undefined")],
)
def test_a_false_alarm_probability_below_the_shown_decimals_is_not_shown_as_zero(probability, shown):
    """A per-bin probability of 3.2e-8 read 0.000000: as if noise never fired."""
    from rich.console import Console

    from ladartui.cli.run import detection_table
    from ladartui.detection.measures import DetectionMeasures

    console = Console(width=120, record=True)
    counts = {"pulses": 100, "coincidence": 10, "seed": 0, "declared_points": 5, "false_alarms": 1}
    console.print(detection_table(DetectionMeasures(**counts, false_alarm_probability=probability)))
    row = next(line for line in console.export_text().splitlines() if "false-alarm probability" in line)
    assert row.split()[-2] == shown


def test_one_pulse_a_look_is_said_in_the_singular(woods, capsys):
    """'1 pulses per look' in the run's table and the scenario's summary."""
    scenario = _geiger(woods, pulses=1, coincidence=1).save()
    assert "detection  geiger, 1 pulse, k = 1" in scenario.summary()
    assert main(["run", str(scenario.path), "--no-write"]) == 0
    assert "Geiger-mode detection: 1 pulse per look, k = 1" in capsys.readouterr().out
