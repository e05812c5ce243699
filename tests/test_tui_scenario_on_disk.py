"""The scenario file changed on disk while it is open: Run is refused until it is
reopened or saved over, and the status bar says so; the same bytes written again
(or only touched) change nothing."""

from __future__ import annotations

import os

from ladartui.tui.status import NOT_READY, READY, StatusBar
from test_tui_edits import capture_runs
from tui_support import make_scenario, opened, wait_until


def bar(app) -> StatusBar:
    return app.query_one(StatusBar)


async def look_at_disk(app, pilot) -> None:
    """The app's timed look at the files on disk, now, and its status redrawn."""
    app.check_outputs_on_disk()
    await pilot.pause()


async def change_on_disk(app, pilot, scenario) -> None:
    """The scenario file edited elsewhere (grid 8 to 12), and the app's look at it."""
    text = scenario.path.read_text(encoding="utf-8")
    scenario.path.write_text(text.replace("grid = 8", "grid = 12"), encoding="utf-8")
    await look_at_disk(app, pilot)


async def test_run_is_refused_while_the_scenario_file_changed_on_disk(tmp_path, scene_files):
    """F5 ran the settings held in the app and recorded them as the file's run, while the
    file on disk said otherwise: validate then called the fresh outputs out of date."""
    scenario = make_scenario(tmp_path, scene_files)  # an 8 x 8 grid
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        runs = capture_runs(app)
        text = scenario.path.read_text(encoding="utf-8")
        stamp = scenario.path.stat().st_mtime_ns
        os.utime(scenario.path, ns=(stamp + 10**9, stamp + 10**9))  # touched: no change
        await look_at_disk(app, pilot)
        assert bar(app).state == READY
        scenario.path.write_text(text.replace("grid = 8", "grid = 12"), encoding="utf-8")
        await look_at_disk(app, pilot)
        said = f"{scenario.path.name} changed on disk; reopen (F3) or save (^S)"
        assert bar(app).state == NOT_READY
        assert bar(app).message == said
        assert any(said in m for m in app.messages)  # told once, as it is found
        await pilot.press("f5")
        await pilot.pause()
        assert runs == []
        assert app.messages[-1] == f"Run is off: {said}."
        scenario.path.write_text(text, encoding="utf-8")  # put back as it was opened
        await look_at_disk(app, pilot)
        assert bar(app).state == READY
        await pilot.press("f5")
        await pilot.pause()
        assert [run.sensor.grid for run in runs] == [8]


async def test_saving_over_a_scenario_changed_on_disk_makes_it_runnable_again(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        runs = capture_runs(app)
        await change_on_disk(app, pilot, scenario)
        assert bar(app).state == NOT_READY
        await pilot.press("ctrl+s")
        await pilot.pause()
        await look_at_disk(app, pilot)
        assert bar(app).state == READY
        assert "grid = 8" in scenario.path.read_text(encoding="utf-8")
        await pilot.press("f5")
        await pilot.pause()
        assert [run.sensor.grid for run in runs] == [8]


async def test_a_scenario_file_gone_from_disk_is_said_so_and_save_writes_it_again(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        runs = capture_runs(app)
        scenario.path.unlink()
        await look_at_disk(app, pilot)
        assert bar(app).state == NOT_READY
        assert bar(app).message == f"{scenario.path.name} is gone from disk; save it (^S)"
        await pilot.press("f5")
        await pilot.pause()
        assert runs == []
        await pilot.press("ctrl+s")
        await wait_until(pilot, lambda: scenario.path.is_file())
        await look_at_disk(app, pilot)
        assert bar(app).state == READY


async def test_reopening_a_scenario_changed_on_disk_reads_it(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        await change_on_disk(app, pilot, scenario)
        assert bar(app).state == NOT_READY
        app.open_path(scenario.path)
        await wait_until(pilot, lambda: app.busy is None and app.scenario.sensor.grid == 12)
        await look_at_disk(app, pilot)
        assert bar(app).state == READY


async def test_a_study_of_a_scenario_changed_on_disk_says_what_it_reads(tmp_path, scene_files):
    """F11 studies the file on disk: changed there since it was opened, it studied other
    settings than those shown with no word of it (edits made here were said)."""
    from ladartui.tui.study_screen import StudyScreen

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        await change_on_disk(app, pilot, scenario)
        await pilot.press("f11")
        await wait_until(pilot, lambda: isinstance(app.screen, StudyScreen) and app.screen.is_mounted)
        assert app.messages[-1] == (
            "The study reads demo.toml as it is on disk, not as shown here; save (Ctrl+S) first "
            "to study what is shown."
        )


def killed_mid_swap(scenario) -> None:
    """A run of ``scenario`` killed between its renames: the new scene output in place,
    the old target output aside under the journal."""
    import signal
    import subprocess
    import sys

    from test_output_kill import PAUSING_RUN

    held = PAUSING_RUN.replace("time.sleep(0.5)", "time.sleep(120)")  # until killed, however slow
    run = subprocess.Popen(
        [sys.executable, "-c", held, "swap", "2", str(scenario.path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert run.stdout.readline().strip() == "paused"
    run.send_signal(signal.SIGKILL)
    run.communicate(timeout=60)
    assert not scenario.target_output.exists()  # aside, under the journal


STOPPED = (
    "the last run was stopped while it replaced the outputs; F5 runs and puts the earlier set back first."
)


async def test_outputs_a_killed_run_left_half_replaced_are_not_read_as_a_run(tmp_path, scene_files):
    """A run killed between its renames leaves the new scene output, the old target output
    aside under the journal: the TUI read them as a run's ("outputs missing
    (S_Target.txt); F5 runs and writes them") though validate said they are not to be read."""
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files)
    simulate(scenario)  # the earlier set
    killed_mid_swap(scenario)
    async with opened(scenario) as (app, pilot):
        assert bar(app).state == NOT_READY
        assert bar(app).message == f"demo.toml: {STOPPED}"
        assert app.output_voxels is None and app.missing_outputs == []
        # a run puts the earlier set back as it takes the lock; cancelled after, its
        # outputs are the earlier set's again, read and shown (the bar said so until F5)
        from ladartui.outputset import recover

        assert recover(app_journal(scenario))
        app.run_finished(cancelled=True)
        await wait_until(pilot, lambda: app.output_voxels is not None, timeout=30)
        assert not app.outputs_interrupted and STOPPED not in bar(app).message


async def test_a_run_killed_mid_swap_while_the_app_is_open_is_told(tmp_path, scene_files):
    """Another run of the file killed between its renames while the app had it open: the
    bar stayed green (the measures file had not moved), or a note said the outputs
    'changed on disk: shown as they are now' of files it did not read."""
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files)
    simulate(scenario)
    async with opened(scenario) as (app, pilot):
        await look_at_disk(app, pilot)
        assert bar(app).state == READY
        shown = app.output_voxels
        killed_mid_swap(scenario)
        await look_at_disk(app, pilot)
        assert (bar(app).state, bar(app).message) == (NOT_READY, f"demo.toml: {STOPPED}")
        assert any("was stopped while it replaced the outputs" in m for m in app.messages)
        assert app.output_voxels is shown  # the earlier set's, read before: the run puts it back


def app_journal(scenario):
    from ladartui.outputset import journal_path
    from ladartui.simulation import output_lock

    return journal_path(output_lock(scenario))
