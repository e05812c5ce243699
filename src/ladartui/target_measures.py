"""Measures per target, and the worst and the mean over the targets.

A target model may hold several targets (``x,y,z,id`` lines, see
``ladartui.scene.voxels``). Every measure of ``ladartui.measures`` is
computed for each target alone, as if its voxels were the whole target model:
coverages against its own voxels, directions from its own centroid, its own
coverage after each scan. The overall ``Measures`` fields keep meaning "all
targets together", so a reader that knows nothing of targets reads the same
figures as before.

Worst and mean: for each summarised measure (``SUMMARY``) the worst value
over the targets (coverages and the obscured/unobscured ratio: the lowest;
shift, missed share and scans for 90 %: the highest) and the plain mean. A
target whose measure is undefined (say, a missed share when nothing of it was
seen unobscured) is left out of that measure's worst and mean; undefined for
every target gives undefined. Coverage after each scan is summarised scan by
scan. Directional statistics are per target only: a "worst" direction has
no meaning.

In a ``.cmf`` file (format 2) the per-target figures follow the overall ones:
a ``[targets]`` section (``count``), ``[targets / worst]`` and
``[targets / mean]`` (recomputed from the targets when read), then per target
``[target N]`` (``name``) and ``[target N / <section>]`` for each overall
section but the flight, with the same keys.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ladartui.errors import InputFileError
from ladartui.levels import LevelThresholds, level_result_from_dict, target_levels
from ladartui.measures import (
    ENOUGH_SHARE,
    Measures,
    compute_measures,
    measures_from_lines,
    section_lines,
)
from ladartui.number_text import coverage_steps
from ladartui.scene.keys import keys_to_voxels, member, sorted_unique, voxel_keys

HIGH, LOW = "high", "low"  # which way is better
# (Measures field, .cmf key, better, kind); the *_after_scan fields are per-scan tuples.
SUMMARY = (
    ("maximum_coverage", "maximum_target_coverage", HIGH, "float"),
    ("unobscured_coverage", "unobscured_target_coverage", HIGH, "float"),
    ("obscured_coverage", "obscured_target_coverage", HIGH, "float"),
    ("coverage_ratio", "coverage_ratio", HIGH, "float"),
    ("missed_share", "missed_share", LOW, "float"),
    ("direction_shift_rad", "shift_in_mean_direction_rad", LOW, "float"),
    ("scans_for_enough", "scans_for_90_percent_of_final", LOW, "float"),
)
PER_SCAN = ("obscured_after_scan", "unobscured_after_scan")

TARGETS_SECTION = "targets"
_TARGET_SECTION = re.compile(r"target ([1-9][0-9]*)(?: / (.+))?$")
_SUMMARY_SECTION = re.compile(r"targets / (worst|mean)$")
_SCAN_KEY = re.compile(r"scan_[1-9][0-9]*$")


@dataclass(frozen=True)
class TargetMeasures:
    """Every measure of one target (``measures``), with its id and name."""

    target_id: int
    name: str
    measures: Measures  # its detect / recognise / identify levels in measures.levels

    def to_dict(self) -> dict:
        return {"id": self.target_id, "name": self.name, "measures": self.measures.to_dict()}


@dataclass(frozen=True)
class TargetSummary:
    """The worst or the mean over targets of each ``SUMMARY`` measure (None: undefined)."""

    maximum_coverage: float | None = None
    unobscured_coverage: float | None = None
    obscured_coverage: float | None = None
    coverage_ratio: float | None = None
    missed_share: float | None = None
    direction_shift_rad: float | None = None
    scans_for_enough: float | None = None
    obscured_after_scan: tuple[float, ...] | None = None
    unobscured_after_scan: tuple[float, ...] | None = None

    def to_dict(self) -> dict:
        return {
            f.name: list(v) if isinstance(v := getattr(self, f.name), tuple) else v
            for f in dataclasses.fields(self)
        }


@dataclass(frozen=True)
class PerTarget:
    """The measures of each target of a target model, ascending ids."""

    targets: tuple[TargetMeasures, ...]

    @functools.cached_property  # summed once: tables, .cmf lines and JSON all read them
    def worst(self) -> TargetSummary:
        return _summary(self.targets, worst=True)

    @functools.cached_property
    def mean(self) -> TargetSummary:
        return _summary(self.targets, worst=False)

    def by_id(self, target_id: int) -> TargetMeasures:
        return next(t for t in self.targets if t.target_id == target_id)

    def to_dict(self) -> dict:
        return {
            "count": len(self.targets),
            "worst": self.worst.to_dict(),
            "mean": self.mean.to_dict(),
            "per_target": [t.to_dict() for t in self.targets],
        }

    @classmethod
    def from_dict(cls, data: dict) -> PerTarget:
        """The inverse of ``to_dict`` (worst and mean are recomputed)."""
        return cls(
            tuple(
                TargetMeasures(int(t["id"]), str(t["name"]), _measures_from_dict(t["measures"]))
                for t in data["per_target"]
            )
        )

    def cmf_lines(self) -> list[str]:
        """The per-target part of a ``.cmf`` file (see the module docstring)."""
        lines = ["", f"[{TARGETS_SECTION}]", f"count = {len(self.targets)}"]
        lines.append("# worst: lowest coverages and ratio, highest shift, missed share and scans")
        for label, summary in (("worst", self.worst), ("mean", self.mean)):
            lines += ["", f"[{TARGETS_SECTION} / {label}]"]
            for attr, key, _better, _kind in SUMMARY:
                lines.append(f"{key} = {_text(getattr(summary, attr))}")
            lines += _per_scan_lines(summary.obscured_after_scan, summary.unobscured_after_scan)
        for target in self.targets:
            lines += ["", f"[target {target.target_id}]", f"name = {json.dumps(target.name)}"]
            lines += section_lines(target.measures, prefix=f"target {target.target_id} / ")
            if target.measures.levels is not None:
                header, *body = target.measures.levels.cmf_lines()
                lines += ["", header.replace("[", f"[target {target.target_id} / ", 1), *body]
        return lines


def compute_target_measures(
    target_model,
    target_ids,
    scene_output,
    target_output,
    scene_per_scan=None,
    target_per_scan=None,
    names: Callable[[int], str] | None = None,
    levels: LevelInputs | None = None,
    **flight,
) -> PerTarget:
    """Every measure for each target of ``target_model`` (ids ``target_ids``, one a voxel).

    The outputs and per-scan returns are as for ``compute_measures``; they are
    cut to target voxels once, so each target costs about what its own voxels
    cost. ``names(id)`` gives a target's name (default "target N"); ``flight``
    passes ``path_length_m``, ``flight_time_s`` and ``voxel_size`` through.
    With ``levels`` (and ``scene_per_scan``) each target's ``measures.levels``
    holds the detect / recognise / identify levels it reached on its own.
    """
    target = np.asarray(target_model, dtype=np.int64).reshape(-1, 3)
    ids = np.asarray(target_ids).reshape(-1)
    if ids.shape != (len(target),):
        raise ValueError(f"target_ids must hold one id per target voxel ({len(target)}), got {ids.shape}")
    all_keys = sorted_unique(voxel_keys(target))

    def on_target(voxels):
        if voxels is None:
            return None
        keys = voxel_keys(voxels)
        return keys_to_voxels(keys[member(keys, all_keys)])

    def per_scan(returns):
        return None if returns is None else [on_target(r) for r in returns]

    scene_cut, target_cut = on_target(scene_output), on_target(target_output)
    scene_scans, target_scans = per_scan(scene_per_scan), per_scan(target_per_scan)
    name_of = names or (lambda i: f"target {i}")
    out = []
    for target_id in (int(i) for i in np.unique(ids)):
        measures = compute_measures(
            target[ids == target_id], scene_cut, target_cut, scene_scans, target_scans, **flight
        )
        if levels is not None and scene_scans is not None:
            result = target_levels(target[ids == target_id], scene_scans, *levels)
            measures = dataclasses.replace(measures, levels=result)
        out.append(TargetMeasures(target_id, name_of(target_id), measures))
    return PerTarget(tuple(out))


@dataclass(frozen=True)
class LevelInputs:
    """What the levels need beside a target's returns: the flight's per-scan times and
    distances (``FlightPlan.scan_times``, ``scan_distances``) and the thresholds."""

    scan_times: Sequence[float]
    scan_distances: Sequence[float]
    thresholds: LevelThresholds | None = None

    def __iter__(self):
        return iter((self.scan_times, self.scan_distances, self.thresholds))


def _measures_from_dict(data: dict) -> Measures:
    measures = Measures.from_dict(data)
    if data.get("levels") is not None:
        measures = dataclasses.replace(measures, levels=level_result_from_dict(data["levels"]))
    return measures


def _summary(targets: Sequence[TargetMeasures], worst: bool) -> TargetSummary:
    values: dict[str, object] = {}
    for attr, _key, better, _kind in SUMMARY:
        defined = [float(v) for t in targets if (v := getattr(t.measures, attr)) is not None]
        values[attr] = _combine(defined, better, worst)
    for attr in PER_SCAN:
        curves = [getattr(t.measures, attr) for t in targets]
        if not curves or any(c is None for c in curves) or len({len(c) for c in curves}) != 1:
            values[attr] = None
            continue
        values[attr] = tuple(
            _combine([float(c[k]) for c in curves], HIGH, worst) for k in range(len(curves[0]))
        )
    return TargetSummary(**values)  # type: ignore[arg-type]


def _combine(values: list[float], better: str, worst: bool) -> float | None:
    if not values:
        return None
    if worst:
        return min(values) if better == HIGH else max(values)
    return math.fsum(values) / len(values)


def _text(value) -> str:
    return "undefined" if value is None else repr(float(value))


def _per_scan_lines(obscured, unobscured) -> list[str]:
    count = max(len(obscured or ()), len(unobscured or ()))
    return [
        f"scan_{k + 1} = "
        + ", ".join(_text(None if curve is None else curve[k]) for curve in (obscured, unobscured))
        for k in range(count)
    ]


# --------------------------------------------------------------------------- reading


def is_target_section(section: str) -> bool:
    """True for the sections this module writes (``[targets ...]``, ``[target N ...]``)."""
    return section == TARGETS_SECTION or bool(
        _SUMMARY_SECTION.match(section) or _TARGET_SECTION.match(section)
    )


def read_target_lines(path, lines: list[tuple[int, str]], overall: Measures) -> PerTarget:
    """The per-target part of a ``.cmf`` file: ``lines`` are (number, text) from the first
    per-target section on. Each target's flight figures are the overall ones."""
    blocks: dict[int, list[tuple[int, str]]] = {}
    headers: dict[int, int] = {}  # each target's first section line
    names: dict[int, str] = {}
    count = None
    section = ""
    target_id = 0
    for number, raw in lines:
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith("[") and line.endswith("]"):
            section = line[1:-1].strip()
            found = _TARGET_SECTION.match(section)
            if found:
                target_id = int(found.group(1))
                headers.setdefault(target_id, number)
                if found.group(2) is not None:
                    blocks.setdefault(target_id, []).append((number, f"[{found.group(2)}]"))
                else:
                    blocks.setdefault(target_id, [])
            elif not is_target_section(section):
                raise InputFileError(path, f"unknown section [{section}] among the targets", line=number)
            continue
        key, sep, value = (part.strip() for part in line.partition("="))
        if _TARGET_SECTION.match(section) and " / " in section:
            blocks[target_id].append((number, line))
        elif _TARGET_SECTION.match(section) and sep and key == "name":
            try:
                name = json.loads(value)
            except ValueError:
                name = None
            if not isinstance(name, str) or not name.isprintable():
                raise InputFileError(
                    path, f'name: expected a quoted name such as "truck", got {value!r}', number
                )
            names[target_id] = name
        elif section == TARGETS_SECTION and sep and key == "count":
            if not value.isdigit():
                raise InputFileError(path, f"count: expected a whole number, got {value!r}", number)
            count = int(value)
        elif _SUMMARY_SECTION.match(section) and sep and _summary_value_ok(key, value):
            continue  # recomputed from the targets
        else:
            raise InputFileError(
                path, f"expected 'key = value' with a known key in [{section}], got {line!r}", number
            )
    targets = []
    flight = {name: getattr(overall, name) for name in ("path_length_m", "flight_time_s", "voxel_size")}
    for target_id in sorted(blocks):
        # a target with no sections but its [target N] line: what it lacks is named there
        end = None if blocks[target_id] else headers[target_id]
        block = measures_from_lines(path, blocks[target_id], f"target {target_id} / ", end)
        measures = dataclasses.replace(block, **flight)
        targets.append(TargetMeasures(target_id, names.get(target_id, f"target {target_id}"), measures))
    if count is not None and count != len(targets):
        raise InputFileError(path, f"[{TARGETS_SECTION}] count = {count} but {len(targets)} targets follow")
    return PerTarget(tuple(targets))


