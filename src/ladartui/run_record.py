"""The run record: the settings that made a run's outputs, written beside them.

A run of ``S.toml`` writes ``S_Run.toml`` with ``S_Scene.txt``, ``S_Target.txt``
and ``S.cmf``, in the same all-or-nothing output set. It is a whole scenario
file: the settings as they ran, which need not be the saved ones (the TUI runs
unsaved edits; ``ladartui run --method`` overrides the file). Opening ``S.toml``
compares it with the record to say whether the outputs are out of date. A set
written before records existed has none; it then counts as the saved file's.

A file of that name that is not a record (its first line is not
``RECORD_HEADER``) is the analyst's own: a run refuses to replace it.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ladartui.errors import LadarError, OutputFileError
from ladartui.scenario_file import RECORD_HEADER, is_record
from ladartui.textsafe import one_line

__all__ = ["RECORD_HEADER", "is_record", "read_run_record", "setting_changes"]


def as_run(scenario, backend=None, method=None, step=None, precision=None):
    """``scenario`` as a run with these overrides (None: the scenario's own) goes,
    placed at its record's path."""
    overrides = {"backend": backend, "method": method, "step": step, "precision": precision}
    changes = {key: value for key, value in overrides.items() if value is not None}
    return scenario.with_changes(path=scenario.run_record, **changes)


def record_text(scenario, ran) -> str:
    """The record's text for a run of ``scenario`` that went as ``ran`` (``as_run``)."""
    # names in comments escaped: a control character there is not TOML
    name = one_line(scenario.path.name)
    scene, target = one_line(scenario.scene_output.name), one_line(scenario.target_output.name)
    header = (
        f"{RECORD_HEADER}: the settings that made {scene}, "
        f"{target} and {one_line(scenario.measures_file.name)},\n"
        f"# written with them by a run of {name} (replaced by its next run).\n"
        f"# They may differ from {name}: a run can go with unsaved edits or flags.\n\n"
    )
    return header + ran.toml_body()


def check_record_spare(scenario) -> None:
    """Refuse a run that would replace a file of the record's name that is not one."""
    path = scenario.run_record
    if path.exists() and not is_record(path):
        raise OutputFileError(
            path,
            f"exists and is not a run record of {scenario.path.name} (a run writes its "
            "settings there): rename that file",
        )


def read_run_record(scenario):
    """The settings that made ``scenario``'s outputs, from its record; None when
    there is none. A record that cannot be read raises ``LadarError`` naming it."""
    from ladartui.scenario import load_scenario

    path = scenario.run_record
    if not path.is_file():
        return None
    if not is_record(path):
        raise LadarError(f"{path}: not a run record (its first line is not {RECORD_HEADER!r})")
    return load_scenario(path, check_files=False)


def setting_changes(ran, scenario) -> list[str]:
    """The settings that made the outputs (``ran``, the record) where they differ from
    ``scenario``'s, as "sensor.grid 12 (here 8)", in file order; empty when a run of
    ``scenario`` writes the same (``Scenario.same_outputs``)."""
    was, now = _flat(ran.to_dict()), _flat(ran.outputs_alike(scenario).to_dict())
    keys = [*was, *(key for key in now if key not in was)]
    return [
        f"{key} {_shown(was.get(key))} (here {_shown(now.get(key))})"
        for key in keys
        if was.get(key) != now.get(key)
    ]


def _flat(data, prefix: str = "") -> dict:
    """Nested TOML data as dotted keys; a list of tables by index from 0, as errors name
    them (flight.segments[0].radius)."""
    out = {}
    if isinstance(data, dict):
        items = [(f"{prefix}{key}", value) for key, value in data.items()]
    else:
        items = [(f"{prefix.removesuffix('.')}[{index}]", value) for index, value in enumerate(data)]
    for name, value in items:
        if isinstance(value, dict) or (isinstance(value, list) and value and isinstance(value[0], dict)):
            out.update(_flat(value, name + "."))
        else:
            out[name] = value
    return out


def _shown(value) -> str:
    if value is None:
        return "none"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, list):
        return "[" + ", ".join(_shown(v) for v in value) + "]"
    return str(value)


def missing_outputs(scenario, is_file: Callable[[Path], bool] = Path.is_file) -> list:
    """The outputs of a partial set: empty when all are on disk or none are (not run).
    ``is_file`` answers from a look already taken (the TUI's one stat of each)."""
    outputs = [scenario.scene_output, scenario.target_output, scenario.measures_file]
    missing = [path for path in outputs if not is_file(path)]
    return [] if len(missing) == len(outputs) else missing


def earlier_las(scenario) -> list:
    """LAS copies of the outputs that an earlier run left (``run --las``) beside a set
    written without them: older than the set's measures, which a set writes before
    its LAS copies."""
    measures = scenario.measures_file
    try:
        written = measures.stat().st_mtime_ns
    except OSError:
        return []
    found = []
    for output in (scenario.scene_output, scenario.target_output):
        las = output.with_suffix(".las")
        try:
            if las.stat().st_mtime_ns < written:
                found.append(las)
        except OSError:
            continue
    return found
