"""One table of the app's commands: its keys, the footer, the palette and the help screen.

Every command is written once (``COMMANDS``): its binding id, the action it
runs, its default key, its footer label (if it has one) and its palette
title and help. The bindings, the palette entries and the help rows are all
drawn from that table with the keys in force, so remapping a key in the
user's ``keys.toml`` changes the footer, the palette and the help together:

    # ~/.config/ladartui/keys.toml  ($LADARTUI_HOME/config/keys.toml)
    [keys]
    run = "ctrl+r"        # binding id = key (or "key1,key2")
    threshold = "t"
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from textual.binding import Binding, BindingType

from ladartui.textsafe import one_line, single_line
from ladartui.toml_lines import read_config_table
from ladartui.tui import bridge
from ladartui.tui.canvas import ProjectionWidget, TopViewWidget
from ladartui.tui.view_area import LAYOUTS
from ladartui.user_data import config_folder

KEYS_FILE = "keys.toml"
# A key as Textual names it: modifiers, then one character or a name ("f9", "question_mark").
KEY_NAME = re.compile(r"((ctrl|shift|alt|meta|super|hyper)\+)*([a-z0-9_]+|[^\s,+\[\]])")


@dataclass(frozen=True)
class Command:
    id: str  # the binding id users remap
    action: str  # what it runs: "run", "layout(1)"
    key: str | None  # the default key; None for palette-only commands
    title: str  # the palette's title
    help: str  # the palette's help and the help screen's line
    footer: str | None = None  # the footer's label; None keeps it out of the footer


COMMANDS = [
    Command("help", "help", "f1,question_mark", "Help: keys", "List every key", "Help"),
    # New, Open and Save are on the File tab's buttons (with their keys), not in the
    # footer, so that F10-F12 fit an 80-column footer
    Command("new", "new_scenario", "f2", "New scenario", "Choose a scenario file and a scene model"),
    Command("open", "open_scenario", "f3", "Open scenario", "Load a scenario; its model files are checked"),
    Command("save", "save", "ctrl+s", "Save scenario", "Write the scenario file"),
    Command(
        "save-as", "save_as", "ctrl+shift+s", "Save scenario as", "Write the scenario under another name"
    ),
    Command("undo", "undo", "ctrl+z", "Undo", "Undo the last change to the scenario"),
    Command("redo", "redo", "ctrl+y", "Redo", "Apply the last undone change again"),
    Command("run", "run", "f5", "Run simulation", "Run the scenario", "Run"),
    # Ctrl+X as on the study and sweep screens, where Esc leaves the screen
    Command(
        "cancel", "cancel_run", "escape,ctrl+x", "Cancel run", "Stop the run; earlier outputs stay", "Cancel"
    ),
    Command("panel", "toggle_panel", "f4", "Toggle parameter panel", "Hide or show the sidebar"),
    Command("layout", "next_layout", "f6", "Next layout", "Cycle the five view layouts", "Layout"),
    Command("angle", "view_angle", "f7", "View angle", "Exact azimuth and elevation of the 3D views"),
    Command(
        "threshold", "threshold", "f8", "Output height threshold", "Draw the output up to a height", "Thresh"
    ),
    Command("measures", "measures", "f9", "Show measures", "The measures of the last run"),
    Command(
        "compare", "compare", "f10", "Compare scenarios", "Two or more .cmf files side by side", "Compare"
    ),
    Command(
        "study",
        "study",
        "f11",
        "Speed-against-accuracy study",
        "Every backend, method and ray grid on this scenario",
        "Study",
    ),
    Command(
        "sweep",
        "sweep",
        "f12",
        "Flight-path sweep",
        "Launch, open or watch a sweep; open its best path",
        "Sweep",
    ),
    Command(
        "zoom-target", "view('fit_target')", "z", "Zoom to target", "Frame the target in every view at once"
    ),
    Command("fit-scene", "view('fit_scene')", None, "Fit the scene", "Frame the whole scene"),
    Command(
        "fit-path",
        "view('fit_path')",
        None,
        "Fit the flight path",
        "Frame the scene and the whole flight path",
    ),
    Command(
        "output-colour",
        "view('cycle_output_colour')",
        None,
        "Output colouring",
        "Colour the output by class, by height, or by the scans that saw it",
    ),
    Command(
        "grey",
        "view('toggle_grey')",
        None,
        "Colour or grey shading",
        "Height in colour, or in the report's 56 greys",
    ),
    Command(
        "overlays",
        "view('cycle_overlays')",
        None,
        "Overlays",
        "All overlays, the path and scans only, or none",
    ),
    Command(
        "save-png",
        "save_png",
        None,
        "Save view as PNG",
        "The current view drawn again at a chosen size, beside the scenario",
    ),
    Command(
        "export-las",
        "export_las",
        None,
        "Export outputs as LAS",
        "Write the scene and target outputs as LAS point clouds beside them",
    ),
    Command(
        "aim-all", "aim_all", None, "Aim all scans at the target", "Point the sensor at the target centre"
    ),
    Command(
        "edit-segment", "edit_segment", None, "Edit selected segment", "Open the selected flight segment"
    ),
    Command(
        "delete-segment",
        "delete_segment",
        None,
        "Delete selected segment",
        "Remove the selected flight segment",
    ),
    Command("manual-poses", "manual_poses", None, "Manual scan poses", "Edit poses in a table"),
    *(
        Command(f"layout-{n}", f"layout({n})", str(n), f"Layout {n}: {name}", "Switch the views")
        for n, name in LAYOUTS.items()
    ),
    *(
        Command(
            f"add-{kind}",
            f"add_segment('{kind}')",
            None,
            f"Add {bridge.SEGMENT_LABELS[kind].lower()} segment",
            f"Append {bridge.with_article(bridge.SEGMENT_LABELS[kind].lower())} to the flight path",
        )
        for kind in ("straight", "turn", "orbit", "flypast", "standoff")
    ),
    *(
        Command(f"tab-{tab}", f"show_tab('{tab}')", None, f"Show {tab} panel", f"Open the {tab} tab")
        for tab in ("file", "sensor", "flight", "run", "results")
    ),
]
BY_ID = {command.id: command for command in COMMANDS}

# actions that only change what is displayed: allowed while busy
DISPLAY_ACTIONS = {
    "help",
    "layout",
    "next_layout",
    "toggle_panel",
    "view_angle",
    "threshold",
    "quit",
    "help_quit",  # Ctrl+C: how to cancel and quit (RunControl)
    "command_palette",
    "show_tab",
    "cancel_run",
    "view",
    "focus_next",  # Tab and Shift+Tab: the views stay reachable from the keyboard
    "focus_previous",
}


def bindings() -> list[BindingType]:
    """The app's key bindings, each with its command's id (so users can remap it)."""
    return [
        Binding(c.key, c.action, c.footer or c.title, show=c.footer is not None, id=c.id)
        for c in COMMANDS
        if c.key
    ]


BINDINGS = bindings()


def keymap_only_bindings(keymap: dict[str, str]) -> list[tuple[str, str, str]]:
    """(key, action, title) of each command with no default key that ``keymap`` gives one.

    Such a command has no entry in ``BINDINGS``, so a keymap alone cannot reach it.
    """
    return [(keymap[c.id], c.action, c.title) for c in COMMANDS if not c.key and c.id in keymap]


def keys_in_force(keymap: dict[str, str] | None = None) -> dict[str, str]:
    """Command id -> the keys that run it: the default, or the user's."""
    keymap = keymap or {}
    keys = {}
    for c in COMMANDS:
        key = keymap.get(c.id, c.key)
        if (c.key or c.id in keymap) and key is not None:
            keys[c.id] = key
    return keys


