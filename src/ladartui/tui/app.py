"""The ladartui terminal app: file setup, parameters, run and results over SSH.

Layout: a parameter sidebar (File, Sensor, Flight, Run, Results tabs) on the
left, the views on the right (the report's five layouts), the status colour
bar and the key footer at the bottom. Everything slow (loading a scene,
probing backends, compiling kernels, running) happens in thread workers that
post messages back, so the interface never blocks.
"""

from __future__ import annotations

import functools
import threading
import time
from pathlib import Path

import numpy as np
from rich.markup import escape
from textual import on, work
from textual.app import App, ComposeResult, SystemCommand
from textual.binding import Binding
from textual.containers import Container, Grid, Horizontal, Vertical, VerticalScroll
from textual.message import Message
from textual.widgets import (Button, Checkbox, DataTable, Footer, Input, Label, Select,
                             Static, TabbedContent, TabPane)

from ladartui import views
from ladartui.errors import Cancelled, LadarError
from ladartui.tui import bridge
from ladartui.tui.canvas import ProjectionWidget, TopViewWidget
from ladartui.tui.fields import NumberField
from ladartui.tui.measures_view import compact_rows
from ladartui.tui.screens import (AngleScreen, CompareScreen, FormScreen, HelpScreen,
                                  MeasuresScreen, PosesScreen, SetupScreen, ThresholdScreen)
from ladartui.tui.status import BUSY, NOT_READY, READY, StatusBar
from ladartui.tui.unsaved import EditGuard

SCENE_POINTS = 80_000  # voxels drawn in the 3D scene view, whatever the scene size
OUTPUT_POINTS = 80_000
LIVE_POINTS = 20_000  # fewer while a run is going, so redraws stay cheap
MAX_FOOTPRINTS = 400
PROGRESS_INTERVAL = 0.1  # seconds between progress messages (at most ~10 a second)
LIVE_INTERVAL = 0.5  # seconds between progressive redraws of the output view
# everything the analyst can change; disabled while busy (Cancel is re-enabled)
CONTROLS = "#sidebar Input, #sidebar Button, #sidebar Select, #sidebar Checkbox, " \
           "#sidebar DataTable"

LAYOUTS = {
    1: "3D scene + top view",
    2: "3D scene + 3D output",
    3: "3D scene, full",
    4: "3D output, full",
    5: "3D scene + 3D output + top view",
}
# actions that only change what is displayed: allowed while busy
DISPLAY_ACTIONS = {"help", "layout", "next_layout", "toggle_panel", "view_angle",
                   "threshold", "quit", "command_palette", "show_tab", "cancel_run"}


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


class RunProgressed(Message):
    """Coalesced run progress; ``live`` holds the fused obscured output so far, if redrawn."""

    def __init__(self, fraction: float, text: str, live=None):
        super().__init__()
        self.fraction, self.text, self.live = fraction, text, live


class RunFinished(Message):
    def __init__(self, result=None, cancelled=False, error: str | None = None):
        super().__init__()
        self.result, self.cancelled, self.error = result, cancelled, error


