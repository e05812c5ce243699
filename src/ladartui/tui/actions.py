"""The app's keys, the command palette's entries and the help screen's rows.

Kept in one place so that a key, its palette entry and its line in the help
screen are written once and cannot disagree with the actions they name.
"""

from __future__ import annotations

import functools

from textual.binding import Binding

from ladartui.tui import bridge
from ladartui.tui.canvas import ProjectionWidget
from ladartui.tui.view_area import LAYOUTS

BINDINGS = [
    Binding("f1", "help", "Help"),
    Binding("question_mark", "help", "Help", show=False),
    Binding("f2", "new_scenario", "New"),
    Binding("f3", "open_scenario", "Open"),
    Binding("ctrl+s", "save", "Save"),
    Binding("ctrl+shift+s", "save_as", "Save as", show=False),
    Binding("ctrl+z", "undo", "Undo", show=False),
    Binding("ctrl+y", "redo", "Redo", show=False),
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

# actions that only change what is displayed: allowed while busy
DISPLAY_ACTIONS = {"help", "layout", "next_layout", "toggle_panel", "view_angle",
                   "threshold", "quit", "command_palette", "show_tab", "cancel_run"}


def palette_entries() -> list[tuple[str, str, str]]:
    """(title, help, action) for every action, as offered in the command palette."""
    entries = [
        ("Help: keys", "List every key (F1)", "help"),
        ("New scenario", "Choose a scenario file and a scene model (F2)", "new_scenario"),
        ("Open scenario", "Load a scenario; every file is checked (F3)", "open_scenario"),
        ("Save scenario", "Write the scenario file (Ctrl+S)", "save"),
        ("Save scenario as", "Write the scenario under another name (Ctrl+Shift+S)",
         "save_as"),
        ("Undo", "Undo the last change to the scenario (Ctrl+Z)", "undo"),
        ("Redo", "Apply the last undone change again (Ctrl+Y)", "redo"),
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
    from ladartui.recent import recent_scenarios

    for path in recent_scenarios():
        entries.append((f"Open recent: {path.name}", str(path), f"open_recent({str(path)!r})"))
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
    """Names of the actions the main app defines (its keys and its palette entries)."""
    keys = [binding.action for binding in BINDINGS]
    fixed = [a for _, _, a in palette_entries() if not a.startswith("open_recent")]
    return frozenset(action.split("(")[0] for action in keys + fixed + ["open_recent"])


def help_rows(dialog_bindings=()) -> list[tuple[str, str, str]]:
    """(where, key, what) for the help screen; ``dialog_bindings`` are the poses dialog's."""
    rows = [("Anywhere", key_name(b.key), b.description) for b in BINDINGS]
    rows.append(("Anywhere", "Ctrl+P", "Command palette: every action by name"))
    rows.append(("Anywhere", "Ctrl+Q", "Quit (asks first when there are unsaved edits)"))
    rows.append(("Anywhere", "Tab / Shift+Tab", "Move between controls"))
    for binding in ProjectionWidget.BINDINGS:
        rows.append(("3D view", key_name(binding.key), binding.description))
    rows.append(("3D view", "mouse drag / wheel", "Rotate / zoom"))
    rows.append(("Fields", "Enter or leave", "Check the value; an invalid one goes back "
                 "to the scenario's value"))
    rows.append(("Segments table", "Enter", "Edit the segment"))
    rows.append(("Recent list", "Enter", "Open the scenario"))
    for binding in dialog_bindings:
        rows.append(("Poses dialog", key_name(binding.key), binding.description))
    rows.append(("Dialogs", "Escape", "Close without changes"))
    return rows


def key_name(key: str) -> str:
    """How a key is written for people: F5, Ctrl+S, ?, +."""
    names = {"question_mark": "?", "equals_sign": "=", "plus": "+", "minus": "-",
             "escape": "Esc", "left": "Left", "right": "Right", "up": "Up", "down": "Down",
             "delete": "Delete"}

    def one(k: str) -> str:
        if k in names:
            return names[k]
        if k.startswith("ctrl+shift+"):
            return "Ctrl+Shift+" + one(k[11:]).upper()
        if k.startswith("ctrl+"):
            return "Ctrl+" + one(k[5:]).upper()
        if k.startswith("f") and k[1:].isdigit():
            return k.upper()
        return k

    return " / ".join(one(k) for k in key.split(","))
