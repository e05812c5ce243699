"""The run record: the settings that made a run's outputs, written beside them.

A run of ``S.toml`` writes ``S_Run.toml`` with ``S_Scene.txt``, ``S_Target.txt``
and ``S.cmf``, in the same all-or-nothing output set. It is a whole scenario
file: the settings as they ran, which need not be the saved ones (the TUI runs
unsaved edits; ``ladartui run --method`` overrides the file). Opening ``S.toml``
compares it with the record to say whether the outputs are out of date. A set
written before records existed has none; it then counts as the saved file's.

After the settings, ``[[run.inputs]]`` tables fingerprint each file the run
read (``run_inputs``: scene model, target model, flight logs) by size and
SHA-256, as the loaders read them; ``input_changes`` names one whose contents
differ now. ``[[run.outputs]]`` fingerprint the scene and target outputs and
the measures as the run wrote them; ``outputs_changed`` names one replaced
since. A record older than inputs has no ``[run]`` section; one older than
outputs has no ``outputs``.

A file of that name that is not a record (its first line is not
``RECORD_HEADER``) is the analyst's own: a run refuses to replace it.
"""

from __future__ import annotations

import os
import re
import tomllib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import tomli_w

from ladartui.errors import LadarError, OutputFileError
from ladartui.fingerprint import Fingerprint
from ladartui.scenario_file import RECORD_HEADER, is_record, resolve_path
from ladartui.scenario_writer import relative_path
from ladartui.textsafe import one_line
from ladartui.trajectory import LogSegment

__all__ = [
    "RECORD_HEADER",
    "InputFile",
    "input_changes",
    "inputs_changed",
    "is_record",
    "read_run_record",
    "recorded_inputs",
    "recorded_outputs",
    "outputs_changed",
    "replaced_outputs",
    "run_inputs",
    "setting_changes",
]

INPUT_ROLES = ("scene model", "target model", "flight log")
_INPUTS_COMMENT = "# The files the run read: size in bytes and SHA-256 of their contents.\n"
# The outputs a record fingerprints, by their name in ``simulation.output_paths``.
OUTPUT_ROLES = {"scene": "scene output", "target": "target output", "measures": "measures"}
_OUTPUTS_COMMENT = "# The files the run wrote, as it wrote them.\n"


@dataclass(frozen=True)
class InputFile:
    """A file a run read (or wrote), with the fingerprint of its bytes as read (written)."""

    role: str  # one of INPUT_ROLES, or of OUTPUT_ROLES for an output
    path: Path
    fingerprint: Fingerprint


def as_run(scenario, backend=None, method=None, step=None, precision=None):
    """``scenario`` as a run with these overrides (None: the scenario's own) goes,
    placed at its record's path."""
    overrides = {"backend": backend, "method": method, "step": step, "precision": precision}
    changes = {key: value for key, value in overrides.items() if value is not None}
    return scenario.with_changes(path=scenario.run_record, **changes)


def record_text(scenario, ran, inputs=(), outputs=()) -> str:
    """The record's text for a run of ``scenario`` that went as ``ran`` (``as_run``),
    having read ``inputs`` (``run_inputs``) and written ``outputs`` (``InputFile`` entries
    of the ``OUTPUT_ROLES``)."""
    # names in comments escaped: a control character there is not TOML
    name = one_line(scenario.path.name)
    scene, target = one_line(scenario.scene_output.name), one_line(scenario.target_output.name)
    header = (
        f"{RECORD_HEADER}: the settings that made {scene}, "
        f"{target} and {one_line(scenario.measures_file.name)},\n"
        f"# written with them by a run of {name} (replaced by its next run).\n"
        f"# They may differ from {name}: a run can go with unsaved edits or flags.\n\n"
    )
    folder = scenario.run_record.parent

    def listed(entries) -> list[dict]:
        return [
            {
                "role": entry.role,
                "file": relative_path(entry.path, folder),
                "bytes": entry.fingerprint.size,
                "sha256": entry.fingerprint.sha256,
            }
            for entry in entries
        ]

    text = (
        header + ran.toml_body() + "\n" + _INPUTS_COMMENT + tomli_w.dumps({"run": {"inputs": listed(inputs)}})
    )
    if outputs:
        text += "\n" + _OUTPUTS_COMMENT + tomli_w.dumps({"run": {"outputs": listed(outputs)}})
    return text


def run_inputs(scenario, scene) -> list[InputFile]:
    """The files a run of ``scenario`` over ``scene`` reads, fingerprinted as they
    were read: the scene's model files (none for a scene made from arrays) and the
    scenario's flight logs."""
    found = {}
    for path, fingerprint in scene.fingerprints.items():
        role = "scene model" if path == scene.path else "target model"
        found[path] = InputFile(role, path, fingerprint)
    for segment in scenario.flight.segments:
        if isinstance(segment, LogSegment) and segment.log.fingerprint is not None:
            path = Path(segment.file)
            found.setdefault(path, InputFile("flight log", path, segment.log.fingerprint))
    return list(found.values())


