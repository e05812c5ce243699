"""Checked form fields: numbers typed by the analyst, validated by the core's own checks.

A field knows how to turn its text into a value and how to ask the core
whether the value is allowed (``check`` raises ``FieldError``). While typing,
a bad value only marks the field; when the analyst commits it (Enter or
leaving the field) a bad value resets the field to its default and the app
says why. Limits are never repeated here: they live in the core.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from textual.widgets import Input

from ladartui.errors import FieldError, LadarError


def parse_number(name: str, text: str, integer: bool = False, scale: float = 1.0):
    """The number typed in ``text`` (times ``scale``), or FieldError naming ``name``."""
    stripped = text.strip()
    try:
        value = float(stripped)
    except ValueError:
        raise FieldError(name, stripped, "a whole number" if integer else "a number") from None
    if not math.isfinite(value):
        raise FieldError(name, stripped, "a finite number")
    if integer:
        if value != int(value):
            raise FieldError(name, stripped, "a whole number")
        return int(value)
    # dividing by 1e6 gives the double nearest 50 um; times 1e-6 one a bit off it
    return value / (1.0 / scale) if 0 < scale < 1 else value * scale


FORM_UNITS = frozenset({"m", "deg", "s", "m/s", "um", "Hz"})  # a form label's last word


def in_label_unit(label: str, expected: str) -> str:
    """``expected`` with its last number in the unit ``label`` ends with ("Radius m":
    "... at most 1000000 m"), as a form's message gives limits."""
    unit = label.rpartition(" ")[2]
    return f"{expected} {unit}" if unit in FORM_UNITS and expected[-1:].isdigit() else expected


def refusal(label: str, typed: str, expected: str) -> str:
    """The one line for a refused value: the field as the form names it, the text
    typed there (``empty`` for none) and what is expected."""
    return f"{label}: {typed.strip() or 'empty'} is not allowed; expected {expected}"


def format_number(value, integer: bool = False, scale: float = 1.0) -> str:
    """Text for a field: integers plain, floats to six significant digits."""
    if value is None:
        return ""
    if integer:
        return str(int(value))
    return f"{float(value) / scale:.6g}"


class NumberField(Input):
    """A one-line numeric input tied to a named parameter.

    ``check(value)`` must raise ``FieldError`` (or another ``LadarError``) for a
    value the core rejects; ``default`` is what the field resets to.
    """

    def __init__(
        self,
        name: str,
        value,
        *,
        default,
        check: Callable[[Any], None],
        integer: bool = False,
        scale: float = 1.0,
        optional: bool = False,
        **kwargs,
    ):
        kwargs.setdefault("compact", True)
        # six digits: a form's check reads fields not built yet (set_number, once they are)
        super().__init__(value=format_number(value, integer, scale), **kwargs)
        self.field_name = name
        self.default = default
        self.check = check
        self.integer = integer
        self.scale = scale
        self.optional = optional
        self.committed = self.value
        self._shown: tuple[Any, str] | None = None  # the last value set and its text

    def parsed(self):
        """The typed value (None for an empty optional field); FieldError if not allowed."""
        if self.optional and not self.value.strip():
            value = None
        else:
            try:
                value = self.number()
            except FieldError as error:
                raise self._with_limits(error) from None
        self.check(value)
        return value

    def number(self):
        """The number the text gives, unchecked (FieldError for text that is none): text
        left as it was shown gives the value shown, not its six digits."""
        if self._shown is not None and self.value == self._shown[1]:
            return self._shown[0]
        return parse_number(self.field_name, self.value, self.integer, self.scale)

    def _with_limits(self, error: FieldError) -> FieldError:
        """For text that is no number (or no whole one): the core's expectation with its
        limits, asked of the check with NaN (inside no range), else ``error`` as it is."""
        try:
            self.check(math.nan)
        except FieldError as core:
            if core.limits is not None:
                expected = core.expected
                if error.expected == "a finite number" and not expected.startswith("a finite"):
                    # "1e400": "a number >= 0" would not say what is wrong with it
                    expected = "a finite " + expected.removeprefix("a ")
                return FieldError(error.field, error.value, expected, limits=core.limits)
        except LadarError:
            pass
        return error

    def problem(self) -> str | None:
        """Why the current text is not allowed, or None."""
        try:
            self.parsed()
        except LadarError as error:
            return str(error)
        return None

    def _text(self, value) -> str:
        """``format_number``'s text, or more digits where its six would round the value
        onto one the field refuses (fov 89.99999 shown as 90, which is not allowed)."""
        text = format_number(value, self.integer, self.scale)
        if value is None or self.integer or float(text) == float(f"{float(value) / self.scale:.15g}"):
            return text  # the value as it is (to the digits a float holds): nothing to check
        if self._shown is not None and self._shown[0] == value:
            return self._shown[1]  # a refresh of the same value: not checked again
        for digits in (9, 12, 17):
            try:
                self.check(parse_number(self.field_name, text, self.integer, self.scale))
                return text
            except LadarError:
                text = f"{float(value) / self.scale:.{digits}g}"
        return text

    def set_number(self, value) -> None:
        self.value = self._text(value)
        self._shown = (value, self.value)
        self.committed = self.value
        self.remove_class("-bad")

    def reset_to_default(self) -> None:
        self.set_number(self.default)
