"""Text cut to the room it has: a long scenario name shortened in the status line, not
what follows (fitted, in cells); the Sensor tab's summary keeping each figure with its
unit at 80 columns, and the IFOV in degrees from one degree up.

Pilot tests on a tiny generated scene.
"""

from __future__ import annotations

import re

from ladartui.tui.status import StatusBar
from tui_support import LadarApp, field, loaded, make_scenario, type_into, wait_until


async def test_a_long_scenario_name_is_shortened_in_the_status_line_not_what_follows(tmp_path, scene_files):
    """At 80 columns a long name pushed '(modified)' and the scan count off the bar."""
    from rich.cells import cell_len

    name = "night-approach-" + "x" * 50 + "-final"
    scenario = make_scenario(tmp_path, scene_files, name=name)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(80, 24)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        await type_into(pilot, field(app, "sensor.grid"), "12")
        bar = app.query_one(StatusBar)
        text = app.query_one("#status-text")
        shown = str(text.render())
        assert re.search(r"\(modified\): \d+ scans x [\d,]+ rays\. F5 runs\.$", shown)
        assert shown.startswith("nigh") and "\u2026" in shown and "nal.toml (modified)" in shown
        assert cell_len(shown) <= text.content_size.width
        assert bar.message.startswith(f"{name}.toml (modified)")  # the message itself whole
        await pilot.resize_terminal(160, 30)
        await pilot.pause()
        assert str(text.render()) == bar.message  # room for all of it: nothing shortened


def test_fitted_shortens_the_name_given_then_cuts_the_end_in_cells():
    """The longest word was cut, which need not be the name ('(mo…ified):'), and wide
    characters were counted as one cell each, so the line still overflowed."""
    from rich.cells import cell_len

    from ladartui.tui.status import fitted

    spaced = "My Night Approach Over The Long Valley Final Plan.toml"
    message = f"{spaced} (modified): 6 scans x 144 rays. F5 runs."
    shown = fitted(message, 60, spaced)
    assert shown.endswith(" (modified): 6 scans x 144 rays. F5 runs.") and cell_len(shown) <= 60
    assert shown.startswith("My N") and "\u2026" in shown and "Plan.toml" in shown
    wide = "\u591c\u9593\u9032\u5165" * 6 + ".toml"  # 48 cells of CJK
    shown = fitted(f"{wide} (modified): 6 scans x 144 rays. F5 runs.", 60, wide)
    assert cell_len(shown) <= 60 and shown.endswith("(modified): 6 scans x 144 rays. F5 runs.")
    # no name given (or the name alone not enough): the end is cut, marked
    shown = fitted("sweep stopped: " + "x" * 100, 40)
    assert cell_len(shown) == 40 and shown.endswith("\u2026")
    # no name given, a path in the message: the path gives way, 'F5 resumes' stays
    said = "sweep cancelled: 12 rows kept in ~/projects/night-approach/final-sweep-results; F5 resumes"
    shown = fitted(said, 60)
    assert cell_len(shown) <= 60 and shown.endswith("results; F5 resumes") and "\u2026" in shown
    assert fitted("short", 40, "short") == "short"


async def test_the_sensor_summary_keeps_each_figure_with_its_unit_at_80_columns(tmp_path, scene_files):
    """'IFOV 125' ended one line and 'mdeg' began the next."""
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(80, 24)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("sensor")
        await pilot.pause()
        info = app.query_one("#sensor-info")
        shown = [
            "".join(segment.text for segment in strip).rstrip()
            for strip in info.render_lines(info.content_region.reset_offset)
        ]
        assert any(re.fullmatch(r"IFOV [\d.e+-]+ m?deg", line) for line in shown), shown


def test_the_ifov_is_said_in_degrees_from_one_degree_up():
    """A 90 degree view on 64 detectors read 'IFOV 1.41e+03 mdeg'."""
    from ladartui.tui.panels.sensor import ifov_text

    assert [ifov_text(fov / 64) for fov in (8.0, 63.0, 64.0, 90.0)] == [
        "125 mdeg",
        "984 mdeg",
        "1 deg",
        "1.41 deg",
    ]
