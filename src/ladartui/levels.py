"""Detect, recognise, identify: how many looks until a target is seen well enough.

The report leaves "the target coverage required for identification" as a
measure still to be investigated (section 2.2). Here each level is a pair of
thresholds the analyst sets in the scenario's ``[levels]`` section:

* a share of the target's *visible* voxels (those with a face open to empty
  space, ``ladartui.measures.visible_mask``) seen through the foliage, and
* a share of its *footprint cells* seen: the (x, y) voxel columns that hold
  at least one target voxel. A footprint cell counts as seen once any target
  voxel in its column has been seen, so the footprint share says how much of
  the vehicle's extent the looks have found, not how many points they found.

A level is reached at the first scan after which both shares reach its
thresholds. The two guard against different misleading views: a patch of roof
voxels at one end of a vehicle may hold a tenth of its visible voxels yet
cover little of its extent (the footprint share stays low), while a view of
the whole roof from above covers the whole footprint with few of the voxels
(the voxel share stays low). A footprint threshold of 0 turns the spatial
check off for that level.

Scans are counted 1..n as the CLI reports them; the flight time and distance
at a scan are measured from the first scan along the flight plan
(``FlightPlan.scan_times`` and ``scan_distances``, the same source as the
run's path length and flight time). "Not reached" is ``reached = False``
with no scan, time or distance (None in Python, null in JSON, the words
``not reached`` in text and in the ``.cmf``), never NaN.

``levels_from_curves`` is the pure rule from share-after-each-scan curves;
``target_levels`` builds the curves for one target from its voxels and each
scan's returns, so a scene with several targets calls it once per target.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from ladartui.checks import number_field, range_text
from ladartui.errors import FieldError, InputFileError
from ladartui.number_text import fixed
from ladartui.scene.voxel_arrays import voxel_list_field

LEVELS = ("detect", "recognise", "identify")
NOT_REACHED = "not reached"
CMF_SECTION = "levels"
# Shares are ratios of counts; a share equal to its threshold in exact
# arithmetic may land a rounding step below it.
_TOLERANCE = 1e-12


@dataclass(frozen=True)
class LevelThresholds:
    """The ``[levels]`` scenario section: per level, a voxel share and a footprint share (0..1).

    Defaults, for a vehicle-sized target: detection needs enough returns to
    stand out from the canopy (10 % of what can be seen, spread over 10 % of
    its extent); recognising its class needs its overall size and shape
    (30 % of its visible voxels over half its footprint); identifying it
    needs most of its visible surface (50 % over three quarters of its
    footprint). The report sets no such values: they are starting points,
    and the analyst sets them for the target class at hand (from looks that
    analysts have judged), per scenario.
    """

    detect: float = 0.10
    recognise: float = 0.30
    identify: float = 0.50
    detect_footprint: float = 0.10
    recognise_footprint: float = 0.50
    identify_footprint: float = 0.75

    def __post_init__(self):
        # Each level needs at least what the level below it needs; a voxel share
        # of 0 would count a target as detected before anything is seen.
        for suffix, what, low_open in (
            ("", "visible voxels", True),
            ("_footprint", "footprint cells", False),
        ):
            below = None
            for level in LEVELS:
                name = level + suffix
                value = getattr(self, name)
                if below is None:
                    expected = range_text(f"a share of the target's {what}", 0.0, 1.0, low_open, False)
                    low = 0.0
                else:
                    low = getattr(self, below)
                    expected = (
                        f"a share of the target's {what} from levels.{below} ({low:g}) to 1 "
                        "(a higher level needs at least as much)"
                    )
                ok = isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
                ok = ok and math.isfinite(value) and value <= 1.0
                ok = ok and (value > low if below is None and low_open else value >= low)
                if not ok:
                    raise FieldError(f"levels.{name}", value, expected)
                object.__setattr__(self, name, float(value))
                below = name

    def voxel_share(self, level: str) -> float:
        return float(getattr(self, level))

    def footprint_share(self, level: str) -> float:
        return float(getattr(self, level + "_footprint"))

    def to_dict(self) -> dict:
        """The TOML section."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


LEVEL_KEYS = tuple(f.name for f in fields(LevelThresholds))


def percent_text(share: float) -> str:
    """A threshold share as a percentage, as written ("12.5" for 0.125, "0.4" for 0.004):
    the one wording of thresholds in the run's table and the scenario's summary."""
    return f"{100 * share:g}"


