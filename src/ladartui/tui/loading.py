"""Loading a scenario and its scene, probing the backends and warming the kernels.

Three jobs (``tui/work.py``): "load" reads the scenario, its scene and any
earlier results and prepares the views ("new" does so for New's scenario and
writes it only then, so a scene model that cannot be read leaves no file and
brings New's form back as typed); once they are shown, "probe" lists
the backends and "warm" has two child processes compile the tracing kernels
for the first Run (``ladartui.precompile``: compiling here would hold the
interpreter lock and freeze the interface), then loads them from numba's
disk cache.
"""

from __future__ import annotations

import os
import stat
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ladartui.errors import LadarError
from ladartui.fingerprint import file_fingerprint
from ladartui.outputset import not_a_file
from ladartui.recent import remember_scenario
from ladartui.run_record import (
    input_changes,
    is_record,
    missing_outputs,
    read_run_record,
    recorded_inputs,
    run_inputs,
)
from ladartui.scenario_file import record_owner
from ladartui.textsafe import single_line, visible
from ladartui.tui import actions, bridge
from ladartui.tui.host import Host
from ladartui.tui.status import StatusBar
from ladartui.tui.view_area import prepare_views
from ladartui.tui.work import running, start_job

if TYPE_CHECKING:
    import numpy as np

    from ladartui.measures import Measures
    from ladartui.scenario import Scenario
    from ladartui.scene.model import Scene


@dataclass(frozen=True)
class OutputFiles:
    """What one ``stat`` of each of a scenario's output files found: enough to read
    them, name a partial set and tell another run's outputs apart without asking again."""

    readable: bool  # the scene output and the measures are files: an earlier run to show
    missing: list[Path]  # those of a partial set (run_record.missing_outputs)
    seen: tuple[int, int] | None  # the measures file's (mtime, size): outputs_on_disk
    # a run was stopped while it replaced them (simulation.swap_interrupted): neither
    # read nor called missing; the next run puts the earlier set back first
    interrupted: bool = False
    # an output's name that a folder or a special file holds: the run would be refused
    blocked: str | None = None


@dataclass
class Earlier:
    """The outputs on disk under a scenario's name, from an earlier run."""

    scenario: Scenario
    output: np.ndarray | None
    measures: Measures | None
    ran: Scenario | None  # the settings that made them (the run record), if recorded
    warning: str | None
    files: OutputFiles  # the look they were read after
    target_output: np.ndarray | None = None  # the target traced without foliage, if on disk
    inputs_changed: list[str] = field(default_factory=list)  # run_record.inputs_changed
    # the names of those read by the run as they are on disk now, which the app read
    # before they changed: only reopening brings them in
    changed_since_opened: list[str] = field(default_factory=list)

    @property
    def made_with(self) -> Scenario | None:
        """What made the outputs: the record, else (a set older than records) the file."""
        if self.output is None and self.measures is None:
            return None
        return self.ran or self.scenario


@dataclass(frozen=True)
class FileSeen:
    """A scenario file as opened or last saved: its (mtime, size) and its bytes (None:
    no file), so that a touch is told apart from a change."""

    stamp: tuple[int, int] | None
    text: bytes | None


@dataclass
class Loaded:
    """What the load job hands the interface."""

    scene: Scene
    prepared: dict[str, Any]
    earlier: Earlier
    file_seen: FileSeen | None = None  # the scenario file, read before the scenario was
    # the (mtime, size) of each model file and flight log, taken before the scene was read
    inputs_seen: dict[Path, tuple[int, int] | None] = field(default_factory=dict)

    @property
    def scenario(self) -> Scenario:
        return self.earlier.scenario


