"""The user's folders, and the bundled scenarios materialised in one.

Bundled scenarios ship as package data (``ladartui/scenarios/NAME.toml``:
``default``, and ``convoy``, three vehicles, one under a camouflage net);
their scenes are generated, never shipped. ``bundled_scenario_path(NAME)``
(``default_scenario_path()`` for the default) puts a scenario and its scene in
the user data folder on first use and returns the scenario's path (a model file
lost later is generated again; the scenario file, perhaps edited, is kept):

    $LADARTUI_HOME/NAME/                         if LADARTUI_HOME is set
    $XDG_DATA_HOME/ladartui/NAME/                else, if XDG_DATA_HOME is set
    ~/.local/share/ladartui/NAME/                otherwise

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
from ladartui.defaults import target_centre, to_millimetres
from ladartui.fileprobe import path_field, user_path
from ladartui.flight import Orbit
from ladartui.scenario import Scenario, scenario_from_toml
from ladartui.scenario import load_scenario as load_scenario_file

DEFAULT_PRESET = "small"
DEFAULT_SCENARIO_NAME = "default.toml"
# Bundled scenario name -> (generator preset, overrides) of the scene it names.
BUNDLED = {
    "default": (DEFAULT_PRESET, {}),
    "convoy": (DEFAULT_PRESET, {"vehicles": 3, "camouflage": True}),
}


def config_folder() -> Path:
    if os.environ.get("LADARTUI_HOME"):
        return user_path(os.environ["LADARTUI_HOME"]) / "config"
    if not os.environ.get("XDG_CONFIG_HOME"):
        home_folder()  # platformdirs would name a folder "~" in the current one
    return platformdirs.user_config_path("ladartui")


def data_home() -> Path:
    """The user data folder of ladartui (default scenario, benchmark scenes)."""
    if os.environ.get("LADARTUI_HOME"):
        return user_path(os.environ["LADARTUI_HOME"])
    base = os.environ.get("XDG_DATA_HOME") or home_folder() / ".local" / "share"
    return user_path(base) / "ladartui"


def home_folder() -> Path:
    """The user's home folder; a LadarError where there is none: no HOME, and a user id
    the password database does not know (a container or batch job given a bare user
    id), where pathlib raised RuntimeError."""
    home = os.path.expanduser("~")
    if home.startswith("~"):
        from ladartui.errors import LadarError

        raise LadarError(
            f"no home folder: HOME is not set and user id {os.getuid()} has no entry in the "
            "password database; set LADARTUI_HOME (or XDG_DATA_HOME and XDG_CONFIG_HOME) to a "
            "folder for ladartui's data and settings"
        )
    return Path(home)


def made_folder(folder: Path) -> Path:
    """``folder``, a folder in the user data folder, made when missing; an OutputFileError
    naming it and the variable that placed the data folder when it cannot be made."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        from ladartui.errors import OutputFileError, os_reason

        reason = os_reason(error)
        source = next(
            (name for name in ("LADARTUI_HOME", "XDG_DATA_HOME") if os.environ.get(name)),
            "default (~/.local/share/ladartui)",
        )
        raise OutputFileError(
            folder,
            f"cannot be made ({reason.lower()}); it is in the user data folder {data_home()}, "
            f"set by {source}",
        ) from None
    return folder


def default_folder() -> Path:
    return data_home() / "default"


def default_scenario_text() -> str:
    """The packaged default scenario (TOML)."""
    return bundled_scenario_text("default")


def bundled_scenario_text(name: str) -> str:
    """The packaged scenario ``name`` (TOML)."""
    return (resources.files("ladartui") / "scenarios" / f"{name}.toml").read_text("utf-8")


def default_scenario_path() -> Path:
    """The default scenario in the user data folder, created with its scene on first use.

    Idempotent: when the scenario and both model files are there it returns at once.
    """
    return bundled_scenario_path("default")


