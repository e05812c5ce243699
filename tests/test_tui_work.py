"""The one worker pattern: jobs report progress and their end as messages, every failure
is shown and none closes the app, cancelling reaches the task through its worker."""

from __future__ import annotations

import threading
from contextlib import asynccontextmanager

from textual.app import App
from textual.widgets import Static

from ladartui.errors import Cancelled
from ladartui.tui.work import JobDone, JobProgress, start_job
from tui_support import LadarApp, loaded, make_scenario, wait_until


@asynccontextmanager
async def study_screen(tmp_path, scene_files, size=(120, 40)):
    """The app on a small scenario with its study screen (F11) open: (app, pilot, screen)."""
    from ladartui.tui.study_screen import StudyScreen

    app = LadarApp(make_scenario(tmp_path, scene_files).path)
    async with app.run_test(size=size) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        await pilot.press("f11")
        await pilot.pause()
        assert isinstance(app.screen, StudyScreen)
        yield app, pilot, app.screen


class Host(App):
    """An app that runs one job and records what it hears."""

    def __init__(self, task):
        super().__init__()
        self.job_task, self.heard, self.worker = task, [], None

    def compose(self):
        yield Static("")

    def on_mount(self) -> None:
        self.worker = start_job(self, "job", self.job_task)

    def on_job_progress(self, message: JobProgress) -> None:
        self.heard.append(("progress", message.text))

    def on_job_done(self, message: JobDone) -> None:
        self.heard.append(("done", message.result, message.cancelled, message.error))


async def test_queued_reports_give_way_to_newer_ones_except_kept_ones_and_live_views():
    """Reports queued before the app reads them, as a fast job posts them: Textual asks
    the older one whether the newer may take its place. A newer report replaces an
    older one of the same job, but never a kept one (a sweep's finished row, its
    stored rows) and never one with a detail (a live view) by one without."""
    heard = []

    class Listener(App):
        def compose(self):
            yield Static("")

        def on_job_progress(self, message: JobProgress) -> None:
            heard.append((message.text, message.detail))

    app = Listener()
    async with app.run_test() as pilot:
        for report in (
            JobProgress("run", 0.1, "a"),  # replaced by b
            JobProgress("run", 0.2, "b"),  # replaced by the kept row
            JobProgress("run", 0.3, "kept row", ["row"], keep=True),
            JobProgress("run", 0.4, "c", ["view"]),  # replaced by d (a detail for a detail)
            JobProgress("run", 0.5, "d", ["view 2"]),
            JobProgress("run", 0.6, "e"),  # no detail: does not replace d
            JobProgress("study", 0.7, "f"),  # another job's: replaces nothing of run's
        ):
            app.post_message(report)
        await pilot.pause()
        await pilot.pause()
    assert heard == [
        ("kept row", ["row"]),
        ("d", ["view 2"]),
        ("e", None),
        ("f", None),
    ]


async def test_a_jobs_reports_reach_the_node_that_started_it_and_not_the_app():
    """Reports said they did not bubble, but Textual set every message class's
    ``bubble`` as it was made: a job of the study screen that failed reached the app
    too, which told its error a second time under the title 'study'."""

    class Starter(Static):
        heard: list = []

        def on_mount(self) -> None:
            start_job(self, "study", lambda cancel, progress: progress(0.5, "half") or 1 / 0)

        def on_job_progress(self, message: JobProgress) -> None:
            self.heard.append(("progress", message.text))

        def on_job_done(self, message: JobDone) -> None:
            self.heard.append(("done", message.error))

    class Above(App):
        heard: list = []

        def compose(self):
            yield Starter("")

        def on_job_progress(self, message: JobProgress) -> None:
            self.heard.append(message)

        def on_job_done(self, message: JobDone) -> None:
            self.heard.append(message)

    app = Above()
    async with app.run_test() as pilot:
        starter = app.query_one(Starter)
        await wait_until(pilot, lambda: len(starter.heard) == 2)
        for _ in range(3):  # a report that bubbled would reach the app within these
            await pilot.pause()
        assert starter.heard == [("progress", "half"), ("done", "ZeroDivisionError: division by zero")]
        assert app.heard == []