def _summary_value_ok(key: str, value: str) -> bool:
    if _SCAN_KEY.match(key):
        items = [v.strip() for v in value.split(",")]
        return len(items) == 2 and all(_number_ok(v) for v in items)
    return any(key == k for _attr, k, _better, _kind in SUMMARY) and _number_ok(value)


def _number_ok(text: str) -> bool:
    if text == "undefined":
        return True
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


# --------------------------------------------------------------------------- display

TABLE_HEADER = ("Target", "Voxels", "Max", "Unobsc.", "Obsc.", "Missed", "Shift rad", "Scans")
TABLE_NOTE = (
    "coverages: maximum, unobscured, obscured; missed: share of the unobscured coverage "
    f"missing when obscured; scans: to reach {ENOUGH_SHARE:.0%} of the final coverage; - undefined"
)
_UNDEFINED = "-"


def table_rows(per_target: PerTarget) -> list[tuple[str, ...]]:
    """One row per target, then the worst and the mean (``TABLE_HEADER`` columns)."""

    def number(value, digits=3):
        return _UNDEFINED if value is None else f"{value:.{digits}f}"

    def share(value):
        return _UNDEFINED if value is None else f"{100.0 * value:.1f}%"

    rows: list[tuple[str, ...]] = []
    for t in per_target.targets:
        m = t.measures
        rows.append(
            (
                f"{t.target_id} {t.name}",
                f"{m.target_voxels:,}",
                share(m.maximum_coverage),
                share(m.unobscured_coverage),
                share(m.obscured_coverage),
                share(m.missed_share),
                number(m.direction_shift_rad),
                _UNDEFINED if m.scans_for_enough is None else f"{m.scans_for_enough} of {m.scans}",
            )
        )
    for label, s in (("worst", per_target.worst), ("mean", per_target.mean)):
        rows.append(
            (
                label,
                "",
                share(s.maximum_coverage),
                share(s.unobscured_coverage),
                share(s.obscured_coverage),
                share(s.missed_share),
                number(s.direction_shift_rad),
                number(s.scans_for_enough, 1 if label == "mean" else 0),
            )
        )
    return rows


def after_scan_rows(per_target: PerTarget) -> list[tuple[str, str]]:
    """(target, obscured coverage after each scan in %) per target, then worst and mean."""

    def curve(values):
        return _UNDEFINED if values is None else coverage_steps(values)

    rows = [(f"{t.target_id} {t.name}", curve(t.measures.obscured_after_scan)) for t in per_target.targets]
    rows.append(("worst", curve(per_target.worst.obscured_after_scan)))
    rows.append(("mean", curve(per_target.mean.obscured_after_scan)))
    return rows


__all__ = [
    "PerTarget",
    "TargetMeasures",
    "TargetSummary",
    "compute_target_measures",
    "read_target_lines",
    "table_rows",
    "after_scan_rows",
]
