"""The built-in default scenario: an orbit around the target of the "small" generated scene.

The scenario ships as package data (``ladartui/scenarios/default.toml``); its
scene is generated, never shipped. ``default_scenario_path()`` puts both in the
user data folder on first use and returns the scenario's path:

    $LADARTUI_HOME/default/                      if LADARTUI_HOME is set
    $XDG_DATA_HOME/ladartui/default/             else, if XDG_DATA_HOME is set
    ~/.local/share/ladartui/default/             otherwise
"""

from __future__ import annotations

import contextlib
import math
import os
from dataclasses import replace
from importlib import resources
from pathlib import Path

import numpy as np

from ladartui.atomic import write_text_atomic
from ladartui.flight import FlightPlan, Orbit
from ladartui.sensor import Sensor

DEFAULT_PRESET = "small"
DEFAULT_SCENARIO_NAME = "default.toml"

# 64 x 64 detectors with 2 x 2 rays: 16,384 rays per scan, a few seconds for a
# full orbit on two cores. An 8 degree view from ~85 m slant range covers about
# 12 m across (17 m along the look direction at 45 degrees depression): a
# vehicle with a generous margin for a cue that is a few metres off.
DEFAULT_SENSOR = Sensor(grid=64, ray_grid=2, fov=8.0, depth_resolution=1.0, pixel_pitch=100e-6)
DEFAULT_SCANS = 24
DEFAULT_DEPRESSION = 45.0
MIN_SLANT_RANGE = 85.0  # metres
VIEW_MARGIN = 1.5  # footprint width over the target's horizontal size


def data_home() -> Path:
    """The user data folder of ladartui (default scenario, benchmark scenes)."""
    if os.environ.get("LADARTUI_HOME"):
        return Path(os.environ["LADARTUI_HOME"]).expanduser()
    base = os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share"
    return Path(base).expanduser() / "ladartui"


def default_folder() -> Path:
    return data_home() / "default"


def default_scenario_text() -> str:
    """The packaged default scenario (TOML)."""
    return (resources.files("ladartui") / "scenarios" / DEFAULT_SCENARIO_NAME).read_text("utf-8")


def target_centre(target_voxels, voxel_size) -> tuple[float, float, float]:
    """Centroid of the target voxel centres in metres."""
    centre = np.asarray(target_voxels, dtype=np.float64).mean(axis=0) * float(voxel_size)
    return tuple(float(c) for c in centre)


def default_flight(target_voxels, voxel_size, sensor: Sensor = DEFAULT_SENSOR) -> FlightPlan:
    """A 24-scan clockwise orbit at 45 degrees depression around the target's centre.

    The slant range is at least 85 m and far enough that the sensor's view is
    ``VIEW_MARGIN`` times the target's horizontal size.
    """
    voxels = np.asarray(target_voxels)
    centre = target_centre(voxels, voxel_size)
    span = (voxels.max(axis=0) - voxels.min(axis=0) + 1) * float(voxel_size)
    size = math.hypot(span[0], span[1])
    slant = max(MIN_SLANT_RANGE, VIEW_MARGIN * size / (2 * math.tan(math.radians(sensor.fov / 2))))
    radius = slant * math.cos(math.radians(DEFAULT_DEPRESSION))
    altitude = centre[2] + slant * math.sin(math.radians(DEFAULT_DEPRESSION))
    orbit = Orbit(centre=centre, radius=round(radius, 1), altitude=round(altitude, 1),
                  scans=DEFAULT_SCANS)
    return FlightPlan(None, (orbit,))


def default_scenario_path() -> Path:
    """The default scenario in the user data folder, created with its scene on first use.

    Idempotent: when the scenario and both model files are there it returns at once.
    """
    folder = default_folder()
    scenario_path = folder / DEFAULT_SCENARIO_NAME
    if _complete(folder):
        return scenario_path
    folder.mkdir(parents=True, exist_ok=True)
    with _lock(folder / ".lock"):
        if not _complete(folder):  # another process may have finished meanwhile
            _materialise(folder)
    return scenario_path


def _model_files(folder: Path):
    return folder / f"{DEFAULT_PRESET}.txt", folder / f"{DEFAULT_PRESET}_Target.txt"


def _complete(folder: Path) -> bool:
    return all(p.is_file() for p in (folder / DEFAULT_SCENARIO_NAME, *_model_files(folder)))


def _materialise(folder: Path) -> None:
    from ladartui.scenario import scenario_from_toml
    from ladartui.scene.generate import generate_scene

    scene = generate_scene(DEFAULT_PRESET)
    scene.write(folder / DEFAULT_PRESET)
    text = default_scenario_text()
    packaged = scenario_from_toml(text, folder / DEFAULT_SCENARIO_NAME)
    # The packaged orbit names the small scene's target centre; follow the
    # generator if its scene ever moves the target.
    centre = target_centre(scene.target, scene.voxel_size)
    segments = tuple(_recentred(seg, centre) for seg in packaged.flight.segments)
    scenario = packaged.with_changes(voxel_size=float(scene.voxel_size),
                                     flight=replace(packaged.flight, segments=segments))
    # Written last: its presence marks the folder complete. Keep the packaged
    # text (with its comments) when nothing had to change.
    if scenario == packaged:
        write_text_atomic(scenario.path, text)
    else:
        scenario.save()


def _recentred(segment, centre):
    # The packaged centre is rounded to millimetres.
    if isinstance(segment, Orbit) and math.dist(segment.centre, centre) > 0.01:
        return replace(segment, centre=tuple(round(c, 3) for c in centre), aim_at=None)
    return segment


@contextlib.contextmanager
def _lock(path: Path):
    """An exclusive lock between processes materialising the same folder (POSIX)."""
    try:
        import fcntl
    except ImportError:  # not POSIX: atomic writes alone keep the files whole
        yield
        return
    with open(path, "a+b") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)