async def test_an_unexpected_exception_is_reported_and_the_app_stays_open():
    def task(cancel, progress):
        progress(0.5, "half way")
        raise ZeroDivisionError("division by zero in a kernel")

    app = Host(task)
    async with app.run_test() as pilot:
        while not any(h[0] == "done" for h in app.heard):
            await pilot.pause(0.05)
        assert app.is_running
        assert ("done", None, False, "ZeroDivisionError: division by zero in a kernel") in app.heard


async def test_cancelling_the_worker_reaches_the_task_and_reports_cancelled():
    started = threading.Event()

    def task(cancel, progress):
        started.set()
        while not cancel.is_set():
            cancel.wait(0.01)
        raise Cancelled()

    app = Host(task)
    async with app.run_test() as pilot:
        while not started.is_set():
            await pilot.pause(0.02)
        app.worker.cancel()
        while not any(h[0] == "done" for h in app.heard):
            await pilot.pause(0.05)
        assert app.heard[-1] == ("done", None, True, None)


async def test_a_study_whose_tracer_fails_unexpectedly_reports_it_and_the_app_stays_open(
    tmp_path, scene_files, monkeypatch
):
    import ladartui.study.run as study_run

    def broken(*args, **kwargs):
        raise RuntimeError("the tracer fell over")

    monkeypatch.setattr(study_run, "run_study", broken)
    async with study_screen(tmp_path, scene_files) as (app, pilot, screen):
        await pilot.press("q")
        status = screen.query_one("#study-status StatusText", Static)
        await wait_until(pilot, lambda: "fell over" in str(status.render()))
        assert "error: RuntimeError: the tracer fell over" in str(status.render())
        assert app.is_running and app.screen is screen
        assert not screen.query_one("#study-quick").disabled  # ready to try again


async def test_ctrl_x_cancels_a_study_as_it_cancels_a_run_and_a_sweep(tmp_path, scene_files, monkeypatch):
    import threading

    import ladartui.study.run as study_run
    from ladartui.errors import Cancelled

    started = threading.Event()

    def until_cancelled(*args, cancel=None, progress=None, **kwargs):
        from types import SimpleNamespace

        progress(SimpleNamespace(done=1, total=3, label="numba exact", scan=1, scans=2))  # a third done
        started.set()
        while not cancel.wait(0.02):
            pass
        raise Cancelled("study cancelled")

    monkeypatch.setattr(study_run, "run_study", until_cancelled)
    async with study_screen(tmp_path, scene_files) as (app, pilot, screen):
        from ladartui.tui.status import BUSY, READY, StatusBar

        # the colour bar as on the main and sweep screens: green, red with progress, green
        bar = screen.query_one("#study-status", StatusBar)
        assert bar.state == READY
        await pilot.press("q")
        await wait_until(pilot, started.is_set)
        await wait_until(pilot, lambda: bar.progress is not None)
        assert bar.state == BUSY and abs(bar.progress - 1 / 3) < 1e-9
        from textual.widgets._footer import FooterKey

        await pilot.pause()
        assert "cancel" in {key.action for key in screen.query(FooterKey)}  # running: offered
        # Ctrl+C, the reflex to stop it, said 'press Ctrl+Q to quit' alone
        said: list[str] = []
        app.tell = lambda message, **kwargs: said.append(message)
        await pilot.press("ctrl+c")
        await pilot.pause()
        assert said == ["Ctrl+C does not stop the study: Ctrl+X cancels it; Ctrl+Q quits."]
        assert bar.state == BUSY
        await pilot.press("ctrl+x")
        status = screen.query_one("#study-status StatusText", Static)
        await wait_until(pilot, lambda: "study cancelled" in str(status.render()))
        assert app.screen is screen  # cancelled, still on the study screen
        assert screen.query_one("#study-progress").percentage == 0  # not left at 33 %
        assert bar.state == READY and bar.progress is None
    # the main screen's Cancel takes Ctrl+X as well as Esc
    from ladartui.tui.actions import keys_in_force

    assert keys_in_force(None)["cancel"].split(",") == ["escape", "ctrl+x"]


