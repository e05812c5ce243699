"""New, Open, Save, Save As, the recent list and the screenshot, as the app runs them.

Every action that would replace the scenario asks first when there are
unsaved edits (``confirm_discard``); a save first commits what is typed in
the fields (``commit_pending``), so what is written is what is on screen.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ladartui.atomic import unused_path, write_text_atomic
from ladartui.errors import LadarError, os_reason
from ladartui.recent import remember_scenario
from ladartui.tui import bridge
from ladartui.tui.file_dialogs import SaveAsScreen, SetupScreen
from ladartui.tui.host import Host


class FileActions(Host):
    """Mixed into ``LadarApp``, which provides the scenario model, ``load`` and ``tell``."""

    def _folder(self) -> Path:
        return self.scenario.path.parent if self.scenario else self.cwd

    def deliver_screenshot(
        self, filename: str | None = None, path: str | None = None, time_format: str | None = None
    ) -> str | None:
        """The palette's Screenshot (and the screenshot action), beside the scenario as a
        saved view is: Textual's own goes to ~/Downloads, which a server reached over SSH
        seldom has, and fails there without a reason."""
        if self.is_web:  # served in a browser: Textual hands the file to it
            return super().deliver_screenshot(filename, path, time_format)
        stem = self.scenario.path.stem if self.scenario else "ladartui"
        target = Path(path) if path else self._folder()
        target /= filename or f"{stem}-screen.svg"
        if not filename:  # beside an earlier picture, never over it
            target = unused_path(target)
        try:
            write_text_atomic(target, self.export_screenshot())
        except OSError as error:
            self.tell(f"Screenshot not saved: {target}: {os_reason(error)}", severity="error")
        else:
            self.tell(f"Wrote {target}")
        return None

    def action_new_scenario(self) -> None:
        self._setup("new")

    def action_open_scenario(self) -> None:
        self._setup("load")

    def _setup(self, mode: str) -> None:
        if self.busy:
            return
        self.confirm_discard(
            "open another scenario" if mode == "load" else "start a new one", lambda: self._open_setup(mode)
        )

    def _open_setup(
        self, mode: str, folder: Path | None = None, typed=None, said: str = "", focus: str | None = None
    ) -> None:
        current = self.scenario.path if self.scenario is not None else None
        setup = SetupScreen(mode, folder or self._folder(), current, typed, said, focus)

        def done(scenario):
            if scenario is not None:
                self.result = None
                # New's form comes back as typed should its scene prove unreadable
                new = setup.mode == "new"
                self.new_pending = (setup.folder, setup.typed, scenario.path) if new else None
                self.load(None, scenario=scenario, new=setup.mode == "new")

        self.push_screen(setup, done)

    def new_refused(self, error: str, error_path: str | None = None) -> None:
        """A new scenario whose scene could not be read (nothing was written): its form
        again, as it was typed, saying why (``error_path``: the file the error is about)."""
        if self.new_pending is not None:
            folder, typed, path = self.new_pending
            # the field to put right has the focus: the scenario file's, where it could not
            # be written, else the scene model's (a bad line, too large, its target model)
            field = "scenario-file" if error_path is not None and Path(error_path) == path else "scene-file"
            self._open_setup("new", folder, typed, error, field)

    def open_path(self, path: Path, before: Callable[[], None] | None = None) -> None:
        """Open a scenario file (recent list, best sweep path), asking about unsaved edits;
        ``before`` is called once the analyst goes on (not on Cancel)."""
        if self.busy:
            return

        def load():
            if before is not None:
                before()
            self.result = None
            self.load(path)

        self.confirm_discard(f"open {path.name}", load, opens=path)

    def action_open_recent(self, path: str) -> None:
        self.open_path(Path(path))

    def action_save(self) -> None:
        if self.scenario is None or self.busy or not self.commit_pending():
            return
        self._save_to(None)

    def save_before_leaving(self) -> None:
        """Save, as asked when leaving with unsaved edits: also while a run goes on, which
        quitting cancels (opening and New are refused while busy before they ask)."""
        if self.scenario is not None and self.commit_pending():
            self._save_to(None)

    def action_save_as(self) -> None:
        if self.scenario is None or self.busy or not self.commit_pending():
            return

        def chosen(path):
            if path is not None:
                self._save_to(path)

        scenario = self.scenario
        self.push_screen(
            SaveAsScreen(scenario.path, lambda path: bridge.save_as_refusal(scenario, path)), chosen
        )

    def _save_to(self, path: Path | None) -> bool:
        """Write the scenario (to ``path`` for Save As); True when written."""
        history = self.history
        if history is None:  # no scenario: nothing to write
            return False
        renamed = path is not None and Path(path) != history.current.path
        try:
            saved = history.current.save(path)
        except (LadarError, OSError) as error:
            self.tell(str(error), title="Not saved", severity="error")
            return False
        if renamed:
            history.reset(saved)  # undo must not bring back the old file name
            self.result = None
            self.output_voxels = None  # the outputs of the old name are not this file's
            self.disk_outputs = (None, None)
            self.outputs_from = None
            self.inputs_changed = []
            self.changed_since_opened = []
            self.show_output()
            self.show_measures(None)
            self.run_panel.say("")  # the last run, if any, was the old file's
            self.show_outputs_of(saved)  # those of the new name, if it has any
        else:
            history.mark_saved(saved)
        self.scenario = saved
        self.note_scenario_saved()  # what is on disk now is this app's
        remember_scenario(saved.path)
        self.scenario_changed()
        self.file_panel.show_recent(saved.path)
        self.tell(f"Saved {saved.path}")
        return True