def recorded_inputs(scenario) -> list[InputFile] | None:
    """The files the record says its run read; None when it does not say (a record
    older than that, or none). ``LadarError`` naming the record when it cannot be read."""
    return _recorded(scenario.run_record, "inputs", INPUT_ROLES, optional=False)


def recorded_outputs(scenario) -> list[InputFile] | None:
    """The outputs the record says its run wrote, as it wrote them; None when it does
    not say. ``LadarError`` naming the record when it cannot be read."""
    return _recorded(scenario.run_record, "outputs", tuple(OUTPUT_ROLES.values()), optional=True)


def _recorded(path: Path, key: str, roles, optional: bool) -> list[InputFile] | None:
    """The ``[[run.KEY]]`` files of the record at ``path``; None without a record or
    ``[run]`` (or, where ``optional``, without the key: records written before it existed)."""
    if not path.is_file():
        return None
    try:
        run = tomllib.loads(path.read_text(encoding="utf-8-sig")).get("run")
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as error:
        raise LadarError(f"{path}: cannot be read: {one_line(str(error))}") from None
    if run is None or (optional and isinstance(run, dict) and key not in run):
        return None
    entries = run.get(key) if isinstance(run, dict) else None
    if not isinstance(entries, list):
        raise LadarError(f"{path}: [run] {key}: expected a list of [[run.{key}]] tables")
    return [_recorded_file(path, key, roles, index, entry) for index, entry in enumerate(entries)]


def outputs_changed(scenario) -> list[str]:
    """Each output the record fingerprints whose bytes on disk differ now, as "S.cmf
    changed since the run wrote it" (none when the record does not say; one that cannot
    be read is not named here: ``missing_outputs`` names it)."""
    return [
        f"{path.name} changed since the run wrote it: it is not the run's output"
        for path in replaced_outputs(scenario.run_record)
    ]


def replaced_outputs(record: Path, only=None, known=None) -> list[Path]:
    """The outputs the record at ``record`` fingerprints whose bytes on disk differ now,
    for a reader holding an output rather than its scenario: ``only`` those of these
    paths, if given (the others are not read); ``known``: fingerprints already taken,
    by path (a file just read is not read again). ``LadarError`` naming the record
    when it cannot be read."""
    from ladartui.fingerprint import file_fingerprint

    wanted = None if only is None else {os.path.abspath(path) for path in only}
    known = {os.path.abspath(path): fingerprint for path, fingerprint in (known or {}).items()}
    changed = []
    for entry in _recorded(record, "outputs", tuple(OUTPUT_ROLES.values()), optional=True) or ():
        where = os.path.abspath(entry.path)
        if wanted is not None and where not in wanted:
            continue
        now = known[where] if where in known else file_fingerprint(entry.path)
        if now is not None and now != entry.fingerprint:
            changed.append(entry.path)
    return changed


def _recorded_file(path: Path, key: str, roles, index: int, entry) -> InputFile:
    entry = entry if isinstance(entry, dict) else {}
    role, file, size, sha256 = (entry.get(name) for name in ("role", "file", "bytes", "sha256"))
    if (
        role not in roles
        or not isinstance(file, str)
        or not file
        or not isinstance(size, int)
        or size < 0
        or not isinstance(sha256, str)
        or not re.fullmatch(r"[0-9a-f]{64}", sha256)
    ):
        raise LadarError(
            f"{path}: run.{key}[{index}]: expected role ({', '.join(roles)}), file, "
            "bytes and sha256 (64 hex digits)"
        )
    return InputFile(role, resolve_path(path.parent, file), Fingerprint(size, sha256))


def inputs_changed(scenario, scene) -> list[str] | None:
    """``input_changes`` between the files the record beside ``scenario`` lists and
    ``scene`` as loaded (with the scenario's flight logs); None when the record lists
    none (older than that, or none). ``LadarError`` naming the record when it cannot be read."""
    recorded = recorded_inputs(scenario)
    return None if recorded is None else input_changes(recorded, run_inputs(scenario, scene))


def input_changes(recorded, now) -> list[str]:
    """Each file in ``recorded`` (``recorded_inputs``) whose contents differ from
    ``now`` (``run_inputs`` of the scenario as it is), as "the scene model small.txt
    changed since the run". A recorded file not read now is another setting
    (``setting_changes`` names it)."""
    current = {entry.path: entry.fingerprint for entry in now}
    return [
        f"the {entry.role} {entry.path.name} changed since the run"
        for entry in recorded
        if entry.path in current and current[entry.path] != entry.fingerprint
    ]


def check_record_spare(scenario) -> None:
    """Refuse a run that would replace a file of the record's name that is not one."""
    path = scenario.run_record
    if path.is_dir():
        raise OutputFileError(path, "is a folder, expected a file name (a run writes its settings there)")
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


def changes_text(changes: list[str], most: int = 4) -> str:
    """``setting_changes`` as one clause: the first ``most``, then how many more."""
    more = len(changes) - most
    return "; ".join(changes[:most]) + (f"; and {more} more" if more > 0 else "")


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
