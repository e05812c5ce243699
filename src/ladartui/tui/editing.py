"""The scenario under edit: its undo history, the one path every change takes, and
showing the current scenario everywhere (a part of ``LadarApp``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ladartui.edit_history import EditHistory
from ladartui.tui import bridge
from ladartui.tui.host import Host
from ladartui.tui.params import ParamField, ParamPanel

if TYPE_CHECKING:
    from ladartui.scenario import Scenario
    from ladartui.scene.model import Scene


class ScenarioEditing(Host):
    """Undoable edits of the scenario; ``scenario_changed`` shows the result."""

    @property
    def scenario(self) -> Scenario | None:
        return self.history.current if self.history is not None else None

    @scenario.setter
    def scenario(self, scenario: Scenario) -> None:
        if self.history is None:
            self.history = EditHistory(scenario)
        else:
            self.history.current = scenario

    @property
    def modified(self) -> bool:
        return self.history is not None and self.history.modified

    def set_scenario(self, scenario: Scenario, modified: bool = True) -> None:
        """Adopt a whole scenario: loaded (``modified=False``) or edited (an undoable step)."""
        if modified and self.history is not None:
            self.edit(scenario, "Scenario replaced")
            return
        if self.history is None:
            self.history = EditHistory(scenario)
        else:
            self.history.reset(scenario)
        self.scenario_changed()

    def edit(self, scenario: Scenario, label: str) -> None:
        """The one path for every change to the scenario: recorded for undo, then shown."""
        if self.history is None:  # the first scenario is adopted, not edited
            self.set_scenario(scenario, modified=False)
            return
        self.history.edit(scenario, label)
        self.scenario_changed()

    def update_scenario(self, scenario: Scenario) -> None:
        self.edit(scenario, "Change")

    def action_undo(self) -> None:
        if self.busy or self.history is None:
            return
        typing = [f for f in self.query(".param").results(ParamField) if f.value != f.committed]
        if typing:  # typed but not committed: undo the typing first, as an editor would
            for f in typing:
                f.set_number(bridge.param_value(self.history.current, f.field_name))
            self.refresh_status()
            self.tell("Undid typing in " + ", ".join(f.param.label for f in typing), timeout=3)
            return
        self._step(self.history.undo(), "Undid")

    def action_redo(self) -> None:
        if self.busy or self.history is None:
            return
        self._step(self.history.redo(), "Redid")

    def _step(self, step, done: str) -> None:
        if step is None:
            self.tell("Nothing to undo." if done == "Undid" else "Nothing to redo.", timeout=2)
            return
        self.scenario_changed()
        self.tell(f"{done}: {step.label}", timeout=3)

    def scenario_changed(self) -> None:
        """Show the current scenario everywhere: panels, views and status."""
        scenario = self.scenario
        if scenario is None:
            return
        if self.scene is not None and scenario.voxel_size != self.scene.voxel_size:
            self._rescale_scene(self.scene, scenario.voxel_size)
        for panel in (self.sensor_panel, self.flight_panel, self.run_panel):
            panel.show(scenario)
        self.file_panel.show(scenario, self.scene, self.modified, self.missing_outputs)
        self.view_area.draw_path(scenario)
        self.sub_title = scenario.path.name + (" (modified)" if self.modified else "")
        self.show_measures(self.measures)  # says whether they are the settings' now
        self.refresh_status()

    def _rescale_scene(self, old: Scene, voxel_size: float) -> None:
        from ladartui.scene.model import Scene

        self.scene = scene = Scene(
            old.voxels,
            old.target,
            voxel_size,
            shape=old.shape,
            name=old.name,
            path=old.path,
            target_ids=old.target_ids,
            fingerprints=old.fingerprints,  # the same files: a run records them
        )
        self.view_area.rescale(voxel_size, tuple(float(v) for v in scene.target_centre_m()))

    def commit_field(self, field: ParamField) -> bool:
        panel = next(a for a in field.ancestors if isinstance(a, ParamPanel))
        return panel.commit_field(field)
