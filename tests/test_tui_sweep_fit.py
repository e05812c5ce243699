"""The sweep screen at 80 x 24: its status line, table and chart read whole and clearly.

A two-variant sweep over the tiny scenario runs once, serially; each test opens or
runs it again (every variant resumes) in a copy under the test's own folder.
"""

from __future__ import annotations

import re
import shutil
from contextlib import asynccontextmanager

import pytest
from rich.cells import cell_len

from ladartui.sweep.ranking import OBJECTIVES
from ladartui.tui.status import StatusText
from ladartui.tui.sweep_screen import SweepScreen
from sweep_screen_support import SIZE, SweepHost, opened, swept_folder, wait_for
from tiny_sweep import write_spec


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """A folder holding the base, the spec and its finished two-variant results."""
    return swept_folder(tmp_path_factory)


def copy_of(swept, folder):
    """``swept`` copied into ``folder`` (a run rewrites its table); the spec there."""
    shutil.copytree(swept, folder)
    return folder / "spec.toml"


@asynccontextmanager
async def run_again(swept, tmp_path, monkeypatch):
    """A copy of ``swept`` under ``tmp_path`` (the working folder) run again serially
    (every variant resumes) on its screen at 80 x 24; the screen once it is done."""
    monkeypatch.chdir(tmp_path)  # folders are shown relative to the working one
    screen = SweepScreen(copy_of(swept, tmp_path / "sw"), serial=True)
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        await wait_for(pilot, lambda: not screen.running)
        await pilot.pause()
        yield screen


async def test_a_finished_sweep_names_its_results_folder_whole_on_the_status_line(
    swept, tmp_path, monkeypatch
):
    """It read 'results in sw/…resu…': the folder cut in its middle, then the line's end
    cut through what was left of it."""
    async with run_again(swept, tmp_path, monkeypatch) as screen:
        line = screen.query_one("#sweep-status StatusText", StatusText)
        shown = line.render().plain
        assert "sw/spec-results" in shown and "\u2026" not in shown, shown
        assert cell_len(shown) <= line.content_size.width
        assert "2 resumed" in screen.last_message


def test_a_path_that_cannot_be_shortened_enough_is_cut_once_at_the_end():
    from ladartui.tui.status import fitted

    said = "sweep done: 2 run, 0 resumed in 2m46s; results in sw/tiny-results"
    shown = fitted(said, 57)
    assert shown == said[:56] + "\u2026"  # not 'sw/…resu…'
    # where the end cut falls after the name, the name is still cut in its middle too
    name = "My Night Approach Over The Long Valley Final Plan.toml"
    shown = fitted(f"{name} (modified): 6 scans x 144 rays. F5 runs.", 40, name)
    assert shown.startswith("My \u2026an.toml (modified): 6 scans") and shown.endswith("\u2026")


async def test_the_chart_names_each_axis_apart_for_either_cost(swept, tmp_path, monkeypatch):
    """Under the chart 'coverage % flight time (s)' read as one phrase, and the distance
    axis's longer name was left out for want of room."""
    from textual_plotext import PlotextPlot

    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))  # no sweep to reopen
    screen = SweepScreen()
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        # empty, with no tick labels to push them apart: the names ran together
        labels = screen.query_one("#sweep-chart", PlotextPlot).render().plain.splitlines()[-1]
        assert "cov" not in labels or len(re.split(r" {2,}", labels.strip())) == 2, labels
    screen = SweepScreen(swept / "spec-results")
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        chart = screen.query_one("#sweep-chart", PlotextPlot)
        for cost, word in (("flight-time", "time (s)"), ("distance", "distance (m)")):
            assert screen.cost == cost
            labels = chart.render().plain.splitlines()[-1]
            # two labels, apart, each with the arrow of its axis
            y_label, x_label = re.split(r" {2,}", labels.strip())
            assert "cov" in y_label and "\u2191" in y_label, labels
            assert word in x_label and "\u2192" in x_label, labels
            await pilot.press("f7")
            await pilot.pause()