def level_below(key: str) -> str | None:
    """The threshold a level key must not fall below: ``recognise_footprint`` ->
    ``detect_footprint``; None for the lowest level."""
    level, _, suffix = key.partition("_")
    at = LEVELS.index(level)
    return f"{LEVELS[at - 1]}{'_' + suffix if suffix else ''}" if at else None


def levels_from_table(table: dict) -> LevelThresholds:
    """A ``[levels]`` table (keys already checked against LEVEL_KEYS) as thresholds."""
    return LevelThresholds(**table)


@dataclass(frozen=True)
class LevelReached:
    """One level for one target: reached or not, and at which scan, flight time and distance."""

    level: str
    reached: bool
    scan: int | None = None  # 1-based
    flight_time_s: float | None = None
    distance_m: float | None = None

    def describe(self) -> str:
        """``scan 3, 4.2 s, 125.7 m`` or ``not reached``."""
        if not self.reached:
            return NOT_REACHED
        assert self.flight_time_s is not None and self.distance_m is not None  # set when reached
        return f"scan {self.scan}, {fixed(self.flight_time_s, 1)} s, {fixed(self.distance_m, 1)} m"

    def to_dict(self) -> dict:
        return {
            "reached": self.reached,
            "scan": self.scan,
            "flight_time_s": self.flight_time_s,
            "distance_m": self.distance_m,
        }


@dataclass(frozen=True)
class LevelResult:
    """The levels one target reached over a flight, with the thresholds and final shares.

    ``visible_share`` and ``footprint_share`` are the shares seen after the
    last scan (None when the target has no visible voxels or no scans).
    """

    thresholds: LevelThresholds
    levels: tuple[LevelReached, ...]
    scans: int = 0
    visible_voxels: int | None = None
    footprint_cells: int | None = None
    visible_share: float | None = None
    footprint_share: float | None = None

    def level(self, name: str) -> LevelReached:
        for item in self.levels:
            if item.level == name:
                return item
        raise KeyError(name)

    @property
    def highest(self) -> LevelReached | None:
        """The highest level reached (None: not even detected)."""
        reached = [item for item in self.levels if item.reached]
        return reached[-1] if reached else None

    def summary(self) -> str:
        """One line: the highest level reached and when, e.g. for a recommended path."""
        top = self.highest
        if top is None:
            return "not detected (no level reached)"
        text = f"reaches {top.level} at {top.describe()}"
        missing = [item.level for item in self.levels if not item.reached]
        if missing:
            text += f"; {', '.join(missing)} {NOT_REACHED}"
        return text

    def to_dict(self) -> dict:
        """A JSON-safe dict; a level not reached has ``reached: false`` and null scan, time, distance."""
        return {
            "visible_voxels": self.visible_voxels,
            "footprint_cells": self.footprint_cells,
            "visible_share": self.visible_share,
            "footprint_share": self.footprint_share,
            "scans": self.scans,
            "thresholds": self.thresholds.to_dict(),
            **{item.level: item.to_dict() for item in self.levels},
        }

    def rows(self) -> list[tuple[str, str, str]]:
        """(level, "voxel % / footprint %" thresholds, where reached) rows for tables."""
        t = self.thresholds
        return [
            (
                item.level.capitalize(),
                f"{percent_text(t.voxel_share(item.level))} % / "
                f"{percent_text(t.footprint_share(item.level))} %",
                item.describe(),
            )
            for item in self.levels
        ]

    def cmf_lines(self) -> list[str]:
        """The ``[levels]`` section of a ``.cmf`` file (read back by ``levels_from_cmf``)."""
        lines = [
            f"[{CMF_SECTION}]",
            "# detect / recognise / identify in the obscured view: a level is reached at the first",
            "# scan after which the shares of the target's visible voxels and of its footprint",
            "# cells (x-y columns) seen both reach its thresholds (level_threshold = voxel, footprint).",
            "# level = scan, flight time s, distance m (from the first scan), or: not reached",
            f"scans = {self.scans}",
            f"visible_voxels = {_text(self.visible_voxels)}",
            f"footprint_cells = {_text(self.footprint_cells)}",
            f"visible_share = {_text(self.visible_share)}",
            f"footprint_share = {_text(self.footprint_share)}",
        ]
        for level in LEVELS:
            t = self.thresholds
            lines.append(f"{level}_threshold = {t.voxel_share(level)!r}, {t.footprint_share(level)!r}")
        for item in self.levels:
            value = (
                f"{item.scan}, {item.flight_time_s!r}, {item.distance_m!r}" if item.reached else NOT_REACHED
            )
            lines.append(f"{item.level} = {value}")
        return lines


