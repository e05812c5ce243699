"""Choosing files: the setup dialog (new or open), Save As, and the folder tree in both.

Every path can be typed (with completion from the disk) or picked in the
tree; picking a file fills the field that takes its kind (a scenario, a
scene model). The checks are the core's: a missing model or a name that
exists is refused with the file named.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, DirectoryTree, Input, RadioButton, RadioSet, Static

from ladartui.errors import FieldError, LadarError
from ladartui.fileprobe import user_path
from ladartui.textsafe import single_line
from ladartui.tui import bridge
from ladartui.tui.fields import NumberField, in_label_unit, refusal
from ladartui.tui.file_tree import SCENARIO_TABLE
from ladartui.tui.host import host_of
from ladartui.tui.plain_text import PathInput, PlainStatic
from ladartui.tui.screens import TreeDialog, _row

SCENARIO_SUFFIXES = (".toml",)
SCENE_SUFFIXES = (".txt",)  # voxel lists: a scenario reads no point cloud or mesh


class SetupScreen(TreeDialog):
    """File setup (report figure 9): a new scenario or an existing one.

    New: choose the scenario file and the scene model; the target model and the
    output names are derived and shown. Load: every file is checked; a missing
    model is named and nothing is loaded. Dismisses with the loaded Scenario.
    Load opens holding ``current`` (the open scenario), selected: Enter reopens it
    as it is on disk, typing replaces it. New opens holding ``typed`` (scenario file,
    scene model, voxel size) and ``said`` when a new scenario's scene could not be read,
    ``focus`` naming the field to put right.
    """

    prefilled_ids = ("scenario-file", "scene-file", "voxel-size")

    def __init__(
        self,
        mode: str = "new",
        folder: Path | None = None,
        current: Path | None = None,
        typed: tuple[str, ...] | None = None,
        said: str = "",
        focus: str | None = None,
    ):
        super().__init__()
        self.mode = mode
        self.current = current
        self.said = said
        self.focus_id = focus or "scenario-file"  # the field that opens with the focus
        # field id -> the text New's form comes back with; its Changed event clears nothing
        self.prefilled = dict(zip(self.prefilled_ids, typed or ()))
        self.typed: tuple[str, ...] = ()  # the fields as OK took them
        self.base = folder or Path.cwd()
        self.folder = self.base

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog", id="setup") as box:
            box.border_title = "Setup scenario"
            with RadioSet(id="mode"):
                yield RadioButton("New scenario", value=self.mode == "new", id="mode-new")
                yield RadioButton("Open scenario", value=self.mode == "load", id="mode-load")
            yield from self.tree_rows(SCENARIO_SUFFIXES + SCENE_SUFFIXES, SCENARIO_TABLE)
            yield _row(
                "Scenario file",
                PathInput(
                    self.prefilled.get("scenario-file", ""),
                    placeholder="name.toml",
                    id="scenario-file",
                    compact=True,
                    suggester=self.path_suggester(SCENARIO_SUFFIXES),
                ),
            )
            yield _row(
                "3D scene model",
                PathInput(
                    self.prefilled.get("scene-file", ""),
                    placeholder="scene.txt",
                    id="scene-file",
                    compact=True,
                    suggester=self.path_suggester(SCENE_SUFFIXES),
                ),
            )
            yield _row(
                "Voxel size m",
                NumberField(
                    "voxel size",
                    float(self.prefilled.get("voxel-size", 1.0)),
                    default=1.0,
                    check=bridge.check_voxel_size,
                    id="voxel-size",
                ),
            )
            yield PlainStatic("", id="derived", classes="info")
            yield PlainStatic("", id="setup-message", classes="message")
            with Horizontal(classes="buttons"):
                yield Button("OK", id="setup-ok", variant="primary", compact=True)
                yield Button("Cancel", id="setup-cancel", compact=True)

    def on_mount(self) -> None:
        super().on_mount()
        self._apply_mode()
        field = self.query_one("#scenario-file", Input)
        if self.mode == "load" and self.current is not None:
            field.value = self.relative(self.current)
        self.query_one("#setup-message", Static).update(self.said)
        self.query_one(f"#{self.focus_id}", Input).focus()

    @on(RadioSet.Changed, "#mode")
    def _mode_changed(self, event: RadioSet.Changed) -> None:
        self.mode = "new" if event.pressed.id == "mode-new" else "load"
        self.query_one("#setup-message", Static).update("")  # the other mode's error
        self._apply_mode()

    def _apply_mode(self) -> None:
        for name in ("#scene-file", "#voxel-size"):  # New's alone: Open hides them
            field = self.query_one(name, Input)
            field.disabled = self.mode != "new"
            if field.parent is not None:
                field.parent.display = self.mode == "new"
        self._show_derived()

    @on(DirectoryTree.FileSelected, "#tree")
    def _picked(self, event: DirectoryTree.FileSelected) -> None:
        event.stop()
        path = Path(event.path)
        if path.suffix.lower() in SCENARIO_SUFFIXES:
            self.query_one("#scenario-file", Input).value = self.relative(path)
        elif self.mode == "new":
            self.query_one("#scene-file", Input).value = self.relative(path)
        else:
            self.query_one("#setup-message", Static).update(
                f"{path.name} is a scene model: choose New scenario to make a scenario "
                "for it, or pick a .toml scenario"
            )

    @on(Input.Changed)
    def _typed(self, event: Input.Changed) -> None:
        # what the analyst types clears the message; the form's own filling does not
        if self.prefilled.get(event.input.id or "") == event.value:
            del self.prefilled[event.input.id or ""]
        else:
            self.query_one("#setup-message", Static).update("")
        if isinstance(event.input, NumberField):
            event.input.set_class(event.input.problem() is not None, "-bad")
        self._show_derived()

    def _paths(self):
        scenario = self.query_one("#scenario-file", Input).value.strip()
        scene = self.query_one("#scene-file", Input).value.strip()
        scenario_path = self.base / user_path(scenario) if scenario else None
        scene_path = self.base / user_path(scene) if scene else None
        return scenario_path, scene_path

    def _show_derived(self) -> None:
        scenario_path, scene_path = self._paths()
        if self.mode == "new":
            names = bridge.derived_names(scenario_path, scene_path)
            text = "\n".join(f"{label:<26}{single_line(value)}" for label, value in names)
        else:
            text = (
                "Every model file of the scenario is checked before anything is loaded; "
                f"missing outputs are listed, and a run{host_of(self).key_note('run')} writes them."
            )
        self.query_one("#derived", Static).update(text)

    @on(Input.Submitted)
    @on(Button.Pressed, "#setup-ok")
    def _ok(self, event=None) -> None:
        scenario_path, scene_path = self._paths()
        message = self.query_one("#setup-message", Static)
        try:
            if scenario_path is None:
                message.update(refusal("Scenario file", "", "a file name"))
                return
            if self.mode == "new":
                if scene_path is None:
                    message.update(refusal("3D scene model", "", "a scene model file (.txt)"))
                    return
                field = self.query_one("#voxel-size", NumberField)
                problem = field.problem()
                if problem:
                    field.focus()
                    expected = in_label_unit("Voxel size m", problem.split("expected ", 1)[-1])
                    message.update(refusal("Voxel size m", field.value, expected))
                    return
                scenario = bridge.new_scenario(scenario_path, scene_path, field.parsed())
            else:
                scenario = bridge.load_checked(scenario_path)
        except FieldError as error:
            message.update(self._field_said(error))
            return
        except LadarError as error:
            message.update(str(error))
            return
        # as typed, for the form to come back with should the scene prove unreadable
        self.typed = tuple(self.query_one(f"#{name}", Input).value for name in self.prefilled_ids)
        self.dismiss(scenario)

    def _field_said(self, error: FieldError) -> str:
        """A new scenario refused for its voxel size (its default flight cannot be flown)
        is said of the form's field; other fields are the scenario's own."""
        if error.field != "voxel_size":
            return str(error)
        return refusal("Voxel size m", self.query_one("#voxel-size", Input).value, error.expected)

    @on(Button.Pressed, "#setup-cancel")
    def _cancel(self) -> None:
        self.dismiss(None)


class SaveAsScreen(TreeDialog):
    """Choose a new file name for the scenario; dismisses with the path (not yet written).

    An existing file is refused unless the analyst confirms by pressing OK a
    second time with the same name.
    """

    def __init__(self, current: Path, name_refusal: Callable[[Path], str | None] | None = None):
        super().__init__()
        self.name_refusal = name_refusal  # why a name cannot take this scenario, or None
        self.base = current.parent
        self.folder = self.base
        self.current = current
        self.confirmed: Path | None = None

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog", id="save-as") as box:
            box.border_title = "Save scenario as"
            yield from self.tree_rows(SCENARIO_SUFFIXES, SCENARIO_TABLE)
            yield _row(
                "Scenario file",
                PathInput(
                    self.current.name,
                    id="save-as-file",
                    compact=True,
                    suggester=self.path_suggester(SCENARIO_SUFFIXES),
                ),
            )
            yield Static("Outputs are named after the scenario and sit beside it.", classes="info")
            yield PlainStatic("", id="save-as-message", classes="message")
            with Horizontal(classes="buttons"):
                yield Button("OK", id="save-as-ok", variant="primary", compact=True)
                yield Button("Cancel", id="save-as-cancel", compact=True)

    def on_mount(self) -> None:
        super().on_mount()
        self.query_one("#save-as-file", Input).focus()

    @on(DirectoryTree.FileSelected, "#tree")
    def _picked(self, event: DirectoryTree.FileSelected) -> None:
        event.stop()
        self.query_one("#save-as-file", Input).value = self.relative(Path(event.path))

    @on(Input.Changed, "#save-as-file")
    def _typed(self) -> None:
        self.query_one("#save-as-message", Static).update("")

    @on(Input.Submitted, "#save-as-file")
    @on(Button.Pressed, "#save-as-ok")
    def _ok(self) -> None:
        text = self.query_one("#save-as-file", Input).value.strip()
        message = self.query_one("#save-as-message", Static)
        if not text:
            message.update(refusal("Scenario file", "", "a file name"))
            return
        path = (self.base / user_path(text)).resolve()
        if path.is_dir():  # before ".toml" is added: a folder's name is not a file's
            message.update(f"{path}: is a folder; expected a scenario file name")
            return
        if path.suffix != ".toml":
            path = path.with_name(path.name + ".toml")
        if not path.parent.is_dir():
            message.update(f"{path.parent}: folder not found")
            return
        from ladartui.outputset import output_problem
        from ladartui.scenario import record_refusal

        problem = output_problem(path) or record_refusal(path)
        if problem:  # said here, where the name can be changed
            message.update(f"{path}: {problem}")
            return
        if self.name_refusal is not None and (refused := self.name_refusal(path)):
            message.update(refused)
            return
        if path.exists() and path != self.current.resolve() and self.confirmed != path:
            self.confirmed = path
            message.update(f"{path.name} exists: OK again replaces it")
            return
        self.dismiss(path)

    @on(Button.Pressed, "#save-as-cancel")
    def _cancel(self) -> None:
        self.dismiss(None)


class PickPathScreen(TreeDialog):
    """Pick a file (or, with ``folders``, a folder) in the tree or type it; dismisses with
    the path, or None."""

    def __init__(
        self, title: str, suffixes: tuple[str, ...], start: Path | None = None, folders: bool = False
    ):
        super().__init__()
        self.title_text = title
        self.suffixes = suffixes
        self.folders = folders
        self.base = start if start is not None and start.is_dir() else Path.cwd()
        self.folder = self.base

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog", id="pick") as box:
            box.border_title = self.title_text
            yield from self.tree_rows(self.suffixes)
            yield _row(
                "Path", PathInput(id="pick-path", compact=True, suggester=self.path_suggester(self.suffixes))
            )
            yield PlainStatic("", id="pick-message", classes="message")
            with Horizontal(classes="buttons"):
                yield Button("OK", id="pick-ok", variant="primary", compact=True)
                yield Button("Cancel", id="pick-cancel", compact=True)

    def on_mount(self) -> None:
        super().on_mount()
        self.query_one("#pick-path", Input).focus()

    @on(DirectoryTree.FileSelected, "#tree")
    def _file_picked(self, event: DirectoryTree.FileSelected) -> None:
        event.stop()
        self.query_one("#pick-path", Input).value = str(event.path)

    @on(DirectoryTree.DirectorySelected, "#tree")
    def _folder_picked(self, event: DirectoryTree.DirectorySelected) -> None:
        if self.folders:
            self.query_one("#pick-path", Input).value = str(event.path)

    @on(Input.Submitted, "#pick-path")
    @on(Button.Pressed, "#pick-ok")
    def _ok(self) -> None:
        text = self.query_one("#pick-path", Input).value.strip()
        path = (self.base / user_path(text)) if text else None
        message = self.query_one("#pick-message", Static)
        if path is None or not path.exists():
            message.update(f"{text or 'Path'}: not found; pick a file in the tree or type its path")
            return
        self.dismiss(path)

    @on(Button.Pressed, "#pick-cancel")
    def _cancel(self) -> None:
        self.dismiss(None)
