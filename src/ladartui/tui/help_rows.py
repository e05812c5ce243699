"""What the help screen lists and the palette offers: every key in force (as the user's
keys.toml remaps them), the views', the dialogs' and the study and sweep screens', and
how the views are drawn."""

from __future__ import annotations

from textual.binding import Binding

from ladartui.tui import actions
from ladartui.tui.canvas import ProjectionWidget, TopViewWidget
from ladartui.tui.poses_screen import PosesScreen


def palette_entries(app=None) -> list[tuple[str, str, str]]:
    """The command palette's entries, with the keys in force in ``app``."""
    return actions.palette_entries(app.keymap if app is not None else None)


def help_rows(app=None) -> list[tuple[str, str, str]]:
    """The help screen's rows: the app's keys (as remapped), the views' and the dialogs',
    and how the views are drawn (``graphics`` in settings.toml forces it)."""
    rows = actions.help_rows(
        app.keymap if app is not None else None,
        ProjectionWidget.BINDINGS,
        PosesScreen.BINDINGS,
        TopViewWidget.BINDINGS,
    )
    from ladartui.tui.study_screen import StudyScreen  # (plotting: loaded for help, shown on demand)
    from ladartui.tui.sweep_screen import SweepScreen

    keymap = app.keymap if app is not None else None
    for where, screen in (("Study screen", StudyScreen), ("Sweep screen", SweepScreen)):
        rows.extend((where, _key_name(b, keymap), b.description) for b in _described(screen))
    if app is not None:
        rows.append(("Views", "settings.toml", "Drawn as " + app.graphics.describe()))
    return rows


def _described(screen) -> list[Binding]:
    return [b for b in screen.BINDINGS if isinstance(b, Binding) and b.description]


def _key_name(binding: Binding, keymap: dict[str, str] | None) -> str:
    """A screen's key as people write it: the user's for a binding with a command's id."""
    key = (keymap or {}).get(binding.id, binding.key) if binding.id else binding.key
    return actions.key_name(key)


def tool_screen_entries(screen) -> list[tuple[str, str, str]]:
    """The palette's entries on the study or sweep screen: (title, its key, action) for
    each of the screen's keys that acts now ("Sweep: Rank by", "F6", "objective")."""
    from ladartui.tui.study_screen import StudyScreen

    name = "Study" if isinstance(screen, StudyScreen) else "Sweep"
    return [
        (f"{name}: {b.description}", _key_name(b, getattr(screen.app, "keymap", None)), b.action)
        for b in _described(screen)
        if screen.check_action(b.action.split("(")[0], ())
    ]
