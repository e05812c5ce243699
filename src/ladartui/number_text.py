"""Numbers as text for tables and sentences."""

from __future__ import annotations

import math
from decimal import ROUND_HALF_UP, Context, Decimal

FIXED_BELOW = 1e10  # from here on a number is written with an exponent


def fixed(value: float, digits: int) -> str:
    """``value`` with ``digits`` decimals; from 1e10 on with an exponent ("4.054e+301"),
    never hundreds of digits that a table cuts to a smaller-looking number."""
    value = float(value)
    if not math.isfinite(value):
        return f"{value}"
    if abs(value) >= FIXED_BELOW:
        return f"{value:.4g}"
    return _half_up(value, digits)


def _half_up(value: float, digits: int, grouped: bool = False) -> str:
    """``value`` to ``digits`` decimals, an exact half away from zero: 5 voxels in 8 is
    62.5 %, shown "63" as a reader rounds it, where formatting gives the even "62"."""
    exact = Decimal(value)  # the binary value itself: 2.675 is 2.67499..., no half
    rounded = exact.quantize(Decimal(1).scaleb(-digits), rounding=ROUND_HALF_UP, context=Context(prec=400))
    return f"{rounded:{',' if grouped else ''}.{digits}f}"


def fixed_or_tiny(value: float, digits: int, grouped: bool = False) -> str:
    """``fixed`` (``grouped``: thousands separated, "12,345.6"), but a value too small for
    ``digits`` decimals and not zero with its exponent ("2.00e-07"): a tiny chance is
    not none, never "0.000000"."""
    value = float(value)
    if 0 < abs(value) < 0.5 * 10**-digits:
        return f"{value:.2e}"
    if grouped and math.isfinite(value) and abs(value) < FIXED_BELOW:
        return _half_up(value, digits, grouped=True)
    return fixed(value, digits)


def trimmed(value: float, digits: int = 6) -> str:
    """``value`` to ``digits`` significant digits without trailing zeros ("18.25", "150",
    not 150.00000000000003); from 1e10 on with an exponent, as ``fixed`` writes it."""
    value = float(value)
    if not math.isfinite(value) or abs(value) >= FIXED_BELOW:
        return f"{value:.4g}"
    text = f"{value:.{digits}g}"
    return f"{value:.0f}" if "e+" in text else text  # a million and up: written out


def extent_metres(shape, voxel_size: float) -> str:
    """The sides of a box of ``shape`` voxels in metres, "2.5 x 2.5 x 18.25": one
    wording for every command that shows a scene's extent."""
    return " x ".join(trimmed(n * voxel_size) for n in shape)


def extent_ranges(lo, hi) -> str:
    """The index ranges of voxels from ``lo`` to ``hi`` and the shape a reader gives
    them: "x 0..239, y 0..239, z 0..72  (shape 240 x 240 x 73)"."""
    ranges = ", ".join(f"{axis} {int(low)}..{int(high)}" for axis, low, high in zip("xyz", lo, hi))
    return f"{ranges}  (shape {' x '.join(str(int(h) + 1) for h in hi)})"


def plural(count: int, noun: str, nouns: str | None = None) -> str:
    """``count`` with thousands separators and ``noun``, plural unless it is 1:
    "1 voxel", "2,048 voxels"; ``nouns`` where the plural is not noun + "s"."""
    return f"{count:,} {noun if count == 1 else nouns or noun + 's'}"


def coverage_steps(shares) -> str:
    """Coverage shares (0..1) as whole percents, "0 <1 12 >99 100": a glimpse never
    reads 0 (never hit) nor a near miss 100 (all of it)."""

    def step(share: float) -> str:
        percent = 100.0 * share
        if 0 < percent < 1:
            return "<1"
        if 99 < percent < 100:
            return ">99"
        return _half_up(percent, 0)

    return " ".join(step(share) for share in shares)


def top_view_width(metres: float) -> str:
    """A width as the top view's title gives it: three figures in m or km, no exponent."""
    if metres < 999.5:
        return f"{metres:.3g} m"
    km = metres / 1000
    return f"{km:.3g} km" if km < 999.5 else f"{km:,.0f} km"


def zoom_text(zoom: float) -> str:
    """A 3D view's zoom as its title gives it: two figures, no exponent (x160, x0.65)."""
    return format(Decimal(f"{zoom:.2g}"), "f")