def bundled_scenario_path(name: str) -> Path:
    """The bundled scenario ``name`` in the user data folder, made with its scene on first use."""
    if name not in BUNDLED:
        from ladartui.errors import FieldError

        raise FieldError("scenario", name, "a bundled scenario: " + ", ".join(BUNDLED))
    folder = data_home() / name
    scenario_path = folder / f"{name}.toml"
    if _complete(folder, name):
        return scenario_path
    made_folder(folder)
    with _lock(folder / ".lock"):
        if not _complete(folder, name):  # another process may have finished meanwhile
            _materialise(folder, name)
    return scenario_path


def bundled_scenario_name(argument) -> str | None:
    """The bundled scenario ``argument`` names (``convoy`` or ``convoy.toml``, no folder), else None.
    A folder written in it (``./convoy``) makes it a path, never a name."""
    if _names_a_folder(argument):
        return None
    path = Path(argument)
    stem = path.stem if path.suffix == ".toml" else path.name
    return stem if path.parent == Path(".") and stem in BUNDLED else None


def _names_a_folder(argument) -> bool:
    text = os.fspath(argument)
    return any(sep in text for sep in (os.sep, os.altsep) if sep)


def bundled_or_path(argument) -> Path:
    """A scenario argument as a path: an existing file as it is, else a bundled name
    (``convoy`` or ``convoy.toml``, with no folder) made ready in the user data folder."""
    path = Path(argument)
    name = bundled_scenario_name(argument)
    if name is not None and not path.is_file():  # a folder of that name is no scenario file
        return bundled_scenario_path(name)
    bare = path.parent == Path(".") and not _names_a_folder(argument)
    if bare and path.suffix in ("", ".toml") and not os.path.lexists(path):  # (a link that loops is there)
        from ladartui.errors import InputFileError
        from ladartui.fileprobe import no_such_file

        # a bare name: perhaps a bundled one mistyped
        expected = "expected a scenario file (.toml) or a bundled scenario: " + ", ".join(BUNDLED)
        raise InputFileError(path.absolute(), f"{no_such_file(path)}; {expected}")
    return path


def bundled_run(argument) -> Path:
    """A file argument as a path, a bundled scenario's bare name (as ``bundled_or_path``
    takes it) standing for that scenario where no file of the name is here; for reading
    what its runs wrote, so one not made yet is not made (``InputFileError``: no run)."""
    path = user_path(argument)
    name = bundled_scenario_name(argument)
    if name is None or path.is_file():
        return path
    scenario = data_home() / name / f"{name}.toml"
    if not scenario.is_file():
        from ladartui.errors import InputFileError

        raise InputFileError(
            scenario.with_suffix(".cmf"), f"measures file of {scenario.name} not found: run it first"
        )
    return scenario


def load_scenario(path, check_files=True) -> Scenario:
    """``ladartui.load_scenario``: ``scenario.load_scenario``, taking a bundled scenario's
    bare name ("default", "convoy") as the commands do, made ready on first use (a
    file of that name where Python runs wins)."""
    checked = path_field("path", path, "a scenario file's path")
    return load_scenario_file(bundled_or_path(path if isinstance(path, str) else checked), check_files)


def _model_files(folder: Path, name: str):
    from ladartui.scenario import target_file_for

    scene_file = scenario_from_toml(bundled_scenario_text(name), folder / f"{name}.toml").scene_file
    return scene_file, target_file_for(scene_file)


def _complete(folder: Path, name: str) -> bool:
    if not (folder / f"{name}.toml").is_file():
        return False
    return all(p.is_file() for p in _model_files(folder, name))


def _materialise(folder: Path, name: str) -> None:
    """Generate the scene, then write the scenario file unless the user's copy is there
    (perhaps edited: a lost model file is made again, never the user's settings)."""
    from ladartui.scene.generate import generate_scene

    preset, overrides = BUNDLED[name]
    scene = generate_scene(preset, **overrides)
    scene.write(_model_files(folder, name)[0])
    if (folder / f"{name}.toml").is_file():
        return
    text = bundled_scenario_text(name)
    packaged = scenario_from_toml(text, folder / f"{name}.toml")
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
        return replace(segment, centre=to_millimetres(centre), aim_at=None)
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
