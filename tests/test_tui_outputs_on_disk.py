"""Outputs on disk while the app has them open: another run's outputs shown, not the
old ones, and their loss told; Save As not taken for another run; earlier outputs read
off the UI thread (the target output too), with one look at each file.

Pilot tests on a tiny generated scene.
"""

from __future__ import annotations

from tui_support import SIZE, LadarApp, loaded, make_scenario, wait_until


async def test_outputs_another_run_writes_on_disk_are_shown_not_the_old_ones(tmp_path, scene_files):
    """A second instance (or the CLI) ran the same file: this one kept showing its own
    measures as current, and Export LAS wrote the other run's files under them."""
    from ladartui.sensor import Sensor
    from ladartui.simulation import simulate
    from ladartui.tui.status import NOT_READY, StatusBar

    scenario = make_scenario(tmp_path, scene_files)
    simulate(scenario)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app) and app.measures is not None)
        app.check_outputs_on_disk()  # nothing changed: nothing happens
        assert not app.outputs_stale() and not any("changed on disk" in m for m in app.messages)
        simulate(scenario.with_changes(sensor=Sensor(grid=12, ray_grid=1, fov=8.0)))  # elsewhere
        app.check_outputs_on_disk()
        await wait_until(pilot, lambda: app.outputs_from is not None and app.outputs_from.sensor.grid == 12)
        assert app.query_one(StatusBar).state == NOT_READY  # out of date for this file's settings
        assert any("changed on disk" in m for m in app.messages)
        scenario.measures_file.unlink()  # gone: said, and named in the status bar
        app.check_outputs_on_disk()
        await pilot.pause()
        assert any("gone from disk" in m for m in app.messages)
        assert "outputs missing" in app.query_one(StatusBar).message


async def test_save_as_is_not_taken_for_another_run(tmp_path, scene_files):
    """After Save As the outputs compared were the old name's: a note said another run
    had changed them."""
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files)
    simulate(scenario)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app) and app.measures is not None)
        assert app._save_to(tmp_path / "copy.toml")
        app.check_outputs_on_disk()
        await pilot.pause()
        assert not any("changed on disk" in m or "gone from disk" in m for m in app.messages)


def count_output_stats(monkeypatch, scenario) -> dict:
    """How often each output file's status is asked (``stat``, which ``is_file`` uses)."""
    from pathlib import Path

    outputs = (scenario.scene_output, scenario.target_output, scenario.measures_file)
    stats = dict.fromkeys(outputs, 0)
    real_stat = Path.stat

    def stat(self, *args, **options):
        if self in stats:
            stats[self] += 1
        return real_stat(self, *args, **options)

    monkeypatch.setattr(Path, "stat", stat)
    return stats


async def test_earlier_outputs_are_read_off_the_ui_thread_target_output_too(
    tmp_path, scene_files, monkeypatch
):
    """The target output of an earlier run (what marks the target voxels the foliage
    hid) was read by the view on the UI thread, and its file looked at on every redraw."""
    import threading
    from pathlib import Path

    import numpy as np

    from ladartui.scene import voxels as voxel_files
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files)
    simulate(scenario)
    real_load, reads = voxel_files.load_voxels, []

    def load_voxels(path, *args, **options):
        reads.append((Path(path).name, threading.current_thread() is threading.main_thread()))
        return real_load(path, *args, **options)

    monkeypatch.setattr(voxel_files, "load_voxels", load_voxels)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app) and app.measures is not None)
        app.show_output()
        app.show_output()
        await pilot.pause()
        target_output = app.view_area._known_target_output(app.output_voxels)
        assert np.array_equal(target_output, real_load(scenario.target_output))
    assert (scenario.target_output.name, False) in reads
    assert not [name for name, on_ui_thread in reads if on_ui_thread and "Target" in name], reads


async def test_earlier_outputs_are_shown_from_one_stat_of_each_file(tmp_path, scene_files, monkeypatch):
    """Opening a file with outputs asked each output's status twice or three times (to
    read them, to name a partial set, to note those shown), and an on-disk change up
    to six times. Now: one look at the set, and the reader's own check that the file
    is no pipe before it opens it (the target output is read too, for the view)."""
    from ladartui.sensor import Sensor
    from ladartui.simulation import simulate

    scenario = make_scenario(tmp_path, scene_files)
    simulate(scenario)
    # (the app's own look every 2 s would add a stat whenever a tick fell in the waits)
    monkeypatch.setattr("ladartui.tui.app.OUTPUTS_CHECK_SECONDS", 3600.0)
    stats = count_output_stats(monkeypatch, scenario)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app) and app.measures is not None)
        assert list(stats.values()) == [2, 2, 2]
        simulate(scenario.with_changes(sensor=Sensor(grid=12, ray_grid=1, fov=8.0)))  # elsewhere
        stats.update(dict.fromkeys(stats, 0))
        app.check_outputs_on_disk()
        await wait_until(pilot, lambda: app.outputs_from is not None and app.outputs_from.sensor.grid == 12)
        assert list(stats.values()) == [2, 2, 2]
        status = scenario.measures_file.stat()
        assert app.outputs_seen == (status.st_mtime_ns, status.st_size)  # those shown, as on disk