async def test_the_empty_table_fits_without_a_sideways_scrollbar(swept, tmp_path, monkeypatch):
    """Before any results its last header was cut to 'erro' over a horizontal scrollbar;
    the error column comes only with a row that has an error."""
    from textual.widgets import DataTable

    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))  # no sweep to reopen
    screen = SweepScreen()
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        table = screen.query_one("#sweep-table", DataTable)
        assert table.row_count == 0
        assert table.virtual_size.width <= table.scrollable_content_region.width
        assert not table.show_horizontal_scrollbar
    screen = SweepScreen(swept / "spec-results")  # every variant ok: no error column
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        table = screen.query_one("#sweep-table", DataTable)
        labels = [column.label.plain for column in table.ordered_columns]
        assert table.row_count == 2 and "status" in labels and "error" not in labels


async def test_the_table_marks_the_best_variant_as_the_chart_and_its_legend_do(swept):
    """The best variant was '◆' (the front's mark) in the table's P column but '★' on
    the chart, whose legend reads '◆ Pareto front  ★ best'."""
    from textual.widgets import DataTable
    from textual_plotext import PlotextPlot

    screen = SweepScreen(swept / "spec-results")
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        chart = screen.query_one("#sweep-chart", PlotextPlot).render().plain.splitlines()
        legend = chart[0]
        front = legend[legend.index(" Pareto front") - 1]
        best = legend[legend.index(" best") - 1]
        assert best in "".join(chart[1:])  # the best point, drawn with the legend's mark
        table = screen.query_one("#sweep-table", DataTable)
        marks = [str(cell) for cell in table.get_column("pareto")]
        assert screen.ranking[0].rank == 1 and marks[0] == best
        for entry, mark in zip(screen.ranking[1:], marks[1:]):
            assert mark == (front if entry.pareto else "")
        assert f"{best} best" in str(screen.query_one("#sweep-detail").render())  # the cursor's row


async def test_a_finished_sweep_puts_the_cursor_on_its_best_variant(tmp_path):
    """The cursor stayed on the variant that came first, wherever the ranking moved it:
    a sweep whose first variant was its worst ended with the cursor on the last row."""
    from textual.widgets import DataTable

    from tiny_sweep import write_tiny_scenario

    write_tiny_scenario(tmp_path)
    # the widest orbit first: it sees the least of the target
    spec = write_spec(tmp_path, "[grid]\nradius = [40.0, 25.0, 15.0]\n")
    screen = SweepScreen(spec, serial=True)
    shown = screen._show_progress

    def redrawn(progress):  # drawn between rows, as the timer does on a longer sweep
        shown(progress)
        screen._redraw_if_dirty()

    screen._show_progress = redrawn
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        await pilot.press("f5")
        await wait_for(pilot, lambda: not screen.running)
        await pilot.pause()
        table = screen.query_one("#sweep-table", DataTable)
        variants = [str(cell) for cell in table.get_column("variant")]
        ranks = [str(cell) for cell in table.get_column("rank")]
        first = next(row for row in screen.rows if row["radius"] == 40.0)["variant"]
        assert variants.index(first) != ranks.index("1")  # the first to come is not the best
        assert ranks[table.cursor_row] == "1", (variants[table.cursor_row], first)
        assert "\u2605 best" in str(screen.query_one("#sweep-detail").render())
        # opened again after the analyst moved down the table: the best again
        table.move_cursor(row=table.row_count - 1)
        await pilot.press("f3")
        await opened(pilot)
        assert ranks[table.cursor_row] == "1"


async def test_every_coverage_column_reads_in_percent_as_cov_percent_does(swept):
    """Ranked by worst-target coverage or coverage within a budget, the objective's column
    read 0.6875 beside 'cov %' 68.75 (and the coverage objective's own 68.75%): a share
    among percentages, read as under one percent."""
    from textual.widgets import DataTable

    screen = SweepScreen(swept / "spec-results")
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        screen.query_one("#sweep-budget").value = "1000"  # every variant within it
        table = screen.query_one("#sweep-table", DataTable)
        for objective in ("coverage-within-budget", "worst-target-coverage"):
            for _ in range(len(OBJECTIVES)):  # F6 goes round them all: never for ever
                if screen.objective == objective:
                    break
                await pilot.press("f6")
            assert screen.objective == objective
            await pilot.pause()
            values = [str(cell) for cell in table.get_column("objective")]
            percents = [str(cell) for cell in table.get_column("coverage")]
            # one target: its worst coverage, and within the budget its coverage, is the
            # coverage itself
            assert all(entry.value == entry.coverage for entry in screen.ranking), objective
            assert values == [f"{100 * e.value:.2f}%" for e in screen.ranking], objective
            assert values == [f"{p}%" for p in percents], objective


