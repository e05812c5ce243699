"""Running the scenario from the app: the worker, its progress and its cancellation.

The run happens in a thread worker that fuses each scan's returns as they
land, so the interface thread only draws; progress messages are coalesced
to a few a second and the live output is redrawn twice a second.
"""

from __future__ import annotations

import threading
import time

import numpy as np
from textual import work
from textual.message import Message
from textual.widgets import TabbedContent

from ladartui.errors import Cancelled, LadarError
from ladartui.tui.screens import MeasuresScreen

LIVE_POINTS = 20_000  # fewer while a run is going, so redraws stay cheap
PROGRESS_INTERVAL = 0.1  # seconds between progress messages (at most ~10 a second)
LIVE_INTERVAL = 0.5  # seconds between progressive redraws of the output view


class RunProgressed(Message):
    """Coalesced run progress; ``live`` holds the fused obscured output so far, if redrawn."""

    def __init__(self, fraction: float, text: str, live=None):
        super().__init__()
        self.fraction, self.text, self.live = fraction, text, live


class RunFinished(Message):
    def __init__(self, result=None, cancelled=False, error: str | None = None):
        super().__init__()
        self.result, self.cancelled, self.error = result, cancelled, error


class RunControl:
    """The app's Run, Cancel and their messages (mixed into ``LadarApp``)."""

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
        if self.closing() or self.busy is None:
            return
        self.set_busy(message.text + " (Esc cancels)", message.fraction)
        if message.live is not None:
            self.output_voxels = message.live
            self.show_output(limit=LIVE_POINTS)

    def action_cancel_run(self) -> None:
        if self.run_in_progress():
            self.cancel_event.set()
            self.set_busy("Cancelling: earlier outputs stay as they were...", self.progress)

    def on_run_finished(self, message: RunFinished) -> None:
        if self.closing():
            return
        self.running = False
        self.set_busy(None)
        if message.cancelled:
            self.tell("Run cancelled; earlier outputs are unchanged.", severity="warning")
            self.run_panel.say("Last run cancelled; nothing was written.")
            self.output_voxels = self.result.scene_output if self.result else None
            self.show_output()
            return
        if message.error:
            self.tell(message.error, title="Run failed", severity="error", timeout=10)
            self.run_panel.say(message.error)
            return
        result = message.result
        self.result = result
        self.missing_outputs = []
        self.output_voxels = result.scene_output
        self.show_output()
        self.show_measures(result.measures)
        total = result.timings.get("total") if isinstance(result.timings, dict) else None
        self.run_panel.say(f"Last run: {result.backend}"
                           + (f", {total:.1f} s" if total else "")
                           + f"; wrote {self.scenario.measures_file.name}")
        self.file_panel.show(self.scenario, self.scene, self.modified)
        self.query_one("#tabs", TabbedContent).active = "tab-results"
        self.push_screen(MeasuresScreen(result.measures,
                                        f"Comparison measures: {self.scenario.name}"))
