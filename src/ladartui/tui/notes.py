"""Notes (toasts) never cover an open dialog: at 80 x 24 one sat over its OK and Cancel.

Notes on screen when a dialog (a modal screen) opens wait, for the time they had
left, and those told while one is open for their whole time, and show once the
analyst is back on a screen that is no dialog. Meanwhile what they said stays
where it matters: a refused field keeps its mark, the status bar its colour and
reason.
"""

from __future__ import annotations

from textual.notifications import Notification, Notifications, SeverityLevel
from textual.screen import ModalScreen, Screen
from textual.widgets._toast import ToastRack  # (the rack of each screen: no public name)

from ladartui.textsafe import single_line, visible
from ladartui.tui.host import Host


class NoteKeeping(Host):
    """Mixed into ``LadarApp``: its notes wait while a dialog is open."""

    notes_held: list[Notification]

    def keep_notes_off_dialogs(self) -> None:
        """Start holding notes while a dialog is open (the app calls it on mount)."""
        self.notes_held = []
        self.screen_change_signal.subscribe(self, self._screen_changed)

    def notify(
        self,
        message: str,
        *,
        title: str = "",
        severity: SeverityLevel = "information",
        timeout: float | None = None,
        markup: bool = True,
    ) -> None:
        seconds = self.NOTIFICATION_TIMEOUT if timeout is None else timeout
        if not markup:  # text from files and fields: its controls written out, its lines kept
            message, title = visible(message), single_line(title)
        if self._dialog_open():
            self.notes_held.append(Notification(message, title, severity, seconds, markup))
            return
        super().notify(message, title=title, severity=severity, timeout=seconds, markup=markup)

    def _dialog_open(self) -> bool:
        stack = self.screen_stack
        return bool(stack) and isinstance(stack[-1], ModalScreen)

    def _screen_changed(self, screen: Screen) -> None:
        if isinstance(screen, ModalScreen):
            # after the notes already posted, which would otherwise land on the dialog
            self.call_later(self._hold_notes_shown)
        else:
            self._show_notes_held()

    def _hold_notes_shown(self) -> None:
        if not self._dialog_open():
            return
        # a note shown a while is held for the time it had left, not shown anew each time
        left = [
            Notification(n.message, n.title, n.severity, n.time_left, n.markup)
            for n in self._notifications
            if not n.has_expired
        ]
        self.notes_held = left + self.notes_held
        self.clear_notifications()
        # the screens under the dialog keep drawing their toasts (Textual clears the top
        # one's only): behind a dialog near the top they showed, half covered
        for screen in self.screen_stack[:-1]:
            for rack in screen.query(ToastRack):
                rack.show(Notifications())

    def _show_notes_held(self) -> None:
        held, self.notes_held = self.notes_held, []
        for note in held:
            self.notify(
                note.message,
                title=note.title,
                severity=note.severity,
                timeout=note.timeout,
                markup=note.markup,
            )
