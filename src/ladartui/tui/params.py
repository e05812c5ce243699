"""Numeric parameter fields in the sidebar panels, and the one way they edit the scenario.

A panel that shows parameters derives from ``ParamPanel``: it makes one
``NumberField`` per ``bridge.Param``, fills them from the scenario, and
commits a typed value through the app's ``edit``, the single path every
change to the scenario takes (so undo, the modified mark and the redraw
all follow). A value the core refuses goes back to the scenario's own value
with a message in the field's label and units.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from textual import on
from textual.containers import Horizontal, VerticalScroll
from textual.widgets import Input, Label

from ladartui.checks import range_text
from ladartui.errors import FieldError, LadarError
from ladartui.tui import bridge
from ladartui.tui.fields import NumberField, format_number, refusal
from ladartui.tui.host import AppHost, host_of


def field_id(key: str) -> str:
    return "f-" + key.replace(".", "-").replace("_", "-")


def field_message(param: bridge.Param, typed: str, error: LadarError) -> str:
    """Why a typed value was refused, in the words and units of the form."""
    shown = f"{param.label} {param.unit}".strip()
    if isinstance(error, FieldError):
        expected = error.expected
        if error.limits is not None:
            low, high, low_open, high_open = error.limits
            kind = "a whole number" if param.integer else "a number"
            expected = range_text(
                kind,
                None if low is None else low / param.scale,
                None if high is None else high / param.scale,
                low_open,
                high_open,
            )
            if param.unit:
                expected += f" {param.unit}"
        return refusal(shown, typed, expected)
    return f"{shown}: {error}"


class ParamField(NumberField):
    """A panel's field for one scenario parameter (``param``)."""

    def __init__(self, param: bridge.Param, *, check: Callable[[Any], None], **kwargs: Any):
        super().__init__(
            param.key, None, default=None, integer=param.integer, scale=param.scale, check=check, **kwargs
        )
        self.param = param


class ParamPanel(VerticalScroll):
    """A sidebar panel with parameter fields; subclasses compose with ``param_row``."""

    DEFAULT_CLASSES = "pane"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.loading_fields = False  # set while filling fields from the scenario

    @property
    def host(self) -> AppHost:
        """The app this panel edits the scenario of."""
        return host_of(self)

    def param_row(self, param: bridge.Param) -> Horizontal:
        field = ParamField(param, check=self._checker(param.key), id=field_id(param.key), classes="param")
        label = f"{param.label} {param.unit}".strip()
        return Horizontal(Label(label), field, classes="row", id=field_id(param.key) + "-row")

    def _checker(self, key):
        def check(value):
            scenario = self.host.scenario
            if scenario is not None:
                bridge.check_param(scenario, key, value)

        return check

    def param_fields(self) -> list[ParamField]:
        return list(self.query(".param").results(ParamField))

    def fill_fields(self, scenario) -> None:
        """Show the scenario's values (typing in progress is replaced)."""
        self.loading_fields = True
        try:
            for field in self.param_fields():
                value = bridge.param_value(scenario, field.field_name)
                field.default = value
                field.set_number(value)
        finally:
            self.loading_fields = False

    @on(Input.Changed, ".param")
    def _typed(self, event: Input.Changed) -> None:
        if self.loading_fields or not isinstance(event.input, NumberField):
            return
        event.input.set_class(event.input.problem() is not None, "-bad")
        self.host.refresh_status()

    @on(Input.Submitted, ".param")
    @on(Input.Blurred, ".param")
    def _committed(self, event) -> None:
        self.commit_field(event.input)

    def commit_field(self, field: ParamField) -> bool:
        """Apply the typed value; an invalid one goes back to the scenario's value, with why.

        True when the field now holds the scenario's value (changed or not).
        """
        app = self.host
        if app.scenario is None or field.value == field.committed:
            field.remove_class("-bad")
            app.refresh_status()
            return True
        param = field.param
        typed = field.value
        try:
            value = field.parsed()
            scenario = bridge.with_param(app.scenario, param.key, value)
        except LadarError as error:
            field.set_number(bridge.param_value(app.scenario, param.key))
            app.tell(
                f"{field_message(param, typed, error)}. Kept {field.value}.",
                title="Invalid value",
                severity="warning",
                timeout=8,
            )
            app.refresh_status()
            return False
        before, after = (
            format_number(bridge.param_value(version, param.key), param.integer, param.scale)
            for version in (app.scenario, scenario)
        )
        field.committed = field.value
        field.remove_class("-bad")
        app.edit(scenario, f"{param.label} {before} -> {after}")  # as the field shows it: 12, not 1.2e1
        return True