def prepare_views(scene) -> dict:
    """View data that depends only on the scene: top view, 3D sample, bounds (worker thread)."""
    heights = scene.top_height_map()
    top = views.TopView(heights, scene.voxel_size,
                        target_columns=np.unique(scene.target[:, :2], axis=0))
    sample = views.subsample(scene.voxels, SCENE_POINTS, seed=0)
    points = np.concatenate([sample, views.surface_points(heights, SCENE_POINTS // 3)])
    nx, ny, nz = scene.shape
    top_z = int(heights.max()) if heights.size and heights.max() >= 0 else nz - 1
    bounds = (np.zeros(3), np.array([nx - 1, ny - 1, max(top_z, 1)], float))
    top.scene_layer(48, 96)  # warm the cache at a typical size
    return {"top": top, "points": points, "bounds": bounds,
            "target_m": tuple(float(v) for v in scene.target_centre_m())}


class LadarApp(EditGuard, App):
    """Plan a foliage-penetrating LADAR collection: set up, fly, run, compare."""

    TITLE = "ladartui"
    CSS_PATH = Path(__file__).with_name("app.tcss")
    BINDINGS = [
        Binding("f1", "help", "Help"),
        Binding("question_mark", "help", "Help", show=False),
        Binding("f2", "new_scenario", "New"),
        Binding("f3", "open_scenario", "Open"),
        Binding("ctrl+s", "save", "Save"),
        Binding("f5", "run", "Run"),
        Binding("escape", "cancel_run", "Cancel"),
        Binding("f4", "toggle_panel", "Panel", show=False),
        Binding("f6", "next_layout", "Layout"),
        Binding("1", "layout(1)", "Layout 1", show=False),
        Binding("2", "layout(2)", "Layout 2", show=False),
        Binding("3", "layout(3)", "Layout 3", show=False),
        Binding("4", "layout(4)", "Layout 4", show=False),
        Binding("5", "layout(5)", "Layout 5", show=False),
        Binding("f7", "view_angle", "Angle", show=False),
        Binding("f8", "threshold", "Threshold"),
        Binding("f9", "measures", "Measures", show=False),
        Binding("f10", "compare", "Compare"),
        Binding("f11", "study", "Study"),
        Binding("f12", "sweep", "Sweep"),
    ]

    def __init__(self, scenario_path: Path | str | None = None, *, start_scenario=None,
                 cwd: Path | None = None, compile_in_child: bool = True):
        super().__init__()
        self.compile_in_child = compile_in_child
        self.scenario_path = Path(scenario_path) if scenario_path else None
        self.start_scenario = start_scenario
        self.cwd = Path(cwd) if cwd else Path.cwd()
        self.scenario = None
        self.scene = None
        self.prepared = None
        self.measures = None
        self.result = None
        self.output_voxels = None
        self.threshold: float | None = None
        self.layout_number = 1
        self.busy: str | None = None
        self.progress: float | None = None
        self.modified = False
        self.cancel_event = threading.Event()
        self.stop_event = threading.Event()  # set when the app quits: ends background work
        self.kernels_ready = threading.Event()  # the child process has compiled the kernels
        self.scene_shown = threading.Event()  # the views show the loaded scene
        self.backend_rows: list[tuple[str, str, bool]] | None = None
        self.backend_values = ["auto"]
        self._fields_loading = False
        self.messages: list[str] = []
        self.leaving = False  # set on exit: late worker messages are ignored
        self.running = False
        self.tool_screen = None  # the study or sweep screen while it is open
        self.study_result = None  # what the last study screen returned

    # -- layout ------------------------------------------------------------------

    def compose(self) -> ComposeResult:
        with Horizontal(id="main"):
            with Vertical(id="sidebar"):
                with TabbedContent(id="tabs"):
                    with TabPane("File", id="tab-file"):
                        yield from self._compose_file()
                    with TabPane("Sensor", id="tab-sensor"):
                        yield from self._compose_params(bridge.SENSOR_PARAMS, "sensor-info")
                    with TabPane("Flight", id="tab-flight"):
                        yield from self._compose_flight()
                    with TabPane("Run", id="tab-run"):
                        yield from self._compose_run()
                    with TabPane("Results", id="tab-results"):
                        yield from self._compose_results()
            with Container(id="views", classes="layout-1"):
                yield ProjectionWidget("3D scene", id="scene3d")
                yield ProjectionWidget("3D output", id="output3d")
                yield TopViewWidget(id="topview")
        yield StatusBar(id="status")
        yield Footer(compact=True)

    def _compose_file(self):
        with VerticalScroll(classes="pane"):
            yield Static("", id="file-info")
            with Grid(classes="button-grid run-buttons"):
                yield Button("New F2", id="btn-new", compact=True)
                yield Button("Open F3", id="btn-open", compact=True)
                yield Button("Save ^S", id="btn-save", compact=True)

    def _param_field(self, param: bridge.Param):
        field = NumberField(param.key, None, default=None, integer=param.integer,
                            scale=param.scale, check=self._param_checker(param.key),
                            id=_field_id(param.key), classes="param")
        return Horizontal(Label(param.label), field, classes="row")

    def _compose_params(self, params, info_id):
        with VerticalScroll(classes="pane"):
            for param in params:
                yield self._param_field(param)
            yield Static("", id=info_id, classes="info")

    def _compose_flight(self):
        with VerticalScroll(classes="pane"):
            for param in bridge.START_PARAMS:
                yield self._param_field(param)
            yield Label("Segments (Enter edits)", classes="heading")
            yield DataTable(id="segments", cursor_type="row", zebra_stripes=True)
            with Grid(classes="button-grid"):
                yield Button("Straight", id="add-straight", compact=True)
                yield Button("Turn", id="add-turn", compact=True)
                yield Button("Orbit", id="add-orbit", compact=True)
                yield Button("Fly-past", id="add-flypast", compact=True)
                yield Button("Standoff", id="add-standoff", compact=True)
                yield Button("Poses", id="add-manual", compact=True)
                yield Button("Edit", id="seg-edit", compact=True)
                yield Button("Delete", id="seg-delete", compact=True)
                yield Button("Aim all", id="aim-all", compact=True)
            yield Label("Scans", classes="heading")
            yield DataTable(id="scans", cursor_type="row", zebra_stripes=True)

    def _compose_run(self):
        with VerticalScroll(classes="pane"):
            yield Horizontal(Label("Backend"), Select([("auto", "auto")], value="auto",
                                                      allow_blank=False, id="backend",
                                                      compact=True), classes="row")
            yield Horizontal(Label("Method"), Select([("exact", "exact"), ("march", "march")],
                                                     value="exact", allow_blank=False,
                                                     id="method", compact=True), classes="row")
            for param in bridge.RUN_PARAMS:
                yield self._param_field(param)
            yield Checkbox("Fast mode", id="fast-mode", compact=True,
                           tooltip="Show only the final output, not each scan as it lands")
            with Grid(classes="button-grid run-buttons"):
                yield Button("Run F5", id="btn-run", variant="success", compact=True)
                yield Button("Save ^S", id="btn-save-run", compact=True)
                yield Button("Cancel", id="btn-cancel-run", variant="error", compact=True,
                             disabled=True)
            with Grid(classes="button-grid run-buttons"):
                yield Button("Study F11", id="btn-study", compact=True,
                             tooltip="Speed against accuracy of every backend and method")
                yield Button("Sweep F12", id="btn-sweep", compact=True,
                             tooltip="Launch, open or watch a flight-path sweep")
            yield Static("", id="run-info", classes="info")
            yield Static("probing backends...", id="backend-info", classes="info")

    def _compose_results(self):
        with VerticalScroll(classes="pane"):
            yield Static("No results yet: F5 runs the scenario.", id="results-info",
                         classes="info")
            yield DataTable(id="measures", cursor_type="row", zebra_stripes=True)
            with Grid(classes="button-grid run-buttons"):
                yield Button("Measures", id="btn-measures", compact=True)
                yield Button("Compare", id="btn-compare", compact=True)
                yield Button("Threshold", id="btn-threshold", compact=True)

    def on_mount(self) -> None:
        self.query_one("#segments", DataTable).add_columns("#", "Kind", "Scans", "Detail")
        self.query_one("#scans", DataTable).add_columns("#", "x", "y", "z", "hdg", "az", "dep")
        self.query_one("#measures", DataTable).add_columns("Measure", "Value")
        self.refresh_status()
        if self.start_scenario is not None:
            self.load(None, scenario=self.start_scenario)
        else:
            self.load(self.scenario_path)

    # -- loading -------------------------------------------------------------------

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
        self.set_scenario(message.scenario, modified=False)
        self.query_one(TopViewWidget).set_scene(self.prepared["top"])
        for widget in self.query(ProjectionWidget):
            widget.height_top = float(self.prepared["bounds"][1][2])
        self.query_one("#scene3d", ProjectionWidget).set_points(
            self.prepared["points"], self.prepared["bounds"], self.scene.voxel_size)
        self.output_voxels = message.output
        self.show_output()
        self.show_measures(message.measures)
        self.set_busy(None)
        self._draw_overlays()
        if message.warning:
            self.tell(message.warning, severity="warning", timeout=8)
        self.scene_shown.set()

    def on_work_failed(self, message: WorkFailed) -> None:
        if self.closing():
            return
        self.set_busy(None)
        self.tell(message.error, title=f"Could not {message.what}", severity="error",
                    timeout=10)
        self.query_one("#run-info", Static).update(escape(message.error))

    def on_backends_probed(self, message: BackendsProbed) -> None:
        if self.closing():
            return
        self.backend_rows = message.choices
        select = self.query_one("#backend", Select)
        current = self.scenario.backend if self.scenario else "auto"
        options = [(f"{name}{'' if ok else ' (unavailable)'}", name)
                   for name, _, ok in message.choices]
        self._fields_loading = True
        select.set_options(options)
        self.backend_values = [name for _, name in options]
        if current in self.backend_values:
            select.value = current
        self._fields_loading = False
        self._show_backend_info()
        self.refresh_status()

    # -- scenario state ------------------------------------------------------------

    def set_scenario(self, scenario, modified=True) -> None:
        """Adopt a (checked) scenario: fill every field and redraw the overlays."""
        self.scenario = scenario
        self.modified = modified
        self._fields_loading = True
        try:
            for key, param in bridge.ALL_PARAMS.items():
                field = self.query_one("#" + _field_id(key), NumberField)
                value = bridge.param_value(scenario, key)
                field.default = bridge.param_default(key, fallback=value)
                field.set_number(value)
            self.query_one("#method", Select).value = scenario.method
            self.query_one("#fast-mode", Checkbox).value = scenario.fast_mode
            backend = self.query_one("#backend", Select)
            if scenario.backend in self.backend_values:
                backend.value = scenario.backend
        finally:
            self._fields_loading = False
        self.scenario_changed()

    def update_scenario(self, scenario) -> None:
        """A parameter changed (already checked): keep it and redraw what depends on it."""
        self.scenario = scenario
        self.modified = True
        self.scenario_changed()

    def scenario_changed(self) -> None:
        scenario = self.scenario
        self._show_file_info()
        self._fill_flight_tables()
        self._draw_overlays()
        s = scenario.sensor
        self.query_one("#sensor-info", Static).update(
            f"{s.grid}x{s.grid} detectors, {s.ray_grid}x{s.ray_grid} rays each\n"
            f"{s.rays_per_scan:,} rays per scan, IFOV {s.ifov * 1000:.3g} mdeg")
        self.query_one("#method", Select).value = scenario.method
        step = self.query_one("#" + _field_id("scenario.step"))
        step.disabled = scenario.method != "march"
        self.refresh_status()

    def _show_file_info(self) -> None:
        sc = self.scenario
        if sc is None:
            self.query_one("#file-info", Static).update("No scenario: F2 new, F3 open.")
            return
        mark = " (modified)" if self.modified else ""
        scene = ""
        if self.scene is not None:
            scene = f"{len(self.scene.voxels):,} voxels"
        target = f"{len(self.scene.target):,} voxels" if self.scene is not None else ""
        rows = [("Scenario", sc.path.name + mark), ("Folder", _shown_folder(sc.path.parent)),
                ("Scene model", sc.scene_file.name), ("", scene),
                ("Target model", sc.target_file.name), ("", target), ("Scene output", sc.scene_output.name),
                ("Target output", sc.target_output.name),
                ("Measures", sc.measures_file.name)]
        text = "\n".join(f"[b]{k:<14}[/b]{escape(v)}" if k else f"{'':<14}{escape(v)}"
                         for k, v in rows if v)
        self.query_one("#file-info", Static).update(text)

    def _fill_flight_tables(self) -> None:
        segments = self.query_one("#segments", DataTable)
        row = segments.cursor_row
        segments.clear()
        try:
            per_segment = self.scenario.flight.segment_poses()
        except LadarError:
            per_segment = [[] for _ in self.scenario.flight.segments]
        for i, (segment, poses) in enumerate(zip(self.scenario.flight.segments, per_segment)):
            segments.add_row(str(i + 1), bridge.SEGMENT_LABELS.get(segment.kind, segment.kind),
                             str(len(poses)), bridge.segment_summary(segment))
        if segments.row_count:
            segments.move_cursor(row=min(max(row, 0), segments.row_count - 1))
        scans = self.query_one("#scans", DataTable)
        scans.clear()
        for i, p in enumerate(pose for poses in per_segment for pose in poses):
            scans.add_row(str(i + 1), f"{p.x:.1f}", f"{p.y:.1f}", f"{p.z:.1f}",
                          f"{p.heading:.0f}", f"{p.azimuth:.0f}", f"{p.depression:.0f}")

    def _draw_overlays(self) -> None:
        top = self.query_one(TopViewWidget)
        if self.scenario is None:
            top.set_overlay(None, None, None)
            return
        poses = self.scenario.poses()
        scans = np.array([[p.x, p.y] for p in poses]) if poses else None
        footprints = []
        step = max(1, len(poses) // MAX_FOOTPRINTS)
        for pose in poses[::step]:
            try:
                footprints.append(self.scenario.sensor.footprint(pose)[:, :2])
            except LadarError:
                pass
        top.set_overlay(scans, scans, footprints)
        if self.prepared is not None and self.scene is not None and poses:
            markers = np.array([p.position for p in poses]) / self.scene.voxel_size
            lo, hi = self.prepared["bounds"]
            bounds = (np.minimum(lo, markers.min(axis=0)), np.maximum(hi, markers.max(axis=0)))
            for widget in self.query(ProjectionWidget):
                widget.set_markers(markers, bounds)

    # -- status --------------------------------------------------------------------

    def set_busy(self, message: str | None, progress: float | None = None) -> None:
        """Red while ``message`` is set: every control but Cancel is disabled."""
        was_busy = self.busy is not None
        self.busy = message
        self.progress = progress
        busy = message is not None
        running = busy and self.run_in_progress()
        if busy != was_busy:
            for widget in self.query(CONTROLS):
                widget.disabled = busy
        self.query_one("#btn-cancel-run", Button).disabled = not running
        if not busy and self.scenario is not None:
            self.query_one("#" + _field_id("scenario.step")).disabled = \
                self.scenario.method != "march"
        if busy and not was_busy and running:
            self.query_one("#status #cancel", Button).focus()
        self.refresh_status()
        if busy != was_busy:
            self.refresh_bindings()

    def run_in_progress(self) -> bool:
        """True from pressing Run until the run's worker has reported back."""
        return self.running

    def problems(self, fields: bool = True) -> list[str]:
        """What is missing before a run (empty: ready); ``fields=False`` leaves out
        typed values, which Run commits (or refuses, focusing the field) itself."""
        if self.scenario is None:
            return ["no scenario: F2 new or F3 open"]
        out = []
        if self.scene is None:
            out.append("scene model not loaded")
        bad = [f.field_name for f in self.query(NumberField) if fields and f.has_class("-bad")]
        if bad:
            out.append("invalid value in " + ", ".join(bad))
        if self.backend_rows is not None:
            status = {name: ok for name, _, ok in self.backend_rows}
            if not status.get(self.scenario.backend, True):
                out.append(f"backend {self.scenario.backend} unavailable")
        return out

    def refresh_status(self) -> None:
        bar = self.query_one(StatusBar)
        if self.busy is not None:
            bar.show(BUSY, self.busy, self.progress, cancellable=self.run_in_progress())
            return
        problems = self.problems()
        if problems:
            bar.show(NOT_READY, "; ".join(problems))
            return
        poses = len(self.scenario.poses())
        rays = self.scenario.sensor.rays_per_scan
        mark = " (modified)" if self.modified else ""
        bar.show(READY, f"{self.scenario.path.name}{mark}: {poses} scans x {rays:,} rays. "
                        "F5 runs.")

    def check_action(self, action: str, parameters) -> bool | None:
        if self.tool_screen is not None and self.screen is self.tool_screen:
            # that screen has its own keys; textual's own actions (focus, quit) stay
            return False if action in own_actions() else True
        if action == "cancel_run":
            return True if self.run_in_progress() else None
        if self.busy is not None and action not in DISPLAY_ACTIONS:
            return None
        if action == "run" and self.problems(fields=False):
            return None
        return True

    # -- fields --------------------------------------------------------------------

    def _param_checker(self, key):
        def check(value):
            if self.scenario is None:
                return
            bridge.check_param(self.scenario, key, value)
        return check

    @on(Input.Changed, ".param")
    def _param_typed(self, event: Input.Changed) -> None:
        if self._fields_loading:
            return
        field = event.input
        field.set_class(field.problem() is not None, "-bad")
        self.refresh_status()

    @on(Input.Submitted, ".param")
    def _param_submitted(self, event: Input.Submitted) -> None:
        self.commit_field(event.input)

    @on(Input.Blurred, ".param")
    def _param_blurred(self, event: Input.Blurred) -> None:
        self.commit_field(event.input)

    def commit_field(self, field: NumberField) -> None:
        """Apply a typed value; an invalid one resets the field to its default, with why."""
        if self.scenario is None or field.value == field.committed:
            field.remove_class("-bad")
            self.refresh_status()
            return
        key = field.field_name
        try:
            value = field.parsed()
            scenario = bridge.with_param(self.scenario, key, value)
        except LadarError as error:
            # back to the scenario's value, never to the program's default
            scenario = self.scenario
            field.set_number(bridge.param_value(scenario, key))
            self.tell(f"{error}. Kept the scenario's value, {field.value}.",
                        title="Invalid value", severity="warning", timeout=6)
            self.refresh_status()  # nothing changed: not a modification
            return
        else:
            field.committed = field.value
        field.remove_class("-bad")
        if key == "scenario.voxel_size" and self.scene is not None \
                and scenario.voxel_size != self.scene.voxel_size:
            self._rescale_scene(scenario.voxel_size)
        self.update_scenario(scenario)

    def _rescale_scene(self, voxel_size: float) -> None:
        from ladartui.scene.model import Scene

        old = self.scene
        self.scene = Scene(old.voxels, old.target, voxel_size, shape=old.shape, name=old.name,
                           path=old.path)
        self.prepared["top"].voxel_size = voxel_size
        self.prepared["target_m"] = tuple(float(v) for v in self.scene.target_centre_m())

    @on(Select.Changed, "#method")
    def _method_changed(self, event: Select.Changed) -> None:
        if self._fields_loading or self.scenario is None or event.value == self.scenario.method:
            return
        self.update_scenario(self.scenario.with_changes(method=event.value))

    @on(Select.Changed, "#backend")
    def _backend_changed(self, event: Select.Changed) -> None:
        self._show_backend_info()
        if self._fields_loading or self.scenario is None or event.value == self.scenario.backend:
            return
        try:
            self.update_scenario(self.scenario.with_changes(backend=event.value))
        except LadarError as error:
            self.tell(str(error), severity="warning")

    def _show_backend_info(self) -> None:
        info = self.query_one("#backend-info", Static)
        if self.backend_rows is None:
            info.update("probing backends...")
            return
        chosen = self.query_one("#backend", Select).value
        lines = []
        for name, text, ok in self.backend_rows:
            mark = "*" if name == chosen else " "
            lines.append(f"{mark}{name}: {'' if ok else '[red]unavailable[/red] '}{text}")
        info.update("\n".join(lines))

    @on(Checkbox.Changed, "#fast-mode")
    def _fast_changed(self, event: Checkbox.Changed) -> None:
        if self._fields_loading or self.scenario is None \
                or event.value == self.scenario.fast_mode:
            return
        self.update_scenario(self.scenario.with_changes(fast_mode=event.value))

    # -- flight segments -----------------------------------------------------------

    def _target_m(self):
        if self.prepared is not None:
            return self.prepared["target_m"]
        return (0.0, 0.0, 0.0)

    @on(Button.Pressed, "#add-straight,#add-turn,#add-orbit,#add-flypast,#add-standoff")
    def _add_segment(self, event: Button.Pressed) -> None:
        self.action_add_segment(event.button.id.removeprefix("add-"))

    def action_add_segment(self, kind: str) -> None:
        if self.scenario is None or self.busy:
            return
        poses = self.scenario.poses()
        segment = bridge.default_segment(kind, self._target_m(), poses[-1] if poses else None)
        self._edit_segment(segment, None)

    def _edit_segment(self, segment, index: int | None) -> None:
        defaults = bridge.default_segment(segment.kind, self._target_m(), None)
        spec = bridge.segment_spec(segment, defaults)
        title = bridge.SEGMENT_LABELS[segment.kind] + (" (new)" if index is None else "")

        def done(result):
            if result is not None:
                self._put_segment(index, result)

        self.push_screen(FormScreen(title, spec, bridge.segment_builder(segment.kind),
                                    note="Empty optional fields keep the current pointing."),
                         done)

    def _put_segment(self, index: int | None, segment) -> bool:
        """Replace segment ``index``, or append when ``index`` is None."""
        segments = list(self.scenario.flight.segments)
        if index is None:
            segments.append(segment)
        else:
            segments[index] = segment
        return self._apply_segments(segments)

    def _apply_segments(self, segments) -> bool:
        try:
            self.update_scenario(bridge.with_segments(self.scenario, segments))
        except LadarError as error:
            self.tell(str(error), title="Flight path not changed", severity="error")
            return False
        return True

    @on(Button.Pressed, "#add-manual")
    def action_manual_poses(self) -> None:
        """Edit manual poses: the selected manual segment, or a new one."""
        if self.scenario is None or self.busy:
            return
        segments = list(self.scenario.flight.segments)
        index = self.query_one("#segments", DataTable).cursor_row
        if 0 <= index < len(segments) and segments[index].kind == "manual":
            self._edit_poses(index)
        else:
            poses = self.scenario.poses()
            start = poses[-1] if poses else bridge.start_pose(self.scenario)
            self._edit_poses(None, [start])

    def _edit_poses(self, index: int | None, poses=None) -> None:
        from ladartui.flight import Manual

        segments = list(self.scenario.flight.segments)
        if poses is None:
            poses = list(segments[index].poses)

        def done(result):
            if not result:
                if result is not None:
                    self.tell("A manual segment needs at least one pose; not changed.",
                                severity="warning")
                return
            self._put_segment(index, Manual(tuple(result)))

        self.push_screen(PosesScreen(poses, bridge.start_pose(self.scenario)), done)

    @on(Button.Pressed, "#seg-edit")
    def action_edit_segment(self) -> None:
        if self.scenario is None or self.busy:
            return
        index = self.query_one("#segments", DataTable).cursor_row
        segments = self.scenario.flight.segments
        if not 0 <= index < len(segments):
            return
        if segments[index].kind == "manual":
            self._edit_poses(index)
        else:
            self._edit_segment(segments[index], index)

    @on(DataTable.RowSelected, "#segments")
    def _segment_selected(self, event: DataTable.RowSelected) -> None:
        self.action_edit_segment()

    @on(Button.Pressed, "#seg-delete")
    def action_delete_segment(self) -> None:
        if self.scenario is None or self.busy:
            return
        index = self.query_one("#segments", DataTable).cursor_row
        segments = list(self.scenario.flight.segments)
        if not 0 <= index < len(segments):
            return
        if len(segments) == 1:
            self.tell("The flight path needs at least one segment.", severity="warning")
            return
        del segments[index]
        self._apply_segments(segments)

    @on(Button.Pressed, "#aim-all")
    def action_aim_all(self) -> None:
        if self.scenario is None or self.busy:
            return
        try:
            self.update_scenario(bridge.aim_all(self.scenario, self._target_m()))
        except LadarError as error:
            self.tell(str(error), title="Cannot aim every scan", severity="error")
            return
        self.tell("Every scan now aims at the target centre.")

    # -- file actions --------------------------------------------------------------

    def _folder(self) -> Path:
        return self.scenario.path.parent if self.scenario else self.cwd

    @on(Button.Pressed, "#btn-new")
    def action_new_scenario(self) -> None:
        self._setup("new")

    @on(Button.Pressed, "#btn-open")
    def action_open_scenario(self) -> None:
        self._setup("load")

    async def action_quit(self) -> None:
        self.confirm_discard("quit", self.exit)

    def _setup(self, mode: str) -> None:
        if self.busy:
            return
        self.confirm_discard("open another scenario" if mode == "load" else
                             "start a new one", lambda: self._open_setup(mode))

    def _open_setup(self, mode: str) -> None:

        def done(scenario):
            if scenario is not None:
                self.result = None
                self.load(None, scenario=scenario)

        self.push_screen(SetupScreen(mode, self._folder()), done)

    @on(Button.Pressed, "#btn-save,#btn-save-run")
    def action_save(self) -> None:
        if self.scenario is None or self.busy:
            return
        if not self.commit_pending():
            return
        try:
            self.scenario = self.scenario.save()
        except (LadarError, OSError) as error:
            self.tell(str(error), title="Not saved", severity="error")
            return
        self.modified = False
        self._show_file_info()
        self.refresh_status()
        self.tell(f"Saved {self.scenario.path}")

    # -- run -------------------------------------------------------------------------

    @on(Button.Pressed, "#btn-run")
    def action_run(self) -> None:
        if self.busy or self.scenario is None:
            return
        if not self.commit_pending():
            return
        problems = self.problems()
        if problems:
            self.tell("; ".join(problems), title="Not ready", severity="warning")
            return
        self.cancel_event = threading.Event()
        self.running = True
        self.set_busy("Starting the run...", 0.0)
        self._run_worker(self.scenario, self.scene, self.scenario.fast_mode, self.cancel_event)

    @work(thread=True, exclusive=True, group="run")
    def _run_worker(self, scenario, scene, fast: bool, cancel: threading.Event) -> None:
        from ladartui.measures import keys_to_voxels, voxel_keys
        from ladartui.simulation import simulate

        last_post = 0.0
        last_live = 0.0
        fused = np.empty(0, np.int64)  # sorted unique keys of the obscured returns so far
        now_posted = [0.0]
        pending: list[np.ndarray] = []

        def progress(p) -> None:
            # runs on the worker thread: fuse here so the interface only draws
            nonlocal last_post, last_live, fused
            if p.returns is not None and p.run == "scene" and not fast and len(p.returns):
                pending.append(voxel_keys(p.returns))
            now = time.monotonic()
            if now - last_post < PROGRESS_INTERVAL:
                return
            last_post = now
            live = None
            if pending and now - last_live >= LIVE_INTERVAL:
                fused = np.union1d(fused, np.concatenate(pending))
                pending.clear()
                last_live = now
                live = keys_to_voxels(fused)
            run = "obscured (scene)" if p.run == "scene" else "unobscured (target)"
            self.post_message(RunProgressed(p.fraction, f"Running {run}: scan {p.scan}/{p.scans}",
                                            live))

        try:
            # wait (without holding the interpreter lock) for the kernels to compile
            while not self.kernels_ready.wait(0.1):
                if cancel.is_set():
                    raise Cancelled()
                if now_posted[0] + 1.0 < time.monotonic():
                    now_posted[0] = time.monotonic()
                    self.post_message(RunProgressed(0.0, "Compiling the tracing kernels "
                                                         "(first run only)..."))
            result = simulate(scenario, progress=progress, cancel=cancel, scene=scene)
        except Cancelled:
            self.post_message(RunFinished(cancelled=True))
        except LadarError as error:
            self.post_message(RunFinished(error=str(error)))
        except Exception as error:
            self.post_message(RunFinished(error=f"{type(error).__name__}: {error}"))
        else:
            self.post_message(RunFinished(result))

    def on_run_progressed(self, message: RunProgressed) -> None:
        if self.closing():
            return
        if self.busy is None:
            return
        self.set_busy(message.text + " (Esc cancels)", message.fraction)
        if message.live is not None:
            self.output_voxels = message.live
            self.show_output(limit=LIVE_POINTS)

    @on(Button.Pressed, "#btn-cancel-run,#cancel")
    def action_cancel_run(self) -> None:
        if self.run_in_progress():
            self.cancel_event.set()
            self.set_busy("Cancelling: earlier outputs stay as they were...", self.progress)

    def on_run_finished(self, message: RunFinished) -> None:
        if self.closing():
            return
        self.running = False
        self.set_busy(None)
        info = self.query_one("#run-info", Static)
        if message.cancelled:
            self.tell("Run cancelled; earlier outputs are unchanged.", severity="warning")
            info.update("Last run cancelled; nothing was written.")
            self.output_voxels = self.result.scene_output if self.result else None
            self.show_output()
            return
        if message.error:
            self.tell(message.error, title="Run failed", severity="error", timeout=10)
            info.update(escape(message.error))
            return
        result = message.result
        self.result = result
        self.output_voxels = result.scene_output
        self.show_output()
        self.show_measures(result.measures)
        total = result.timings.get("total") if isinstance(result.timings, dict) else None
        info.update(f"Last run: {result.backend}"
                    + (f", {total:.1f} s" if total else "")
                    + f"; wrote {self.scenario.measures_file.name}")
        self.query_one("#tabs", TabbedContent).active = "tab-results"
        self.push_screen(MeasuresScreen(result.measures,
                                        f"Comparison measures: {self.scenario.name}"))

    # -- results and views -----------------------------------------------------------

    def show_output(self, limit: int = OUTPUT_POINTS) -> None:
        widget = self.query_one("#output3d", ProjectionWidget)
        voxels = self.output_voxels
        title = "3D output"
        if self.threshold is not None:
            title += f" <= {self.threshold:g} m"
        widget.base_title = title
        widget._update_title()
        if voxels is None or self.scene is None:
            widget.placeholder = "no output yet: F5 runs"
            widget.set_points(None)
            return
        shown = views.threshold_points(voxels, self.scene.voxel_size, self.threshold)
        widget.placeholder = "nothing below the threshold" if len(voxels) else "no returns"
        widget.set_points(views.subsample(shown, limit, seed=0),
                          widget.bounds if widget.bounds is not None else
                          (self.prepared["bounds"] if self.prepared else None),
                          self.scene.voxel_size)

    def show_measures(self, measures) -> None:
        self.measures = measures
        table = self.query_one("#measures", DataTable)
        table.clear()
        info = self.query_one("#results-info", Static)
        if measures is None:
            info.update("No results yet: F5 runs the scenario.")
            return
        info.update(f"Measures of {self.scenario.name if self.scenario else ''}:")
        for label, value in compact_rows(measures):
            table.add_row(label, value)

    def action_layout(self, number: int) -> None:
        self.layout_number = int(number)
        box = self.query_one("#views")
        for n in LAYOUTS:
            box.set_class(n == self.layout_number, f"layout-{n}")

    def action_next_layout(self) -> None:
        self.action_layout(self.layout_number % len(LAYOUTS) + 1)
        self.tell(f"Layout {self.layout_number}: {LAYOUTS[self.layout_number]}", timeout=2)

    def action_toggle_panel(self) -> None:
        sidebar = self.query_one("#sidebar")
        sidebar.display = not sidebar.display

    def action_show_tab(self, tab: str) -> None:
        sidebar = self.query_one("#sidebar")
        sidebar.display = True
        self.query_one("#tabs", TabbedContent).active = f"tab-{tab}"

    def _focused_projection(self) -> ProjectionWidget:
        focused = self.focused
        if isinstance(focused, ProjectionWidget):
            return focused
        if self.layout_number == 4:
            return self.query_one("#output3d", ProjectionWidget)
        return self.query_one("#scene3d", ProjectionWidget)

    def action_view_angle(self) -> None:
        widget = self._focused_projection()

        def done(result):
            if result is not None:
                az, el = result
                camera = widget.camera
                widget.set_camera(views.Camera(az % 360.0, el, camera.zoom, camera.pan_x,
                                               camera.pan_y))

        self.push_screen(AngleScreen(widget.camera.azimuth, widget.camera.elevation), done)

    def on_projection_widget_camera_changed(self, message: ProjectionWidget.CameraChanged):
        # scene and output views turn together, so they stay comparable
        for widget in self.query(ProjectionWidget):
            if widget is not message.widget and widget.camera != message.widget.camera:
                widget.camera = message.widget.camera
                widget._update_title()
                widget.invalidate()

    @on(Button.Pressed, "#btn-threshold")
    def action_threshold(self) -> None:
        def apply(result):
            # None means both "cancelled" and "no threshold": the flag tells them apart
            if screen.cancelled:
                return
            self.threshold = result
            self.show_output()

        screen = ThresholdScreen(self.threshold)
        self.push_screen(screen, apply)

    @on(Button.Pressed, "#btn-measures")
    def action_measures(self) -> None:
        if self.measures is None:
            self.tell("No measures yet: run the scenario first (F5).", severity="warning")
            return
        self.push_screen(MeasuresScreen(self.measures))

    @on(Button.Pressed, "#btn-compare")
    def action_compare(self) -> None:
        paths = []
        if self.scenario is not None:
            folder = self.scenario.path.parent
            own = self.scenario.measures_file
            if own.is_file():
                paths.append(own)
            paths += sorted(p for p in folder.glob("*.cmf") if p != own)
        self.push_screen(CompareScreen(paths[:4]))

    def action_help(self) -> None:
        self.push_screen(HelpScreen(help_rows(self)))

    # -- study and sweep screens -------------------------------------------------------

    @on(Button.Pressed, "#btn-study")
    def action_study(self) -> None:
        """The speed-against-accuracy study of the open scenario (its saved file)."""
        if self.busy or self.tool_screen is not None:
            return
        from ladartui.tui.study_screen import StudyScreen  # plotting loads only when used

        path = None
        if self.scenario is not None and self.scenario.path.is_file():
            path = self.scenario.path
            if self.modified:
                self.tell("The study reads the saved scenario file; save (Ctrl+S) to include "
                          "your changes.", severity="warning", timeout=8)

        def closed(result) -> None:
            self.tool_screen = None
            if result is not None:
                self.study_result = result
            self.refresh_bindings()

        self.tool_screen = StudyScreen(scenario_path=path)
        self.push_screen(self.tool_screen, closed)

    @on(Button.Pressed, "#btn-sweep")
    def action_sweep(self) -> None:
        """Launch, open or watch flight-path sweeps."""
        if self.busy or self.tool_screen is not None:
            return
        from ladartui.tui.sweep_screen import SweepScreen  # Dask loads only when used

        def closed(_result) -> None:
            self.tool_screen = None
            self.refresh_bindings()

        self.tool_screen = SweepScreen()
        self.push_screen(self.tool_screen, closed)

    def on_sweep_screen_open_scenario(self, message) -> None:
        """The sweep's best flight path: open its scenario as F3 would (leaving the sweep
        screen unless a sweep is still running there)."""
        if self.closing():
            return
        if self.run_in_progress():
            self.tell("A run is in progress; the best path was not opened.", severity="warning")
            return
        screen = self.tool_screen
        if screen is not None and self.screen is screen and not getattr(screen, "running", False):
            screen.dismiss(None)
        else:
            self.tell(f"Opening {message.path.name}; Esc leaves the sweep screen to see it.")
        path = message.path

        def load():
            self.result = None
            self.load(path)

        self.confirm_discard(f"open {path.name}", load)

    def tell(self, message: str, *, title: str = "", severity: str = "information",
             timeout: float = 5) -> None:
        """Show a message to the analyst (and keep it in ``messages`` for the record)."""
        self.messages.append(f"{title}: {message}" if title else message)
        # text from files and fields must not be read as markup
        self.notify(escape(message), title=escape(title), severity=severity, timeout=timeout)

    def closing(self) -> bool:
        """True once the app is shutting down: stop any run, ignore late worker news."""
        if self.leaving or not self.is_running:
            self.leaving = True
            self.cancel_event.set()
            self.stop_event.set()
            self.scene_shown.set()
        return self.leaving

    def on_unmount(self) -> None:
        self.closing()

    def exit(self, *args, **kwargs) -> None:
        # a run in a thread cannot be killed: ask it to stop so quitting is quick
        self.cancel_event.set()
        self.stop_event.set()
        self.leaving = True
        super().exit(*args, **kwargs)

    # -- command palette -------------------------------------------------------------

    def get_system_commands(self, screen):
        yield from super().get_system_commands(screen)
        if self.tool_screen is not None and screen is self.tool_screen:
            return  # the study and sweep screens have their own keys
        for title, help_text, action in palette_entries():
            yield SystemCommand(title, help_text, _runner(self, action))


def _runner(app, action: str):
    def run():
        app.call_later(app.run_action, action)
    return run


def palette_entries() -> list[tuple[str, str, str]]:
    """(title, help, action) for every action, as offered in the command palette."""
    entries = [
        ("Help: keys", "List every key (F1)", "help"),
        ("New scenario", "Choose a scenario file and a scene model (F2)", "new_scenario"),
        ("Open scenario", "Load a scenario; every file is checked (F3)", "open_scenario"),
        ("Save scenario", "Write the scenario file (Ctrl+S)", "save"),
        ("Run simulation", "Run the scenario (F5)", "run"),
        ("Cancel run", "Stop the run; earlier outputs stay (Esc)", "cancel_run"),
        ("Next layout", "Cycle the five view layouts (F6)", "next_layout"),
        ("Toggle parameter panel", "Hide or show the sidebar (F4)", "toggle_panel"),
        ("View angle", "Exact azimuth and elevation of the 3D views (F7)", "view_angle"),
        ("Output height threshold", "Draw the output up to a height (F8)", "threshold"),
        ("Show measures", "The measures of the last run (F9)", "measures"),
        ("Compare scenarios", "Two or more .cmf files side by side (F10)", "compare"),
        ("Speed-against-accuracy study", "Every backend, method and ray grid on this "
         "scenario (F11)", "study"),
        ("Flight-path sweep", "Launch, open or watch a sweep; open its best path (F12)",
         "sweep"),
        ("Aim every scan at the target", "Point the sensor at the target centre", "aim_all"),
        ("Edit selected segment", "Open the selected flight segment", "edit_segment"),
        ("Delete selected segment", "Remove the selected flight segment", "delete_segment"),
        ("Manual scan poses", "Edit poses in a table", "manual_poses"),
    ]
    for n, name in LAYOUTS.items():
        entries.append((f"Layout {n}: {name}", f"Switch the views (key {n})", f"layout({n})"))
    for kind in ("straight", "turn", "orbit", "flypast", "standoff"):
        label = bridge.SEGMENT_LABELS[kind]
        entries.append((f"Add {label.lower()} segment", f"Append a {label.lower()} to the "
                        "flight path", f"add_segment('{kind}')"))
    for tab in ("file", "sensor", "flight", "run", "results"):
        entries.append((f"Show {tab} panel", f"Open the {tab} tab", f"show_tab('{tab}')"))
    return entries


@functools.cache
def own_actions() -> frozenset[str]:
    """Names of the actions this app defines (its keys and its palette entries)."""
    keys = [binding.action for binding in LadarApp.BINDINGS]
    return frozenset(action.split("(")[0] for action in keys + [a for _, _, a in palette_entries()])


def help_rows(app) -> list[tuple[str, str, str]]:
    rows = []
    for binding in LadarApp.BINDINGS:
        rows.append(("Anywhere", _key_name(binding.key), binding.description))
    rows.append(("Anywhere", "Ctrl+P", "Command palette: every action by name"))
    rows.append(("Anywhere", "Ctrl+Q", "Quit"))
    rows.append(("Anywhere", "Tab / Shift+Tab", "Move between controls"))
    for binding in ProjectionWidget.BINDINGS:
        rows.append(("3D view", _key_name(binding.key), binding.description))
    rows.append(("3D view", "mouse drag / wheel", "Rotate / zoom"))
    rows.append(("Fields", "Enter or leave", "Check the value; an invalid one resets "
                 "to its default"))
    rows.append(("Segments table", "Enter", "Edit the segment"))
    for binding in PosesScreen.BINDINGS:
        rows.append(("Poses dialog", _key_name(binding.key), binding.description))
    rows.append(("Dialogs", "Escape", "Close without changes"))
    return rows


def _key_name(key: str) -> str:
    """How a key is written for people: F5, Ctrl+S, ?, +."""
    names = {"question_mark": "?", "equals_sign": "=", "plus": "+", "minus": "-",
             "escape": "Esc", "left": "Left", "right": "Right", "up": "Up", "down": "Down",
             "delete": "Delete"}

    def one(k: str) -> str:
        if k in names:
            return names[k]
        if k.startswith("ctrl+"):
            return "Ctrl+" + one(k[5:]).upper()
        if k.startswith("f") and k[1:].isdigit():
            return k.upper()
        return k

    return " / ".join(one(k) for k in key.split(","))


def _shown_folder(folder: Path) -> str:
    """The folder relative to the working directory when inside it (shorter, and stable)."""
    try:
        relative = folder.relative_to(Path.cwd())
    except ValueError:
        return str(folder)
    return "./" + str(relative) if str(relative) != "." else "."


def _field_id(key: str) -> str:
    return "f-" + key.replace(".", "-").replace("_", "-")


def _existing_results(scenario):
    """The scene output and measures of an earlier run, if both are on disk."""
    if not (scenario.scene_output.is_file() and scenario.measures_file.is_file()):
        return None, None
    from ladartui.measures import read_cmf
    from ladartui.scene.voxels import load_voxels

    return load_voxels(scenario.scene_output), read_cmf(scenario.measures_file)
