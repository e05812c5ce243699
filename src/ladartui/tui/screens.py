"""Modal screens: the segment editor and other number forms (view angle, threshold,
image size) and help, and the base of the dialogs with a folder tree; the measures
and comparison dialogs are tui/measures_screens.py, the pose editor
tui/poses_screen.py, the file dialogs tui/file_dialogs.py."""

from __future__ import annotations

import os
import shlex
from collections.abc import Callable
from pathlib import Path

from rich.text import Text
from textual import on
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.suggester import Suggester
from textual.widget import Widget
from textual.widgets import Button, DataTable, Input, Label, Select, Static

from ladartui.errors import FieldError, LadarError
from ladartui.fileprobe import user_path
from ladartui.tui import bridge
from ladartui.tui.fields import NumberField, format_number, in_label_unit, parse_number, refusal
from ladartui.tui.file_tree import FileTree
from ladartui.tui.plain_text import PlainStatic


class PathSuggester(Suggester):
    """Completes the path being typed from what exists on disk.

    A relative path is read in ``base()``, the folder its dialog reads typed names
    in (the working folder by default); in a field of ``several`` paths the last
    word is completed.
    """

    def __init__(
        self, suffixes: tuple[str, ...] = (), base: Callable[[], Path] = Path.cwd, several: bool = False
    ):
        super().__init__(use_cache=False, case_sensitive=True)
        self.suffixes = suffixes
        self.base = base
        self.several = several

    async def get_suggestion(self, value: str) -> str | None:
        word = value[value.rfind(" ") + 1 :] if self.several else value
        if not word:
            return None
        folder_text, stem = os.path.split(word)  # "sub/" -> ("sub", ""); "." -> ("", ".")
        folder = user_path(folder_text or ".")
        try:
            names = sorted(
                p.name + ("/" if p.is_dir() else "")
                for p in (folder if folder.is_absolute() else self.base() / folder).iterdir()
                if p.name.startswith(stem) and not p.name.startswith(".")
            )
        except OSError:
            return None
        for name in names:
            if name.endswith("/") or not self.suffixes or name.endswith(self.suffixes):
                return value + name[len(stem) :]
        return None


class Dialog(ModalScreen):
    """A modal with a title, closed by Escape."""

    BINDINGS = [Binding("escape", "dismiss_dialog", "Close")]
    DEFAULT_CSS = """
    Dialog { align: center middle; }
    Dialog > .dialog { width: 76; max-width: 100%; height: auto; max-height: 100%;
                       border: thick $accent; background: $surface; padding: 0 1; }
    Dialog .row { height: 1; margin: 0 0; }
    Dialog .row Label { width: 18; }
    Dialog .row Input, Dialog .row Select { width: 1fr; }
    Dialog .buttons { height: 1; margin-top: 1; align-horizontal: right; }
    Dialog .buttons Button { margin-left: 2; }
    Dialog .message { color: $error; height: auto; }
    Dialog .info { color: $text-muted; height: auto; }
    """

    def action_dismiss_dialog(self) -> None:
        self.dismiss(None)


def _row(label: str, widget) -> Horizontal:
    return Horizontal(Label(label), widget, classes="row")


