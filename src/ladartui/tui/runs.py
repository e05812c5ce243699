"""Running the scenario from the app: the run job, its progress and its cancellation.

The run is a job (``tui/work.py``) that fuses each scan's returns as they
land, so the interface thread only draws; progress messages replace each
other, and the live output is redrawn twice a second. It waits for the
warm-up job to finish compiling the kernels first, without holding the
interpreter lock.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from textual.widgets import TabbedContent

from ladartui.errors import Cancelled
from ladartui.textsafe import single_line
from ladartui.tui.host import Host
from ladartui.tui.loading import look_at_outputs
from ladartui.tui.measures_screens import MeasuresScreen
from ladartui.tui.plain_text import literal
from ladartui.tui.status import format_eta
from ladartui.tui.work import running, start_job

if TYPE_CHECKING:
    from ladartui.simulation import SimulationResult

LIVE_POINTS = 20_000  # fewer while a run is going, so redraws stay cheap
LIVE_INTERVAL = 0.5  # seconds between progressive redraws of the output view
WARM_POLL = 0.1  # seconds between looks at the warm-up while waiting for it
ETA_AFTER_SCANS = 2  # the time left is shown once this many scans have given a pace


class RunControl(Host):
    """The app's Run and Cancel (mixed into ``LadarApp``)."""

    def action_run(self) -> None:
        if self.busy or self.scenario is None:
            return
        if not self.commit_pending():
            return
        problems = self.problems()
        if problems:
            self.tell("; ".join(problems), title="Not ready", severity="warning")
            return
        self.running = True
        # shown again if the run ends without outputs (its live output replaces them)
        self.shown_before_run = (self.output_voxels, self.disk_outputs)
        self.set_busy("Starting the run...", 0.0)
        self._run_worker(self.scenario, self.scene, self.scenario.fast_mode)

    def blind_note(self) -> str | None:
        """The first of validate's notes on scans that see nothing of the scene or of a
        target: found in a thread for each path, sensor, speed and target names (what the
        notes read; an edit of another field keeps the note) and scene (a 10,000-scan path
        takes a second on two busy cores), None until then; the bar is redrawn once it is."""
        scenario, scene = self.scenario, self.scene
        if scenario is None or scene is None:
            return None
        reach = _reach_inputs(scenario)
        kept = self.blind_kept
        if kept is None or kept[0] != reach or kept[1] is not scene:
            self.blind_kept = (reach, scene, None)
            self.run_worker(
                lambda: self._find_blind(scenario, reach, scene),
                group="reach",
                thread=True,
                exclusive=True,
                exit_on_error=False,
            )
            return None
        return kept[2]

    def _find_blind(self, scenario, reach, scene) -> None:
        from ladartui.view_reach import reach_notes

        notes = reach_notes(scenario, scene, partial=False)
        self.call_from_thread(self._blind_found, reach, scene, notes[0] if notes else None)

    def _blind_found(self, reach, scene, note: str | None) -> None:
        kept = self.blind_kept
        if note and kept is not None and kept[0] == reach and kept[1] is scene:
            self.blind_kept = (reach, scene, note)
            self.refresh_status()

    def _run_worker(self, scenario, scene, fast: bool) -> None:
        warm = self.warm_worker
        self.run_worker_handle = start_job(
            self, "run", lambda cancel, progress: _run(scenario, scene, fast, warm, cancel, progress)
        )

    def run_progressed(self, fraction, text: str, live) -> None:
        if self.busy is None:
            return
        self.set_busy(text + " (Esc cancels)", fraction)
        if live is not None:
            self.output_voxels = live
            self.disk_outputs = (None, None)  # the live output is no earlier run's
            self.show_output(limit=LIVE_POINTS)

    def action_cancel_run(self) -> None:
        worker = self.run_worker_handle
        if self.run_in_progress() and worker is not None:
            worker.cancel()
            self.set_busy("Cancelling: earlier outputs stay as they were...", self.progress)

    def stop_on_signals(self) -> None:
        """SIGTERM (``kill PID`` from another login, ``timeout``) killed the app where it
        stood, the terminal left on the alternate screen, mouse reports on and nothing
        echoed, and SIGHUP (an SSH connection dropping) cut a run's swap short: each now
        cancels a run (the earlier outputs stay; a swap under way finishes) and leaves
        as Quit does, giving the terminal back, status 128 + the signal. A signal
        ignored at start (``nohup``) stays ignored."""
        import asyncio
        import contextlib

        from ladartui.stop_signals import stop_signals_to_catch

        with contextlib.suppress(NotImplementedError, RuntimeError, ValueError):  # not the main thread
            loop = asyncio.get_running_loop()
            for number in stop_signals_to_catch():  # nohup's ignore kept
                loop.add_signal_handler(number, self._terminated, int(number))

    def _terminated(self, number: int) -> None:
        self.action_cancel_run()
        self.exit(return_code=128 + number)

    def on_unmount(self) -> None:
        import asyncio
        import contextlib

        from ladartui.stop_signals import STOP_SIGNALS

        with contextlib.suppress(NotImplementedError, RuntimeError, ValueError):
            for number in STOP_SIGNALS:
                asyncio.get_running_loop().remove_signal_handler(number)

    def action_help_quit(self) -> None:
        """Ctrl+C: a terminal app's copy, which Textual follows with how to quit. During
        a run, the reflex to stop it, it says how to cancel the run as well; so on a study's
        or sweep's screen while it works (its Ctrl+X cancels it)."""
        work = getattr(self.screen, "work_going_on", lambda: None)()
        if work:
            self.tell(f"Ctrl+C does not stop the {work}: Ctrl+X cancels it; Ctrl+Q quits.")
            return
        if not self.run_in_progress():
            super().action_help_quit()
            return
        cancel = self.key_says("cancel", "cancels it")
        self.tell("Ctrl+C does not stop the run" + (f": {cancel}" if cancel else "") + "; Ctrl+Q quits.")

    def run_finished(
        self, result: SimulationResult | None = None, cancelled: bool = False, error: str | None = None
    ) -> None:
        self.running = False
        self.set_busy(None)
        shown_before, self.shown_before_run = self.shown_before_run, (None, None)
        if cancelled or error or result is None:
            # nothing was written: the outputs shown before the run, not its partial live one
            self.output_voxels, self.disk_outputs = shown_before
            self.show_output()
            if self.outputs_interrupted and self.scenario is not None:  # it put the earlier set back
                self.show_outputs_of(self.scenario)
        if cancelled:
            self.tell("Run cancelled; earlier outputs are unchanged.", severity="warning")
            self.run_panel.say("Last run cancelled; nothing was written.")
            return
        if error or result is None:
            self.run_panel.say(error or "Run failed: no result.")
            if self.scenario is not None:  # refused for an output's name a folder took since?
                self.output_blocked = look_at_outputs(self.scenario).blocked
                self.refresh_status()
            return
        self.result = result
        self.missing_outputs, self.outputs_interrupted = [], False  # (it put the earlier set back first)
        self.outputs_from = self.scenario  # (not editable while the run went on)
        # read as the app holds them: a model changed on disk since it was opened still is
        self.inputs_changed = list(self.changed_since_opened)
        self.note_outputs_seen()  # this run's own: not another's
        self.output_voxels = result.scene_output
        self.disk_outputs = (None, None)
        self.show_output()
        self.show_measures(result.measures)
        total = result.timings.get("total") if isinstance(result.timings, dict) else None
        scenario = self.scenario
        names = [Path(path).name for path in result.outputs.values()]
        wrote = f"; wrote {', '.join(names)}" if names else ""
        self.run_panel.say(f"Last run: {result.backend}" + (f", {total:.1f} s" if total else "") + wrote)
        self.file_panel.show(scenario, self.scene, self.modified)
        self.refresh_status()
        self.query_one("#tabs", TabbedContent).active = "tab-results"
        name = scenario.name if scenario is not None else ""
        self.push_screen(
            MeasuresScreen(result.measures, f"Comparison measures: {literal(single_line(name))}")
        )


