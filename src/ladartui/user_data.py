"""The user's folders, and the built-in default scenario materialised in one.

The default scenario ships as package data (``ladartui/scenarios/default.toml``);
its scene is generated, never shipped. ``default_scenario_path()`` puts both in
the user data folder on first use and returns the scenario's path:

    $LADARTUI_HOME/default/                      if LADARTUI_HOME is set
    $XDG_DATA_HOME/ladartui/default/             else, if XDG_DATA_HOME is set
    ~/.local/share/ladartui/default/             otherwise

Settings (recent files, keys) live in ``config_folder()``: ``$LADARTUI_HOME/config``
when that is set, else the platform's user config folder. This module sits
above ``scenario.py``, which it uses; nothing below imports it.
"""

from __future__ import annotations

import contextlib
import math
import os
from dataclasses import replace
from importlib import resources
from pathlib import Path

import platformdirs

from ladartui.atomic import write_text_atomic
from ladartui.defaults import target_centre
from ladartui.flight import Orbit
from ladartui.scenario import scenario_from_toml

DEFAULT_PRESET = "small"
DEFAULT_SCENARIO_NAME = "default.toml"


def config_folder() -> Path:
    if os.environ.get("LADARTUI_HOME"):
        return Path(os.environ["LADARTUI_HOME"]).expanduser() / "config"
    return platformdirs.user_config_path("ladartui")


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
    from ladartui.scene.generate import generate_scene

    scene = generate_scene(DEFAULT_PRESET)
    scene.write(folder / DEFAULT_PRESET)
    text = default_scenario_text()
    packaged = scenario_from_toml(text, folder / DEFAULT_SCENARIO_NAME)
    # The packaged orbit names the small scene's target centre; follow the
    # generator if its scene ever moves the target.
    centre = target_centre(scene.target, scene.voxel_size)
    segments = tuple(_recentred(seg, centre) for seg in packaged.flight.segments)
    scenario = packaged.with_changes(
        voxel_size=float(scene.voxel_size), flight=replace(packaged.flight, segments=segments)
    )
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