class TreeDialog(Dialog):
    """A dialog with a folder tree whose root can move up a folder.

    The dialog takes the screen's height (up to a limit) and the tree what the
    fields leave, so OK and Cancel stay visible on a 24-line terminal.
    """

    DEFAULT_CSS = """
    TreeDialog > .dialog { height: 100%; max-height: 34; }
    TreeDialog .tree-row { height: 1; }
    TreeDialog #tree-root { width: 1fr; margin: 0; color: $text-muted; }
    TreeDialog #tree-up { margin-left: 1; }
    """

    folder: Path

    def tree_rows(self, suffixes, toml_table: str | None = None) -> ComposeResult:
        with Horizontal(classes="tree-row"):
            yield PlainStatic("", id="tree-root")
            yield Button("Up a folder", id="tree-up", compact=True)
        yield FileTree(self.folder, suffixes, toml_table, id="tree")

    def on_mount(self) -> None:
        self._show_root()

    def _show_root(self) -> None:
        self.query_one("#tree-root", Static).update(f"Folder: {self.folder}")

    @on(Button.Pressed, "#tree-up")
    def _up(self) -> None:
        """The tree's root goes up a folder, and names typed are read there from now on
        (the Folder line names it): what the path fields hold is put in its terms."""
        old = self.base
        self.folder = self.folder.parent
        self.base = self.folder
        for field in self.query(Input):
            if isinstance(field.suggester, PathSuggester) and field.value.strip():
                field.value = self._rebased(field.value, old, field.suggester.several)
        self.query_one(FileTree).path = self.folder
        self._show_root()

    def _rebased(self, text: str, old: Path, several: bool) -> str:
        """``text`` (one path, or shell words) read in ``old``, as read in ``self.base``."""

        def moved(name: str) -> str:
            path = user_path(name)
            return name if path.is_absolute() or name.startswith("~") else self.relative(old / path)

        if not several:
            return moved(text.strip())
        try:
            words = shlex.split(text)
        except ValueError:  # an open quote: left as typed, and said on Enter
            return text
        return shlex.join(moved(word) for word in words)

    def path_suggester(self, suffixes: tuple[str, ...], several: bool = False) -> PathSuggester:
        """Completion read in the folder this dialog reads typed names in."""
        return PathSuggester(suffixes, lambda: self.base, several)

    def relative(self, path: Path) -> str:
        try:
            return str(path.relative_to(self.base))
        except ValueError:
            return str(path)

    base: Path