async def test_the_study_screen_keeps_its_controls_at_80x24(tmp_path, scene_files):

    async with study_screen(tmp_path, scene_files, size=(80, 24)) as (app, pilot, screen):
        status = str(screen.query_one("#study-status StatusText", Static).render())
        assert status.endswith("q quick, f full, Esc back")
        # a result's chart, legend, table and verdict leave the controls on screen
        from pathlib import Path

        from ladartui.study.results import read_study

        screen.show_result(read_study(Path(__file__).parent.parent / "docs" / "study.json"))
        await pilot.pause()
        for selector in ("#study-status", "#study-quick", "#study-cancel"):
            region = screen.query_one(selector).region
            assert region.height >= 1 and region.bottom <= 23, selector  # above the footer
        # whole columns only (19.1 ms cut to "19." read as 19), the others named
        table = screen.query_one("#study-table")
        assert table.max_scroll_x == 0
        shown = [str(column.label) for column in table.columns.values()]
        assert shown[:2] == ["setting", "s/scan"] and len(shown) < 7
        note = str(screen.query_one("#study-table-note", Static).render())
        assert note.startswith("no room here for ") and note.endswith(": see study.csv in demo-study")


async def test_a_finished_study_shows_its_whole_100_percent(tmp_path, scene_files, monkeypatch):
    """At 80x24 the progress row's buttons left the bar 29 columns, less than its
    32-column bar and percentage: a finished study's "100%" was cut off the screen."""
    from pathlib import Path
    from types import SimpleNamespace

    import ladartui.study.run as study_run
    from ladartui.study.results import read_study

    kept = read_study(Path(__file__).parent.parent / "docs" / "study.json")

    def finished(*args, progress=None, **kwargs):
        progress(SimpleNamespace(done=3, total=3, label="numba exact", scan=2, scans=2))
        return kept

    monkeypatch.setattr(study_run, "run_study", finished)
    for size in ((80, 24), (120, 40)):
        async with study_screen(tmp_path, scene_files, size=size) as (app, pilot, screen):
            await pilot.press("q")
            await wait_until(pilot, lambda: screen.result is kept)
            await pilot.pause()
            bar = screen.query_one("#study-progress")
            percent = screen.query_one("#study-progress PercentageStatus")
            assert str(percent.render()) == "100%", size
            # all of it inside the bar's row, left of the buttons
            assert percent.content_region.width >= len("100%"), size
            assert percent.region.right <= bar.region.right <= screen.query_one("#study-quick").region.x, size
            assert screen.query_one("#study-progress Bar").region.width >= 10, size  # still a bar


async def test_a_study_line_cut_at_80_columns_comes_whole_as_a_note(tmp_path, scene_files, monkeypatch):
    """At 80x24 "quick study done on default.toml; kept in /tmp/.../default-study" lost
    where the study was kept, and nothing said it whole."""
    from pathlib import Path

    import ladartui.study.run as study_run
    from ladartui.study.results import read_study

    kept = read_study(Path(__file__).parent.parent / "docs" / "study.json")
    monkeypatch.setattr(study_run, "run_study", lambda *args, **kwargs: kept)
    monkeypatch.setattr(study_run, "write_outputs", lambda result, folder: None)
    async with study_screen(tmp_path, scene_files, size=(80, 24)) as (app, pilot, screen):
        await pilot.press("q")
        await wait_until(pilot, lambda: screen.result is kept)
        await pilot.pause()
        said = screen.query_one("#study-status").message
        assert said.startswith("quick study done on ") and "; kept in " in said
        await wait_until(pilot, lambda: any(note.message == said for note in app._notifications))
    # as on the sweep and main screens, a line that fits is not said again
    async with study_screen(tmp_path, scene_files, size=(len(said) + 80, 40)) as (app, pilot, screen):
        await pilot.press("q")
        await wait_until(pilot, lambda: screen.result is kept)
        await pilot.pause()
        assert not [note for note in app._notifications if "kept in" in note.message]
    # a failed study's error is said once, as a note of its own, not twice
    from ladartui.errors import LadarError

    def failing(*args, **kwargs):
        raise LadarError("the study could not go on: " + "a long reason " * 8)

    monkeypatch.setattr(study_run, "run_study", failing)
    async with study_screen(tmp_path, scene_files, size=(80, 24)) as (app, pilot, screen):
        await pilot.press("q")
        await wait_until(pilot, lambda: screen.query_one("#study-status").message.startswith("error: "))
        await pilot.pause()
        assert [note.message[:30] for note in app._notifications if "could not go on" in note.message] == [
            "Study failed: the study could "
        ]


