"""With the realism options off, outputs and measures are the report's ideal model, byte for byte.

Each scenario (the default one and the examples in scenarios/, their sensors
made smaller to keep this quick) is run three ways and every written file
compared byte for byte:

- as written (no [detection] section, no mount: the options absent);
- with the options spelled out at their defaults ([detection] model =
  "ideal", mount = "stabilised");
- by the ideal model's own steps, called here without ``simulate``: the
  report's rays (``Sensor.rays`` without attitude), ``trace``, the depth
  rule, fusion and ``compute_measures`` (the path before the options existed).
"""

import dataclasses
import shutil
from pathlib import Path

import pytest

from ladartui.levels import target_levels
from ladartui.measures import compute_measures
from ladartui.returns import fuse_scans, scan_returns
from ladartui.scenario import load_scenario
from ladartui.scene.voxels import save_voxels
from ladartui.sensor import Sensor
from ladartui.simulation import simulate
from ladartui.target_measures import LevelInputs, compute_target_measures
from ladartui.tracing import trace
from ladartui.user_data import default_scenario_path

EXAMPLES = Path(__file__).resolve().parents[1] / "scenarios"


@pytest.fixture(scope="module")
def small_scene():
    # The default scenario generates the "small" scene in the data folder; the
    # examples expect it at generated/small.txt beside them.
    path = default_scenario_path()
    return path, path.parent / "small.txt"


def _copy(name, tmp_path, small_scene, extra=""):
    default, scene = small_scene
    source = default if name == "default" else EXAMPLES / f"{name}.toml"
    folder = tmp_path / name
    (folder / "generated").mkdir(parents=True)
    for stem in ("small.txt", "small_Target.txt"):
        shutil.copy(scene.parent / stem, folder / stem)
        shutil.copy(scene.parent / stem, folder / "generated" / stem)
    text = source.read_text(encoding="utf-8") + extra
    path = folder / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    scenario = load_scenario(path)
    s = scenario.sensor
    small = Sensor(
        grid=24,
        ray_grid=2,
        fov=s.fov,
        depth_resolution=s.depth_resolution,
        pixel_pitch=s.pixel_pitch,
        mount=s.mount,
    )
    return scenario.with_changes(sensor=small, backend="numba")


def _files(scenario):
    return [p.read_bytes() for p in (scenario.scene_output, scenario.target_output, scenario.measures_file)]


def _ideal_by_hand(scenario, folder):
    """The ideal model's outputs from its steps, without simulate's option hooks."""
    scene = scenario.load_scene()
    per_scan = {"scene": [], "target": []}
    for pose in scenario.poses():
        origins, directions, detector = scenario.sensor.rays(pose)
        for run, occupancy in (("scene", scene.occupancy), ("target", scene.target_occupancy)):
            hits = trace(
                occupancy,
                origins,
                directions,
                voxel_size=scene.voxel_size,
                backend="numba",
                method=scenario.method,
                step=scenario.step,
                precision=scenario.precision,
            )
            per_scan[run].append(scan_returns(hits, detector, scenario.sensor.depth_resolution))
    scene_output, target_output = fuse_scans(per_scan["scene"]), fuse_scans(per_scan["target"])
    measures = compute_measures(
        scene.target,
        scene_output,
        target_output,
        scene_per_scan=per_scan["scene"],
        target_per_scan=per_scan["target"],
        path_length_m=scenario.path_length(),
        flight_time_s=scenario.flight_time(),
        voxel_size=scene.voxel_size,
    )
    # Detect / recognise / identify belong to every run's measures (not an option).
    levels = target_levels(
        scene.target,
        per_scan["scene"],
        scenario.flight.scan_times(scenario.speed),
        scenario.flight.scan_distances(),
        scenario.level_thresholds,
    )
    measures = dataclasses.replace(measures, levels=levels)
    # Every run scores each target of the target model too (one here).
    per_target = compute_target_measures(
        scene.target,
        scene.target_ids,
        scene_output,
        target_output,
        per_scan["scene"],
        per_scan["target"],
        levels=LevelInputs(
            scenario.flight.scan_times(scenario.speed),
            scenario.flight.scan_distances(),
            scenario.level_thresholds,
        ),
        path_length_m=measures.path_length_m,
        flight_time_s=measures.flight_time_s,
        voxel_size=measures.voxel_size,
    )
    measures = dataclasses.replace(measures, targets=per_target)
    folder.mkdir()
    save_voxels(folder / "scene.txt", scene_output)
    save_voxels(folder / "target.txt", target_output)
    (folder / "m.cmf").write_text(measures.to_cmf(), encoding="utf-8")
    return [(folder / n).read_bytes() for n in ("scene.txt", "target.txt", "m.cmf")], measures


@pytest.mark.parametrize("name", ["default", "orbit", "flypast", "standoff", "manoeuvres"])
def test_options_off_are_byte_identical(name, tmp_path, small_scene):
    absent = _copy(name, tmp_path / "absent", small_scene)
    explicit = _copy(name, tmp_path / "explicit", small_scene, extra='\n[detection]\nmodel = "ideal"\n')
    explicit = explicit.with_changes(sensor=Sensor(**{**vars(explicit.sensor), "mount": "stabilised"}))
    assert absent.detection is None and explicit.detection.model == "ideal"

    result = simulate(absent)
    by_hand, measures = _ideal_by_hand(absent, tmp_path / "by-hand")
    assert result.measures == measures and result.measures.detection is None
    assert "detection" not in result.measures.to_dict()
    assert _files(absent) == by_hand

    simulate(explicit)
    assert _files(explicit) == by_hand