async def test_rows_left_out_of_the_ranking_are_said_first_on_the_status_line(swept, tmp_path):
    """A spec narrowed after its run opened as '...: 1 variants, 1 ok, 0 failed; 1…' at
    80 columns: the rows of other variants left out of the ranking were cut away."""
    spec = copy_of(swept, tmp_path / "sw")
    narrowed = write_spec(spec.parent, "[grid]\nradius = [15.0]\n")
    screen = SweepScreen(narrowed)
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        await wait_for(pilot, lambda: "ranked by" in screen.last_message)
        shown = screen.query_one("#sweep-status StatusText", StatusText).render().plain
        assert shown.startswith("1 row not ranked: other variants;"), shown
        assert "ranked by obscured-coverage: 1 variant, 1 ok" in screen.last_message


async def test_a_failed_variants_whole_error_is_on_the_detail_line_at_80_columns(tmp_path):
    """The detail line was one row: at 80 columns a failed variant's error read
    'radius = -60.0: expected a number greater', the rest cut with no mark."""
    from ladartui.sweep import run_sweep
    from tiny_sweep import write_tiny_scenario

    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [15.0, -60.0]\n")
    run_sweep(spec, serial=True)
    screen = SweepScreen(spec.with_name("spec-results"))
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        table = screen.query_one("#sweep-table")
        table.move_cursor(row=table.row_count - 1)
        await pilot.pause()
        detail = screen.query_one("#sweep-detail")
        error = "radius = -60.0: expected a number greater than 0 and at most 1000000"
        assert error in str(detail.render())
        shown = " ".join(
            "".join(segment.text for segment in strip).strip()
            for strip in detail.render_lines(detail.region.reset_offset)
        )
        assert error in " ".join(shown.split()), shown
        assert screen.query_one("#sweep-table").size.height >= 4  # the table keeps its rows


async def test_a_results_table_with_no_rows_is_not_ready(tmp_path, monkeypatch):
    """A table of a header and a torn line opened green: 'READY ranked by
    obscured-coverage: 0 variants, 0 ok, 0 failed', with nothing ranked or to open."""
    from ladartui.tui.status import NOT_READY, StatusBar

    monkeypatch.chdir(tmp_path)  # the table is named relative to the working folder
    folder = tmp_path / "torn-results"
    folder.mkdir()
    (folder / "results.csv").write_text('variant,status,radius\n"abc,ok\n', encoding="utf-8")
    screen = SweepScreen(folder)
    async with SweepHost(screen).run_test(size=SIZE) as pilot:
        await opened(pilot)
        bar = screen.query_one("#sweep-status", StatusBar)
        assert bar.state == NOT_READY
        assert screen.last_message == "no variant rows to rank in torn-results/results.csv"


async def test_a_finished_sweep_is_ready_without_a_percentage(swept, tmp_path, monkeypatch):
    """The bar read 'READY 100%' once a sweep was done: green with a progress figure, as
    only a busy (red) bar has; the progress row above already says 100%."""
    from ladartui.tui.status import READY, StatusBar

    async with run_again(swept, tmp_path, monkeypatch) as screen:
        bar = screen.query_one("#sweep-status", StatusBar)
        assert bar.state == READY and bar.progress is None
        assert str(bar.query_one("#status-word").render()) == "READY"


def test_the_chart_of_variants_that_all_saw_nothing_shows_no_negative_coverage():
    """Every variant at 0 % drew the sweep screen's chart on an axis from -1.00 to 1.00."""
    import plotext as plt

    from ladartui.sweep.ranking import Ranked
    from ladartui.tui.sweep_view import draw_pareto

    ranking = [Ranked({"variant": f"v{i}"}, 0.0, i + 1, i == 0, 100.0 + 10 * i, 0.0) for i in range(5)]
    plt.clf()
    plt.plotsize(80, 20)
    draw_pareto(plt, ranking, "distance")
    ticks = [line.split("\u2524")[0] for line in plt.build().splitlines() if "\u2524" in line]
    plain = [re.sub(r"\x1b\[[0-9;]*m", "", tick).strip() for tick in ticks]
    assert plain and not any(tick.startswith("-") for tick in plain), plain
    assert max(float(tick) for tick in plain) == 100.0
    plt.clf()
