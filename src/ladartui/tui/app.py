"""The ladartui terminal app: file setup, parameters, run and results over SSH.

Layout: a sidebar of panels (``tui/panels``: File, Sensor, Flight, Run,
Results tabs) on the left, the views on the right (``view_area``: the
report's five layouts), the status colour bar and the key footer at the
bottom. The app holds the one scenario under edit (``edit`` is the only way
to change it, with undo and redo) and wires the panels to it and to the
workers. Everything slow (loading a scene, probing backends, compiling
kernels, running) happens in thread workers that post messages back, so the
interface never blocks.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path

from textual import events, on
from textual.app import App, ComposeResult, SystemCommand
from textual.containers import Horizontal, Vertical
from textual.css.query import NoMatches
from textual.notifications import SeverityLevel
from textual.screen import ModalScreen, Screen
from textual.widgets import Button, Footer, TabbedContent, TabPane, Tabs

from ladartui.atomic import unused_path
from ladartui.edit_history import EditHistory
from ladartui.measures_compare import measures_files_to_offer
from ladartui.run_record import setting_changes
from ladartui.scenario import Scenario
from ladartui.textsafe import single_line
from ladartui.tui import actions, bridge
from ladartui.tui.canvas import PictureWidget
from ladartui.tui.editing import ScenarioEditing
from ladartui.tui.file_actions import FileActions
from ladartui.tui.graphics import Graphics, has_truecolor
from ladartui.tui.help_rows import help_rows, palette_entries, tool_screen_entries
from ladartui.tui.key_words import KeyWords
from ladartui.tui.loading import SceneLoading
from ladartui.tui.measures_screens import CompareScreen, MeasuresScreen
from ladartui.tui.notes import NoteKeeping
from ladartui.tui.panels import FilePanel, FlightPanel, ResultsPanel, RunPanel, SensorPanel
from ladartui.tui.params import ParamField
from ladartui.tui.plain_text import literal
from ladartui.tui.runs import RunControl
from ladartui.tui.screens import AngleScreen, HelpScreen, ImageSizeScreen, ThresholdScreen
from ladartui.tui.startup_problems import startup_notice
from ladartui.tui.status import BUSY, NOT_READY, READY, StatusBar
from ladartui.tui.tool_screens import ToolScreens
from ladartui.tui.unsaved import EditGuard
from ladartui.tui.view_area import LAYOUTS, OUTPUT_POINTS, ViewArea
from ladartui.tui.work import JobDone, JobProgress, start_job
from ladartui.user_data import config_folder

# everything the analyst can change; disabled while busy (Cancel is re-enabled)
CONTROLS = (
    "#sidebar Input, #sidebar Button, #sidebar Select, #sidebar Checkbox, "
    "#sidebar DataTable, #sidebar OptionList"
)
own_actions = actions.own_actions

OUTPUTS_CHECK_SECONDS = 2.0  # how often the outputs on disk are compared with those shown


class LadarApp(
    KeyWords, ScenarioEditing, EditGuard, FileActions, SceneLoading, RunControl, ToolScreens, NoteKeeping, App
):
    """Plan a foliage-penetrating LADAR collection: set up, fly, run, compare."""

    TITLE = "ladartui"
    CSS_PATH = Path(__file__).with_name("app.tcss")
    BINDINGS = actions.BINDINGS

    def __init__(
        self,
        scenario_path: Path | str | None = None,
        *,
        start_scenario: Scenario | None = None,
        cwd: Path | None = None,
        compile_in_child: bool = True,
        graphics: Graphics | None = None,
        graphics_problems: list[str] | None = None,
    ):
        super().__init__()
        # how the views reach the terminal (chosen before the app starts: tui/graphics.py)
        self.graphics = graphics or Graphics(truecolor=has_truecolor(os.environ), reason="not chosen")
        self.graphics_problems = list(graphics_problems or [])
        self.compile_in_child = compile_in_child
        self.scenario_path = Path(scenario_path) if scenario_path else None
        self.start_scenario = start_scenario
        self.cwd = Path(cwd) if cwd else Path.cwd()
        self.history: EditHistory[Scenario] | None = None
        self.scene = None
        self.blind_kept: tuple | None = None  # (reach inputs, scene, note): RunControl.blind_note
        self.prepared = None
        self.measures = None
        self.result = None
        self.output_voxels = None
        # An earlier run's scene and target outputs as read from disk (in a worker).
        self.disk_outputs: tuple = (None, None)
        self.shown_before_run: tuple = (None, None)  # the outputs a cancelled run shows again
        self.missing_outputs: list[Path] = []
        self.outputs_interrupted = False  # a killed run's swap is on disk (not read)
        self.output_blocked: str | None = None  # an output's name held by a folder (loading)
        self.outputs_from: Scenario | None = None  # the settings that made the outputs shown
        self.inputs_changed: list[str] = []  # the files they read that changed since their run
        self.changed_since_opened: list[str] = []  # read here before they changed (reopen)
        self.inputs_drifted: list[tuple[str, str]] = []  # those found changed on disk since
        self.inputs_seen = {}  # when each was last looked at (SceneLoading.check_inputs_on_disk)
        self.outputs_seen: tuple[int, int] | None = None  # (mtime, size) of the measures read
        self.threshold: float | None = None
        self.busy: str | None = None
        self.progress: float | None = None
        self.load_worker = self.warm_worker = self.run_worker_handle = None  # the jobs
        self.new_pending: tuple[Path, tuple[str, ...], Path] | None = None  # New's folder, fields, file
        self.messages: list[str] = []
        self.leaving = False  # set by exit: news from jobs is no longer shown
        self.running = False
        self.tool_screen: Screen[None] | None = None  # the study or sweep screen while it is open
        self.keymap, self.keymap_problems = actions.load_keymap()
        self.set_keymap(self.keymap)
        for key, action, title in actions.keymap_only_bindings(self.keymap):
            self.bind(key, action, description=title, show=False)

    def target_m(self) -> tuple[float, ...]:
        if self.prepared is not None:
            return self.prepared["target_m"]
        return (0.0, 0.0, 0.0)

    # -- layout ------------------------------------------------------------------------

    def compose(self) -> ComposeResult:
        with Horizontal(id="main"):
            with Vertical(id="sidebar"):
                with TabbedContent(id="tabs"):
                    with TabPane("File", id="tab-file"):
                        yield FilePanel(id="file-panel")
                    with TabPane("Sensor", id="tab-sensor"):
                        yield SensorPanel(id="sensor-panel")
                    with TabPane("Flight", id="tab-flight"):
                        yield FlightPanel(id="flight-panel")
                    with TabPane("Run", id="tab-run"):
                        yield RunPanel(id="run-panel")
                    with TabPane("Results", id="tab-results"):
                        yield ResultsPanel(id="results-panel")
            yield ViewArea(id="views")
        yield StatusBar(id="status", tell=lambda said: self.tell(said, severity="warning", timeout=10))
        yield Footer(compact=True)

    def on_mount(self) -> None:
        self.file_panel = self.query_one(FilePanel)
        self.sensor_panel = self.query_one(SensorPanel)
        self.flight_panel = self.query_one(FlightPanel)
        self.run_panel = self.query_one(RunPanel)
        self.results_panel = self.query_one(ResultsPanel)
        self.keep_notes_off_dialogs()
        # back from SIGTSTP (fg): the alternate screen starts blank, and Textual draws nothing
        self.app_resume_signal.subscribe(self, lambda _app: self.refresh(layout=True))
        self.stop_on_signals()
        self.view_area = self.query_one(ViewArea)
        runs = self.key_says("run", "runs")
        self.view_area.no_output = "no output yet" + (f": {runs}" if runs else "")
        problems = [("Key not remapped", p) for p in self.keymap_problems]
        problems += [("Settings", p) for p in self.graphics_problems]
        if problems:  # one notice: several stacked ran off the top at 80 x 24
            self.messages += [f"{title}: {problem}" for title, problem in problems]
            title, said = startup_notice(problems, config_folder(), (self.size.width, self.size.height))
            self.notify(said, title=title, severity="warning", timeout=10, markup=False)
        self.refresh_status()
        self.set_interval(OUTPUTS_CHECK_SECONDS, self.check_outputs_on_disk)  # another run's outputs
        if self.start_scenario is not None:
            self.load(None, scenario=self.start_scenario)
        else:
            self.load(self.scenario_path)

    @property
    def layout_number(self) -> int:
        return self.view_area.layout_number

    @property
    def backend_rows(self):
        return self.run_panel.backend_rows

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
        self.run_panel.set_running(running)
        if not busy and self.scenario is not None:
            self.run_panel.enable_step()
            self.flight_panel.enable_start()
        if busy and not was_busy and running and not isinstance(self.focused, PictureWidget):
            self.query_one("#status #cancel").focus()  # a view keeps its keys (turn, zoom)
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
            return [f"no scenario: new{self.key_note('new')} or open{self.key_note('open')}"]
        out = [problem] if (problem := self.scenario_file_problem()) else []  # changed on disk
        if self.scene is None:
            out.append("scene model not loaded")
        bad = [
            f"{f.param.label} {f.param.unit}".strip()
            for f in self.query(ParamField)
            if fields and f.has_class("-bad")
        ]
        if bad:
            out.append("invalid value in " + ", ".join(bad))
        rows = self.backend_rows
        if rows is not None:
            status = {name: ok for name, _, ok in rows}
            if not status.get(self.scenario.backend, True):
                out.append(f"backend {self.scenario.backend} unavailable")
        refusal = bridge.run_refusal(self.scenario) or self.output_blocked
        if refusal:
            out.append(refusal)
        return out

    def refresh_status(self) -> None:
        bar = self.query_one(StatusBar)
        scenario = self.scenario
        name = scenario.path.name if scenario is not None else None

        def show(state: str, message: str, progress: float | None = None, cancellable: bool = False):
            bar.show(state, message, progress, cancellable, name=name)  # the name is what shortens

        if self.busy is not None:
            show(BUSY, self.busy, self.progress, cancellable=self.run_in_progress())
            return
        problems = self.problems()
        if problems or scenario is None:  # no scenario is one of the problems
            show(NOT_READY, "; ".join(problems))
            return
        poses = len(scenario.poses())
        rays = scenario.sensor.rays_per_scan
        mark = " (modified)" if self.modified else ""
        runs = self.key_says("run", "runs")
        text = f"{scenario.path.name}{mark}: {poses} scans x {rays:,} rays." + (f" {runs}." if runs else "")
        if self.outputs_interrupted:
            puts = f"; {runs} and puts the earlier set back first" if runs else ""
            show(
                NOT_READY,
                f"{scenario.path.name}{mark}: the last run was stopped while it replaced the outputs{puts}.",
            )
            return
        if self.missing_outputs:
            # runnable, but the set on disk is incomplete: yellow until a run rewrites it
            names = ", ".join(p.name for p in self.missing_outputs)
            writes = f"; {runs} and writes them" if runs else ""
            show(NOT_READY, f"{scenario.path.name}{mark}: outputs missing ({names}){writes}.")
            return
        if self.outputs_stale() or self.inputs_drifted:
            # short: the bar is one line (the Results tab says which settings they came from)
            reruns = self.key_says("run", "reruns")
            stale = "outputs out of date" + (f"; {reruns}." if reruns else ".")
            if files := self.changed_on_disk():  # a rerun would read the copies from before
                stale = f"{', '.join(files)} changed on disk; reopen to read {'them' if files[1:] else 'it'}."
            show(NOT_READY, f"{scenario.path.name}{mark}: {stale}")
            return
        if blind := self.blind_note():  # runnable, but a run would see nothing there
            show(NOT_READY, f"{scenario.path.name}{mark}: {blind}" + (f"; {runs} anyway." if runs else "."))
            return
        show(READY, text)

    def check_action(self, action: str, parameters) -> bool | None:
        if self.tool_screen is not None and self.screen is self.tool_screen:
            # that screen has its own keys (its F1 asks for help); textual's own (focus, quit) stay
            return False if action in own_actions() and action != "help" else True
        if action == "cancel_run":  # in the footer only while there is a run to cancel
            return True if self.run_in_progress() else False
        if self.busy is not None and action not in actions.DISPLAY_ACTIONS:
            return None
        if action == "run" and self.problems(fields=False):
            return None
        return True

    def on_key(self, event: events.Key) -> None:
        """A key whose command is off (dimmed in the footer) says why, not nothing."""
        if len(self.screen_stack) > 1:  # a dialog or tool screen: its own keys
            return
        active = self.screen.active_bindings.get(event.key)
        if active is None or active.enabled:
            return
        self.tell_why_off(active.binding.description or active.binding.action, active.binding.action)

    def tell_why_off(self, what: str, action: str) -> None:
        """Why the command ``what`` (its ``action``) is off, from its key or the palette."""
        if self.run_in_progress():
            cancel = self.key_says("cancel", "cancels the run")
            self.tell(f"{what} is off while the run goes on" + (f"; {cancel}." if cancel else "."), timeout=3)
        elif self.busy is not None:
            self.tell(f"{what} is off while busy: {self.busy}", timeout=3)
        elif action == "run" and (problems := self.problems(fields=False)):
            self.tell(f"Run is off: {'; '.join(problems)}.", timeout=3)

    # -- flight path (the palette and keys reach the flight panel through these) -------

    def action_add_segment(self, kind: str) -> None:
        self.flight_panel.add_segment(kind)

    def action_edit_segment(self) -> None:
        self.flight_panel.edit_selected()

    def action_delete_segment(self) -> None:
        self.flight_panel.delete_selected()

    def action_manual_poses(self) -> None:
        self.flight_panel.manual_poses()

    def action_aim_all(self) -> None:
        self.flight_panel.aim_all()

    @on(Button.Pressed, "#cancel")
    def _cancel_pressed(self) -> None:  # the status bar's Cancel
        self.action_cancel_run()

    async def action_quit(self) -> None:
        self.confirm_quit()  # asks first about a run going on, then about unsaved edits

    # -- results and views -----------------------------------------------------------

    def show_output(self, limit: int = OUTPUT_POINTS) -> None:
        if self.scene is None:
            self.view_area.show_output(None, self.threshold, limit)
            return
        self.view_area.show_output(self.output_voxels, self.threshold, limit)

    def show_measures(self, measures) -> None:
        self.measures = measures
        self.results_panel.show_measures(
            measures, self.scenario.name if self.scenario else "", made_with=self.outputs_made_with()
        )

    def outputs_made_with(self) -> str | None:
        """Which other settings made the outputs shown, in words; None: the scenario's now."""
        made, scenario = self.outputs_from, self.scenario
        if made is None or scenario is None or not self.outputs_stale():
            return None
        settings = setting_changes(made, scenario)
        inputs = list(self.inputs_changed)
        for role, name in self.inputs_drifted:  # the outputs came from the copies read here
            said = f"the {role} {name} changed on disk since it was opened (reopen to read it)"
            inputs += [] if said in inputs else [said]
        differ = named_changes(settings + inputs)
        record = scenario.run_record
        if record.is_file():  # written by every run since records exist
            other = " and ".join(
                word for word, changed in (("settings", settings), ("inputs", inputs)) if changed
            )
            return f"other {other}{differ}. The run's settings are in {record.name}."
        return f"the settings before your edits{differ}."

    def outputs_stale(self) -> bool:
        """Whether the outputs shown came from other settings than the scenario's now, or
        from model files or flight logs that changed since their run, or on disk since
        the app read them."""
        made, scenario = self.outputs_from, self.scenario
        if made is None or scenario is None:
            return False
        return bool(self.inputs_changed or self.inputs_drifted) or not made.same_outputs(scenario)

    def action_layout(self, number: int) -> None:
        self.view_area.set_layout(number)

    def action_next_layout(self) -> None:
        self.action_layout(self.layout_number % len(LAYOUTS) + 1)
        self.tell(f"Layout {self.layout_number}: {LAYOUTS[self.layout_number]}", timeout=2)

    def action_toggle_panel(self) -> None:
        sidebar = self.query_one("#sidebar")
        sidebar.display = not sidebar.display

    def action_show_tab(self, tab: str) -> None:
        self.query_one("#sidebar").display = True
        tabs = self.query_one("#tabs", TabbedContent)
        shown, focused = tabs.active_pane, tabs.screen.focused
        if (
            shown is not None
            and shown.id != f"tab-{tab}"
            and focused is not None
            and shown in focused.ancestors
        ):
            # hidden, it would hand the focus to a neighbour in its tab, which then takes
            # over again: the tab bar takes it, as a click on a tab leaves it
            tabs.screen.set_focus(tabs.query_one(Tabs))
        tabs.active = f"tab-{tab}"

    def action_view_angle(self) -> None:
        widget = self.view_area.focused_projection(self.focused)

        def done(result):
            if result is not None:
                widget.set_camera(widget.camera.at_angle(*result))  # keeps zoom and centre

        self.push_screen(AngleScreen(widget.camera.azimuth, widget.camera.elevation), done)

    def action_threshold(self) -> None:
        def apply(result):
            # None means both "cancelled" and "no threshold": the flag tells them apart
            if screen.cancelled:
                return
            self.threshold = result
            self.show_output()

        screen = ThresholdScreen(self.threshold)
        self.push_screen(screen, apply)

    def action_measures(self) -> None:
        if self.measures is None:
            self.tell(f"No measures yet: run the scenario first{self.key_note('run')}.", severity="warning")
            return
        made_with = self.outputs_made_with()
        stale = ""
        if made_with is not None:  # as the Results tab and the status bar say it
            # a rerun would read the app's old copies of files changed on disk since
            reruns = "" if self.changed_on_disk() else self.key_says("run", "reruns")
            stale = f"Out of date: made from {made_with}" + (f" {reruns}." if reruns else "")
        self.push_screen(MeasuresScreen(self.measures, stale=stale))

    def action_compare(self) -> None:
        paths = [] if self.scenario is None else measures_files_to_offer(self.scenario.measures_file)
        self.push_screen(CompareScreen(paths, self._folder()))

    def action_view(self, name: str) -> None:
        """A view command (zoom to target, fit, colouring, overlays) in every view."""
        getattr(self.view_area, name)()

    def action_save_png(self) -> None:
        if self.scenario is None or self.scene is None:
            return
        view = self.view_area.current_view(self.focused)
        name = getattr(view, "base_title", None) or view.border_title or view.id or "view"  # not its camera
        # beside an earlier picture, never over it
        path = unused_path(self.scenario.path.with_name(f"{self.scenario.path.stem}-{view.id}.png"))

        def chosen(size: tuple[int, int] | None) -> None:
            if size is not None:
                area, (width, height) = self.view_area, size
                start_job(self, "png", lambda cancel, progress: area.save_png(path, width, height, view))

        self.push_screen(ImageSizeScreen(name), chosen)

    def action_export_las(self) -> None:
        if self.scenario is None or self.busy:
            return
        scenario, scene = self.scenario, self.scene
        made_with = self.outputs_made_with()  # outputs out of date: the note says so

        def export(cancel, progress):
            return bridge.export_outputs_las(scenario, scene=scene), made_with

        start_job(self, "export", export)

    def action_help(self) -> None:
        self.push_screen(HelpScreen(help_rows(self)))

    def tell(
        self, message: str, *, title: str = "", severity: SeverityLevel = "information", timeout: float = 5
    ) -> None:
        """Show a message to the analyst (and keep it in ``messages`` for the record)."""
        # a file name's controls written out (a newline, an escape) must not reach the terminal
        message, title = single_line(message), single_line(title)
        self.messages.append(f"{title}: {message}" if title else message)
        # text from files and fields must not be read as markup
        self.notify(message, title=title, severity=severity, timeout=timeout, markup=False)

    # -- jobs: every slow piece of work reports here (tui/work.py) -------------------

    JOB_FAILED = {
        "load": "Could not load",
        "new": "New scenario not written",
        "run": "Run failed",
        "probe": "Backends not probed",
        "warm": "Kernels not compiled",
        "export": "Nothing exported",
        "png": "View not saved",
        "earlier": "Earlier outputs not read",
        "inputs": "Model files not checked",
    }

    def on_job_progress(self, message: JobProgress) -> None:
        if self.leaving:
            return
        if message.job == "run":
            self.run_progressed(message.fraction, message.text, message.detail)

    def on_job_done(self, message: JobDone) -> None:
        if self.leaving:  # news from a job that ends as the app shuts down
            return
        try:
            self._job_done(message)
        except NoMatches:  # the app was taken down while the job reported
            pass

    def _job_done(self, message: JobDone) -> None:
        if message.error:  # every failure, expected or not, is told the same way
            self.tell(
                message.error,
                title=self.JOB_FAILED.get(message.job, message.job),
                severity="error",
                timeout=10,
            )
        if message.job in ("load", "new"):
            if message.result is not None:
                self.loaded(message.result)
            else:
                self.set_busy(None)
                if message.error:
                    self.run_panel.say(message.error)
                    # a recent scenario deleted since leaves the list (it lists files there are)
                    self.file_panel.show_recent(self.scenario.path if self.scenario else None)
                if message.job == "new" and message.error:
                    self.new_refused(message.error, message.error_path)
        elif message.job == "probe":
            self.backends_probed(
                message.result
                if message.result is not None
                else [("auto", f"backends could not be probed: {message.error}", False)]
            )
        elif message.job == "run":
            self.run_finished(message.result, message.cancelled, message.error)
        elif message.job == "earlier" and message.result is not None:
            self.earlier_read(message.result)
        elif message.job == "inputs" and message.result is not None:
            self.inputs_looked_at(message.result)
        elif message.job == "png" and message.result is not None:
            self.tell(f"Wrote {message.result}")
        elif message.job == "export" and message.result is not None:
            paths, made_with = message.result
            wrote = "Wrote " + ", ".join(str(p) for p in paths)
            if made_with is None:
                self.tell(wrote)
            else:  # as the status bar and the Results tab call them
                self.tell(f"{wrote} from outputs out of date: made from {made_with}", severity="warning")

    def exit(self, *args, **kwargs) -> None:
        # a thread cannot be killed: cancelling tells every job to stop, so quitting is quick
        self.leaving = True
        self.workers.cancel_all()
        super().exit(*args, **kwargs)

    # -- command palette -------------------------------------------------------------

    def get_system_commands(self, screen):
        waiting = isinstance(screen, ModalScreen)  # a dialog or prompt waits for its answer
        for command in super().get_system_commands(screen):
            if not (waiting and command.callback == self.action_quit):  # quit would ask again
                yield command
        if self.tool_screen is not None and screen is self.tool_screen:
            # the study and sweep screens have their own keys: those, not the app's
            for title, keys, action in tool_screen_entries(screen):
                yield SystemCommand(
                    literal(title),
                    literal(keys),
                    functools.partial(screen.call_later, screen.run_action, action),
                )
            return
        if waiting:
            return  # nothing may start under it
        for title, help_text, action in palette_entries(self):
            # the palette reads its titles and help as markup: a recent file's path is text
            yield SystemCommand(literal(title), literal(help_text), _runner(self, action, title))


def _runner(app, action: str, title: str):
    def run():
        name = action.split("(")[0]
        if not app.check_action(name, ()):  # off (busy, or Run not ready): say why, as its key does
            app.tell_why_off(title, name)
            return
        app.call_later(app.run_action, action)

    return run


def named_changes(changes: list[str], shown: int = 2) -> str:
    """ ": a; b; and 3 more" for the first ``shown`` changes (empty for none)."""
    if not changes:
        return ""
    more = len(changes) - shown
    return ": " + "; ".join(changes[:shown]) + (f"; and {more} more" if more > 0 else "")