def level_result_from_dict(data: dict) -> LevelResult:
    """The inverse of ``LevelResult.to_dict`` (the JSON of a run)."""
    return LevelResult(
        thresholds=LevelThresholds(**data["thresholds"]),
        levels=tuple(LevelReached(level=name, **data[name]) for name in LEVELS),
        scans=data["scans"],
        visible_voxels=data["visible_voxels"],
        footprint_cells=data["footprint_cells"],
        visible_share=data["visible_share"],
        footprint_share=data["footprint_share"],
    )


def _text(value) -> str:
    if value is None:
        return "undefined"
    return repr(value) if isinstance(value, float) else str(value)


def _first_scan(curve: Sequence[float], threshold: float) -> int | None:
    for k, value in enumerate(curve, start=1):
        if value >= threshold - _TOLERANCE:
            return k
    return None


def levels_from_curves(
    visible_share: Sequence[float] | None,
    footprint_share: Sequence[float] | None,
    scan_times: Sequence[float],
    scan_distances: Sequence[float],
    thresholds: LevelThresholds | None = None,
    *,
    visible_voxels: int | None = None,
    footprint_cells: int | None = None,
) -> LevelResult:
    """For each level: the first scan whose shares both reach its thresholds, and its time and distance.

    ``visible_share[k]`` and ``footprint_share[k]`` are the shares seen after
    scans 1..k+1 (cumulative, so never falling); ``scan_times`` and
    ``scan_distances`` are seconds and metres from the first scan to each
    scan. None curves (a target with nothing visible) reach no level.
    """
    thresholds = thresholds or LevelThresholds()
    count = len(scan_times)
    for name, values in (
        ("scan_distances", scan_distances),
        ("visible_share", visible_share),
        ("footprint_share", footprint_share),
    ):
        if values is not None and len(values) != count:
            raise FieldError(f"len({name})", len(values), f"one per scan time ({count})")
    # a NaN here would reach the .cmf and the JSON as "reached after nan s"
    scan_times = [number_field(f"scan_times[{k}]", t, 0) for k, t in enumerate(scan_times)]
    scan_distances = [number_field(f"scan_distances[{k}]", d, 0) for k, d in enumerate(scan_distances)]
    usable = visible_share is not None and footprint_share is not None and count > 0
    results = []
    for level in LEVELS:
        scan = None
        if visible_share is not None and footprint_share is not None:
            by_voxels = _first_scan(visible_share, thresholds.voxel_share(level))
            by_footprint = _first_scan(footprint_share, thresholds.footprint_share(level))
            if by_voxels is not None and by_footprint is not None:
                scan = max(by_voxels, by_footprint)
        if scan is None:
            results.append(LevelReached(level, False))
        else:
            results.append(
                LevelReached(level, True, scan, float(scan_times[scan - 1]), float(scan_distances[scan - 1]))
            )
    return LevelResult(
        thresholds=thresholds,
        levels=tuple(results),
        scans=count,
        visible_voxels=visible_voxels,
        footprint_cells=footprint_cells,
        visible_share=float(visible_share[-1]) if usable and visible_share else None,
        footprint_share=float(footprint_share[-1]) if usable and footprint_share else None,
    )


def share_curves(target_voxels, per_scan_returns) -> tuple[list[float], list[float], int, int] | None:
    """Cumulative (visible-voxel share, footprint share) after each scan, and the two totals.

    ``per_scan_returns``: each scan's returned voxels, (K, 3), in flight order;
    returns that are not target voxels (foliage, ground) are ignored. None
    when the target has no visible voxel.
    """
    # Here, not at the top: the CLI reads level names without loading numba's kernels.
    from ladartui.scene.keys import visible_mask, voxel_keys

    target = np.unique(voxel_list_field("target_voxels", target_voxels).astype(np.int64), axis=0)
    if target.shape[0] == 0:
        return None
    visible = visible_mask(target)
    visible_count = int(visible.sum())
    if visible_count == 0:
        return None
    target_keys = voxel_keys(target)  # sorted: np.unique sorts the rows, keys keep their order
    column_of = np.unique(target[:, :2], axis=0, return_inverse=True)[1].ravel()
    cells = int(column_of.max()) + 1
    seen = np.zeros(target.shape[0], dtype=bool)
    column_seen = np.zeros(cells, dtype=bool)
    voxel_curve, footprint_curve = [], []
    for scan, returns in enumerate(per_scan_returns):
        keys = voxel_keys(voxel_list_field(f"per_scan_returns[{scan}]", returns))
        if keys.size:
            pos = np.minimum(np.searchsorted(target_keys, keys), target_keys.size - 1)
            hit = pos[target_keys[pos] == keys]
            seen[hit] = True
            column_seen[column_of[hit]] = True
        voxel_curve.append(int((seen & visible).sum()) / visible_count)
        footprint_curve.append(int(column_seen.sum()) / cells)
    return voxel_curve, footprint_curve, visible_count, cells