class SceneLoading(Host):
    """The app's load, probe and warm-up jobs (mixed into ``LadarApp``)."""

    scenario_seen: FileSeen | None = None  # the scenario file as opened or last saved
    scenario_on_disk: str | None = None  # "changed" or "gone" since then; None: as it was
    # each model file and flight log read here: its (mtime, size) when last looked at, and
    # whether its bytes on disk then differed from those read
    inputs_seen: dict[Path, tuple[tuple[int, int] | None, bool]]
    inputs_worker = None  # the job hashing the files written since (check_inputs_on_disk)

    def load(self, path: Path | None, scenario: Scenario | None = None, new: bool = False) -> None:
        """Load a scenario and its scene in a worker (the default scenario when no path).
        ``new``: ``scenario`` is New's, written once its scene has been read (job "new")."""
        name = path.name if path else (scenario.path.name if scenario else "default scenario")
        self.set_busy(f"Loading {name}...")
        self.load_worker = start_job(
            self, "new" if new else "load", lambda cancel, progress: _load(path, scenario, new)
        )

    def loaded(self, done: Loaded) -> None:
        """The load job's result: show it, then probe the backends and warm the kernels."""
        self.scene = done.scene
        self.prepared = done.prepared
        self.view_area.set_scene(done.prepared, done.scene.voxel_size)
        self.missing_outputs = done.earlier.files.missing
        self.outputs_interrupted = done.earlier.files.interrupted
        self.output_blocked = done.earlier.files.blocked
        self.outputs_from = done.earlier.made_with  # before the status is drawn
        self.inputs_changed = done.earlier.inputs_changed
        self.changed_since_opened = done.earlier.changed_since_opened
        self.scenario_seen, self.scenario_on_disk = done.file_seen, None
        self.inputs_seen = {path: (stamp, False) for path, stamp in done.inputs_seen.items()}
        self.inputs_drifted = []
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

    def show_outputs_of(self, scenario: Scenario, files: OutputFiles | None = None) -> None:
        """After Save As onto a name: the outputs already on disk under it, shown as
        opening that file would show them (read in a worker). ``files``: the look
        at them already taken."""
        if files is None:
            files = look_at_outputs(scenario)
        self.outputs_seen = files.seen  # the ones about to be shown: no other run's
        self.missing_outputs = files.missing
        self.outputs_interrupted = files.interrupted
        self.output_blocked = files.blocked
        if files.readable:
            scene = self.scene
            start_job(self, "earlier", lambda cancel, progress: _earlier(scenario, files, scene))

    def earlier_read(self, earlier: Earlier) -> None:
        if self.scenario is None or self.scenario.path != earlier.scenario.path:
            return  # another file since
        self._show_earlier(earlier)
        self.scenario_changed()

    def check_outputs_on_disk(self) -> None:
        """Every few seconds: outputs another run of this file wrote (a second instance, the
        CLI) are read and shown, said in a note; the ones shown are no longer on disk.
        The scenario file itself is looked at first (``check_scenario_on_disk``)."""
        self.check_scenario_on_disk()
        scenario = self.scenario
        if scenario is None or self.busy is not None or self.running:
            return
        self.check_inputs_on_disk()
        if self.check_swap_on_disk(scenario):
            return
        if self.output_blocked:  # looked at again while an output's name is held
            files = look_at_outputs(scenario)
            if files.blocked != self.output_blocked:
                self.show_outputs_of(scenario, files)
                self.scenario_changed()
                return
        measures = _file_status(scenario.measures_file)
        now = _stamp(measures)
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
        # reads them, or names the files missing; the measures file as just found
        self.show_outputs_of(scenario, outputs_with(scenario, measures))
        self.scenario_changed()

    def check_swap_on_disk(self, scenario) -> bool:
        """Another run of this file stopped while it replaced the outputs (or the earlier
        set since put back): said, and the outputs looked at again once it is back.
        True while the files on disk are not to be read."""
        from ladartui.simulation import swap_interrupted

        interrupted = swap_interrupted(scenario)
        if interrupted and not self.outputs_interrupted:
            self.outputs_interrupted, self.missing_outputs = True, []
            self.tell(
                f"A run of {scenario.path.name} was stopped while it replaced the outputs: those "
                "shown were read before it, and the next run puts them back first.",
                severity="warning",
                timeout=8,
            )
            self.scenario_changed()
        elif self.outputs_interrupted and not interrupted:
            self.show_outputs_of(scenario)  # put back (a run of it elsewhere): read again
            self.scenario_changed()
        return interrupted

    def check_scenario_on_disk(self) -> None:
        """The scenario file changed (or went) on disk since it was opened or saved: Run
        would go with settings the file no longer holds, so it is off until a reopen or
        a save (``scenario_file_problem``); said once, when found."""
        scenario, seen = self.scenario, self.scenario_seen
        if scenario is None or seen is None:
            return
        stamp = _stamp(_file_status(scenario.path))
        if stamp == seen.stamp:
            return
        now = file_seen(scenario.path)
        self.scenario_seen = FileSeen(now.stamp, seen.text)  # the bytes compared stay those opened
        change = None if now.text == seen.text else "gone" if now.text is None else "changed"
        if change == self.scenario_on_disk:
            return
        self.scenario_on_disk = change
        if change is not None:
            problem = self.scenario_file_problem()
            self.tell(f"{problem}.", severity="warning", timeout=8)
            self.query_one("#status", StatusBar).told = single_line(problem)  # told: not again as a cut line
        self.scenario_changed()

    def check_inputs_on_disk(self) -> None:
        """A model file or flight log read here that changed on disk since: the app holds
        its old copy, which a run would read, so only reopening brings the new one in;
        said once, when found, and on the status bar while it lasts. A file only touched,
        or put back as it was read, changes nothing. Its bytes are hashed in a worker
        (job "inputs"), and only once its (mtime, size) moved."""
        scenario, scene = self.scenario, self.scene
        if scenario is None or scene is None or running(self.inputs_worker):
            return
        written = []  # (path, stamp now, fingerprint as read) of those written since looked at
        for entry in run_inputs(scenario, scene):
            stamp = _stamp(_file_status(entry.path))
            seen = self.inputs_seen.get(entry.path)
            if seen is None or seen[0] != stamp:
                written.append((entry.path, stamp, entry.fingerprint))
        if written:
            self.inputs_worker = start_job(
                self,
                "inputs",
                lambda cancel, progress: (
                    scenario.path,
                    {path: (stamp, file_fingerprint(path) != read) for path, stamp, read in written},
                ),
            )

    def inputs_looked_at(self, looked: tuple[Path, dict]) -> None:
        """The inputs job's answer: for each file written since, its stamp and whether its
        bytes differ from those read; the files now changed are said and shown."""
        scenario, scene = self.scenario, self.scene
        path, seen = looked
        if scenario is None or scene is None or scenario.path != path:
            return  # another file since
        self.inputs_seen.update(seen)
        drifted = [
            (entry.role, visible(entry.path.name))
            for entry in run_inputs(scenario, scene)
            if self.inputs_seen.get(entry.path, (None, False))[1]
        ]
        if drifted == self.inputs_drifted:
            return
        new = [name for _, name in drifted if name not in self.changed_on_disk()]
        self.inputs_drifted = drifted
        if new:
            reopen = self.key_note("open")
            self.tell(
                f"{', '.join(new)} changed on disk since it was opened; reopen{reopen} to read "
                f"{'them' if new[1:] else 'it'}.",
                severity="warning",
                timeout=8,
            )
        self.scenario_changed()

    def changed_on_disk(self) -> list[str]:
        """The names of the model files and flight logs read here that changed on disk
        since (found by a run that read them, or by looking): a run would read the old
        copies, so only reopening the scenario brings them in."""
        names = list(self.changed_since_opened)
        return names + [name for _, name in self.inputs_drifted if name not in names]

    def note_scenario_saved(self) -> None:
        """The scenario file as just written by this app: the one compared from now on."""
        self.scenario_seen = file_seen(self.scenario.path) if self.scenario is not None else None
        self.scenario_on_disk = None

    def scenario_file_problem(self) -> str:
        """What stops a run while the scenario file differs from the one opened ("" if none)."""
        if self.scenario is None or self.scenario_on_disk is None:
            return ""
        name = self.scenario.path.name
        save, reopen = (actions.key_hint(command, self.keymap, short=True) for command in ("save", "open"))
        if self.scenario_on_disk == "gone":
            return f"{name} is gone from disk; save it" + (f" ({save})" if save else "")
        ways = " or ".join(
            f"{word} ({key})" if key else word for word, key in (("reopen", reopen), ("save", save))
        )
        return f"{name} changed on disk; {ways}"

    def note_outputs_seen(self) -> None:
        """The outputs on disk are the ones shown (read, or written by this app's run)."""
        self.outputs_seen = outputs_on_disk(self.scenario) if self.scenario is not None else None

    def _show_earlier(self, earlier: Earlier) -> None:
        """An earlier run's outputs and measures in the views, and what made them."""
        self.outputs_seen = earlier.files.seen  # as found before they were read
        self.outputs_from = earlier.made_with
        self.inputs_changed = earlier.inputs_changed
        self.changed_since_opened = earlier.changed_since_opened
        self.output_voxels = earlier.output
        self.disk_outputs = (earlier.output, earlier.target_output)
        self.show_output()
        self.show_measures(earlier.measures)
        if earlier.warning:
            self.tell(earlier.warning, severity="warning", timeout=8)

    def backends_probed(self, choices) -> None:
        self.run_panel.show_backends(choices, self.scenario.backend if self.scenario else "auto")
        self.refresh_status()


