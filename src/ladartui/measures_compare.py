"""Several runs' measures side by side: the TUI's Compare (F10) and ``ladartui compare``.

``side_by_side`` gives one ``CompareRow`` per measure (then per level, then per
Geiger-mode figure when a run has them, then per target when every run holds the
same several targets): the runs' values, their
text, whether the runs differ, and which columns are best and worst for a
measure with a direction of goodness. ``styled`` colours a row for a terminal
(rich): differing labels and values yellow, the best bold green, the worst
bold red.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from rich.text import Text

from ladartui.errors import InputFileError, LadarError
from ladartui.fileprobe import file_problem
from ladartui.levels import LEVELS, NOT_REACHED
from ladartui.measures_table import UNDEFINED
from ladartui.number_text import fixed, fixed_or_tiny

if TYPE_CHECKING:
    from ladartui.scenario import Scenario

# (label, Measures.to_dict path, kind, better): better is "high", "low" or None
ROWS = [
    ("Maximum target coverage", "maximum_coverage", "pct", "high"),
    ("Unobscured target coverage", "unobscured_coverage", "pct", "high"),
    ("Obscured target coverage", "obscured_coverage", "pct", "high"),
    ("Target voxels", "target_voxels", "int", None),
    ("Visible target voxels", "visible_voxels", "int", None),
    ("Unobscured voxels", "unobscured_voxels", "int", "high"),
    ("Obscured voxels", "obscured_voxels", "int", "high"),
    ("Seen obscured but not unobscured", "obscured_only_voxels", "int", None),
    ("Model mean vector", "model_directions.mean_vector", "vec", None),
    ("Model resultant length", "model_directions.resultant_length", "num", None),
    ("Model mean direction", "model_directions.mean_direction", "vec", None),
    ("Unobscured mean vector", "unobscured_directions.mean_vector", "vec", None),
    ("Unobscured resultant length", "unobscured_directions.resultant_length", "num", None),
    ("Unobscured mean direction", "unobscured_directions.mean_direction", "vec", None),
    ("Obscured mean vector", "obscured_directions.mean_vector", "vec", None),
    ("Obscured resultant length", "obscured_directions.resultant_length", "num", None),
    ("Obscured mean direction", "obscured_directions.mean_direction", "vec", None),
    ("Shift in mean direction (rad)", "direction_shift_rad", "num", "low"),
    ("Missed share", "missed_share", "pct", "low"),
    ("Coverage ratio", "coverage_ratio", "num", "high"),
    ("Scans", "scans", "int", None),
    ("Scans for 90% of final", "scans_for_enough", "int", "low"),
    ("Path length (m)", "path_length_m", "num1", "low"),
    ("Flight time (s)", "flight_time_s", "num1", "low"),
]

# Geiger-mode figures (the .cmf's [geiger detection]), shown when a run has them; a run
# of the ideal sensor reads IDEAL there, but for the ideal coverages: its own
DETECTION_ROWS = [
    ("Pulses per look", "detection.pulses", "int", None),
    ("Coincidence k", "detection.coincidence", "int", None),
    ("Random seed", "detection.seed", "int", None),
    ("Declared points", "detection.declared_points", "int", None),
    ("Declared points per look", "detection.declared_per_look", "num1", None),
    ("False alarms", "detection.false_alarms", "int", "low"),
    ("False alarms per look", "detection.false_alarms_per_look", "num1", "low"),
    ("False-alarm probability per noise bin", "detection.false_alarm_probability", "prob", "low"),
    ("P_d of target voxels", "detection.target_detection", "pct", "high"),
    ("Ideal sensor: obscured coverage", "detection.ideal_obscured_coverage", "pct", None),
    ("Ideal sensor: unobscured coverage", "detection.ideal_unobscured_coverage", "pct", None),
]
IDEAL = "ideal sensor"
IDEAL_OWN = {
    "detection.ideal_obscured_coverage": "obscured_coverage",
    "detection.ideal_unobscured_coverage": "unobscured_coverage",
}

# per target, in the comparison
TARGET_ROWS = [
    ("obscured coverage", "obscured_coverage", "pct", "high"),
    ("unobscured coverage", "unobscured_coverage", "pct", "high"),
    ("maximum coverage", "maximum_coverage", "pct", "high"),
    ("identify at scan", "levels.identify", "level", "low"),
]


def lookup(data: dict, path: str):
    """The value at dotted ``path`` of a measures dict, or None where it has none."""
    value = data
    for part in path.split("."):
        if not isinstance(value, dict) or part not in value:
            return None
        value = value[part]
    return value


def format_value(value, kind: str) -> str:
    """Text for one measure; None is shown as "undefined"."""
    if value is None:
        return UNDEFINED
    if kind == "pct":
        return f"{100 * float(value):.1f}%"
    if kind == "int":
        return f"{int(value):,}"
    if kind == "vec":
        return ", ".join(fixed(v, 3) for v in value)
    if kind == "num1":
        return fixed(value, 1)
    if kind == "prob":
        return fixed_or_tiny(value, 6)
    return fixed(value, 3)


@dataclass(frozen=True)
class CompareRow:
    """One measure across the runs: ``best`` and ``worst`` are column numbers (empty
    where the measure has no better way, or every run has the same value)."""

    label: str
    values: tuple
    texts: tuple[str, ...]
    differ: bool
    best: tuple[int, ...]
    worst: tuple[int, ...]


def side_by_side(all_measures: list) -> list[CompareRow]:
    """One row per measure of ``all_measures`` (``Measures`` or their dicts), then the
    scan each level was reached at, then the Geiger-mode figures when a run has them,
    then rows per target when every run holds the same several targets."""
    dicts = [m if isinstance(m, dict) else m.to_dict() for m in all_measures]
    rows = [
        _compare_row(label, [lookup(d, path) for d in dicts], kind, better)
        for label, path, kind, better in ROWS
    ]
    for level in LEVELS:
        rows.append(
            _level_row(f"{level.capitalize()} at scan", [lookup(d, f"levels.{level}") for d in dicts])
        )
    geiger = [isinstance(d.get("detection"), dict) for d in dicts]
    if any(geiger):
        for label, path, kind, better in DETECTION_ROWS:
            own = IDEAL_OWN.get(path)
            values = [lookup(d, path) if g else own and lookup(d, own) for d, g in zip(dicts, geiger)]
            texts = tuple(format_value(v, kind) if g or own else IDEAL for v, g in zip(values, geiger))
            rows.append(_compare_row(label, values, kind, better, texts=texts))
    targets = [d.get("targets") for d in dicts]
    if all(isinstance(t, dict) for t in targets):
        per = [{t["id"]: t for t in tt["per_target"]} for tt in targets if isinstance(tt, dict)]
        ids = sorted(per[0]) if per else []
        if len(ids) > 1 and all(sorted(p) == ids for p in per):
            for target_id in ids:
                name = per[0][target_id]["name"]
                for label, path, kind, better in TARGET_ROWS:
                    values = [lookup(p[target_id]["measures"], path) for p in per]
                    if kind == "level":
                        rows.append(_level_row(f"{name}: {label}", values))
                    else:
                        rows.append(_compare_row(f"{name}: {label}", values, kind, better))
    return rows


def _compare_row(label: str, values: list, kind: str, better, texts=None, numeric=None) -> CompareRow:
    texts = tuple(format_value(v, kind) for v in values) if texts is None else texts
    differ = len(set(texts)) > 1
    best: tuple[int, ...] = ()
    worst: tuple[int, ...] = ()
    if numeric is None:
        numeric = [
            (float(v), i) for i, v in enumerate(values) if v is not None and not isinstance(v, (list, tuple))
        ]
    if differ and better and len(numeric) >= 2:
        high, low = max(numeric)[0], min(numeric)[0]
        top, bottom = (high, low) if better == "high" else (low, high)
        if top != bottom:
            best = tuple(i for v, i in numeric if v == top)
            worst = tuple(i for v, i in numeric if v == bottom)
    return CompareRow(label, tuple(values), texts, differ, best, worst)


def _reached_text(scan, flight_time_s) -> str:
    """``10, 4.7 s``: the scan and, flights of other scan rates being compared, the
    flight time it came at (the scan alone from a file without it)."""
    text = format_value(scan, "int")
    return text if flight_time_s is None else f"{text}, {fixed(flight_time_s, 1)} s"


def _level_row(label: str, levels: list) -> CompareRow:
    """The scan each run reached a level at, with its flight time (``levels``: each run's
    level dict, None where its file has no levels), ranked by scans (looks needed): one
    never reached reads "not reached" and ranks after every scan, as the Results tab
    and the .cmf say it."""
    scans = [level.get("scan") if isinstance(level, dict) else None for level in levels]
    texts = tuple(
        UNDEFINED
        if not isinstance(level, dict)
        else _reached_text(scan, level.get("flight_time_s"))
        if level.get("reached")
        else NOT_REACHED
        for level, scan in zip(levels, scans)
    )
    ranks = [
        (float(scan) if level.get("reached") and scan is not None else math.inf, i)
        for i, (level, scan) in enumerate(zip(levels, scans))
        if isinstance(level, dict)
    ]
    return _compare_row(label, scans, "int", "low", texts=texts, numeric=ranks)


def styled(row: CompareRow) -> list[Text]:
    """The row as rich text, label first: names from files are text, never markup."""
    cells = []
    for i, text in enumerate(row.texts):
        if i in row.best:
            cells.append(Text(text, style="bold green"))
        elif i in row.worst:
            cells.append(Text(text, style="bold red"))
        else:
            cells.append(Text(text, style="yellow" if row.differ else ""))
    return [Text(row.label, style="bold yellow" if row.differ else ""), *cells]


def column_names(paths: list[Path]) -> list[str]:
    """Each file's stem, with as many of its folders as it takes to tell files of one
    stem apart ("d2/default" and "default/default" for two default.cmf), its suffix
    where that tells them ("orbit.toml", "orbit.cmf"), and a count for a file given
    twice ("orbit (2)")."""

    def parts_of(path: Path) -> tuple[str, ...]:
        bare = path.with_suffix("")
        twin = any(other != path and other.with_suffix("") == bare for other in paths)
        return path.parts if twin else bare.parts  # a twin: told apart by the suffix

    keyed = [parts_of(path) for path in paths]
    names = []
    for k, parts in enumerate(keyed):
        same = [o for j, o in enumerate(keyed) if o[-1] == parts[-1] and paths[j] != paths[k]]
        depth = 1
        while any(other[-depth:] == parts[-depth:] for other in same) and depth < len(parts):
            depth += 1
        names.append("/".join(parts[-depth:]))
    given = list(names)  # counted as given, not as renamed so far
    return [
        f"{name} ({given[: k + 1].count(name)})" if name in given[:k] else name
        for k, name in enumerate(given)
    ]


def read_measures_files(paths) -> list:
    """The ``Measures`` of each .cmf file (a scenario's .toml: its run's measures file);
    ``InputFileError`` naming the first that cannot be read."""
    return read_compared(paths)[0]


def read_compared(paths) -> tuple[list, list[str]]:
    """The ``Measures`` of each .cmf file (a scenario's .toml: its run's measures file),
    and for each scenario given (once, however often it is given) whose last run went
    with other settings than the file has now, a note saying so (``earlier_settings_note``).
    ``InputFileError`` naming the first file that cannot be read. Each scenario is
    loaded once (a flight log's records read once)."""
    from ladartui.cmf import read_cmf
    from ladartui.scenario import load_scenario

    measures = []
    notes: dict[Path, str | None] = {}
    for path in map(Path, paths):
        scenario = path.suffix.lower() == ".toml"
        if path.is_dir():
            raise InputFileError(path, "is a folder; expected a .cmf measures file or a scenario (.toml)")
        if problem := file_problem(path):
            raise InputFileError(path, f"{'scenario' if scenario else 'measures file'} {problem}")
        if not scenario:
            measures.append(read_cmf(path))
            continue
        loaded = load_scenario(path, check_files=False)
        measures.append(read_cmf(_measures_file_of(loaded, path)))
        if path not in notes:
            notes[path] = earlier_settings_note(loaded, path)
    return measures, [note for note in notes.values() if note]


def earlier_settings_note(scenario: Scenario, path: Path) -> str | None:
    """For a scenario (loaded from ``path``) compared by its last run's measures: a line
    naming the settings that run went with where the file now says otherwise (an edit
    not run again); None where they agree, or no readable record says."""
    from ladartui.run_record import changes_text, read_run_record, setting_changes

    try:
        ran = read_run_record(scenario)
    except LadarError:  # a record that does not read: validate names it
        return None
    changes = [] if ran is None else setting_changes(ran, scenario)
    if not changes:
        return None
    return (
        f"{path}: its measures are its last run's, made with other settings than this file: "
        f"{changes_text(changes)}; run it again to compare these"
    )


def measures_files_to_offer(own: Path, most: int = 4) -> list[Path]:
    """The measures files to compare a scenario's run with: its own (``own``) first, then
    the others in its folder by name, ``most`` in all, each one that reads (one that
    does not would stop the comparison of the rest before it began)."""
    from ladartui.cmf import read_cmf

    candidates = [own] + sorted(p for p in own.parent.glob("*.cmf") if p != own)
    offered: list[Path] = []
    for path in candidates:
        if len(offered) == most:
            break
        try:
            read_cmf(path)
        except (LadarError, OSError):
            continue
        offered.append(path)
    return offered


def _measures_file_of(scenario: Scenario, path: Path) -> Path:
    """The measures file a scenario's runs write (the scenario loaded from ``path``),
    there to be read."""
    measures = scenario.measures_file
    if problem := file_problem(measures):
        first = ": run it first" if problem == "not found" else ""
        raise InputFileError(measures, f"measures file of {path.name} {problem}{first}")
    return measures