def palette_entries(keymap: dict[str, str] | None = None) -> list[tuple[str, str, str]]:
    """(title, help, action) for every command and every recent scenario."""
    keys = keys_in_force(keymap)
    entries = []
    for c in COMMANDS:
        key = keys.get(c.id)
        entries.append((c.title, f"{c.help} ({key_name(key)})" if key else c.help, c.action))
    from ladartui.recent import recent_scenarios

    for path in recent_scenarios():
        # a name's controls written out: one line each, and no escape reaches the terminal
        title, where = single_line(f"Open recent: {path.name}"), single_line(path)
        entries.append((title, where, f"open_recent({str(path)!r})"))
    return entries


def own_actions() -> frozenset[str]:
    """Names of the actions the main app defines (its commands, and opening a recent file)."""
    return frozenset({c.action.split("(")[0] for c in COMMANDS} | {"open_recent"})


def help_rows(
    keymap: dict[str, str] | None = None, view_bindings=(), dialog_bindings=(), top_bindings=()
) -> list[tuple[str, str, str]]:
    """(where, key, what) for the help screen, with the keys in force."""
    keys = keys_in_force(keymap)
    rows = [("Anywhere", key_name(keys[c.id]), c.title) for c in COMMANDS if keys.get(c.id)]
    rows.append(("Anywhere", "Ctrl+P", "Command palette: every action by name"))
    rows.append(("Anywhere", "Ctrl+Q", "Quit (asks first while a run goes on or edits are unsaved)"))
    rows.append(("Anywhere", "Tab / Shift+Tab", "Move between controls"))
    for binding in view_bindings:
        rows.append(("3D view", key_name(binding.key), binding.description))
    rows.append(("3D view", "mouse drag / wheel", "Rotate / zoom"))
    for binding in top_bindings:
        rows.append(("Top view", key_name(binding.key), binding.description))
    rows.append(("Top view", "mouse wheel", "Zoom about the pointer"))
    rows.append(
        ("Fields", "Enter or leave", "Check the value; an invalid one goes back to the scenario's value")
    )
    rows.append(("Segments table", "Enter", "Edit the segment"))
    rows.append(("Recent list", "Enter", "Open the scenario"))
    for binding in dialog_bindings:
        rows.append(("Poses dialog", key_name(binding.key), binding.description))
    rows.append(("Dialogs", "Escape", "Close without changes"))
    return rows


