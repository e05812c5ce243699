"""The Flight tab: speed, the start pose, the segments of the path and the scans they make.

The start pose shapes the path only when the first segment is relative (a
straight or a turn); otherwise its fields are disabled, with a note, rather
than accepting values that change nothing.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from textual import on
from textual.containers import Grid
from textual.widgets import Button, DataTable, Label, Static

from ladartui.errors import LadarError
from ladartui.flight import Manual
from ladartui.tui import bridge
from ladartui.tui.fitted_tables import SEGMENT_COLUMNS, FittingTable, fill_segments, fill_whole_columns
from ladartui.tui.params import ParamPanel, field_id
from ladartui.tui.plain_text import PlainStatic
from ladartui.tui.poses_screen import PosesScreen
from ladartui.tui.screens import FormScreen

if TYPE_CHECKING:
    from ladartui.scenario import Scenario

SCAN_COLUMNS = ("#", "x", "y", "z", "hdg", "az", "dep")
# Kinds whose usual label is too wide for the segments table (the buttons use these words).
SHORT_KINDS = {"manual": "Poses", "log": "Log"}
ADD_BUTTONS = "#add-straight,#add-turn,#add-orbit,#add-flypast,#add-standoff"
START_UNUSED = "The path starts at its first segment: the start pose is not used."


# Rows the scans table lists: Textual measures every cell of a new row, and 9,000 rows
# held the screen still for seconds; the views show the whole path.
MOST_SCAN_ROWS = 1000


class FlightPanel(ParamPanel):
    def compose(self):
        for param in bridge.FLIGHT_PARAMS + bridge.START_PARAMS:
            yield self.param_row(param)
        yield PlainStatic("", id="start-note", classes="info")
        yield Label("Segments (Enter edits)", classes="heading")
        yield FittingTable(self.refit_tables, id="segments", cursor_type="row", zebra_stripes=True)
        with Grid(classes="button-grid"):
            yield Button("Straight", id="add-straight", compact=True)
            yield Button("Turn", id="add-turn", compact=True)
            yield Button("Orbit", id="add-orbit", compact=True)
            yield Button("Fly-past", id="add-flypast", compact=True)
            yield Button("Standoff", id="add-standoff", compact=True)
            yield Button("Poses", id="add-manual", compact=True)
            yield Button("Edit", id="seg-edit", compact=True)
            yield Button("Delete", id="seg-delete", compact=True)
            yield Button("Aim all", id="aim-all", compact=True)
        yield Label("Scans", id="scans-heading", classes="heading")
        yield FittingTable(self.refit_tables, id="scans", cursor_type="row", zebra_stripes=True)

    def on_mount(self) -> None:
        self.query_one("#segments", DataTable).add_columns(*SEGMENT_COLUMNS)
        self.query_one("#scans", DataTable).add_columns(*SCAN_COLUMNS)

    def refit_tables(self) -> None:
        """A table changed width: draw both to their widths now."""
        if self.host.scenario is not None:
            self._fill_tables(self.host.scenario)

    # -- showing the scenario --------------------------------------------------------

    def show(self, scenario) -> None:
        self.fill_fields(scenario)
        self.enable_start(scenario)
        self._fill_tables(scenario)

    def enable_start(self, scenario=None) -> None:
        """Start fields only where the path uses them (and never while busy)."""
        scenario = scenario or self.host.scenario
        used = scenario is not None and scenario.flight.uses_start
        for param in bridge.START_PARAMS:
            self.query_one("#" + field_id(param.key)).disabled = not used or bool(self.host.busy)
        note = self.query_one("#start-note", Static)
        note.update("" if used else START_UNUSED)
        note.display = not used

    def _fill_tables(self, scenario) -> None:
        try:
            per_segment = scenario.flight.segment_poses()
        except LadarError:
            per_segment = [[] for _ in scenario.flight.segments]
        segments = [
            (
                str(i + 1),
                SHORT_KINDS.get(segment.kind) or bridge.SEGMENT_LABELS.get(segment.kind, segment.kind),
                str(len(poses)),
                bridge.segment_summary(segment),
            )
            for i, (segment, poses) in enumerate(zip(scenario.flight.segments, per_segment))
        ]
        fill_segments(self.query_one("#segments", FittingTable), segments)
        # Whole metres and degrees (round: an int, never "-0"): more columns fit
        every_scan = [pose for poses in per_segment for pose in poses]
        scans = [
            (str(i + 1), *(str(round(v)) for v in (p.x, p.y, p.z, p.heading, p.azimuth, p.depression)))
            for i, p in enumerate(every_scan[:MOST_SCAN_ROWS])
        ]
        left_out = fill_whole_columns(self.query_one("#scans", FittingTable), SCAN_COLUMNS, scans)
        notes = [f"the first {len(scans):,} of {len(every_scan):,}"] if len(every_scan) > len(scans) else []
        notes += [f"no room for {', '.join(left_out)}"] if left_out else []
        self.query_one("#scans-heading", Label).update("Scans" + (f" ({'; '.join(notes)})" if notes else ""))

    # -- editing segments ------------------------------------------------------------

    def _editing(self) -> Scenario | None:
        """The scenario to edit, or None when there is none or the app is busy."""
        return None if self.host.busy else self.host.scenario

    def selected(self) -> int:
        return self.query_one("#segments", DataTable).cursor_row

    @on(Button.Pressed, ADD_BUTTONS)
    def _add_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.add_segment((event.button.id or "").removeprefix("add-"))

    def add_segment(self, kind: str) -> None:
        scenario = self._editing()
        if scenario is None:
            return
        poses = scenario.poses()
        segment = bridge.default_segment(kind, self.host.target_m(), poses[-1] if poses else None)
        self._edit_segment(segment, None)

    def _edit_segment(self, segment, index: int | None) -> None:
        defaults = bridge.default_segment(segment.kind, self.host.target_m(), None)
        spec = bridge.segment_spec(segment, defaults)
        label = bridge.SEGMENT_LABELS[segment.kind]
        count = len(self.host.scenario.flight.segments) if self.host.scenario is not None else 0
        title = label + (" (new)" if index is None else f" (segment {index + 1} of {count})")
        build = bridge.segment_builder(segment.kind)

        def build_in_path(values):
            """The segment, refused while the form is open (what was typed kept) when the
            path it makes is not allowed (more scans in all than the limit)."""
            built = build(values)
            scenario = self.host.scenario
            if scenario is not None:
                segments = _placed(scenario.flight.segments, index, built)
                bridge.with_segment_at(scenario, segments, len(segments) - 1 if index is None else index)
            return built

        def done(result):
            if result is not None:
                what = f"add {label.lower()}" if index is None else f"edit segment {index + 1}"
                self._put_segment(index, result, what)

        self.app.push_screen(
            FormScreen(
                title,
                spec,
                build_in_path,
                note="Empty optional fields keep the current pointing; x, y alone sets z = 0.",
            ),
            done,
        )

    def _put_segment(self, index: int | None, segment, what: str) -> bool:
        """Replace segment ``index``, or append when ``index`` is None."""
        scenario = self.host.scenario
        if scenario is None:
            return False
        return self._apply_segments(_placed(scenario.flight.segments, index, segment), what)

    def _apply_segments(self, segments, what: str) -> bool:
        scenario = self.host.scenario
        if scenario is None:
            return False
        try:
            scenario = bridge.with_segments(scenario, segments)
        except LadarError as error:
            self.host.tell(str(error), title="Flight path not changed", severity="error")
            return False
        self.host.edit(scenario, what.capitalize())
        return True

    @on(Button.Pressed, "#add-manual")
    def _manual_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.manual_poses()

    def manual_poses(self) -> None:
        """Edit manual poses: the selected manual segment, or a new one."""
        scenario = self._editing()
        if scenario is None:
            return
        segments = scenario.flight.segments
        index = self.selected()
        if 0 <= index < len(segments) and isinstance(segments[index], Manual):
            self._edit_poses(scenario, index)
        else:
            poses = scenario.poses()
            start = poses[-1] if poses else bridge.start_pose(scenario)
            self._edit_poses(scenario, None, [start])

    def _edit_poses(self, scenario: Scenario, index: int | None, poses=None) -> None:
        """Edit the poses of manual segment ``index``, or ``poses`` as a new one (index None)."""
        if index is not None:
            segment = scenario.flight.segments[index]
            poses = list(segment.poses) if isinstance(segment, Manual) else []

        def done(result):
            if not result:
                if result is not None:
                    self.host.tell(
                        "A manual segment needs at least one pose; not changed.", severity="warning"
                    )
                return
            what = "add manual poses" if index is None else f"edit poses of segment {index + 1}"
            self._put_segment(index, Manual(tuple(result)), what)

        self.app.push_screen(PosesScreen(poses, bridge.start_pose(scenario), new=index is None), done)

    @on(Button.Pressed, "#seg-edit")
    def _edit_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.edit_selected()

    @on(DataTable.RowSelected, "#segments")
    def _segment_selected(self, event: DataTable.RowSelected) -> None:
        event.stop()
        self.edit_selected()

    def edit_selected(self) -> None:
        scenario = self._editing()
        if scenario is None:
            return
        index = self.selected()
        segments = scenario.flight.segments
        if not 0 <= index < len(segments):
            return
        kind = segments[index].kind
        if kind == "manual":
            self._edit_poses(scenario, index)
        elif kind in bridge.FILE_SEGMENTS:
            self.host.tell(
                f"A {bridge.SEGMENT_LABELS[kind].lower()} segment comes from its "
                f"file ({segments[index].file}): change its file, rate or times in "
                "the scenario file. Delete removes it; Aim all points it at the "
                "target.",
                severity="warning",
                timeout=8,
            )
        else:
            self._edit_segment(segments[index], index)

    @on(Button.Pressed, "#seg-delete")
    def _delete_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.delete_selected()

    def delete_selected(self) -> None:
        scenario = self._editing()
        if scenario is None:
            return
        index = self.selected()
        segments = list(scenario.flight.segments)
        if not 0 <= index < len(segments):
            return
        if len(segments) == 1:
            self.host.tell("The flight path needs at least one segment.", severity="warning")
            return
        del segments[index]
        self._apply_segments(segments, f"delete segment {index + 1}")

    @on(Button.Pressed, "#aim-all")
    def _aim_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.aim_all()

    def aim_all(self) -> None:
        scenario = self._editing()
        if scenario is None:
            return
        try:
            scenario = bridge.aim_all(scenario, self.host.target_m())
        except LadarError as error:
            self.host.tell(str(error), title="Cannot aim every scan", severity="error")
            return
        self.host.edit(scenario, "Aim every scan at the target")
        self.host.tell("Every scan now aims at the target centre.")


def _placed(segments, index: int | None, segment) -> list:
    """``segments`` with ``segment`` in place of segment ``index``, or after them (None)."""
    out = list(segments)
    if index is None:
        out.append(segment)
    else:
        out[index] = segment
    return out