class FormScreen(Dialog):
    """A form of checked number fields and choices; dismisses with the built object.

    ``spec`` is a list of (name, label, kind, value, default) where kind is
    "int", "float", "optional", "point", "points", or a tuple of choices;
    ``build(values)`` makes the object (raising FieldError naming a field).
    """

    def __init__(self, title: str, spec, build, note: str = ""):
        super().__init__()
        self.title_text = title
        self.spec = spec
        self.build = build
        self.note = note
        self.cancelled = True
        self._left_for_refusal: Widget | None = None  # the field OK's refusal moved from

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog") as box:
            box.border_title = self.title_text
            with VerticalScroll(classes="form"):
                for name, label, kind, value, default in self.spec:
                    widget: Widget
                    if isinstance(kind, tuple):
                        widget = Select(
                            [(c, c) for c in kind],
                            value=value,
                            allow_blank=False,
                            id=f"f-{name}",
                            compact=True,
                        )
                    elif kind in ("int", "float", "optional"):
                        widget = NumberField(
                            name,
                            value,
                            default=default,
                            check=self._checker(name),
                            integer=kind == "int",
                            optional=kind == "optional",
                            id=f"f-{name}",
                        )
                    else:
                        widget = PointsField(name, value, kind, id=f"f-{name}")
                    yield _row(label, widget)
            if self.note:
                yield Static(self.note, classes="info")
            yield PlainStatic("", id="form-message", classes="message")
            with Horizontal(classes="buttons"):
                yield Button("OK", id="form-ok", variant="primary", compact=True)
                yield Button("Cancel", id="form-cancel", compact=True)

    # Anchored at the top, with two lines kept for the message: a message that grows or
    # shrinks moved the centred dialog a row, and a click meant for a field hit the next.
    DEFAULT_CSS = """
    FormScreen { align: center top; }
    FormScreen > .dialog { margin-top: 2; }
    FormScreen .form { height: auto; max-height: 16; }
    FormScreen #form-message { min-height: 2; }
    FormScreen .buttons { margin-top: 0; }  /* the message keeps two lines above them */
    """

    def on_mount(self) -> None:
        fields = self.query(".form Input, .form Select")
        if fields:
            fields.first().focus()
        # the values again, now that the checks can read every field: one that six digits
        # would round onto a refused value gets more
        for name, _label, kind, value, _default in self.spec:
            if kind in ("int", "float", "optional"):
                self.query_one(f"#f-{name}", NumberField).set_number(value)

    def _checker(self, name):
        def check(value):
            values = self.values(raw=True)
            values[name] = value
            try:
                self.build(values)
            except FieldError as error:
                if field_matches(error.field, name):
                    raise

        return check

    def values(self, raw=False) -> dict:
        out = {}
        for name, _label, kind, _value, default in self.spec:
            if isinstance(kind, tuple):
                out[name] = self.query_one(f"#f-{name}", Select).value
                continue
            widget = self.query_one(f"#f-{name}", Input)  # a NumberField or a PointsField
            try:  # text left as shown gives the value shown, not its six digits
                if isinstance(widget, NumberField):
                    out[name] = None if kind == "optional" and not widget.value.strip() else widget.number()
                else:
                    assert isinstance(widget, PointsField)
                    out[name] = widget.points()
            except FieldError:
                if not raw:
                    raise
                out[name] = default
        return out

    def on_input_blurred(self, event: Input.Blurred) -> None:
        if event.input is self._left_for_refusal:
            # OK named another field and focused it: this one stays marked (typing
            # marks it) without saying why over that refusal
            self._left_for_refusal = None
            return
        self._check(event.input)

    def _focus_refused(self, widget: Widget) -> None:
        """Focus the field a refusal names, the message staying that refusal."""
        if self.app.focused is not widget:
            self._left_for_refusal = self.app.focused
        widget.focus()

    def _label(self, name: str) -> str:
        return next((label for n, label, *_ in self.spec if n == name), name)

    def _check(self, widget) -> bool:
        """Say why a typed value is refused (the text stays, marked, for correcting)."""
        if isinstance(widget, NumberField):
            problem = widget.problem()
            if problem:
                self._refuse(widget, widget.field_name, problem.split("expected ", 1)[-1])
                return False
        return True

    def _refuse(self, widget, name: str, expected: str) -> None:
        """Mark ``widget`` and say that its text is not allowed, in the form's words (a
        limit in the unit its label ends with: "Radius m" ... "at most 1000000 m")."""
        widget.add_class("-bad")
        label = self._label(name)
        if expected.startswith("an integer"):  # the form's word for it, as in the sidebar
            expected = "a whole number" + expected.removeprefix("an integer")
        expected = in_label_unit(label, expected)
        self.query_one("#form-message", Static).update(refusal(label, widget.value, expected))

    @on(Input.Changed)
    def _typing(self, event: Input.Changed) -> None:
        widget = event.input
        if isinstance(widget, NumberField):
            widget.set_class(widget.problem() is not None, "-bad")
        elif isinstance(widget, PointsField) and widget.has_class("-bad"):  # marked by a refusal only
            try:
                widget.points()
                widget.remove_class("-bad")
            except FieldError:
                pass
        if not self.query(".form .-bad"):  # every refusal put right: nothing left to say
            self.query_one("#form-message", Static).update("")

    @on(Input.Submitted)
    @on(Button.Pressed, "#form-ok")
    def _ok(self, event=None) -> None:
        # nothing is replaced behind the analyst's back: an invalid field stops OK,
        # the topmost first, as the analyst reads the form
        for name, _label, kind, *_ in self.spec:
            if not self._typed_allowed(name, kind):
                return
        try:
            result = self.build(self.values())
        except LadarError as error:
            for name, *_ in self.spec:
                if isinstance(error, FieldError) and field_matches(error.field, name):
                    wrong = self.query_one(f"#f-{name}")
                    self._focus_refused(wrong)
                    if isinstance(wrong, Input):
                        self._refuse(wrong, name, error.expected)
                        return
            self.query_one("#form-message", Static).update(str(error))
            return
        self.cancelled = False
        self.dismiss(result)

    def _typed_allowed(self, name: str, kind) -> bool:
        """Whether the text of field ``name`` is allowed on its own; if not, it is
        focused and the form says why."""
        widget = self.query_one(f"#f-{name}")
        if isinstance(widget, NumberField):
            allowed = self._check(widget)
        elif isinstance(widget, PointsField):
            try:
                widget.points()
                allowed = True
            except FieldError as error:
                self._refuse(widget, name, error.expected)
                allowed = False
        else:
            return True
        if not allowed:
            self._focus_refused(widget)
        return allowed

    @on(Button.Pressed, "#form-cancel")
    def _cancel(self) -> None:
        self.dismiss(None)


def field_matches(field: str, name: str) -> bool:
    return field == name or field.endswith("." + name)


class PointsField(Input):
    """A point ("x, y, z") or a list of numbers, typed; ``points()`` reads it, text left
    as it was shown giving the value shown (not its six digits), as NumberField does."""

    def __init__(self, name: str, value, kind: str, **kwargs):
        text = _point_text(value)
        placeholder = "x, y, z (z 0 if left out)" if kind == "point" else "a, b, c"
        super().__init__(text, compact=True, placeholder=placeholder, **kwargs)
        self.field_name, self.kind, self._shown = name, kind, (value, text)

    def points(self):
        """The point or numbers typed (None when empty); FieldError naming the field."""
        if self.value == self._shown[1]:
            return self._shown[0]
        return _parse_points(self.field_name, self.value, self.kind)


