"""Loading a scenario and its scene, probing the backends and warming the kernels.

All of it runs in a thread worker that posts messages back: the interface
shows the scenario as soon as its scene is ready, then the backend list,
while a child process compiles the tracing kernels for the first Run.
"""

from __future__ import annotations

from pathlib import Path

from textual import work
from textual.message import Message

from ladartui.errors import LadarError
from ladartui.recent import remember_scenario
from ladartui.tui import bridge
from ladartui.tui.view_area import prepare_views


class SceneReady(Message):
    """The load worker finished: the scenario, its scene and the prepared view data."""

    def __init__(self, scenario, scene, prepared, output, measures, warning=None):
        super().__init__()
        self.scenario, self.scene, self.prepared = scenario, scene, prepared
        self.output, self.measures, self.warning = output, measures, warning


class WorkFailed(Message):
    def __init__(self, what: str, error: str):
        super().__init__()
        self.what, self.error = what, error


class BackendsProbed(Message):
    def __init__(self, choices):
        super().__init__()
        self.choices = choices


class SceneLoading:
    """The app's loading worker and its messages (mixed into ``LadarApp``)."""

    def load(self, path: Path | None, scenario=None) -> None:
        """Load a scenario and its scene in a worker (the default scenario when no path)."""
        name = path.name if path else (scenario.path.name if scenario else "default scenario")
        self.set_busy(f"Loading {name}...")
        self._load_worker(path, scenario)

    @work(thread=True, exclusive=True, group="load")
    def _load_worker(self, path: Path | None, scenario) -> None:
        try:
            if scenario is None:
                if path is None:
                    from ladartui.defaults import default_scenario_path

                    path = default_scenario_path()
                scenario = bridge.load_checked(path)
            scene = scenario.load_scene()
            prepared = prepare_views(scene)
            warning = None
            try:
                output, measures = _existing_results(scenario)
            except LadarError as error:  # old results must not stop the scenario loading
                output, measures, warning = None, None, f"earlier results not shown: {error}"
        except LadarError as error:
            self.post_message(WorkFailed("load", str(error)))
            return
        except Exception as error:  # keep the app alive; say what broke
            self.post_message(WorkFailed("load", f"{type(error).__name__}: {error}"))
            return
        self.scene_shown.clear()
        self.post_message(SceneReady(scenario, scene, prepared, output, measures, warning))
        # probing imports the GPU library: let the interface fill its panels first
        self.scene_shown.wait(2.0)
        self._probe_backends()
        self._warm_up(scenario, scene)

    def _warm_up(self, scenario, scene) -> None:
        """Have the tracing kernels compiled before the first Run (worker thread).

        A child process compiles them into numba's disk cache (compiling here
        would hold the interpreter lock and freeze the interface); then a
        one-ray run in this process loads them from the cache.
        """
        from ladartui.tui.warmup import tiny_run, warm_in_child

        try:
            if self.compile_in_child and scenario.path.is_file():
                warm_in_child(scenario.path, stop=self.stop_event)
        finally:
            self.kernels_ready.set()
        if self.stop_event.is_set():
            return
        try:
            tiny_run(scenario, scene, cancel=self.stop_event)
        except Exception:  # a warm-up only; the real run reports any problem
            pass

    def _probe_backends(self) -> None:
        try:
            choices = bridge.backend_choices()
        except Exception as error:
            choices = [("auto", f"backends could not be probed: {error}", False)]
        self.post_message(BackendsProbed(choices))

    def on_scene_ready(self, message: SceneReady) -> None:
        if self.closing():
            return
        self.scene = message.scene
        self.prepared = message.prepared
        self.view_area.set_scene(self.prepared, self.scene.voxel_size)
        self.missing_outputs = bridge.missing_outputs(message.scenario)
        self.set_scenario(message.scenario, modified=False)
        if message.scenario.path.is_file():
            remember_scenario(message.scenario.path)
        self.file_panel.show_recent(message.scenario.path)
        self.output_voxels = message.output
        self.show_output()
        self.show_measures(message.measures)
        self.set_busy(None)
        if message.warning:
            self.tell(message.warning, severity="warning", timeout=8)
        self.scene_shown.set()

    def on_work_failed(self, message: WorkFailed) -> None:
        if self.closing():
            return
        self.set_busy(None)
        self.tell(message.error, title=f"Could not {message.what}", severity="error",
                  timeout=10)
        self.run_panel.say(message.error)

    def on_backends_probed(self, message: BackendsProbed) -> None:
        if self.closing():
            return
        self.run_panel.show_backends(message.choices,
                                     self.scenario.backend if self.scenario else "auto")
        self.refresh_status()


def _existing_results(scenario):
    """The scene output and measures of an earlier run, if both are on disk."""
    if not (scenario.scene_output.is_file() and scenario.measures_file.is_file()):
        return None, None
    from ladartui.measures import read_cmf
    from ladartui.scene.voxels import load_voxels

    return load_voxels(scenario.scene_output), read_cmf(scenario.measures_file)
