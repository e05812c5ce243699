"""Numbers as text for tables and sentences."""

from __future__ import annotations

import math

FIXED_BELOW = 1e10  # from here on a number is written with an exponent


def fixed(value: float, digits: int) -> str:
    """``value`` with ``digits`` decimals; from 1e10 on with an exponent ("4.054e+301"),
    never hundreds of digits that a table cuts to a smaller-looking number."""
    value = float(value)
    if math.isfinite(value) and abs(value) >= FIXED_BELOW:
        return f"{value:.4g}"
    return f"{value:.{digits}f}"


def plural(count: int, noun: str, nouns: str | None = None) -> str:
    """``count`` with thousands separators and ``noun``, plural unless it is 1:
    "1 voxel", "2,048 voxels"; ``nouns`` where the plural is not noun + "s"."""
    return f"{count:,} {noun if count == 1 else nouns or noun + 's'}"
