"""Per-target columns of a sweep row, and reading them back per target.

A row keeps the overall measures (all targets as one) under their own names,
and per target flat columns named by the target's id::

    targets.ids                         [1, 2, 3]   (JSON list, ascending)
    targets.count                       3
    targets.worst.obscured_coverage     worst over the targets (and the other summaries)
    targets.mean.obscured_coverage      mean over the targets
    target.2.name                       "van"
    target.2.obscured_coverage          that target's figures (SCALARS)
    target.2.levels.identify.scan       its levels: LEVEL.reached / .scan / .flight_time_s / .distance_m

Variants of one sweep share the base scene, so they share the targets; a
table mixing bases (or an older table) may hold rows with other ids or none:
their missing cells read back as None. A row holding instead a
``targets.per_target`` cell (each target's ``Measures.to_dict``, as an
earlier version wrote) is read from that cell; a row with neither reads as
one target through the overall columns. Why id-named columns and not
one JSON cell per row: a spreadsheet can sort and chart ``target.2.obscured_coverage``
directly, and a row stays a few hundred cells even with many targets (the
per-target direction vectors and after-scan curves are left to the run's
``.cmf``; the worst and mean curves stay in the row).
"""

from __future__ import annotations

from ladartui.levels import LEVELS

IDS_COLUMN = "targets.ids"
PER_TARGET_KEY = "per_target"
PER_TARGET_COLUMN = "targets.per_target"  # the JSON cell of an earlier table (read, not written)
# Per-target measures kept as columns (the rest of a target's measures are in its run's .cmf).
SCALARS = (
    "target_voxels",
    "visible_voxels",
    "maximum_coverage",
    "unobscured_coverage",
    "obscured_coverage",
    "coverage_ratio",
    "missed_share",
    "direction_shift_rad",
    "scans_for_enough",
)
LEVEL_FIELDS = ("reached", "scan", "flight_time_s", "distance_m")
LEVEL_SHARES = ("visible_share", "footprint_share", "scans")


def target_column(target_id: int, column: str) -> str:
    """The column of ``column`` (a measure or ``levels.LEVEL.FIELD``) for one target."""
    return f"target.{int(target_id)}.{column}"


def per_target_columns(per_target: list[dict]) -> dict:
    """Flat columns of ``PerTarget.to_dict()['per_target']``: ids, then each target's figures."""
    out: dict[str, object] = {IDS_COLUMN: [int(t["id"]) for t in per_target]}
    for target in per_target:
        target_id = int(target["id"])
        measures = target["measures"]
        out[target_column(target_id, "name")] = target["name"]
        for key in SCALARS:
            out[target_column(target_id, key)] = measures.get(key)
        levels = measures.get("levels") or {}
        for key in LEVEL_SHARES:
            out[target_column(target_id, f"levels.{key}")] = levels.get(key)
        for level in LEVELS:
            reached = levels.get(level) or {}
            for field in LEVEL_FIELDS:
                out[target_column(target_id, f"levels.{level}.{field}")] = reached.get(field)
    return out


def target_ids(row: dict) -> list[int]:
    """The row's target ids (empty for a row from before per-target columns, or a failed one)."""
    ids = row.get(IDS_COLUMN)
    if not isinstance(ids, list):
        return []
    return [i for i in ids if isinstance(i, int) and not isinstance(i, bool)]


def target_names(row: dict) -> list[str]:
    """Each target's name in target order ("target N" where the row has none)."""
    ids = target_ids(row)
    if ids:
        return [str(row.get(target_column(i, "name")) or f"target {i}") for i in ids]
    cell = _per_target_cell(row)
    if cell:
        return [str(t.get("name") or f"target {t.get('id', n + 1)}") for n, t in enumerate(cell)]
    return ["target 1"]


def target_values(row: dict, column: str) -> list:
    """The value of ``column`` for each target of the row, in target order.

    ``column`` is a measure or a dotted levels path (``levels.identify.scan``).
    A row with per-target columns gives one value per target id; one with a
    ``targets.per_target`` cell, each target's value from it; a row with
    neither, the overall column as one target.
    """
    ids = target_ids(row)
    if ids:
        return [row.get(target_column(i, column)) for i in ids]
    cell = _per_target_cell(row)
    if not cell:
        return [row.get(column)]
    values = []
    for target in cell:
        value = target.get("measures")
        for part in column.split("."):
            value = value.get(part) if isinstance(value, dict) else None
        values.append(value)
    return values


def _per_target_cell(row: dict) -> list[dict]:
    cell = row.get(PER_TARGET_COLUMN)
    return [t for t in cell if isinstance(t, dict)] if isinstance(cell, list) else []