def _load(path: Path | None, scenario, new: bool = False) -> Loaded:
    if scenario is None:
        if path is None:
            from ladartui.user_data import default_scenario_path

            path = default_scenario_path()
        seen = file_seen(path)  # before it is read: a change after is found, not missed
        scenario = bridge.load_checked(path)
    else:
        seen = file_seen(scenario.path)
    inputs_seen = {path: _stamp(_file_status(path)) for path in _input_paths(scenario)}
    scene = scenario.load_scene()
    _check_memory(scenario, scene)
    if new:  # written only once its scene is read and fits: a bad model leaves no file
        scenario = scenario.save()
        seen = file_seen(scenario.path)
    return Loaded(scene, prepare_views(scene), _earlier(scenario, scene=scene), seen, inputs_seen)


def _input_paths(scenario) -> list[Path]:
    """The model files and flight logs a run of ``scenario`` reads (``run_inputs``' paths)."""
    from ladartui.trajectory import LogSegment

    logs = [Path(s.file) for s in scenario.flight.segments if isinstance(s, LogSegment)]
    return [scenario.scene_file, scenario.target_file, *logs]


def _check_memory(scenario, scene) -> None:
    """Refuse, with its estimate, a scene whose tracing structures the memory cannot
    hold, as validate and run do, and one whose views' height map (``Scene.view_columns``:
    one cell a column over the voxels' x-y extent, or the occupied columns alone where
    that extent is wide for them) it cannot hold."""
    from ladartui.errors import ResourceLimitError
    from ladartui.resources import available_memory, gib
    from ladartui.scene.column_tops import map_layout

    scene.tracing_bytes()
    nx, ny = scene.column_box()  # the height map spans the scene's voxels' columns
    dense, need = map_layout(nx, ny, len(scene.voxels))
    if need > available_memory():
        held = (
            f"{nx:,} x {ny:,} columns" if dense else f"the occupied columns of {len(scene.voxels):,} voxels"
        )
        why = "its voxels spread too far apart for the views: " if dense else ""
        raise ResourceLimitError(
            f"{scenario.scene_file}: the views' height map of {held} needs about {gib(need)}, more "
            f"than the {gib(available_memory())} of memory available; {why}crop the scene or use "
            "a coarser voxel size"
        )