def _view_keys() -> dict[str, tuple[str, str]]:
    """Key -> (what it does in a 3D or top view, the app action doing the same in every
    view, or ""), the first view that has the key deciding."""
    keys: dict[str, tuple[str, str]] = {}
    for widget in (ProjectionWidget, TopViewWidget):
        for binding in widget.BINDINGS:
            if isinstance(binding, Binding):
                # the views' shared keys ask for view_request('X'); the palette's view('X')
                same = binding.action.replace("view_request(", "view(", 1)
                for key in binding.key.split(","):
                    keys.setdefault(
                        key.strip(), (binding.description, same if same != binding.action else "")
                    )
    return keys


# The views' own keys: a view with the focus takes them before the app's, so no
# command is remapped onto one (it would run everywhere but in the views), unless
# the command does what the view's key does.
VIEW_KEYS = _view_keys()

# Keys the app keeps for itself (Textual's quit, palette, focus and Ctrl+C): a command
# remapped onto one would take it from them (Ctrl+Q would run, and nothing would quit).
APP_KEYS = {
    "ctrl+q": "quits the app",
    "ctrl+p": "opens the command palette",
    "ctrl+c": "says how to quit (and copies selected text)",
    "tab": "moves to the next control",
    "shift+tab": "moves to the previous control",
    "ctrl+i": "is the terminal's Tab, which moves to the next control",
}


