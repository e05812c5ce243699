"""The app as its parts see it: the state and services ``LadarApp`` gives its
mixins (``KeyWords``, ``EditGuard``, ``FileActions``, ``SceneLoading``, ``RunControl``)
and its sidebar panels.

``AppHost`` declares them with their types so each part is checked against
what the app really provides: a mixin derives from it for the type checker
only (``Host`` below is ``object`` at run time), and a panel reaches the app
through ``host_of``. ``LadarApp`` derives from the mixins, so the type checker
also holds its own definitions to these declarations.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from textual.app import App

from ladartui.tui.view_area import OUTPUT_POINTS

if TYPE_CHECKING:
    import numpy as np
    from textual.notifications import SeverityLevel
    from textual.screen import Screen
    from textual.widget import Widget
    from textual.worker import Worker

    from ladartui.edit_history import EditHistory
    from ladartui.measures import Measures
    from ladartui.scenario import Scenario
    from ladartui.scene.model import Scene
    from ladartui.simulation import SimulationResult
    from ladartui.tui.panels import FilePanel, FlightPanel, ResultsPanel, RunPanel, SensorPanel
    from ladartui.tui.params import ParamField
    from ladartui.tui.view_area import ViewArea


class AppHost(App[None]):
    """What ``LadarApp`` provides to its parts (declarations only; never instantiated)."""

    # the scenario under edit, its scene and results
    history: EditHistory[Scenario] | None
    scene: Scene | None
    blind_kept: tuple | None
    prepared: dict[str, Any] | None
    measures: Measures | None
    result: SimulationResult | None
    output_voxels: np.ndarray | None
    disk_outputs: tuple  # (scene output, target output) of an earlier run, read from disk
    shown_before_run: tuple  # (output_voxels, disk_outputs) while a run goes on
    missing_outputs: list[Path]
    outputs_interrupted: bool  # a run was stopped while it replaced the outputs
    output_blocked: str | None  # an output's name that a folder or special file holds
    outputs_from: Scenario | None  # the settings that made the outputs shown
    inputs_changed: list[str]  # their model files and flight logs changed since (out of date)
    changed_since_opened: list[str]  # names of those the app read before they changed on disk
    inputs_drifted: list[tuple[str, str]]  # (role, name) of files read here changed on disk since
    outputs_seen: tuple[int, int] | None  # the measures file's (mtime, size) when they were read
    cwd: Path
    keymap: dict[str, str]  # the user's keys.toml remapping (actions.load_keymap)
    scenario_on_disk: str | None  # "changed" or "gone" since opened or saved (SceneLoading)
    compile_in_child: bool
    # the jobs and the busy state
    busy: str | None
    progress: float | None
    running: bool
    load_worker: Worker[Any] | None
    new_pending: tuple[Path, tuple[str, ...], Path] | None  # New's folder, fields as typed, file
    warm_worker: Worker[Any] | None
    run_worker_handle: Worker[Any] | None
    tool_screen: Screen[None] | None  # the study or sweep screen while it is open
    # the widgets, found once mounted
    file_panel: FilePanel
    sensor_panel: SensorPanel
    flight_panel: FlightPanel
    run_panel: RunPanel
    results_panel: ResultsPanel
    view_area: ViewArea

    @property
    def scenario(self) -> Scenario | None:
        raise NotImplementedError

    @scenario.setter
    def scenario(self, scenario: Scenario) -> None:
        raise NotImplementedError

    @property
    def modified(self) -> bool:
        raise NotImplementedError

    # LadarApp's own
    def tell(
        self, message: str, *, title: str = "", severity: SeverityLevel = "information", timeout: float = 5
    ) -> None:
        raise NotImplementedError

    def set_busy(self, message: str | None, progress: float | None = None) -> None:
        raise NotImplementedError

    def button_text(self, label: str, command_id: str) -> str:
        raise NotImplementedError

    def key_says(self, command_id: str, words: str) -> str:
        raise NotImplementedError

    def key_note(self, command_id: str) -> str:
        raise NotImplementedError

    def tell_why_off(self, what: str, action: str) -> None:
        raise NotImplementedError

    def refresh_status(self) -> None:
        raise NotImplementedError

    def problems(self, fields: bool = True) -> list[str]:
        raise NotImplementedError

    def run_in_progress(self) -> bool:
        raise NotImplementedError

    def set_scenario(self, scenario: Scenario, modified: bool = True) -> None:
        raise NotImplementedError

    def scenario_changed(self) -> None:
        raise NotImplementedError

    def edit(self, scenario: Scenario, label: str) -> None:
        raise NotImplementedError

    def commit_field(self, field: ParamField) -> bool:
        raise NotImplementedError

    def target_m(self) -> tuple[float, ...]:
        raise NotImplementedError

    def show_output(self, limit: int = OUTPUT_POINTS) -> None:
        raise NotImplementedError

    def show_measures(self, measures: Measures | None) -> None:
        raise NotImplementedError

    def outputs_stale(self) -> bool:
        raise NotImplementedError

    def changed_on_disk(self) -> list[str]:
        raise NotImplementedError

    # one mixin's, used by another or by the panels
    def commit_pending(self) -> bool:
        raise NotImplementedError

    def show_outputs_of(self, scenario: Scenario) -> None:
        raise NotImplementedError

    def note_outputs_seen(self) -> None:
        raise NotImplementedError

    def note_scenario_saved(self) -> None:
        raise NotImplementedError

    def scenario_file_problem(self) -> str:
        raise NotImplementedError

    def confirm_discard(self, doing: str, then: Callable[[], None], opens: Path | None = None) -> None:
        raise NotImplementedError

    def action_save(self) -> None:
        raise NotImplementedError

    def save_before_leaving(self) -> None:
        raise NotImplementedError

    def open_path(self, path: Path, before: Callable[[], None] | None = None) -> None:
        raise NotImplementedError

    def load(self, path: Path | None, scenario: Scenario | None = None, new: bool = False) -> None:
        raise NotImplementedError

    def new_refused(self, error: str, error_path: str | None = None) -> None:
        raise NotImplementedError


if TYPE_CHECKING:
    Host = AppHost
else:
    Host = object  # the mixins are plain classes at run time; LadarApp brings App


def host_of(widget: Widget) -> AppHost:
    """The ``LadarApp`` that ``widget`` is mounted in, typed as its parts use it."""
    return cast(AppHost, widget.app)
