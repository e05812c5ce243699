"""The Flight tab's segments table wraps a long detail at a sensible place: a file
name after a hyphen, underscore or slash (else a dot), never leaving its comma, or a
lone piece of punctuation, to start the next line."""

from __future__ import annotations

import shutil
from pathlib import Path

from rich.cells import cell_len

from ladartui.flight import FlightPlan
from ladartui.trajectory import LogSegment
from ladartui.tui.fitted_tables import wrap_detail
from tui_support import make_scenario, opened, wait_until


def test_a_file_name_wider_than_the_room_breaks_after_a_hyphen_or_a_dot():
    # it read "flight-log.csv" then ", 2 Hz": the rate's comma began a line
    assert wrap_detail("flight-log.csv, 2 Hz", 14) == ["flight-", "log.csv, 2 Hz"]
    assert wrap_detail("flight-log.csv, 2 Hz", 13) == ["flight-", "log.csv, 2 Hz"]
    assert wrap_detail("flight-log.csv, 2 Hz", 15) == ["flight-log.csv,", "2 Hz"]
    assert wrap_detail("flightlog.csv, 2 Hz", 11) == ["flightlog.", "csv, 2 Hz"]
    # no mark to break after: cut in cells, the comma kept with what it ends
    assert wrap_detail("flightlogcsv, 2 Hz", 12) == ["flightlogcs", "v, 2 Hz"]
    assert wrap_detail("飛行記録.csv, 2 Hz", 6) == ["飛行記", "録.", "csv,", "2 Hz"]
    for room in range(4, 22):
        for text in ("flight-log.csv, 2 Hz", "飛行記録.csv, 2 Hz", "flightlogcsv, 2 Hz"):
            lines = wrap_detail(text, room)
            assert all(cell_len(line) <= room for line in lines), (text, room, lines)
            assert not any(line.startswith(",") for line in lines), (text, room, lines)
            assert "".join("".join(lines).split()) == "".join(text.split())


async def test_the_log_segment_detail_keeps_its_rate_after_the_file_name(tmp_path, scene_files):
    log = tmp_path / "flight-log.csv"
    shutil.copy(Path(__file__).parent.parent / "scenarios" / "flight-log.csv", log)
    scenario = make_scenario(tmp_path, scene_files)
    segments = (*scenario.flight.segments, LogSegment(str(log), rate=2.0))
    scenario = scenario.with_changes(flight=FlightPlan(None, segments)).save()
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        app.action_show_tab("flight")
        table = app.query_one("#segments")
        await wait_until(pilot, lambda: table.row_count == 2 and table.max_scroll_x == 0, timeout=10.0)
        detail = str(table.get_row_at(1)[3]).split("\n")
        assert len(detail) > 1 and detail[0] == "flight-", detail
        assert detail[-1].endswith("2 Hz") and not any(line.startswith(",") for line in detail)