def file_seen(path: Path) -> FileSeen:
    """The scenario file at ``path`` as it is now (no text when it is no readable file)."""
    status = _file_status(path)
    if status is None or not stat.S_ISREG(status.st_mode):
        return FileSeen(None, None)
    try:
        return FileSeen(_stamp(status), path.read_bytes())
    except OSError:
        return FileSeen(_stamp(status), None)


def _earlier(scenario, files: OutputFiles | None = None, scene: Scene | None = None) -> Earlier:
    """The outputs of an earlier run under ``scenario``'s name, and what made them;
    ``files``: the look at them already taken; ``scene``: the scenario's, as loaded
    (a model file it read that changed since the run is named)."""
    if files is None:
        files = look_at_outputs(scenario)
    warning, ran = None, None
    target_output = None
    changed: list[str] = []
    since_opened: list[str] = []
    try:
        output, measures = _existing_results(scenario, files)
    except LadarError as error:  # old results must not stop the scenario loading
        output, measures, warning = None, None, f"earlier results not shown: {error}"
    if output is not None:
        try:
            ran = read_run_record(scenario)
        except LadarError as error:
            warning = f"settings of the earlier run not read, taken as the file's: {error}"
        if ran is not None and scene is not None:
            changed, since_opened, warning = _inputs_changed(scenario, scene)
        if ran is not None:  # (a record that cannot be read is said above)
            warning = _with_replaced_outputs(scenario, warning)
        target_output = _target_output(scenario)
    return Earlier(scenario, output, measures, ran, warning, files, target_output, changed, since_opened)