async def test_the_study_chart_is_drawn_again_without_a_crash(tmp_path, scene_files):
    """plotext applies its log scale to the data it holds, in place: a second drawing of
    one chart (a resize, or leaving the screen) took log10 of log10 seconds and the app
    ended with 'math domain error'."""
    from pathlib import Path

    from ladartui.study.results import read_study
    from ladartui.tui.study_screen import StudyScreen

    async with study_screen(tmp_path, scene_files, size=(120, 40)) as (app, pilot, screen):
        screen.show_result(read_study(Path(__file__).parent.parent / "docs" / "study.json"))
        await pilot.pause()
        chart = screen.query_one("#study-chart")
        for size in ((100, 30), (81, 24), (120, 40)):
            await pilot.resize_terminal(*size)
            await pilot.pause()
            chart.refresh()  # drawn again from the data it holds
            await pilot.pause()
        text = "\n".join(line.text for line in chart.render_lines(chart.region.reset_offset))
        assert "seconds per scan" in text
        await pilot.press("escape")
        await pilot.pause()
        assert not isinstance(app.screen, StudyScreen) and app.is_running


async def test_f1_on_the_study_screen_lists_every_key_its_own_too(tmp_path, scene_files):
    """F1 did nothing on the study and sweep screens, and help never listed their keys."""
    from ladartui.tui.screens import HelpScreen

    async with study_screen(tmp_path, scene_files, size=(120, 40)) as (app, pilot, screen):
        await pilot.press("f1")
        await pilot.pause()
        assert isinstance(app.screen, HelpScreen)
        table = app.screen.query_one("DataTable")
        rows = [[str(cell) for cell in table.get_row_at(i)] for i in range(table.row_count)]
        assert ["Study screen", "q", "Quick study"] in rows
        assert any(row[0] == "Sweep screen" and row[2] == "Best" for row in rows)


async def test_the_study_screen_shows_text_from_a_study_file_as_it_is(tmp_path, scene_files):
    """A reason in study.json reached the verdict as markup ('[b]') and raw escapes."""
    import json
    from pathlib import Path

    from ladartui.study.results import read_study

    data = json.loads((Path(__file__).parent.parent / "docs" / "study.json").read_text())
    data["rows"][1]["status"], data["rows"][1]["reason"] = "skipped", "no gpu\x1b[2J [b]here[/b] [/x]"
    tampered = tmp_path / "e.json"
    tampered.write_text(json.dumps(data))
    async with study_screen(tmp_path, scene_files, size=(120, 40)) as (app, pilot, screen):
        screen.show_result(read_study(tampered))
        await pilot.pause()
        verdict = str(screen.query_one("#study-verdict", Static).render())
        assert "no gpu\\x1b[2J [b]here[/b] [/x]" in verdict.replace("\n", " ")


async def test_the_study_status_names_the_scenario_and_keeps_the_keys(tmp_path, scene_files):
    """At 80 columns 'Study on /a/long/path.toml: q quick, f full, ...' lost its keys; then
    the path cut to fit cut the file's name ('/tmp/...fault.toml'). And the chart's title,
    wider than half the screen, was dropped by plotext, leaving its row blank."""
    from rich.cells import cell_len

    folder = tmp_path / ("a-long-folder-name-" * 3)
    folder.mkdir()
    async with study_screen(folder, scene_files, size=(80, 24)) as (app, pilot, screen):
        status = screen.query_one("#study-status StatusText", Static)
        shown = str(status.render())
        assert shown == f"Study on {screen.scenario_path.name}: q quick, f full, Esc back"
        assert cell_len(shown) <= status.content_size.width
        chart = screen.query_one("#study-chart")
        drawn = [
            "".join(seg.text for seg in strip) for strip in chart.render_lines(chart.region.reset_offset)
        ]
        assert any("Speed" in line and "q" in line for line in drawn)  # the title drawn, keys and all


