"""Measures as table rows: the report's figure 10 layout, the sidebar's short list, levels and
targets (the side-by-side comparison is ladartui.measures_compare's)."""

from __future__ import annotations

from rich.text import Text

from ladartui.colour import target_colour
from ladartui.measures_compare import ROWS, format_value, lookup
from ladartui.number_text import fixed

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


def measure_rows(measures) -> list[tuple[str, str]]:
    """(label, text) for each measure of one run (``Measures`` or its dict)."""
    data = measures if isinstance(measures, dict) else measures.to_dict()
    return [(label, format_value(lookup(data, path), kind)) for label, path, kind, _ in ROWS]


def compact_rows(measures) -> list[tuple[str, str]]:
    """The sidebar's short list of measures."""
    data = measures if isinstance(measures, dict) else measures.to_dict()
    return [(label, format_value(lookup(data, path), kind)) for label, path, kind in COMPACT]


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
