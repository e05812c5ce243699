"""Measures as tables for people: the report's figure 10 (one column a view) and the
comparison rows, with "undefined" where a figure has no value (the CLI's ``run``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ladartui.measures import ENOUGH_SHARE
from ladartui.number_text import coverage_steps, fixed

if TYPE_CHECKING:
    from ladartui.measures import Measures

UNDEFINED = "undefined"


def format_share(value) -> str:
    """A fraction as a percentage with one decimal, or "undefined"."""
    return UNDEFINED if value is None else f"{100.0 * value:.1f} %"


def format_number(value, digits=3, unit="") -> str:
    """A number with ``digits`` decimals (and a unit), or "undefined"."""
    if value is None:
        return UNDEFINED
    return f"{fixed(value, digits)}{' ' + unit if unit else ''}"


def format_vector(vector, digits=3) -> str:
    """A 3-vector as "x, y, z", or "undefined"."""
    if vector is None:
        return UNDEFINED
    return ", ".join(fixed(c, digits) for c in vector)


def view_rows(measures: Measures) -> list[tuple[str, ...]]:
    """Rows (label, target model, unobscured, obscured) as in the report's figure 10."""
    m = measures
    views = (m.model_directions, m.unobscured_directions, m.obscured_directions)
    return [
        (
            "Target coverage",
            format_share(m.maximum_coverage),
            format_share(m.unobscured_coverage),
            format_share(m.obscured_coverage),
        ),
        (
            "Voxels",
            f"{m.visible_voxels:,} of {m.target_voxels:,}",
            f"{m.unobscured_voxels:,}",
            f"{m.obscured_voxels:,}",
        ),
        ("Sample mean vector", *(format_vector(v.mean_vector) for v in views)),
        ("Mean resultant length", *(format_number(v.resultant_length) for v in views)),
        ("Mean direction", *(format_vector(v.mean_direction) for v in views)),
    ]


def comparison_rows(measures: Measures) -> list[tuple[str, str]]:
    """Rows (label, value) comparing the views, coverage per scan and the flight."""
    m = measures

    def after(values):
        return UNDEFINED if values is None else coverage_steps(values) + " (%)"

    return [
        ("Shift in mean direction", format_number(m.direction_shift_rad, unit="rad")),
        ("Unobscured coverage missed when obscured", format_share(m.missed_share)),
        ("Obscured / unobscured coverage", format_share(m.coverage_ratio)),
        (
            "Seen obscured but not unobscured",
            f"{m.obscured_only_voxels} voxel{'' if m.obscured_only_voxels == 1 else 's'}",
        ),
        ("Obscured coverage after each scan", after(m.obscured_after_scan)),
        ("Unobscured coverage after each scan", after(m.unobscured_after_scan)),
        (
            f"Scans to reach {ENOUGH_SHARE:.0%} of final coverage",
            UNDEFINED if m.scans_for_enough is None else f"{m.scans_for_enough} of {m.scans}",
        ),
        ("Path length", format_number(m.path_length_m, 1, "m")),
        ("Flight time", format_number(m.flight_time_s, 1, "s")),
    ]