async def test_tab_reaches_the_views_while_a_run_goes_on(tmp_path, scene_files, monkeypatch):
    """A long run leaves the views to look at: Tab moves the focus to them, and the arrow
    keys turn them, as a click would."""
    import ladartui.simulation as simulation
    from ladartui.tui.canvas import ProjectionWidget

    started = threading.Event()

    def until_cancelled(*args, cancel=None, **kwargs):
        started.set()
        while not cancel.wait(0.02):
            pass
        raise Cancelled()

    monkeypatch.setattr(simulation, "simulate", until_cancelled)
    app = LadarApp(make_scenario(tmp_path, scene_files).path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        await pilot.press("f5")
        await wait_until(pilot, started.is_set)
        await pilot.pause()
        assert app.run_in_progress()
        view = app.query_one("#scene3d", ProjectionWidget)
        for _ in range(5):
            if app.focused is view:
                break
            await pilot.press("tab")
        assert app.focused is view
        azimuth = view.camera.azimuth
        await pilot.press("left")
        assert view.camera.azimuth != azimuth
        await pilot.press("escape")
        await wait_until(pilot, lambda: app.busy is None)


async def test_a_cancelled_run_shows_again_the_earlier_outputs_read_from_disk(
    tmp_path, scene_files, monkeypatch
):
    """The outputs on disk stay as they were when a run is cancelled, and so does the
    view: the earlier run's output comes back in place of the live one."""
    import numpy as np

    import ladartui.simulation as simulation
    from ladartui.simulation import RunProgress
    from ladartui.tui.canvas import ProjectionWidget

    scenario = make_scenario(tmp_path, scene_files)
    simulation.simulate(scenario)  # the earlier outputs, on disk before the app opens
    live = threading.Event()

    def live_then_until_cancelled(*args, progress=None, cancel=None, **kwargs):
        returns = np.array([[1, 2, 3]], dtype=np.int32)
        progress(RunProgress("scene", 1, 6, 1, 12, 1 / 12, returns))
        live.set()
        while not cancel.wait(0.02):
            pass
        raise Cancelled()

    monkeypatch.setattr(simulation, "simulate", live_then_until_cancelled)
    app = LadarApp(scenario.path)
    async with app.run_test(size=(120, 40)) as pilot:
        await wait_until(pilot, lambda: loaded(app) and app.output_voxels is not None)
        earlier = app.output_voxels
        output = app.query_one("#output3d", ProjectionWidget)
        await pilot.press("f5")
        await wait_until(pilot, lambda: live.is_set() and app.output_voxels is not earlier)
        await pilot.press("escape")
        await wait_until(pilot, lambda: app.busy is None)
        assert app.output_voxels is earlier
        assert output.points is not None and len(output.points)
        assert app.disk_outputs[0] is earlier  # its hidden target voxels are marked again


async def test_the_study_screen_offers_cancel_only_while_a_study_runs(tmp_path, scene_files):
    """Idle, the footer showed '^x Cancel' and the status line 'Ctrl+X cancel', and the
    key did nothing and said nothing."""
    from textual.widgets._footer import FooterKey

    async with study_screen(tmp_path, scene_files, size=(80, 24)) as (app, pilot, screen):
        await pilot.pause()
        shown = {key.action for key in screen.query(FooterKey)}
        assert "cancel" not in shown and {"run('quick')", "close"} <= shown
        assert "Ctrl+X" not in str(screen.query_one("#study-status StatusText").render())


async def test_a_failed_studys_note_writes_out_a_control_character(tmp_path, scene_files, monkeypatch):
    """A study's error naming a file whose name holds a terminal escape reached the
    note raw: every note, not only those told through the app, writes controls out."""
    import ladartui.study.run as study_run
    from ladartui.errors import LadarError

    def failing(*args, **kwargs):
        raise LadarError("cannot read /tmp/bad\x1b[31mname")

    monkeypatch.setattr(study_run, "run_study", failing)
    async with study_screen(tmp_path, scene_files, size=(120, 40)) as (app, pilot, screen):
        await pilot.press("q")
        await wait_until(pilot, lambda: any("Study failed" in note.message for note in app._notifications))
        note = next(note.message for note in app._notifications if "Study failed" in note.message)
        assert note == "Study failed: cannot read /tmp/bad\\x1b[31mname"
