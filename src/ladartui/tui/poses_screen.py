"""The manual poses editor: scan poses in a table, one row edited in the fields below.

A value that is not allowed stays in its field, marked, with the reason; Apply
and OK refuse until it is corrected, and OK applies the row being edited first.
"""

from __future__ import annotations

from textual import on
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Grid, Horizontal, Vertical
from textual.widgets import Button, DataTable, Input, Label, Static

from ladartui.errors import FieldError, LadarError
from ladartui.tui import bridge
from ladartui.tui.fields import NumberField, in_label_unit, refusal
from ladartui.tui.plain_text import PlainStatic
from ladartui.tui.screens import Dialog, field_matches


class PosesScreen(Dialog):
    """Manual scan poses in an editable table: pick a row, edit its fields, apply."""

    BINDINGS = [
        Binding("escape", "dismiss_dialog", "Close"),
        Binding("ctrl+n", "add_pose", "Add pose"),
        Binding("delete", "delete_pose", "Delete pose"),
    ]
    COLUMNS = ("x", "y", "z", "heading", "azimuth", "depression")
    # with their units, as the segment forms and the sidebar name them (limits in messages too)
    LABELS = {
        "x": "x m",
        "y": "y m",
        "z": "z m",
        "heading": bridge.FIELD_LABELS["heading"],
        "azimuth": bridge.FIELD_LABELS["azimuth"],
        "depression": bridge.FIELD_LABELS["depression"],
    }

    def __init__(self, poses, defaults, new: bool = False):
        """``new``: the poses of a segment not yet in the path (the title says so)."""
        super().__init__()
        self.poses = list(poses)
        self.defaults = defaults
        self.new = new
        self.shown_row = -1

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog") as box:
            box.border_title = "Manual scan poses" + (" (new)" if self.new else "")
            yield DataTable(id="poses-table", cursor_type="row", zebra_stripes=True)
            with Grid(id="pose-fields"):
                for name in self.COLUMNS:
                    yield Label(self.LABELS[name])
                for name in self.COLUMNS:
                    yield NumberField(
                        name,
                        None,
                        default=getattr(self.defaults, name),
                        check=self._checker(name),
                        id=f"p-{name}",
                    )
            yield PlainStatic("", id="poses-message", classes="message")
            with Horizontal(classes="buttons"):
                yield Button("Apply row", id="pose-apply", compact=True)
                yield Button("Add", id="pose-add", compact=True)
                yield Button("Delete", id="pose-delete", compact=True)
                yield Button("OK", id="poses-ok", variant="primary", compact=True)
                yield Button("Cancel", id="poses-cancel", compact=True)

    DEFAULT_CSS = """
    PosesScreen #poses-table { height: 10; }
    PosesScreen #pose-fields {
        grid-size: 6 2; height: 2; grid-gutter: 0 1;
        grid-columns: 1fr 1fr 1fr 14 14 14;  /* "Depression deg" whole at 80 columns */
    }
    PosesScreen .buttons Button { min-width: 0; width: auto; padding: 0 1; }
    """

    def on_mount(self) -> None:
        table = self.query_one(DataTable)
        table.add_columns("#", *(self.LABELS[name] for name in self.COLUMNS))
        self._fill()
        table.focus()

    def _fill(self, select: int | None = None) -> None:
        table = self.query_one(DataTable)
        table.clear()
        for i, pose in enumerate(self.poses):
            table.add_row(str(i + 1), *(f"{getattr(pose, c):.6g}" for c in self.COLUMNS))
        if self.poses:
            row = min(select if select is not None else 0, len(self.poses) - 1)
            table.move_cursor(row=row)
            self._show(row)

    def _show(self, row: int) -> None:
        if not 0 <= row < len(self.poses):
            return
        self.shown_row = row
        for name in self.COLUMNS:
            self.query_one(f"#p-{name}", NumberField).set_number(getattr(self.poses[row], name))

    def _checker(self, name):
        def check(value):
            values = {c: self._raw(c) for c in self.COLUMNS}
            values[name] = value
            try:
                bridge.make_pose(values)
            except FieldError as error:
                if field_matches(error.field, name):
                    raise

        return check

    def _raw(self, name):
        widget = self.query_one(f"#p-{name}", NumberField)
        try:
            return widget.number()
        except FieldError:
            return widget.default

    @on(DataTable.RowHighlighted)
    def _highlighted(self, event: DataTable.RowHighlighted) -> None:
        # a refill re-highlights the row already shown: keep what is being typed
        if event.cursor_row == self.shown_row:
            return
        if self._edited() and 0 <= self.shown_row < len(self.poses):
            # what was typed goes to the row it was typed for, or the choice waits
            if not self._apply(row=self.shown_row, select=event.cursor_row):
                self.query_one(DataTable).move_cursor(row=self.shown_row)
            return
        self._show(event.cursor_row)

    def on_input_blurred(self, event: Input.Blurred) -> None:
        if isinstance(event.input, NumberField):
            self._check(event.input)

    def _check(self, widget: NumberField) -> bool:
        """Say why a typed value is refused (the text stays, marked, for correcting)."""
        problem = widget.problem()
        if problem:
            widget.add_class("-bad")
            label = self.LABELS[widget.field_name]
            expected = in_label_unit(label, problem.split("expected ", 1)[-1])
            self.query_one("#poses-message", Static).update(refusal(label, widget.value, expected))
        return problem is None

    def _refused(self) -> bool:
        """True when a field's text is not allowed: said, and that field focused."""
        for name in self.COLUMNS:
            widget = self.query_one(f"#p-{name}", NumberField)
            if not self._check(widget):
                widget.focus()
                return True
        return False

    @on(Input.Changed)
    def _typing(self, event: Input.Changed) -> None:
        if isinstance(event.input, NumberField):
            event.input.set_class(event.input.problem() is not None, "-bad")
            if not any(self.query_one(f"#p-{name}").has_class("-bad") for name in self.COLUMNS):
                self.query_one("#poses-message", Static).update("")  # nothing left to say

    @on(Input.Submitted)
    @on(Button.Pressed, "#pose-apply")
    def _pressed_apply(self) -> None:
        self._apply()

    def _apply(self, row: int | None = None, select: int | None = None) -> bool:
        """The fields into ``row`` (default: the selected one; a new one when none is),
        then ``select`` shown (default: that row); False, with the reason said, when a
        field is not allowed."""
        if self._refused():
            return False
        message = self.query_one("#poses-message", Static)
        try:
            pose = bridge.make_pose({c: self._raw(c) for c in self.COLUMNS})
        except LadarError as error:
            message.update(str(error))
            return False
        row = self.query_one(DataTable).cursor_row if row is None else row
        if 0 <= row < len(self.poses):
            self.poses[row] = pose
        else:
            self.poses.append(pose)
            row = len(self.poses) - 1
        message.update("")
        self.shown_row = -1  # the fields are shown again from the rows
        self._fill(row if select is None else select)
        return True

    def _edited(self) -> bool:
        """Whether a field holds text not yet applied to its row."""
        return any(
            self.query_one(f"#p-{name}", NumberField).value
            != self.query_one(f"#p-{name}", NumberField).committed
            for name in self.COLUMNS
        )

    @on(Button.Pressed, "#pose-add")
    def action_add_pose(self) -> None:
        """A new last row, a copy of the selected one with what is typed applied."""
        rows = len(self.poses)
        if self._edited() and not self._apply():
            return
        if len(self.poses) > rows:
            return  # what was typed went in as a new row (there was none to apply it to)
        row = self.query_one(DataTable).cursor_row
        template = self.poses[row] if 0 <= row < len(self.poses) else self.defaults
        self.poses.append(template)
        self._fill(len(self.poses) - 1)

    @on(Button.Pressed, "#pose-delete")
    def action_delete_pose(self) -> None:
        row = self.query_one(DataTable).cursor_row
        if 0 <= row < len(self.poses):
            del self.poses[row]
            self._fill(row)

    @on(Button.Pressed, "#poses-ok")
    def _ok(self) -> None:
        # typed values are applied first, as Run and Save commit the main form's
        if self._edited() and not self._apply():
            return
        if not self.poses:  # stays open, as every dialog does while a value is not allowed
            self.query_one("#poses-message", Static).update(
                "A manual segment needs at least one pose: Add one, or Cancel."
            )
            return
        self.dismiss(list(self.poses))

    @on(Button.Pressed, "#poses-cancel")
    def _cancel(self) -> None:
        self.dismiss(None)
