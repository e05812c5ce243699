"""What a study traces: a scene, a sensor and scan poses, from a scenario or a default.

Without a scenario the study uses a generated scene (``reference`` by default,
``small`` for a quick check), cached under the data folder (``LADARTUI_HOME``,
else ``~/.local/share/ladartui``, in ``scenes/``) so it is generated once, and
the default scenario's orbit around the target at 45 degrees depression.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ladartui.atomic import write_text_atomic
from ladartui.errors import FieldError
from ladartui.number_text import plural
from ladartui.user_data import data_home

if TYPE_CHECKING:
    from ladartui.scene.model import Scene
    from ladartui.sensor import Sensor

DEFAULT_SCANS = 8


@dataclass
class StudyInputs:
    """A scene, a sensor and the scan poses to trace; ``name`` says where they came from.
    ``attitudes``: per pose, the aircraft's (roll, pitch) turning a body-fixed sensor's
    rays, as a run of the scenario turns them (None, or None for a pose: stabilised)."""

    scene: Scene
    sensor: Sensor
    poses: list
    name: str
    notes: list = field(default_factory=list)
    attitudes: list | None = None

    def attitude(self, scan: int):
        """The attitude the rays of scan ``scan`` (0-based) are turned by; None: stabilised."""
        return None if self.attitudes is None else self.attitudes[scan]

    def describe(self) -> dict:
        scene = self.scene
        return {
            "name": self.name,
            "scene": scene.name,
            "voxels": int(len(scene.voxels)),
            "target_voxels": int(len(scene.target)),
            "shape": list(scene.shape),
            "voxel_size_m": scene.voxel_size,
            "scans": len(self.poses),
            "sensor": {
                "grid": self.sensor.grid,
                "fov_deg": self.sensor.fov,
                "depth_resolution_m": self.sensor.depth_resolution,
                "mount": self.sensor.mount,
            },
            "poses": [p.to_dict() for p in self.poses],
        }


def pick_scans(poses, limit: int | None, closed: bool = False):
    """At most ``limit`` poses, evenly spread over the flight (first one included): over
    its length, both ends kept, or where the flight is ``closed`` around its loop."""
    poses = list(poses)
    if limit is None or len(poses) <= limit:
        return poses
    if closed:
        picks = (np.arange(limit) * (len(poses) / limit)).round().astype(int)
    else:
        picks = np.linspace(0, len(poses) - 1, limit).round().astype(int)
    return [poses[i] for i in sorted(set(picks.tolist()))]


def check_scans(field: str, scans: int | None, available: int, flight: str) -> None:
    """FieldError ``field`` when more scans are asked for than ``flight`` has."""
    if scans is not None and scans > available:
        raise FieldError(field, scans, f"at most {available}: {flight} has {plural(available, 'scan')}")


def scenario_inputs(path, scans: int | None = DEFAULT_SCANS, refuse_as: str | None = None) -> StudyInputs:
    """The scene, sensor and poses of the scenario file at ``path``. More ``scans`` than
    the flight has: all of them, or with ``refuse_as`` (a flag) a FieldError naming it."""
    from ladartui.attitude import plan_attitudes
    from ladartui.scenario import load_scenario

    scenario = load_scenario(path)
    all_poses = list(scenario.poses())
    if refuse_as:
        check_scans(refuse_as, scans, len(all_poses), f"the flight of {path}")  # before the scene loads
    scene = scenario.load_scene()
    picks = pick_scans(range(len(all_poses)), scans, scenario.flight.closed)
    poses = [all_poses[i] for i in picks]
    attitudes = plan_attitudes(scenario.flight, scenario.speed, scenario.sensor)  # as a run turns its rays
    inputs = StudyInputs(scene, scenario.sensor, poses, str(path), attitudes=[attitudes[i] for i in picks])
    if len(poses) < len(all_poses):
        inputs.notes.append(
            f"{len(poses)} of the scenario's {len(all_poses)} scans traced "
            f"(evenly spread{' around its orbit' if scenario.flight.closed else ''}; --scans changes this)."
        )
    return inputs


def generated_inputs(
    preset: str = "reference", scans: int = DEFAULT_SCANS, progress=None, refuse_as: str | None = None
) -> StudyInputs:
    """A cached generated scene, the full-size sensor and the default orbit aimed at the target.

    The sensor is the default ``Sensor()`` (128 x 128 detectors, 10 degree view);
    the flight is the default scenario's orbit at 45 degrees depression, of which
    ``scans`` evenly spread scans are traced (``refuse_as`` as for ``scenario_inputs``).
    """
    from ladartui import defaults
    from ladartui.defaults import default_flight
    from ladartui.sensor import Sensor

    if refuse_as:  # the orbit's scan count needs no scene: checked before one is loaded or made
        check_scans(refuse_as, scans, defaults.DEFAULT_SCANS, "the default orbit")
    scene = cached_scene(preset, progress=progress)
    sensor = Sensor()
    flight = default_flight(scene.target, scene.voxel_size, sensor)
    all_poses = flight.poses()
    poses = pick_scans(all_poses, scans, flight.closed)
    inputs = StudyInputs(scene, sensor, poses, f"generated scene {preset!r}")
    inputs.notes.append(f"{len(poses)} of the default orbit's {len(all_poses)} scans traced.")
    return inputs


def cached_scene(preset: str, folder=None, progress=None):
    """The generated scene ``preset``, read from the cache or generated and saved there."""
    from ladartui.scene.generate import generate_scene
    from ladartui.scene.model import Scene

    folder = Path(folder) if folder is not None else data_home() / "scenes"
    scene_path = folder / f"{preset}.txt"
    target_path = folder / f"{preset}_Target.txt"
    meta_path = folder / f"{preset}.json"
    if scene_path.is_file() and target_path.is_file() and meta_path.is_file():
        try:
            meta = json.loads(meta_path.read_text())
            return Scene.load(scene_path, meta["voxel_size"], shape=tuple(meta["shape"]))
        except (ValueError, KeyError, OSError):
            pass  # a damaged cache is regenerated below
    if progress is not None:
        progress(f"generating the {preset!r} scene (once; cached in {folder})")
    scene = generate_scene(preset)
    scene.write(folder / preset)
    # The metadata goes last: its presence says the voxel files are complete.
    write_text_atomic(
        meta_path, json.dumps({"voxel_size": scene.voxel_size, "shape": list(scene.shape)}) + "\n"
    )
    return scene.to_scene(name=preset, path=scene_path)


def with_ray_grid(sensor, ray_grid: int):
    return replace(sensor, ray_grid=int(ray_grid))