def _reach_inputs(scenario) -> tuple:
    """What ``view_reach.reach_notes`` reads of ``scenario``, compared with ==: a flight
    log's segment is equal to one of the same file whose contents changed since, so the
    contents read are in it too."""
    flight = scenario.flight
    logs = tuple(segment.log.fingerprint for segment in flight.segments if segment.kind == "log")
    return (flight, logs, scenario.sensor, scenario.speed, scenario.target_names)


def _run(scenario, scene, fast: bool, warm, cancel, progress):
    """The run job (worker thread): wait for the kernels, simulate, fuse as scans land."""
    from ladartui.scene.keys import keys_to_voxels, voxel_keys
    from ladartui.simulation import simulate

    last_live = 0.0
    started = None  # when the first scan began: the pace excludes waiting for the kernels
    fused = np.empty(0, np.int64)  # sorted unique keys of the obscured returns so far
    pending: list[np.ndarray] = []

    def scanned(p) -> None:
        nonlocal last_live, fused, started
        if p.returns is not None and p.run == "scene" and not fast and len(p.returns):
            pending.append(voxel_keys(p.returns))
        live = None
        now = time.monotonic()
        if pending and now - last_live >= LIVE_INTERVAL:
            fused = np.union1d(fused, np.concatenate(pending))
            pending.clear()
            last_live = now
            live = keys_to_voxels(fused)
        run = "obscured (scene)" if p.run == "scene" else "unobscured (target)"
        text = f"Running {run}: scan {p.scan}/{p.scans}"
        if started is None:
            started = (now, p.fraction)
        elif p.scan >= ETA_AFTER_SCANS or p.run != "scene":
            done = p.fraction - started[1]
            if done > 0:  # at the pace since the first scan
                text += f", about {format_eta((now - started[0]) * (1 - p.fraction) / done)} left"
        progress(p.fraction, text, live)

    if running(warm):
        progress(0.0, "Compiling kernels (first run only)...")
        while running(warm):
            if cancel.is_set():
                raise Cancelled()
            time.sleep(WARM_POLL)
    return simulate(scenario, progress=scanned, cancel=cancel, scene=scene)
