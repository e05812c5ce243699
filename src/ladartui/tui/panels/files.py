"""The File tab: what the scenario reads and writes, New / Open / Save / Save As, and
the scenarios opened lately."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from rich.text import Text
from textual import on
from textual.containers import Grid, VerticalScroll
from textual.widgets import Button, Label, OptionList, Static
from textual.widgets.option_list import Option

from ladartui.recent import recent_scenarios
from ladartui.textsafe import single_line
from ladartui.tui.host import host_of


class FilePanel(VerticalScroll):
    DEFAULT_CLASSES = "pane"

    def compose(self):
        yield Static("", id="file-info")
        button = host_of(self).button_text
        with Grid(classes="button-grid file-buttons"):
            yield Button(button("New", "new"), id="btn-new", compact=True)
            yield Button(button("Open", "open"), id="btn-open", compact=True)
            yield Button(button("Save", "save"), id="btn-save", compact=True)
            yield Button("Save as", id="btn-save-as", compact=True)
            yield Button(button("Undo", "undo"), id="btn-undo", compact=True)
            yield Button(button("Redo", "redo"), id="btn-redo", compact=True)
        yield Label("Recent scenarios (Enter opens)", classes="heading", id="recent-heading")
        yield OptionList(id="recent", compact=True)

    def on_mount(self) -> None:
        self.show_recent()

    def show(self, scenario, scene, modified: bool, missing: Sequence[Path] = ()) -> None:
        if scenario is None:
            host = host_of(self)
            keys = ", ".join(k for k in (host.key_says("new", "new"), host.key_says("open", "open")) if k)
            self.query_one("#file-info", Static).update(Text("No scenario" + (f": {keys}." if keys else ".")))
            return
        voxels = f"{len(scene.voxels):,} voxels" if scene is not None else ""
        target = f"{len(scene.target):,} voxels" if scene is not None else ""
        rows = [
            ("Scenario", scenario.path.name + (" (modified)" if modified else "")),
            ("Folder", shown_folder(scenario.path.parent)),
            ("Scene model", scenario.scene_file.name),
            ("", voxels),
            ("Target model", scenario.target_file.name),
            ("", target),
            ("Scene output", scenario.scene_output.name),
            ("Target output", scenario.target_output.name),
            ("Measures", scenario.measures_file.name),
            ("Run record", scenario.run_record.name),
        ]
        text = Text()
        for key, value in rows:
            if not value:
                continue
            if text:
                text.append("\n")
            text.append(f"{key:<14}", style="bold")
            text.append(single_line(value))  # names from files: plain text, controls written out
        if missing:
            host = host_of(self)  # the key in force, and only while a run would write them
            writes = "" if host.problems(fields=False) else host.key_says("run", "writes them")
            names = single_line(", ".join(p.name for p in missing))
            text.append(f"\nNot on disk yet: {names}" + (f" ({writes})" if writes else ""), style="yellow")
        self.query_one("#file-info", Static).update(text)

    def show_recent(self, current: Path | None = None) -> None:
        listing = self.query_one("#recent", OptionList)
        listing.clear_options()
        paths = [p for p in recent_scenarios() if p != current]
        for path in paths:
            shown = single_line(f"{path.name}  {shown_folder(path.parent)}")
            listing.add_option(Option(Text(shown), id=str(path)))
        listing.display = bool(paths)
        self.query_one("#recent-heading", Label).display = bool(paths)

    @on(OptionList.OptionSelected, "#recent")
    def _recent_chosen(self, event: OptionList.OptionSelected) -> None:
        event.stop()
        if event.option.id is not None:  # each recent entry's id is its path
            host_of(self).open_path(Path(event.option.id))

    @on(Button.Pressed, "#btn-new,#btn-open,#btn-save,#btn-save-as,#btn-undo,#btn-redo")
    async def _pressed(self, event: Button.Pressed) -> None:
        event.stop()
        action = {
            "btn-new": "new_scenario",
            "btn-open": "open_scenario",
            "btn-save": "save",
            "btn-save-as": "save_as",
            "btn-undo": "undo",
            "btn-redo": "redo",
        }
        await self.app.run_action(action[event.button.id or ""])


def shown_folder(folder: Path) -> str:
    """The folder relative to the working directory when inside it (shorter, and stable)."""
    try:
        relative = folder.relative_to(Path.cwd())
    except ValueError:
        return str(folder)
    return "./" + str(relative) if str(relative) != "." else "."