def load_keymap(folder: Path | None = None) -> tuple[dict[str, str], list[str]]:
    """The user's key remapping from ``keys.toml``, and one line per problem found.

    A missing file is no remapping; a damaged one, an unknown table or command
    id, a key that is not text, one the app keeps (``APP_KEYS``), one the views take
    (``VIEW_KEYS``), or one
    another command has, is reported (on its line) and left out, never fatal.
    """
    config = read_config_table((folder or config_folder()) / KEYS_FILE, "keys", "command id = key")
    table, problems, at = config.table, config.problems, config.at
    keymap = {}
    for command_id, key in table.items():
        where = at(f"keys.{command_id}")
        if command_id not in BY_ID:
            # only what the file says is cut: the ids to choose from are all told
            ids = ", ".join(sorted(BY_ID))
            problems.append(
                f"{one_line(f'{where}: keys.{command_id}')}: no such command; expected one of {ids}"
            )
        elif not isinstance(key, str) or not all(KEY_NAME.fullmatch(k.strip()) for k in key.split(",")):
            problems.append(
                one_line(
                    f'{where}: keys.{command_id} = {key!r}: expected a key name such as "f9" or "ctrl+r"'
                )
            )
        elif kept := [k for k in _bound_keys(key) if k in APP_KEYS]:
            problems.append(
                one_line(
                    f"{where}: keys.{command_id} = {key!r}: {key_name(kept[0])} {APP_KEYS[kept[0]]}; "
                    "choose another key"
                )
            )
        elif taken_by_views := [
            k for k in _bound_keys(key) if k in VIEW_KEYS and VIEW_KEYS[k][1] != BY_ID[command_id].action
        ]:
            # a focused view's own key wins over the app's: the command would not run there
            view_key = taken_by_views[0]
            problems.append(
                one_line(
                    f"{where}: keys.{command_id} = {key!r}: in the views {key_name(view_key)} is "
                    f"{VIEW_KEYS[view_key][0]}; choose another key"
                )
            )
        else:
            keymap[command_id] = key.strip()
    # In file order, again until none is left out: a remap refused puts its command's
    # default key back, which may be one a remap taken earlier uses.
    clashed = True
    while clashed:
        clashed = False
        for command_id in list(keymap):
            mine = _key_set(keymap[command_id])
            in_force = keys_in_force(keymap)
            taken = [c for c, keys in in_force.items() if c != command_id and mine & _key_set(keys)]
            if taken:
                key, clashed = keymap.pop(command_id), True
                problems.append(
                    one_line(
                        f"{at(f'keys.{command_id}')}: keys.{command_id} = {key!r}: also the key "
                        f"of {', '.join(taken)}; remap that too, or choose another"
                    )
                )
    return keymap, problems


def _bound_keys(keys: str) -> list[str]:
    """The keys of a binding, in order, as Textual binds them: "=" is equals_sign, "-" minus."""
    from textual.keys import _character_to_key  # (what Textual's own bindings do to a character)

    return [_character_to_key(key) if len(key) == 1 else key for key in (k.strip() for k in keys.split(","))]


def _key_set(keys: str) -> set[str]:
    return set(_bound_keys(keys))


def key_hint(command_id: str, keymap: dict[str, str] | None = None, short: bool = False) -> str:
    """The first key in force for a command as messages show it (F5, Ctrl+S), or
    ``short`` as buttons do (F5, ^S); empty when no key runs it."""
    key = keys_in_force(keymap).get(command_id, "").split(",")[0].strip()
    if short and key.startswith("ctrl+") and len(key) == 6:
        return "^" + key[5:].upper()
    return key_name(key) if key else ""


def key_note(command_id: str, keymap: dict[str, str] | None = None) -> str:
    """ " (F5)": the first key in force for a command, to follow the advice that names
    it ("run the scenario first (F5)"); empty when no key runs it."""
    key = key_hint(command_id, keymap)
    return f" ({key})" if key else ""


def key_name(key: str) -> str:
    """How a key is written for people: F5, Ctrl+S, ?, +."""
    names = {
        "question_mark": "?",
        "equals_sign": "=",
        "plus": "+",
        "minus": "-",
        "escape": "Esc",
        "left": "Left",
        "right": "Right",
        "up": "Up",
        "down": "Down",
        "delete": "Delete",
        "tab": "Tab",
        "shift+tab": "Shift+Tab",
    }

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

    return " / ".join(one(k.strip()) for k in key.split(","))
