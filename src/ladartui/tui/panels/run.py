"""The Run tab: backend and method, voxel size and march step, fast mode, and the run,
study and sweep buttons with what the last run said."""

from __future__ import annotations

from typing import Any

from rich.text import Text
from textual import on
from textual.containers import Grid, Horizontal
from textual.widgets import Button, Checkbox, Label, Select, Static

from ladartui.errors import LadarError
from ladartui.tracing.backend import METHODS
from ladartui.tui import bridge
from ladartui.tui.params import ParamPanel, field_id
from ladartui.tui.plain_text import PlainStatic

STEP_KEY = "scenario.step"


class RunPanel(ParamPanel):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.backend_rows: list[tuple[str, str, bool]] | None = None
        self.backend_values = ["auto"]

    def compose(self):
        yield Horizontal(
            Label("Backend"),
            Select([("auto", "auto")], value="auto", allow_blank=False, id="backend", compact=True),
            classes="row",
        )
        yield Horizontal(
            Label("Method"),
            Select(
                [(method, method) for method in METHODS],
                value="exact",
                allow_blank=False,
                id="method",
                compact=True,
            ),
            classes="row",
        )
        for param in bridge.RUN_PARAMS:
            yield self.param_row(param)
        yield Checkbox(
            "Fast mode",
            id="fast-mode",
            compact=True,
            tooltip="Show only the final output, not each scan as it lands",
        )
        with Grid(classes="button-grid run-buttons"):
            button = self.host.button_text
            yield Button(button("Run", "run"), id="btn-run", variant="success", compact=True)
            yield Button(button("Save", "save"), id="btn-save-run", compact=True)
            yield Button("Cancel", id="btn-cancel-run", variant="error", compact=True, disabled=True)
        with Grid(classes="button-grid run-buttons two-buttons"):
            yield Button(
                button("Study", "study"),
                id="btn-study",
                compact=True,
                tooltip="Speed against accuracy of every backend and method",
            )
            yield Button(
                button("Sweep", "sweep"),
                id="btn-sweep",
                compact=True,
                tooltip="Launch, open or watch a flight-path sweep",
            )
        yield PlainStatic("", id="run-info", classes="info")
        yield Static("probing backends...", id="backend-info", classes="info")

    def show(self, scenario) -> None:
        self.loading_fields = True
        try:
            self.query_one("#method", Select).value = scenario.method
            self.query_one("#fast-mode", Checkbox).value = scenario.fast_mode
            if scenario.backend in self.backend_values:
                self.query_one("#backend", Select).value = scenario.backend
        finally:
            self.loading_fields = False
        self.fill_fields(scenario)
        self.enable_step(scenario)

    def enable_step(self, scenario=None) -> None:
        """The march step only matters to the march method."""
        scenario = scenario or self.host.scenario
        step = self.query_one("#" + field_id(STEP_KEY))
        step.disabled = scenario is None or scenario.method != "march" or bool(self.host.busy)

    def say(self, text: str) -> None:
        self.query_one("#run-info", Static).update(text)

    def set_running(self, running: bool) -> None:
        self.query_one("#btn-cancel-run", Button).disabled = not running

    # -- backends --------------------------------------------------------------------

    def show_backends(self, rows, current: str) -> None:
        self.backend_rows = rows
        select = self.query_one("#backend", Select)
        options = [(f"{name}{'' if ok else ' (unavailable)'}", name) for name, _, ok in rows]
        self.loading_fields = True
        try:
            select.set_options(options)
            self.backend_values = [name for _, name in options]
            if current in self.backend_values:
                select.value = current
        finally:
            self.loading_fields = False
        self._show_backend_info()

    def _show_backend_info(self) -> None:
        info = self.query_one("#backend-info", Static)
        if self.backend_rows is None:
            info.update("probing backends...")
            return
        chosen = self.query_one("#backend", Select).value
        text = Text()
        for name, description, ok in self.backend_rows:
            if text:
                text.append("\n")
            text.append(f"{'*' if name == chosen else ' '}{name}: ")
            if not ok:
                text.append("unavailable ", style="red")
            text.append(description)
        info.update(text)

    # -- choices that edit the scenario ----------------------------------------------

    def _choose(self, label: str, **change) -> None:
        app = self.host
        if self.loading_fields or app.scenario is None:
            return
        name, value = next(iter(change.items()))
        if getattr(app.scenario, name) == value:
            return
        try:
            scenario = app.scenario.with_changes(**change)
        except LadarError as error:
            app.tell(str(error), severity="warning")
            return
        app.edit(scenario, f"{label} {value}")

    @on(Select.Changed, "#method")
    def _method_changed(self, event: Select.Changed) -> None:
        self._choose("Method", method=event.value)

    @on(Select.Changed, "#backend")
    def _backend_changed(self, event: Select.Changed) -> None:
        self._show_backend_info()
        self._choose("Backend", backend=event.value)

    @on(Checkbox.Changed, "#fast-mode")
    def _fast_changed(self, event: Checkbox.Changed) -> None:
        self._choose("Fast mode", fast_mode=event.value)

    @on(Button.Pressed, "#btn-run,#btn-save-run,#btn-cancel-run,#btn-study,#btn-sweep")
    async def _pressed(self, event: Button.Pressed) -> None:
        event.stop()
        action = {
            "btn-run": "run",
            "btn-save-run": "save",
            "btn-cancel-run": "cancel_run",
            "btn-study": "study",
            "btn-sweep": "sweep",
        }
        await self.app.run_action(action[event.button.id or ""])
