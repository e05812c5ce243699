"""Opening a scenario whose scene cannot be held: refused in one line, as validate and
run refuse it, and the scenario open before stays."""

from __future__ import annotations

import numpy as np

from ladartui.scene.voxels import save_voxels
from tui_support import make_scenario, opened, wait_until


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
    shape (2000000001, 6) and data type int32', naming no file. (Apart on x alone they now
    fit: their column tops are left out; apart on y too, the root grid is 5.7 GiB.)"""
    voxels = [[1, 2, 3], [20_000_000, 20_000_000, 5]]
    said, scene = await refusal_on_opening(tmp_path, scene_files, monkeypatch, voxels, 100 * 2**20)
    assert f"{scene}: 2 voxels spanning" in said and "crop the scene or use a coarser voxel size" in said


async def test_a_small_scene_far_from_the_origin_opens_with_views_on_its_voxels(tmp_path, scene_files):
    """Two neighbouring voxels 40 million voxels from the origin: the views' height map
    spanned every column from the origin (320 MB here) and such a scene was refused
    under a memory limit that run traces it in. The map now spans the voxels' columns."""
    from ladartui.tui.canvas import TopViewWidget

    scenario = make_scenario(tmp_path, scene_files)
    voxels = np.array([[40_000_000, 7, 0], [40_000_001, 7, 3]], np.int32)
    save_voxels(tmp_path / "far.txt", voxels)
    save_voxels(tmp_path / "far_Target.txt", voxels[:1])
    far = scenario.with_changes(path=tmp_path / "far.toml", scene_file=tmp_path / "far.txt").save()
    async with opened(far, size=(80, 24)) as (app, pilot):
        top = app.query_one(TopViewWidget).top
        assert top.heights.shape == (2, 1) and top.heights.tolist() == [[0], [3]]
        assert top.scene_frame() == (40_000_000.0, 7.0, 40_000_002.0, 8.0)
        lo, hi = app.query_one("#views").prepared["bounds"]
        assert lo.tolist() == [40_000_000, 7, 0] and hi.tolist() == [40_000_001, 7, 3]


def sparse_voxels(count=200, side=40_000, levels=4_000, seed=5) -> np.ndarray:
    """``count`` random voxels over a ``side`` x ``side`` x ``levels`` box, its corners held."""
    rng = np.random.default_rng(seed)
    voxels = rng.integers(0, [side, side, levels], size=(count, 3))
    voxels[:2, :2] = [[0, 0], [side - 1, side - 1]]
    return voxels.astype(np.int32)


async def test_a_sparse_scene_over_a_wide_box_opens_with_views_that_cost_its_columns(
    tmp_path, scene_files, monkeypatch
):
    """200 voxels over 40,000 x 40,000 columns (10 km at 0.25 m): the top view kept one
    8-byte entry a column of the box, and under 1 GB the scene was refused ('the views'
    height map of 40,000 x 40,000 columns needs about 11.9 GiB') though run traces it in
    about 100 MB. The view now keeps the occupied columns only."""
    from ladartui.tui.canvas import TopViewWidget

    voxels = sparse_voxels()
    scenario = make_scenario(tmp_path, scene_files)
    save_voxels(tmp_path / "wide.txt", voxels)
    save_voxels(tmp_path / "wide_Target.txt", voxels[2:3])
    wide = scenario.with_changes(path=tmp_path / "wide.toml", scene_file=tmp_path / "wide.txt").save()
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(10**9))
        app.open_path(wide.path)
        await wait_until(
            pilot, lambda: app.busy is None and (app.messages or app.scenario.path == wide.path), 60
        )
        assert [m for m in app.messages if "Could not load" in m] == []
        assert app.scenario.path == wide.path
        from ladartui.scene.column_tops import SparseTops

        top = app.query_one(TopViewWidget).top
        assert isinstance(top.heights, SparseTops) and top.heights.shape == (40_000, 40_000)
        assert len(top.heights.keys) == len(np.unique(voxels[:, :2], axis=0))
        assert top.heights.nbytes <= 12 * len(voxels)
        assert top.scene_frame() == (0.0, 0.0, 40_000.0, 40_000.0)
        assert top.renders >= 1 and top.scene_layer(48, 96).mask.any()


async def test_a_scene_whose_views_cannot_be_held_is_refused_with_their_estimate(
    tmp_path, scene_files, monkeypatch
):
    """Two voxels at opposite corners of a flat 2,001 x 2,001 column square: the tracing
    structures fit in 20 MB, the views' height map (8 bytes a column, 30.5 MiB) does not."""
    voxels = [[0, 0, 0], [2_000, 2_000, 0]]
    said, scene = await refusal_on_opening(tmp_path, scene_files, monkeypatch, voxels, 20 * 2**20)
    assert f"{scene}: the views' height map of 2,001 x 2,001 columns needs about 30.5 MiB" in said
    assert "crop the scene or use a coarser voxel size" in said
