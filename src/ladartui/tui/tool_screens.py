"""The study and sweep screens, opened over the main screen (F11, F12), and the sweep's
request to open its best flight path. One at a time: ``tool_screen`` is the one open."""

from __future__ import annotations

from textual.screen import Screen

from ladartui.tui.host import Host


class ToolScreens(Host):
    """Mixed into ``LadarApp``, which provides the scenario, ``tell`` and ``open_path``."""

    def action_study(self) -> None:
        """The speed-against-accuracy study of the open scenario (its saved file)."""
        if self.busy or self.tool_screen is not None:
            return
        from ladartui.tui.study_screen import StudyScreen  # plotting loads only when used

        if not self.commit_pending():
            return
        path = None
        if self.scenario is not None and self.scenario.path.is_file():
            path = self.scenario.path
            if self.modified or self.scenario_on_disk:  # edited here, or changed there since
                self.tell(
                    f"The study reads {path.name} as it is on disk, not as shown here; "
                    f"save{self.key_note('save')} first to study what is shown.",
                    severity="warning",
                    timeout=8,
                )
        self._open_tool(StudyScreen(scenario_path=path))

    def action_sweep(self) -> None:
        """Launch, open or watch flight-path sweeps."""
        if self.busy or self.tool_screen is not None:
            return
        from ladartui.tui.sweep_screen import SweepScreen  # Dask loads only when used

        self._open_tool(SweepScreen())

    def _open_tool(self, screen: Screen) -> None:
        def closed(_result) -> None:
            self.tool_screen = None
            self.refresh_bindings()

        self.tool_screen = screen
        self.push_screen(screen, closed)

    def on_sweep_screen_open_scenario(self, message) -> None:
        """The sweep's best flight path: open its scenario as F3 would (leaving the sweep
        screen unless a sweep is still running there)."""
        if self.run_in_progress():
            self.tell("A run is in progress; the best path was not opened.", severity="warning")
            return

        def leave_the_sweep() -> None:  # once unsaved edits are dealt with: Cancel stays
            screen = self.tool_screen
            if screen is not None and self.screen is screen and not getattr(screen, "running", False):
                screen.dismiss(None)
            else:
                self.tell(f"Opening {message.path.name}; Esc leaves the sweep screen to see it.")

        self.open_path(message.path, before=leave_the_sweep)
