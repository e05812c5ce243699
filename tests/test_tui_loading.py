"""Opening a scenario whose scene cannot be held: refused in one line, as validate and
run refuse it, and the scenario open before stays."""

from __future__ import annotations

import numpy as np

from ladartui.scene.voxels import save_voxels
from test_tui_dialogs import opened
from test_tui_flow import make_scenario, wait_until


async def refusal_on_opening(tmp_path, scene_files, monkeypatch, voxels, limit) -> tuple[str, object]:
    """The app's message on opening a scenario whose scene holds ``voxels`` (its target
    the first) under a memory limit of ``limit`` bytes; the scene model's path."""
    scenario = make_scenario(tmp_path, scene_files)
    scene = tmp_path / "far.txt"
    save_voxels(scene, np.array(voxels, np.int32))
    save_voxels(tmp_path / "far_Target.txt", np.array(voxels[:1], np.int32))
    far = scenario.with_changes(path=tmp_path / "far.toml", scene_file=scene).save()
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(limit))
        app.open_path(far.path)
        await wait_until(
            pilot, lambda: app.busy is None and (app.messages or app.scenario.path == far.path), 60
        )
        assert app.scenario.path == scenario.path  # the one open before stays
        return [m for m in app.messages if "Could not load" in m][-1], scene


async def test_a_scene_too_large_for_memory_is_refused_with_its_estimate(tmp_path, scene_files, monkeypatch):
    """Two voxels 20 million apart: the views' height map was allocated whatever its size,
    and a wider scene ended in numpy's 'Unable to allocate 44.7 GiB for an array with
    shape (2000000001, 6) and data type int32', naming no file."""
    voxels = [[1, 2, 3], [20_000_000, 5, 5]]
    said, scene = await refusal_on_opening(tmp_path, scene_files, monkeypatch, voxels, 100 * 2**20)
    assert f"{scene}: 2 voxels spanning" in said and "crop the scene or use a coarser voxel size" in said


async def test_a_small_scene_far_from_the_origin_is_refused_for_its_views(tmp_path, scene_files, monkeypatch):
    """Two neighbouring voxels 40 million voxels from the origin: the tracing structures
    follow the voxels and fit, but the views' height map spans every column from the
    origin (160 MB here), and was allocated unchecked."""
    voxels = [[40_000_000, 0, 0], [40_000_001, 0, 0]]
    said, scene = await refusal_on_opening(tmp_path, scene_files, monkeypatch, voxels, 100 * 10**6)
    assert f"{scene}: the views' height map of 40,000,002 x 1 columns needs about" in said
    assert "crop the scene to where its voxels are, or use a coarser voxel size" in said
