"""How buttons and messages name a command's key: always the one in force, as the
user's keys.toml may remap it (``actions.keys_in_force``), never "F5" written out."""

from __future__ import annotations

from textual import events
from textual.errors import NoWidget
from textual.widgets._footer import FooterKey

from ladartui.tui import actions
from ladartui.tui.host import Host


class KeyWords(Host):
    """Mixed into ``LadarApp``, which provides ``keymap``."""

    def key_says(self, command_id: str, words: str) -> str:
        """The key in force and ``words``: ("run", "runs") gives F5 runs; empty when no key runs it."""
        key = actions.key_hint(command_id, self.keymap)
        return f"{key} {words}" if key else ""

    def button_text(self, label: str, command_id: str) -> str:
        """A button's label with the key in force: ("Save", "save") gives Save ^S."""
        key = actions.key_hint(command_id, self.keymap, short=True)
        return f"{label} {key}" if key else label

    def key_note(self, command_id: str) -> str:
        """ " (F5)" after the advice that names the command ("run the scenario first (F5)")."""
        return actions.key_note(command_id, self.keymap)

    def on_mouse_down(self, event: events.MouseDown) -> None:
        """A click on a dimmed key in the footer says why its command is off, as pressing
        the key does (``LadarApp.on_key``); the footer itself only rings the bell."""
        if len(self.screen_stack) > 1:  # a dialog or tool screen: its own footer
            return
        try:  # what is under the pointer (a terminal's click is addressed to no widget)
            key, _ = self.get_widget_at(*event.screen_offset)
        except NoWidget:
            return
        if isinstance(key, FooterKey) and key.has_class("-disabled"):
            self.tell_why_off(key.description or key.action, key.action)
