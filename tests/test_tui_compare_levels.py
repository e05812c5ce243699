"""The comparison's level rows (Compare, F10, and ``ladartui compare``): a level one run
never reached reads 'not reached', as the Results tab, the measures dialog and the .cmf
file say, and counts as the worst."""

from __future__ import annotations

import dataclasses

from ladartui.levels import levels_from_curves
from ladartui.measures import Measures
from ladartui.measures_compare import side_by_side, styled

GREEN, RED = "bold green", "bold red"


def with_levels(visible: list[float]) -> Measures:
    """Measures whose levels come from the visible (and footprint) share after each scan."""
    times = [float(k) for k in range(len(visible))]
    levels = levels_from_curves(visible, visible, times, [30.0 * t for t in times], visible_voxels=100)
    return dataclasses.replace(Measures(target_voxels=100, scans=len(visible)), levels=levels)


def test_a_level_not_reached_reads_not_reached_and_is_the_worst():
    """Compare showed 'Recognise at scan: undefined' for a fly-past that never
    recognised the target (its Results tab: 'not reached'), beside '3' for the orbit
    that did, neither marked best nor worst: 'undefined' reads as a figure missing from
    the file, not as the run that fell short."""
    orbit = with_levels([0.2, 0.4, 0.6, 0.8])  # detect 1, recognise 3, identify 4
    flypast = with_levels([0.2, 0.2, 0.2, 0.2])  # detect 1 only
    rows = {row.label: row for row in side_by_side([orbit, flypast])}
    assert rows["Detect at scan"].texts == ("1, 0.0 s", "1, 0.0 s")
    assert rows["Recognise at scan"].texts == ("3, 2.0 s", "not reached")
    assert rows["Identify at scan"].texts == ("4, 3.0 s", "not reached")
    recognise = rows["Recognise at scan"]
    assert (recognise.best, recognise.worst) == ((0,), (1,))
    assert recognise.values == (3, None)  # the scans, as --json gives them
    assert [str(cell.style) for cell in styled(recognise)[1:]] == [GREEN, RED]
    # never reached by either: the same words, nothing marked
    both = {row.label: row for row in side_by_side([flypast, flypast])}["Identify at scan"]
    assert both.texts == ("not reached", "not reached") and not both.differ and both.best == ()
    # a file without levels (format 1) still reads 'undefined'
    old = Measures(target_voxels=100, scans=4)
    mixed = {row.label: row for row in side_by_side([old, orbit])}["Identify at scan"]
    assert mixed.texts == ("undefined", "4, 3.0 s") and mixed.best == ()


def test_flights_of_other_scan_rates_show_the_flight_time_beside_the_scan():
    """A 24-scan and a 12-scan orbit compared read 'Identify at scan: 10' and '6': the
    looks needed, not how long each flew to get there. The time is now beside the scan;
    the ranking stays by scans (looks needed), as --json gives them."""
    visible = [0.2, 0.4, 0.6, 0.8]
    times = [0.5 * k for k in range(4)]
    levels = levels_from_curves(visible, visible, times, [30.0 * t for t in times], visible_voxels=100)
    quick = dataclasses.replace(Measures(target_voxels=100, scans=4), levels=levels)
    identify = {row.label: row for row in side_by_side([with_levels(visible), quick])}["Identify at scan"]
    assert identify.texts == ("4, 3.0 s", "4, 1.5 s")
    assert identify.values == (4, 4) and identify.best == () and identify.worst == ()
