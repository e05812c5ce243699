"""Several targets in the terminal UI: rows per target with their levels, a colour per
target in every view, and the comparison target by target."""

from __future__ import annotations

from ladartui.colour import TARGET_PALETTE
from ladartui.tui.canvas import PictureWidget
from ladartui.tui.measures_screens import CompareScreen, MeasuresScreen
from test_targets import two_box_scenario
from tui_support import LadarApp, loaded, wait_until

SIZE = (120, 40)
NAME = "[b]open[/b] box"  # markup characters in a name from a file: shown as written


def cells(table) -> list[tuple[str, ...]]:
    return [tuple(str(c) for c in table.get_row_at(i)) for i in range(table.row_count)]


def colours_in(picture) -> set[tuple[int, int, int]]:
    return {tuple(int(v) for v in p) for p in picture.rgb[picture.mask]}


async def test_rows_colours_and_comparison_per_target(tmp_path):
    scenario = two_box_scenario(tmp_path, names=((1, NAME), (2, "roofed"))).save()
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        # The 3D scene view draws each target in its own colour from the start.
        scene3d = app.query_one("#scene3d", PictureWidget)
        picture = scene3d.make_picture(*scene3d.picture_size())
        assert {TARGET_PALETTE[0], TARGET_PALETTE[1]} <= colours_in(picture)
        top = app.query_one("#topview", PictureWidget)
        assert {TARGET_PALETTE[0], TARGET_PALETTE[1]} <= colours_in(top.make_picture(*top.picture_size()))

        await pilot.press("f5")
        await wait_until(pilot, lambda: app.busy is None and app.measures is not None)
        await pilot.pause(0.2)
        rows = cells(app.query_one("#measures"))
        labels = [label for label, _ in rows]
        # levels of the whole model, then a row per target (its name as written) and the summaries
        assert labels[-8:] == [
            "Detect",
            "Recognise",
            "Identify",
            "Targets",
            f"\u25a0 {NAME}",
            "\u25a0 roofed",
            "worst",
            "mean",
        ]
        values = dict(rows)
        # the open box's roof is seen at scan 1 (recognised there); the roofed one never
        assert values[f"\u25a0 {NAME}"] == "33.3% rec@1"
        assert values["\u25a0 roofed"] == "0.0% none"
        assert values["worst"] == "0.0%" and values["mean"] == "16.7%"

        # The output view: each target seen in its colour (the roofed one is not seen).
        app.action_layout(5)
        await pilot.pause(0.2)
        output3d = app.query_one("#output3d", PictureWidget)
        shown = colours_in(output3d.make_picture(*output3d.picture_size()))
        assert TARGET_PALETTE[0] in shown and TARGET_PALETTE[1] not in shown

        # The measures dialog lists the levels and the targets too.
        await pilot.press("f9")
        await pilot.pause(0.2)
        assert isinstance(app.screen, MeasuresScreen)
        dialog = cells(app.screen.query_one("DataTable"))
        assert ("Identify", "not reached") in dialog
        assert (f"\u25a0 {NAME}", "33.3% obscured, recognise @ 1") in dialog
        await pilot.press("escape")

        # Compare (two runs holding the same targets): rows per target follow the overall rows.
        app.push_screen(CompareScreen([scenario.measures_file, scenario.measures_file]))
        await pilot.pause(0.3)
        table = cells(app.screen.query_one("#compare-table"))
        by_label = {row[0]: row[1:] for row in table}
        assert by_label[f"{NAME}: obscured coverage"] == ("33.3%", "33.3%")
        assert by_label["roofed: unobscured coverage"] == ("50.0%", "50.0%")
        assert by_label["Identify at scan"] == ("not reached", "not reached")
        assert all(len(row) == 3 for row in table)
