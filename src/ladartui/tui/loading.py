"""Loading a scenario and its scene, probing the backends and warming the kernels.

Three jobs (``tui/work.py``): "load" reads the scenario, its scene and any
earlier results and prepares the views; once they are shown, "probe" lists
the backends and "warm" has a child process compile the tracing kernels
for the first Run (compiling here would hold the interpreter lock and
freeze the interface), then loads them from numba's disk cache.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ladartui.errors import LadarError
from ladartui.recent import remember_scenario
from ladartui.run_record import is_record, missing_outputs, read_run_record
from ladartui.scenario_file import record_owner
from ladartui.tui import bridge
from ladartui.tui.host import Host
from ladartui.tui.view_area import prepare_views
from ladartui.tui.work import start_job

if TYPE_CHECKING:
    import numpy as np

    from ladartui.measures import Measures
    from ladartui.scenario import Scenario
    from ladartui.scene.model import Scene


@dataclass
class Earlier:
    """The outputs on disk under a scenario's name, from an earlier run."""

    scenario: Scenario
    output: np.ndarray | None
    measures: Measures | None
    ran: Scenario | None  # the settings that made them (the run record), if recorded
    warning: str | None

    @property
    def made_with(self) -> Scenario | None:
        """What made the outputs: the record, else (a set older than records) the file."""
        if self.output is None and self.measures is None:
            return None
        return self.ran or self.scenario


@dataclass
class Loaded:
    """What the load job hands the interface."""

    scene: Scene
    prepared: dict[str, Any]
    earlier: Earlier

    @property
    def scenario(self) -> Scenario:
        return self.earlier.scenario


class SceneLoading(Host):
    """The app's load, probe and warm-up jobs (mixed into ``LadarApp``)."""

    def load(self, path: Path | None, scenario: Scenario | None = None) -> None:
        """Load a scenario and its scene in a worker (the default scenario when no path)."""
        name = path.name if path else (scenario.path.name if scenario else "default scenario")
        self.set_busy(f"Loading {name}...")
        self.load_worker = start_job(self, "load", lambda cancel, progress: _load(path, scenario))

    def loaded(self, done: Loaded) -> None:
        """The load job's result: show it, then probe the backends and warm the kernels."""
        self.scene = done.scene
        self.prepared = done.prepared
        self.view_area.set_scene(done.prepared, done.scene.voxel_size)
        self.missing_outputs = missing_outputs(done.scenario)
        self.outputs_from = done.earlier.made_with  # before the status is drawn
        self.set_scenario(done.scenario, modified=False)
        if done.scenario.path.is_file():
            remember_scenario(done.scenario.path)
        self.file_panel.show_recent(done.scenario.path)
        self._show_earlier(done.earlier)
        self.run_panel.say("")  # the last run, if any, was another scenario's
        self.set_busy(None)
        if is_record(done.scenario.path):
            self.tell(
                f"{done.scenario.path.name} is a run record: the settings that made "
                f"{record_owner(done.scenario.path)}'s outputs. Its runs "
                "replace it, and Save does not: Save As keeps these settings as a scenario.",
                severity="warning",
                timeout=10,
            )
        # after the panels are drawn: probing imports the GPU library
        self.call_after_refresh(self._start_background, done.scenario, done.scene)

    def _start_background(self, scenario, scene) -> None:
        start_job(self, "probe", lambda cancel, progress: bridge.backend_choices())
        compile_in_child = self.compile_in_child
        self.warm_worker = start_job(
            self, "warm", lambda cancel, progress: _warm_up(scenario, scene, compile_in_child, cancel)
        )

    def show_outputs_of(self, scenario: Scenario) -> None:
        """After Save As onto a name: the outputs already on disk under it, shown as
        opening that file would show them (read in a worker)."""
        self.outputs_seen = outputs_on_disk(scenario)  # the ones about to be shown: no other run's
        self.missing_outputs = missing_outputs(scenario)
        if scenario.scene_output.is_file() and scenario.measures_file.is_file():
            start_job(self, "earlier", lambda cancel, progress: _earlier(scenario))

    def earlier_read(self, earlier: Earlier) -> None:
        if self.scenario is None or self.scenario.path != earlier.scenario.path:
            return  # another file since
        self._show_earlier(earlier)
        self.scenario_changed()

    def check_outputs_on_disk(self) -> None:
        """Every few seconds: outputs another run of this file wrote (a second instance, the
        CLI) are read and shown, said in a note; the ones shown are no longer on disk."""
        scenario = self.scenario
        if scenario is None or self.busy is not None or self.running:
            return
        now = outputs_on_disk(scenario)
        if now == self.outputs_seen:
            return
        if now is None:
            self.tell(
                f"The outputs of {scenario.path.name} are gone from disk: those shown were read before."
            )
        else:
            self.tell(
                f"The outputs of {scenario.path.name} changed on disk (another run?): shown as they are now."
            )
        self.show_outputs_of(scenario)  # reads them, or names the files missing
        self.scenario_changed()

    def note_outputs_seen(self) -> None:
        """The outputs on disk are the ones shown (read, or written by this app's run)."""
        self.outputs_seen = outputs_on_disk(self.scenario) if self.scenario is not None else None

    def _show_earlier(self, earlier: Earlier) -> None:
        """An earlier run's outputs and measures in the views, and what made them."""
        self.note_outputs_seen()
        self.outputs_from = earlier.made_with
        self.output_voxels = earlier.output
        self.show_output()
        self.show_measures(earlier.measures)
        if earlier.warning:
            self.tell(earlier.warning, severity="warning", timeout=8)

    def backends_probed(self, choices) -> None:
        self.run_panel.show_backends(choices, self.scenario.backend if self.scenario else "auto")
        self.refresh_status()


