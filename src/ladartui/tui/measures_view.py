"""Measures as table rows: the report's figure 10 layout and the side-by-side comparison."""

from __future__ import annotations

from rich.text import Text

from ladartui.colour import target_colour
from ladartui.levels import LEVELS
from ladartui.number_text import fixed

UNDEFINED = "undefined"

# (label, Measures.to_dict path, kind, better): better is "high", "low" or None
ROWS = [
    ("Maximum target coverage", "maximum_coverage", "pct", "high"),
    ("Unobscured target coverage", "unobscured_coverage", "pct", "high"),
    ("Obscured target coverage", "obscured_coverage", "pct", "high"),
    ("Target voxels", "target_voxels", "int", None),
    ("Visible target voxels", "visible_voxels", "int", None),
    ("Unobscured voxels", "unobscured_voxels", "int", "high"),
    ("Obscured voxels", "obscured_voxels", "int", "high"),
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


# the sidebar's short list (F9 shows every measure)
COMPACT = [
    ("Max coverage", "maximum_coverage", "pct"),
    ("Unobscured cov.", "unobscured_coverage", "pct"),
    ("Obscured cov.", "obscured_coverage", "pct"),
    ("Dir. shift rad", "direction_shift_rad", "num"),
    ("Missed share", "missed_share", "pct"),
    ("Coverage ratio", "coverage_ratio", "num"),
    ("Scans", "scans", "int"),
    ("Scans for 90%", "scans_for_enough", "int"),
    ("Path m", "path_length_m", "num1"),
    ("Time s", "flight_time_s", "num1"),
]


def lookup(data: dict, path: str):
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
    return fixed(value, 3)


def measure_rows(measures) -> list[tuple[str, str]]:
    """(label, text) for each measure of one run (``Measures`` or its dict)."""
    data = measures if isinstance(measures, dict) else measures.to_dict()
    return [(label, format_value(lookup(data, path), kind)) for label, path, kind, _ in ROWS]


def compact_rows(measures) -> list[tuple[str, str]]:
    """The sidebar's short list of measures."""
    data = measures if isinstance(measures, dict) else measures.to_dict()
    return [(label, format_value(lookup(data, path), kind)) for label, path, kind in COMPACT]


def comparison_rows(all_measures: list) -> list[list]:
    """One row per measure: label then one cell per scenario, differences highlighted.

    Where the scenarios disagree the row label is bold yellow; for a measure
    with a direction of goodness the best value is green and the worst red.
    When every run holds the same several targets, rows per target follow.
    """
    dicts = [m if isinstance(m, dict) else m.to_dict() for m in all_measures]
    rows = [
        _compare_row(label, [lookup(d, path) for d in dicts], kind, better)
        for label, path, kind, better in ROWS
    ]
    for level in LEVELS:
        scans = [lookup(d, f"levels.{level}.scan") for d in dicts]
        rows.append(_compare_row(f"{level.capitalize()} at scan", scans, "int", "low"))
    targets = [d.get("targets") for d in dicts]
    if all(isinstance(t, dict) for t in targets):
        per = [{t["id"]: t for t in tt["per_target"]} for tt in targets if isinstance(tt, dict)]
        ids = sorted(per[0]) if per else []
        if len(ids) > 1 and all(sorted(p) == ids for p in per):
            for target_id in ids:
                name = per[0][target_id]["name"]
                for label, path, kind, better in TARGET_ROWS:
                    values = [lookup(p[target_id]["measures"], path) for p in per]
                    rows.append(_compare_row(f"{name}: {label}", values, kind, better))
    return rows


def _compare_row(label: str, values: list, kind: str, better) -> list:
    texts = [format_value(v, kind) for v in values]
    differ = len(set(texts)) > 1
    cells = [Text(t) for t in texts]
    if differ:
        numeric = [
            (float(v), i) for i, v in enumerate(values) if v is not None and not isinstance(v, (list, tuple))
        ]
        for cell in cells:
            cell.stylize("yellow")
        if better and len(numeric) >= 2:
            best = max(numeric) if better == "high" else min(numeric)
            worst = min(numeric) if better == "high" else max(numeric)
            if best[0] != worst[0]:
                for v, i in numeric:
                    if v == best[0]:
                        cells[i] = Text(texts[i], style="bold green")
                    elif v == worst[0]:
                        cells[i] = Text(texts[i], style="bold red")
    return [Text(label, style="bold yellow" if differ else ""), *cells]


# per target, in the comparison and the measures dialog
TARGET_ROWS = [
    ("obscured coverage", "obscured_coverage", "pct", "high"),
    ("unobscured coverage", "unobscured_coverage", "pct", "high"),
    ("maximum coverage", "maximum_coverage", "pct", "high"),
    ("identify at scan", "levels.identify.scan", "int", "low"),
]


def level_rows(measures, short: bool = False) -> list[tuple[str, str]]:
    """(level, where it was reached or "not reached") for the whole target model."""
    levels = measures.levels
    if levels is None:
        return []
    rows = []
    for item in levels.levels:
        if short and item.reached:
            text = f"scan {item.scan}, {fixed(item.flight_time_s, 1)} s"
        else:
            text = item.describe()
        rows.append((item.level.capitalize(), text))
    return rows


SHORT_LEVELS = {"detect": "det", "recognise": "rec", "identify": "id"}


def highest_level(levels, short: bool = False) -> str:
    """``identify @ 15`` (the highest level reached and its scan; ``id@15`` short), or ``none``."""
    top = None if levels is None else levels.highest
    if top is None:
        return "none"
    return f"{SHORT_LEVELS[top.level]}@{top.scan}" if short else f"{top.level} @ {top.scan}"


def target_rows(measures, short: bool = False) -> list[tuple[Text, str, str]]:
    """(name in its view colour, obscured coverage, highest level @ scan) per target, then
    the worst and the mean coverage; empty for a model of one target."""
    per = measures.targets
    if per is None or len(per.targets) < 2:
        return []
    rows = []
    for index, target in enumerate(per.targets):
        swatch = Text("\u25a0 ", style="rgb({},{},{})".format(*target_colour(index)))
        name = swatch + Text(target.name)  # a name from a file: text, never markup
        m = target.measures
        rows.append((name, format_value(m.obscured_coverage, "pct"), highest_level(m.levels, short)))
    for label, summary in (("worst", per.worst), ("mean", per.mean)):
        rows.append((Text(label, style="italic"), format_value(summary.obscured_coverage, "pct"), ""))
    return rows
