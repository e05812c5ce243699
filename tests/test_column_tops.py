"""The top view's sparse columns (ladartui.scene.column_tops): the same pictures as the
dense height map, at memory that follows the occupied columns."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from ladartui import views
from ladartui.scene.column_tops import SPARSE_BYTES_PER_VOXEL, SparseTops, map_layout
from ladartui.scene.model import Scene, top_height_map
from ladartui.views import TopView


def _scattered(count, nx, ny, seed, origin=(0, 0)):
    """``count`` voxels in an nx x ny box from ``origin``, some columns held twice."""
    rng = np.random.default_rng(seed)
    voxels = rng.integers(0, [nx, ny, 40], size=(count, 3))
    voxels[: count // 4, :2] = voxels[count // 4 : 2 * (count // 4), :2]  # stacked columns
    voxels[:, :2] += origin
    return voxels.astype(np.int32)


def _both(voxels, nx, ny, origin, **kwargs):
    dense = TopView(top_height_map(voxels, nx, ny, origin), 0.25, origin=origin, **kwargs)
    sparse = TopView(SparseTops.of_voxels(voxels, nx, ny, origin), 0.25, origin=origin, **kwargs)
    return dense, sparse


FRAMES = [
    None,  # the scene
    (0.0, 0.0, 7.3, 5.1),  # zoomed in far: a column is many pixels
    (-20.5, -13.25, 30.75, 22.0),  # wider than the map, its edges inside the window
    (37.2, 11.9, 61.4, 70.0),  # off one side, partly outside
    (200.0, 200.0, 260.0, 230.0),  # beside the map: nothing of it drawn
    (3.0, 4.0, 3.6, 4.2),  # less than a column across
]


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("size", [(24, 40), (7, 3), (61, 97)])
@pytest.mark.parametrize("frame", FRAMES, ids=range(len(FRAMES)))
def test_the_sparse_columns_draw_the_pictures_the_dense_map_draws(seed, size, frame):
    nx, ny, origin = 53, 41, (1_000, 7)
    voxels = _scattered(150, nx, ny, seed, origin)
    dense, sparse = _both(voxels, nx, ny, origin, ground=(1_060, 60))
    if frame is not None:
        frame = (frame[0] + origin[0], frame[1] + origin[1], frame[2] + origin[0], frame[3] + origin[1])
    for colours in ("height", "grey"):
        dense.colour_map = sparse.colour_map = colours
        a, b = dense.scene_layer(*size, frame), sparse.scene_layer(*size, frame)
        np.testing.assert_array_equal(b.mask, a.mask)
        np.testing.assert_array_equal(b.rgb, a.rgb)
    assert sparse.extent == dense.extent and sparse.scene_frame() == dense.scene_frame()


def test_a_full_and_an_empty_map_draw_alike_too():
    full = np.stack(np.meshgrid(np.arange(9), np.arange(6), indexing="ij"), -1).reshape(-1, 2)
    voxels = np.column_stack([full, (full.sum(axis=1) % 5)]).astype(np.int32)
    for held in (voxels, voxels[:0]):
        dense, sparse = _both(held, 9, 6, (0, 0))
        for frame in (None, (-3.0, -2.0, 12.0, 9.0), (1.5, 1.5, 4.0, 3.0)):
            a, b = dense.scene_layer(20, 30, frame), sparse.scene_layer(20, 30, frame)
            np.testing.assert_array_equal(b.rgb, a.rgb)
            np.testing.assert_array_equal(b.mask, a.mask)


def test_surface_points_of_the_sparse_columns_are_the_dense_maps():
    voxels = _scattered(3_000, 400, 300, 4, (50, 60))
    dense = top_height_map(voxels, 400, 300, (50, 60))
    sparse = SparseTops.of_voxels(voxels, 400, 300, (50, 60))
    for limit in (250_000, 5_000, 700):
        np.testing.assert_array_equal(
            views.surface_points(sparse, limit, (50, 60)), views.surface_points(dense, limit, (50, 60))
        )
    assert sparse.max() == dense.max() and SparseTops.of_voxels(voxels[:0], 4, 3).max() == -1


def test_a_wide_box_of_few_voxels_is_kept_sparse_and_its_estimate_bounds_what_is_made():
    """200 voxels over 40,000 x 40,000 columns: the dense map took 12.8 GB (8 bytes a
    column estimated); the sparse columns take 12 bytes a column, and making them
    allocates no more than the estimate the loading check refuses with."""
    assert map_layout(40_000, 40_000, 200) == (False, SPARSE_BYTES_PER_VOXEL * 200)
    for count in (200, 200_000):
        voxels = _scattered(count, 40_000, 40_000, 5)
        voxels[:2, :2] = [[0, 0], [39_999, 39_999]]
        scene = Scene(voxels, voxels[:1], 0.25)
        scene.bounds()
        tracemalloc.start()
        try:
            origin, tops = scene.view_columns()
            _, peak = tracemalloc.get_traced_memory()
        finally:
            tracemalloc.stop()
        assert isinstance(tops, SparseTops) and origin == (0, 0) and tops.shape == (40_000, 40_000)
        assert peak <= SPARSE_BYTES_PER_VOXEL * count + 32_768  # a few small arrays aside
        assert tops.nbytes == 12 * len(np.unique(voxels[:, :2], axis=0))
        assert TopView(tops, 0.25, origin=origin).scene_layer(200, 400).mask.any()


def test_a_picture_of_the_sparse_columns_costs_the_columns_in_its_window(monkeypatch):
    """A window holding a few of 200,000 columns pools those only, not the box's."""
    voxels = _scattered(200_000, 40_000, 40_000, 6)
    tops = SparseTops.of_voxels(voxels, 40_000, 40_000)
    pooled = []
    maximum_at = np.maximum.at
    monkeypatch.setattr(np.maximum, "at", lambda a, i, v: (pooled.append(len(v)), maximum_at(a, i, v)))
    top = TopView(tops, 0.25)
    assert top.scene_layer(100, 200).mask.any()
    # the whole scene: every column once, the edge ones again for the margin's pixels
    assert len(tops.keys) <= pooled[-1] <= len(tops.keys) + 4 * 100 * 200
    top.scene_layer(100, 200, (10_000.0, 10_000.0, 10_400.0, 10_200.0))
    inside = (voxels[:, 0] >= 10_000) & (voxels[:, 0] < 10_400) & (voxels[:, 1] >= 10_000)
    assert pooled[-1] <= 4 * int((inside & (voxels[:, 1] < 10_200)).sum()) + 4 * 100 * 200


def test_a_box_the_voxels_fill_or_a_small_one_stays_dense():
    assert map_layout(2_000, 2_000, 2) == (True, 8 * 2_000 * 2_000)  # 32 MB: cheap
    assert map_layout(4_000, 4_000, 4_000_000) == (True, 8 * 16_000_000)  # the voxels fill it
    assert map_layout(4_000, 4_000, 3_000_000)[0] is False
    small = Scene(np.array([[3, 4, 1], [5, 9, 2]], np.int32), np.array([[3, 4, 1]], np.int32), 1.0)
    origin, tops = small.view_columns()
    assert origin == (3, 4) and isinstance(tops, np.ndarray) and tops.shape == (3, 6)