def _load(path: Path | None, scenario) -> Loaded:
    if scenario is None:
        if path is None:
            from ladartui.user_data import default_scenario_path

            path = default_scenario_path()
        scenario = bridge.load_checked(path)
    scene = scenario.load_scene()
    return Loaded(scene, prepare_views(scene), _earlier(scenario))


def _earlier(scenario) -> Earlier:
    """The outputs of an earlier run under ``scenario``'s name, and what made them."""
    warning, ran = None, None
    try:
        output, measures = _existing_results(scenario)
    except LadarError as error:  # old results must not stop the scenario loading
        output, measures, warning = None, None, f"earlier results not shown: {error}"
    if output is not None:
        try:
            ran = read_run_record(scenario)
        except LadarError as error:
            warning = f"settings of the earlier run not read, taken as the file's: {error}"
    return Earlier(scenario, output, measures, ran, warning)


def _warm_up(scenario, scene, compile_in_child: bool, cancel) -> None:
    from ladartui.tui.warmup import tiny_run, warm_in_child

    if compile_in_child and scenario.path.is_file():
        warm_in_child(scenario.path, stop=cancel)
    if cancel.is_set():
        return
    try:
        tiny_run(scenario, scene, cancel=cancel)
    except Exception:  # a warm-up only; the real run reports any problem
        pass


def _existing_results(scenario):
    """The scene output and measures of an earlier run, if both are on disk."""
    if not (scenario.scene_output.is_file() and scenario.measures_file.is_file()):
        return None, None
    from ladartui.cmf import read_cmf
    from ladartui.scene.voxels import load_voxels

    return load_voxels(scenario.scene_output), read_cmf(scenario.measures_file)


def outputs_on_disk(scenario) -> tuple[int, int] | None:
    """When and how large the measures file is (a run replaces it with the rest of its
    set), or None when there is none: what tells another run's outputs apart."""
    try:
        status = scenario.measures_file.stat()
    except OSError:
        return None
    return status.st_mtime_ns, status.st_size