def _inputs_changed(scenario, scene) -> tuple[list[str], list[str], str | None]:
    """The earlier outputs' model files or flight logs that differ from those read here,
    the names of those the run read as they are on disk now (changed since they were
    opened here, not since the run), and the note that says so (or that the record
    could not tell)."""
    try:
        recorded = recorded_inputs(scenario) or []
    except LadarError as error:
        return [], [], visible(f"model files of the earlier run not read: {error}")
    here = run_inputs(scenario, scene)
    read_here = {entry.path: entry.fingerprint for entry in here}
    newer = [
        entry
        for entry in recorded
        if entry.path in read_here
        and read_here[entry.path] != entry.fingerprint
        and file_fingerprint(entry.path) == entry.fingerprint
    ]
    changes = [visible(change) for change in input_changes([e for e in recorded if e not in newer], here)]
    changes += [
        visible(f"the {entry.role} {entry.path.name} changed on disk since it was opened (reopen to read it)")
        for entry in newer
    ]
    names = [visible(entry.path.name) for entry in newer]
    return changes, names, f"Earlier outputs: {'; '.join(changes)}." if changes else None


def _with_replaced_outputs(scenario, warning: str | None) -> str | None:
    """``warning`` and then the outputs replaced since their run wrote them, if any."""
    from ladartui.run_record import outputs_changed

    try:
        replaced = [visible(change) for change in outputs_changed(scenario)]
    except LadarError as error:
        replaced = [visible(f"outputs of the earlier run not read: {error}")]
    if not replaced:
        return warning
    said = f"Earlier outputs: {'; '.join(replaced)}."
    return said if warning is None else f"{warning} {said}"


def _target_output(scenario) -> np.ndarray | None:
    """The earlier run's target output (it marks the target voxels the foliage hid in
    the output view), or None when it cannot be read: the view then marks none."""
    from ladartui.scene.voxels import load_voxels

    try:
        return load_voxels(scenario.target_output)
    except (OSError, LadarError):
        return None


def _warm_up(scenario, scene, compile_in_child: bool, cancel) -> None:
    from ladartui.precompile import HALVES, compile_ahead, compile_half

    if compile_in_child:
        compile_ahead(scenario, stop=cancel)
    for half in HALVES:  # loaded from the cache the children filled
        if cancel.is_set():
            return
        try:
            compile_half(half, scenario, scene, cancel=cancel)
        except Exception:  # a warm-up only; the real run reports any problem
            pass


def _existing_results(scenario, files: OutputFiles):
    """The scene output and measures of an earlier run, if both are on disk."""
    if not files.readable:
        return None, None
    from ladartui.cmf import read_cmf
    from ladartui.scene.voxels import load_voxels

    return load_voxels(scenario.scene_output), read_cmf(scenario.measures_file)


def outputs_on_disk(scenario) -> tuple[int, int] | None:
    """When and how large the measures file is (a run replaces it with the rest of its
    set), or None when there is none: what tells another run's outputs apart."""
    return _stamp(_file_status(scenario.measures_file))


def look_at_outputs(scenario) -> OutputFiles:
    """One ``stat`` of each output file of ``scenario``."""
    return outputs_with(scenario, _file_status(scenario.measures_file))


def outputs_with(scenario, measures: os.stat_result | None) -> OutputFiles:
    """The look at ``scenario``'s outputs, the measures file's status already taken."""
    from ladartui.simulation import swap_interrupted

    found = {
        scenario.scene_output: _file_status(scenario.scene_output),
        scenario.target_output: _file_status(scenario.target_output),
        scenario.measures_file: measures,
    }
    if swap_interrupted(scenario):
        return OutputFiles(readable=False, missing=[], seen=_stamp(measures), interrupted=True)
    is_file = {path: status is not None and stat.S_ISREG(status.st_mode) for path, status in found.items()}
    blocked = next(
        (
            f"output {path.name} {not_a_file(folder=stat.S_ISDIR(status.st_mode))}"
            for path, status in found.items()
            if status is not None and not is_file[path]
        ),
        None,
    )
    return OutputFiles(
        readable=is_file[scenario.scene_output] and is_file[scenario.measures_file],
        missing=missing_outputs(scenario, is_file.__getitem__),
        seen=_stamp(measures),
        blocked=blocked,
    )


def _file_status(path: Path) -> os.stat_result | None:
    try:
        return path.stat()
    except (OSError, ValueError):  # ValueError: a name Path.is_file also takes as no file
        return None


def _stamp(status: os.stat_result | None) -> tuple[int, int] | None:
    return None if status is None else (status.st_mtime_ns, status.st_size)