def _point_text(value) -> str:
    if value is None:
        return ""
    return ", ".join(format_number(v) for v in value)


def _parse_points(name, text, kind):
    text = text.strip()
    if not text:
        return None
    joined = text.replace(";", ",")
    # "10 20" too: without a comma, spaces part the numbers
    parts = [p.strip() for p in joined.split(",")] if "," in joined else joined.split()
    if len(parts) > 1 and not parts[-1]:
        parts.pop()  # one trailing comma
    expected = "x, y, z in metres (z 0 if left out)" if kind == "point" else "numbers separated by commas"
    if not all(parts):
        raise FieldError(name, text, expected + ", none of them empty")
    try:
        numbers = tuple(parse_number(name, p) for p in parts)
    except FieldError:  # "10 x": the field's form, not "a number"
        raise FieldError(name, text, expected) from None
    if kind == "point" and len(numbers) not in (2, 3):
        raise FieldError(name, text, expected)
    if kind == "point" and len(numbers) == 2:
        numbers = numbers + (0.0,)
    return numbers


class AngleScreen(FormScreen):
    """Exact azimuth and elevation for the 3D views (report section 3.5)."""

    def __init__(self, azimuth: float, elevation: float):
        spec = [
            ("azimuth", "Azimuth (deg)", "float", azimuth, 210.0),
            ("elevation", "Elevation (deg)", "float", elevation, 30.0),
        ]
        super().__init__(
            "View angle",
            spec,
            bridge.view_angles,
            note="Azimuth: compass bearing the view is from; elevation -90..90 above the horizon.",
        )


class ThresholdScreen(FormScreen):
    """Height threshold for the output view (report section 3.5.2)."""

    def __init__(self, threshold: float | None):
        spec = [("threshold", "Max height m", "optional", threshold, None)]
        super().__init__(
            "Output height threshold",
            spec,
            bridge.threshold_value,
            note="The output is drawn up to this height; empty shows all.",
        )


class ImageSizeScreen(FormScreen):
    """The size of a view saved as PNG."""

    def __init__(self, view_name: str, width: int = 1200, height: int = 800):
        spec = [("width", "Width px", "int", width, width), ("height", "Height px", "int", height, height)]
        super().__init__(
            f"Save {view_name} as PNG",
            spec,
            bridge.image_size,
            note="The view is drawn again at this size, with the same framing.",
        )


class HelpScreen(Dialog):
    """Every key of the app, its views and its dialogs."""

    DEFAULT_CSS = """
    HelpScreen > .dialog { width: 100%; max-width: 110; height: 100%; }
    HelpScreen DataTable { height: 1fr; }
    """

    def __init__(self, rows: list[tuple[str, str, str]]):
        super().__init__()
        self.rows = rows
        self._filled_width = -1

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog") as box:
            box.border_title = "Keys (Escape closes; Ctrl+P finds any action)"
            yield DataTable(cursor_type="row", zebra_stripes=True)

    def on_mount(self) -> None:
        self.query_one(DataTable).focus()

    def on_resize(self) -> None:
        table = self.query_one(DataTable)
        width = table.scrollable_content_region.width
        if width > 0 and width != self._filled_width:
            self._fill(table, width)

    def _fill(self, table: DataTable, width: int) -> None:
        """The rows with the action column as wide as the rest of ``width`` leaves, its
        text wrapped there: nothing is cut off or needs scrolling sideways."""
        self._filled_width = width
        padding = 2 * table.cell_padding
        where = max(len("Where"), *(len(r[0]) for r in self.rows))
        key = max(len("Key"), *(len(r[1]) for r in self.rows))
        action = max(12, width - where - key - 3 * padding - table.styles.scrollbar_size_vertical)
        row = table.cursor_row
        table.clear(columns=True)
        table.add_column("Where", width=where)
        table.add_column("Key", width=key)
        table.add_column("Action", width=action)
        for place, keys, text in self.rows:
            table.add_row(Text(place), Text(keys), Text(text), height=None)
        table.move_cursor(row=row)