def target_levels(
    target_voxels,
    per_scan_returns,
    scan_times: Sequence[float],
    scan_distances: Sequence[float],
    thresholds: LevelThresholds | None = None,
) -> LevelResult:
    """The levels one target reaches: its share curves from each scan's returns, then the rule."""
    curves = share_curves(target_voxels, per_scan_returns)
    if curves is None:
        return levels_from_curves(None, None, scan_times, scan_distances, thresholds)
    voxel_curve, footprint_curve, visible, cells = curves
    return levels_from_curves(
        voxel_curve,
        footprint_curve,
        scan_times,
        scan_distances,
        thresholds,
        visible_voxels=visible,
        footprint_cells=cells,
    )


# --------------------------------------------------------------------------- .cmf


def levels_from_cmf(path, entries: dict[str, tuple[int, str]]) -> LevelResult:
    """The ``[levels]`` section of a ``.cmf`` file back as a LevelResult.

    ``entries`` maps each key to (line number, value text). Errors name the
    file, the line and what was expected.
    """
    known = {"scans", "visible_voxels", "footprint_cells", "visible_share", "footprint_share"}
    known |= {f"{level}_threshold" for level in LEVELS} | set(LEVELS)
    for key, (line, _) in entries.items():
        if key not in known:
            raise InputFileError(path, f"unknown key {key!r} in [{CMF_SECTION}]", line=line)
    first_line = min((line for line, _ in entries.values()), default=None)

    def get(key):
        if key not in entries:
            raise InputFileError(path, f"[{CMF_SECTION}] lacks {key}", line=first_line)
        return entries[key]

    def number(key, kind):
        line, text = get(key)
        if text == "undefined" and key != "scans":
            return None
        try:
            value = kind(text)
        except ValueError:
            raise InputFileError(path, f"{key}: expected {kind.__name__}, got {text!r}", line=line) from None
        if not math.isfinite(value):
            raise InputFileError(path, f"{key}: expected a finite number, got {text!r}", line=line)
        return value

    def numbers(key, count, what):
        line, text = get(key)
        parts = [p.strip() for p in text.split(",")]
        try:
            values = [float(p) for p in parts]
        except ValueError:
            values = []
        if len(values) != count or not all(math.isfinite(v) for v in values):
            raise InputFileError(path, f"{key}: expected {what}, got {text!r}", line=line)
        return values

    shares = {}
    for level in LEVELS:
        voxel, footprint = numbers(f"{level}_threshold", 2, "voxel share, footprint share")
        shares[level], shares[level + "_footprint"] = voxel, footprint
    try:
        thresholds = LevelThresholds(**shares)
    except FieldError as error:
        line = get(error.field.split(".")[-1].replace("_footprint", "") + "_threshold")[0]
        raise InputFileError(path, str(error), line=line) from None
    reached = []
    for level in LEVELS:
        line, text = get(level)
        if text == NOT_REACHED:
            reached.append(LevelReached(level, False))
            continue
        scan, time_s, distance = numbers(level, 3, f"scan, flight time, distance or {NOT_REACHED!r}")
        if scan != int(scan) or scan < 1:
            raise InputFileError(path, f"{level}: expected a scan number >= 1, got {text!r}", line=line)
        reached.append(LevelReached(level, True, int(scan), time_s, distance))
    return LevelResult(
        thresholds=thresholds,
        levels=tuple(reached),
        scans=number("scans", int),
        visible_voxels=number("visible_voxels", int),
        footprint_cells=number("footprint_cells", int),
        visible_share=number("visible_share", float),
        footprint_share=number("footprint_share", float),
    )
