"""Field checks: a value a person wrote, taken or refused with a FieldError.

Shared by flight, sensor, scenario, detection settings, flight logs and the
forms; each check names the field and says what was expected (``errors``).
"""

from __future__ import annotations

import math
import numbers
import operator

import numpy as np

from ladartui.errors import FieldError

MAX_COORDINATE = 1e6  # metres; a scene is never larger than a few kilometres


def number_field(name, value, low=None, high=None, *, low_open=False, high_open=False):
    """``value`` as a finite float within the limits, else FieldError naming ``name``."""
    # numbers.Real covers numpy scalars; bool is an int but never a number here.
    ok = isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
    number = float(value) if ok else math.nan
    ok = ok and math.isfinite(number)
    if ok and low is not None:
        ok = number > low if low_open else number >= low
    if ok and high is not None:
        ok = number < high if high_open else number <= high
    if not ok:
        raise FieldError(
            name,
            value,
            range_text("a number", low, high, low_open, high_open),
            limits=(low, high, low_open, high_open),
        )
    return number


def compass_field(name, value):
    """A compass angle typed by a person: degrees from 0 to 360 (computed headings fold)."""
    return number_field(name, value, 0.0, 360.0)


def integer_field(name, value, low, high):
    """``value`` as an int from ``low`` to ``high``, else FieldError naming ``name``."""
    try:
        number = None if isinstance(value, bool) else operator.index(value)
    except TypeError:
        number = None
    if number is None or not low <= number <= high:
        raise FieldError(name, value, f"an integer from {low} to {high}", limits=(low, high, False, False))
    return int(number)


def choice_field(name, value, choices):
    """``value`` if it is one of ``choices``, else FieldError listing them."""
    if not isinstance(value, str) or value not in choices:
        raise FieldError(name, value, "one of " + ", ".join(repr(c) for c in choices))
    return value


def switch_field(name, value, expected: str = "True or False") -> bool:
    """``value`` as a bool if it is True or False (numpy's too), else FieldError: text
    such as "no" is true, and a switch given it did the opposite of what was meant.
    ``expected`` words the error in the reader's terms ("true or false" in TOML)."""
    if not isinstance(value, bool | np.bool_):
        raise FieldError(name, value, expected)
    return bool(value)


def items_or_none(value) -> list | None:
    """The items of ``value`` as a list where it is an iterable but not text (a string
    is an iterable of its letters, which no list field means); else None."""
    if isinstance(value, (str, bytes)):
        return None
    try:
        return list(value)
    except TypeError:
        return None


def point_field(name, value):
    """A point [x, y] or [x, y, z] in metres as a float tuple of three (z = 0 if absent)."""
    expected = f"a point [x, y] or [x, y, z] in metres, each within +-{number_text(MAX_COORDINATE)}"
    items = items_or_none(value)
    if items is None or len(items) not in (2, 3):
        raise FieldError(name, value, expected)
    try:
        xyz = [number_field(name, v, -MAX_COORDINATE, MAX_COORDINATE) for v in items]
    except FieldError:
        raise FieldError(name, value, expected) from None
    return (xyz[0], xyz[1], xyz[2] if len(xyz) == 3 else 0.0)


def range_text(kind, low, high, low_open, high_open):
    if low is not None and high is not None:
        if not low_open and not high_open:
            return f"{kind} from {number_text(low)} to {number_text(high)}"
        lo = "greater than" if low_open else "at least"
        hi = "less than" if high_open else "at most"
        return f"{kind} {lo} {number_text(low)} and {hi} {number_text(high)}"
    if low is not None:
        return f"{kind} {'>' if low_open else '>='} {number_text(low)}"
    if high is not None:
        return f"{kind} {'<' if high_open else '<='} {number_text(high)}"
    return f"a finite {kind.removeprefix('a ')}"


def number_text(x) -> str:
    """A limit as people write it: 100 not 100.0, 1e+06 for a million."""
    return str(int(x)) if float(x).is_integer() else f"{x:g}"
