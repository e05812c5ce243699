"""Measures of effectiveness of a collection (report sections 2.2 and 4.4, figure 10).

A run produces two fused voxel lists: the *obscured* view (the full scene, foliage
in the way) and the *unobscured* view (the target model alone, the ideal that a
flight path could reach without foliage). Both are scored against the target
model. Every share is a fraction in 0..1; a measure that has no meaning for the
inputs (empty target, nothing seen) is ``None`` and shown as "undefined".

The maximum target coverage is the share of target-model voxels with at least
one face open to empty space, the ground-facing (-z) face aside. It is decided
with the target model alone (foliage next to the vehicle does not close a
face): it bounds what any flight path could see, whatever the scene.

Directional statistics use, for each covered target voxel, the unit vector from
the target's centroid (the mean of all target-model voxel centres) to that
voxel's centre, in the scene frame (x east, y north, z up). The distribution of
these vectors says *where around the vehicle* the coverage lies: coverage of
the roof only gives a mean direction near straight up, coverage of one side
tilts it towards that side, and an even coverage all round gives a short mean
resultant length. A covered voxel at the centroid itself has no direction and
is left out of the statistics (it still counts for coverage).

The ``.cmf`` file ("comparison measures file") is plain text: a header line
``# ladartui comparison measures, format cmf 1``, then ``[section]`` lines and
``key = value`` lines. Values are integers, floats (written so they read back
exactly), comma-separated vectors, or ``undefined``. The coverage after each
scan is one line per scan, ``scan_k = obscured, unobscured``. Lines starting
with ``#`` are comments. ``ladartui.cmf.read_cmf`` reads it back into ``Measures``.

Format 2 adds, after these, the measures of each target of a target model
with several targets and their worst and mean (``ladartui.target_measures``);
the sections above keep meaning all targets together. Format 1 files (no
per-target part) still read as before.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, fields, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ladartui.atomic import write_errors_named, write_text_atomic
from ladartui.checks import items_or_none, number_field
from ladartui.directions import DirectionStats, angle_between, direction_stats
from ladartui.errors import FieldError, InputFileError
from ladartui.fileprobe import path_field
from ladartui.scene.keys import member as _member
from ladartui.scene.keys import sorted_unique, visible_mask, voxel_keys
from ladartui.scene.voxel_arrays import voxel_list_field

if TYPE_CHECKING:
    from ladartui.levels import LevelResult

CMF_FORMAT = "cmf"
CMF_VERSION = 2
CMF_HEADER = f"# ladartui comparison measures, format {CMF_FORMAT} {CMF_VERSION}"
# Headers read: this version's, and format 1 (written before per-target measures).
CMF_HEADERS = {f"# ladartui comparison measures, format {CMF_FORMAT} {v}": v for v in (1, CMF_VERSION)}

# Coverage share of the final obscured coverage that counts as "enough looks".
ENOUGH_SHARE = 0.9


def _unique_keys(voxels) -> np.ndarray:
    return sorted_unique(voxel_keys(voxels))


@dataclass(frozen=True)
class Measures:
    """Measures of effectiveness of one simulated collection.

    Counts are voxels; coverages and shares are fractions 0..1 (``None`` when
    undefined). ``*_after_scan`` lists give cumulative coverage after scan
    1..k. ``scans_for_enough`` is the first scan count whose cumulative obscured
    coverage reaches ``ENOUGH_SHARE`` of the final obscured coverage.
    """

    target_voxels: int = 0
    visible_voxels: int = 0
    unobscured_voxels: int = 0
    obscured_voxels: int = 0
    maximum_coverage: float | None = None
    unobscured_coverage: float | None = None
    obscured_coverage: float | None = None
    model_directions: DirectionStats = field(default_factory=DirectionStats)
    unobscured_directions: DirectionStats = field(default_factory=DirectionStats)
    obscured_directions: DirectionStats = field(default_factory=DirectionStats)
    direction_shift_rad: float | None = None
    missed_share: float | None = None
    coverage_ratio: float | None = None
    obscured_only_voxels: int = 0
    obscured_after_scan: tuple[float, ...] | None = None
    unobscured_after_scan: tuple[float, ...] | None = None
    scans_for_enough: int | None = None
    scans: int | None = None
    path_length_m: float | None = None
    flight_time_s: float | None = None
    voxel_size: float | None = None
    # Geiger-mode figures (ladartui.detection.measures.DetectionMeasures); None with
    # the ideal sensor, and then absent from the dict and the .cmf.
    detection: object | None = None
    # Detect / recognise / identify (ladartui.levels.LevelResult); None: not computed.
    levels: LevelResult | None = None
    # Each target's measures, worst and mean (ladartui.target_measures.PerTarget);
    # None when not computed (a format-1 file), and then absent likewise.
    targets: object | None = None

    def to_dict(self) -> dict:
        """A JSON-safe dict (no NaN: undefined measures are None)."""
        out: dict[str, object] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in ("detection", "levels", "targets"):
                if value is not None:
                    out[f.name] = value.to_dict()
                continue
            if isinstance(value, DirectionStats):
                value = value.to_dict()
            elif isinstance(value, tuple):
                value = list(value)
            out[f.name] = value
        return out

    @classmethod
    def from_dict(cls, data: dict) -> Measures:
        """``to_dict``'s JSON back, less ``levels`` and ``targets`` (left None): the whole
        inverse, with those, is ``ladartui.cmf.measures_from_dict``."""
        values: dict[str, object] = {}
        for f in fields(cls):
            if f.name not in data:
                continue
            value = data[f.name]
            if f.name == "detection":
                from ladartui.detection.measures import DetectionMeasures

                value = DetectionMeasures(**value)
            elif f.name in ("targets", "levels"):
                continue  # their readers sit above this module: ladartui.cmf.measures_from_dict
            elif f.name.endswith("_directions"):
                value = DirectionStats(
                    **{k: tuple(v) if isinstance(v, list) else v for k, v in value.items()}  # type: ignore[arg-type]
                )
            elif isinstance(value, list):
                value = tuple(value)
            values[f.name] = value
        return cls(**values)  # type: ignore[arg-type]

    def to_cmf(self) -> str:
        """The measures as ``.cmf`` text (see the module docstring)."""
        lines = [CMF_HEADER, *_CMF_NOTES, *section_lines(self)]
        if self.detection is not None:
            lines.extend(_detection_lines(self.detection))
        if self.levels is not None:
            lines.extend(["", *self.levels.cmf_lines()])
        if self.targets is not None:
            lines.extend(self.targets.cmf_lines())  # type: ignore[attr-defined]
        return "\n".join(lines) + "\n"

    def write_cmf(self, path) -> None:
        """Write ``to_cmf()`` to ``path`` atomically."""
        path = path_field("path", path, "a measures file's path (.cmf)")
        with write_errors_named(path):
            write_text_atomic(path, self.to_cmf())


def compute_measures(
    target_model,
    scene_output,
    target_output,
    scene_per_scan=None,
    target_per_scan=None,
    path_length_m=None,
    flight_time_s=None,
    voxel_size=None,
) -> Measures:
    """Score the obscured (``scene_output``) and unobscured (``target_output``) views.

    All voxel arguments are (K, 3) integer index arrays; outputs may hold
    non-target voxels (foliage, ground), which are ignored. ``*_per_scan`` are
    lists of each scan's returns, in flight order, for coverage after each scan.
    Bad arrays or figures raise ``FieldError`` naming the argument.
    """
    target = voxel_list_field("target_model", target_model).astype(np.int64, copy=False)
    scene_output = _voxels_or_none("scene_output", scene_output)
    target_output = _voxels_or_none("target_output", target_output)
    scene_per_scan = _checked_scans("scene_per_scan", scene_per_scan)
    target_per_scan = _checked_scans("target_per_scan", target_per_scan)
    if (
        scene_per_scan is not None
        and target_per_scan is not None
        and len(scene_per_scan) != len(target_per_scan)
    ):
        raise FieldError(
            "len(target_per_scan)",
            len(target_per_scan),
            f"as many scans as scene_per_scan ({len(scene_per_scan)})",
        )
    path_length_m = None if path_length_m is None else number_field("path_length_m", path_length_m, 0)
    flight_time_s = None if flight_time_s is None else number_field("flight_time_s", flight_time_s, 0)
    voxel_size = None if voxel_size is None else number_field("voxel_size", voxel_size, 0, low_open=True)
    target_keys, first = np.unique(voxel_keys(target), return_index=True)
    target = target[first]
    total = int(target.shape[0])

    def covered_mask(voxels):
        if voxels is None:
            return np.zeros(total, dtype=bool)
        return _member(target_keys, _unique_keys(voxels))

    unobscured = covered_mask(target_output)
    obscured = covered_mask(scene_output)
    visible = visible_mask(target) if total else np.zeros(0, dtype=bool)

    def share(count, whole):
        return count / whole if whole else None

    centroid = target.mean(axis=0) if total else np.zeros(3)
    model_dirs = direction_stats(target[visible], centroid)
    unobscured_dirs = direction_stats(target[unobscured], centroid)
    obscured_dirs = direction_stats(target[obscured], centroid)

    n_unobscured = int(unobscured.sum())
    n_obscured = int(obscured.sum())
    missed = int((unobscured & ~obscured).sum())

    obscured_after = _cumulative_coverage(target_keys, scene_per_scan)
    unobscured_after = _cumulative_coverage(target_keys, target_per_scan)
    per_scan = scene_per_scan if scene_per_scan is not None else target_per_scan
    scans = None if per_scan is None else len(per_scan)

    return Measures(
        target_voxels=total,
        visible_voxels=int(visible.sum()),
        unobscured_voxels=n_unobscured,
        obscured_voxels=n_obscured,
        maximum_coverage=share(int(visible.sum()), total),
        unobscured_coverage=share(n_unobscured, total),
        obscured_coverage=share(n_obscured, total),
        model_directions=model_dirs,
        unobscured_directions=unobscured_dirs,
        obscured_directions=obscured_dirs,
        direction_shift_rad=angle_between(unobscured_dirs.mean_direction, obscured_dirs.mean_direction),
        missed_share=share(missed, n_unobscured),
        coverage_ratio=share(n_obscured, n_unobscured),
        obscured_only_voxels=int((obscured & ~unobscured).sum()),
        obscured_after_scan=obscured_after,
        unobscured_after_scan=unobscured_after,
        scans_for_enough=_scans_for_enough(obscured_after),
        scans=scans,
        path_length_m=path_length_m,
        flight_time_s=flight_time_s,
        voxel_size=voxel_size,
    )


def _voxels_or_none(name, voxels):
    return None if voxels is None else voxel_list_field(name, voxels)


def _checked_scans(name, per_scan):
    if per_scan is None:
        return None
    scans = items_or_none(per_scan)
    if scans is None:
        raise FieldError(name, per_scan, "a list of each scan's returns, (K, 3) voxel index arrays")
    return [voxel_list_field(f"{name}[{scan}]", returns) for scan, returns in enumerate(scans)]


def _cumulative_coverage(target_keys, per_scan) -> tuple[float, ...] | None:
    if per_scan is None or target_keys.size == 0:
        return None
    seen = np.zeros(target_keys.size, dtype=bool)
    out = []
    for returns in per_scan:
        keys = voxel_keys(returns)
        if keys.size:
            pos = np.searchsorted(target_keys, keys)
            inside = pos < target_keys.size
            pos, keys = pos[inside], keys[inside]
            seen[pos[target_keys[pos] == keys]] = True
        out.append(int(seen.sum()) / target_keys.size)
    return tuple(out)


def _scans_for_enough(after) -> int | None:
    if not after or after[-1] <= 0:
        return None
    goal = ENOUGH_SHARE * after[-1]
    for k, value in enumerate(after, start=1):
        if value >= goal - 1e-12:
            return k
    return len(after)


# The .cmf layout: sections follow the report's figure 10 (target model,
# unobscured output, obscured output, comparison), then the per-scan and flight
# figures. Each entry is (key, Measures attribute path, value kind).
def _direction_entries(prefix):
    return [
        ("directions_counted", f"{prefix}.count", "int"),
        ("sample_mean_vector", f"{prefix}.mean_vector", "vector"),
        ("mean_resultant_length", f"{prefix}.resultant_length", "float"),
        ("mean_direction", f"{prefix}.mean_direction", "vector"),
    ]


_CMF_SECTIONS = [
    (
        "3d target model",
        [
            ("target_voxels", "target_voxels", "int"),
            ("visible_voxels", "visible_voxels", "int"),
            ("maximum_target_coverage", "maximum_coverage", "float"),
            *_direction_entries("model_directions"),
        ],
    ),
    (
        "unobscured 3d target output",
        [
            ("covered_voxels", "unobscured_voxels", "int"),
            ("target_coverage", "unobscured_coverage", "float"),
            *_direction_entries("unobscured_directions"),
        ],
    ),
    (
        "obscured 3d target output",
        [
            ("covered_voxels", "obscured_voxels", "int"),
            ("target_coverage", "obscured_coverage", "float"),
            *_direction_entries("obscured_directions"),
        ],
    ),
    (
        "comparison",
        [
            ("shift_in_mean_direction_rad", "direction_shift_rad", "float"),
            ("missed_share", "missed_share", "float"),
            ("coverage_ratio", "coverage_ratio", "float"),
            ("obscured_only_voxels", "obscured_only_voxels", "int"),
        ],
    ),
    (
        "coverage after each scan",
        [
            ("scans", "scans", "int"),
            ("scans_for_90_percent_of_final", "scans_for_enough", "int"),
        ],
    ),
    (
        "flight",
        [
            ("path_length_m", "path_length_m", "float"),
            ("flight_time_s", "flight_time_s", "float"),
            ("voxel_size_m", "voxel_size", "float"),
        ],
    ),
]

CMF_FLIGHT_SECTION = "flight"

_CMF_NOTES = [
    "# shares are fractions 0..1, angles radians, lengths metres, times seconds;",
    "# 'undefined' marks a measure with no meaning for this run (e.g. nothing seen).",
    "# directions: unit vectors from the target centroid to each covered voxel centre,",
    "# frame x east, y north, z up. missed_share: share of the unobscured coverage",
    "# missing from the obscured view; coverage_ratio: obscured / unobscured coverage.",
]


def section_lines(measures: Measures, prefix: str = "") -> list[str]:
    """The figure-10 sections of ``measures`` as ``.cmf`` lines, headers ``[prefix + name]``.

    With a prefix (one target's block) the flight section is left out: it is
    the run's, written once.
    """
    lines = []
    for section, entries in _CMF_LAYOUT:
        if prefix and section == CMF_FLIGHT_SECTION:
            continue
        lines.append("")
        lines.append(f"[{prefix}{section}]")
        for key, getter, _kind in entries:
            lines.append(f"{key} = {_format_value(getter(measures))}")
        if section == _PER_SCAN_SECTION:
            lines.extend(_per_scan_lines(measures))
    return lines


def _get_path(measures, path):
    value = measures
    for part in path.split("."):
        value = getattr(value, part)
    return value


_PER_SCAN_SECTION = "coverage after each scan"
_PER_SCAN_KEY = re.compile(r"scan_([1-9][0-9]*)$")


def _per_scan_lines(measures) -> list[str]:
    """``scan_k = obscured, unobscured`` lines: cumulative coverage after scan k."""
    obscured, unobscured = measures.obscured_after_scan, measures.unobscured_after_scan
    count = max(len(obscured or ()), len(unobscured or ()))
    if not count:
        return []
    lines = ["# scan_k = obscured, unobscured target coverage after scans 1..k"]
    for k in range(count):
        pair = [None if values is None else values[k] for values in (obscured, unobscured)]
        lines.append(f"scan_{k + 1} = {_format_value(pair)}")
    return lines


def _per_scan_lists(path, rows) -> dict:
    """The two coverage-after-scan tuples from ``{k: (line, obscured, unobscured)}``."""
    out: dict[str, tuple | None] = {}
    if not rows:
        return out
    for k in range(1, len(rows) + 1):
        if k not in rows:
            raise InputFileError(path, f"scan_{k} missing: expected scan_1 .. scan_{len(rows)}")
    for column, name in enumerate(("obscured_after_scan", "unobscured_after_scan")):
        values = [rows[k][column + 1] for k in range(1, len(rows) + 1)]
        if all(v is None for v in values):
            out[name] = None
        elif any(v is None for v in values):
            line = next(rows[k][0] for k in rows if rows[k][column + 1] is None)
            raise InputFileError(path, "undefined among defined coverages", line=line)
        else:
            out[name] = tuple(values)
    return out


def _detection_entries():
    from ladartui.detection.measures import CMF_ENTRIES, CMF_SECTION

    return CMF_SECTION, CMF_ENTRIES


def _detection_lines(detection) -> list[str]:
    section, entries = _detection_entries()
    return [
        "",
        f"[{section}]",
        *(f"{key} = {_format_value(getattr(detection, attr))}" for key, attr, _kind in entries),
    ]


_CMF_LAYOUT = [
    (section, [(key, (lambda m, p=path: _get_path(m, p)), kind) for key, path, kind in entries])
    for section, entries in _CMF_SECTIONS
]


def _format_value(value) -> str:
    if value is None:
        return "undefined"
    if isinstance(value, (tuple, list)):
        return ", ".join(_format_value(v) for v in value)
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _parse_value(text: str, kind: str):
    """A value as ``.cmf`` writes it; ValueError says what was expected and what was found."""
    if text == "undefined":
        return None
    if kind == "int":
        try:
            return int(text)
        except ValueError:
            raise ValueError(f"expected an integer, got {text!r}") from None
    if kind == "float":
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"expected a number, got {text!r}") from None
        if not math.isfinite(value):
            raise ValueError(f"expected a finite number, got {text!r}")
        return value
    items = text.split(",")
    if len(items) != 3:
        raise ValueError("expected three comma-separated numbers")
    return tuple(_parse_value(item.strip(), "float") for item in items)


def measures_from_lines(path, numbered_lines, prefix: str = "", end_line: int | None = None) -> Measures:
    """``Measures`` from the (line number, text) pairs of the figure-10 and detection sections.

    Every key those sections are written with must be there: a file cut short is named
    with what it lacks, never read as undefined measures. ``prefix`` names the block's
    sections in messages ("target 2 / "; such a block has no flight section, as
    ``section_lines`` writes it); ``end_line`` is the line the block ends at (default
    its last).
    """
    kinds: dict[tuple[str | None, str], tuple[str, str]] = {
        (section, key): (attr, kind) for section, entries in _CMF_SECTIONS for key, attr, kind in entries
    }
    detection_section, detection_entries = _detection_entries()
    kinds.update(
        {(detection_section, key): ("detection." + attr, kind) for key, attr, kind in detection_entries}
    )
    from ladartui.levels import CMF_SECTION as levels_section
    from ladartui.levels import levels_from_cmf

    values: dict[str, object] = {}
    per_scan: dict[int, tuple] = {}
    levels: dict[str, tuple[int, str]] | None = None
    section = None
    found: dict[str | None, tuple[int, dict[str, int]]] = {}  # section: its line, its keys' lines
    for number, raw in numbered_lines:
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith("[") and line.endswith("]"):
            section = line[1:-1].strip()
            found.setdefault(section, (number, {}))
            if section == levels_section:
                levels = {}
            elif not any(section == name for name, _ in _CMF_SECTIONS) and section != detection_section:
                raise InputFileError(path, f"unknown section [{section}]", line=number)
            continue
        key, sep, value = line.partition("=")
        key = key.strip()
        if sep and section == levels_section and levels is not None:
            levels[key] = (number, value.strip())
            continue
        scan_key = _PER_SCAN_KEY.match(key)
        if sep and section == _PER_SCAN_SECTION and scan_key:
            pair = [t.strip() for t in value.split(",")]
            try:
                if len(pair) != 2:
                    raise ValueError("expected two values: obscured, unobscured")
                per_scan[int(scan_key.group(1))] = (number, *(_parse_value(t, "float") for t in pair))
            except ValueError as error:
                raise InputFileError(path, f"{key}: {error}", line=number) from None
            continue
        if not sep or (section, key) not in kinds:
            raise InputFileError(
                path, f"expected 'key = value' with a known key in [{section}], got {line!r}", line=number
            )
        attr, kind = kinds[(section, key)]
        try:
            values[attr] = _parse_value(value.strip(), kind)
        except ValueError as error:
            raise InputFileError(path, f"{key}: {error}", line=number) from None
        found[section][1][key] = number
    after_scan = _per_scan_lists(path, per_scan)  # a scan_k missing is named first
    if end_line is None and numbered_lines:
        end_line = numbered_lines[-1][0]
    _check_complete(path, found, per_scan, values.get("scans"), prefix, end_line)
    plain: dict[str, Any] = {}
    nested: dict[str, dict[str, Any]] = {}
    for attr, parsed in values.items():
        head, _, tail = attr.partition(".")
        if tail:
            nested.setdefault(head, {})[tail] = parsed
        else:
            plain[attr] = parsed
    for head, parts in nested.items():
        if head == "detection":
            from ladartui.detection.measures import DetectionMeasures

            plain[head] = DetectionMeasures(**parts)
        else:
            plain[head] = DirectionStats(**parts)
    plain.update(after_scan)
    measures = Measures(**plain)
    if levels is not None:
        measures = replace(measures, levels=levels_from_cmf(path, levels))
    return measures


def _check_complete(path, found, per_scan, scans, prefix: str, end_line: int | None) -> None:
    """Every figure-10 section with every key, and a ``scan_k`` line for each scan when
    there are any (``found``: section -> (its line, {key: line}))."""
    expected = [
        (name, entries) for name, entries in _CMF_SECTIONS if not (prefix and name == CMF_FLIGHT_SECTION)
    ]
    for index, (name, entries) in enumerate(expected):
        if name not in found:
            later = [found[other][0] for other, _ in expected[index + 1 :] if other in found]
            raise InputFileError(
                path, f"lacks the [{prefix}{name}] section", line=min(later, default=end_line)
            )
        line, keys = found[name]
        missing = [key for key, _attr, _kind in entries if key not in keys]
        if missing:
            raise InputFileError(path, f"[{prefix}{name}] lacks {', '.join(missing)}", line=line)
    if per_scan and scans is not None and len(per_scan) != scans:
        count = "1 scan_k line follows" if len(per_scan) == 1 else f"{len(per_scan)} scan_k lines follow"
        line = found[_PER_SCAN_SECTION][1]["scans"]
        raise InputFileError(path, f"[{prefix}{_PER_SCAN_SECTION}] scans = {scans} but {count}", line=line)
