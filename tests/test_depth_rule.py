"""The detector depth-resolution rule (report section 7.4) on hand-made detectors."""

import numpy as np
import pytest

from ladartui.returns import apply_depth_resolution, fuse_scans, kept_returns, scan_returns, unique_voxels
from ladartui.tracing.backend import GROUND, MISS, VOXEL


def kept(detector, kind, ranges, depth):
    mask = apply_depth_resolution(
        np.array(detector, dtype=np.int32),
        np.array(kind, dtype=np.uint8),
        np.array(ranges, dtype=np.float64),
        depth,
    )
    return sorted(np.flatnonzero(mask).tolist())


def test_one_detector_keeps_returns_spaced_by_the_depth_resolution():
    # Ranges 10, 10.4, 11.0, 11.5, 12.1: keep 10; 10.4 is 0.4 behind it (dropped);
    # 11.0 is 1.0 behind (kept, resolution reached exactly); 11.5 is 0.5 behind
    # 11.0 (dropped); 12.1 is 1.1 behind 11.0 (kept).
    ranges = [11.5, 10.0, 12.1, 10.4, 11.0]
    assert kept([0] * 5, [VOXEL] * 5, ranges, 1.0) == [1, 2, 4]


def test_spacing_is_measured_from_the_last_kept_return_not_the_last_seen():
    # 0.6 apart each: 20.0 kept, 20.6 dropped, 21.2 kept (1.2 from 20.0),
    # 21.8 dropped, 22.4 kept.
    ranges = [20.0, 20.6, 21.2, 21.8, 22.4]
    assert kept([3] * 5, [VOXEL] * 5, ranges, 1.0) == [0, 2, 4]


def test_detectors_are_independent_and_misses_never_return():
    detector = [0, 0, 0, 1, 1, 1, 2, 2]
    kind = [VOXEL, MISS, VOXEL, MISS, GROUND, VOXEL, MISS, MISS]
    ranges = [5.0, np.inf, 5.5, np.inf, 30.0, 29.2, np.inf, np.inf]
    # detector 0: 5.0 kept, 5.5 dropped; detector 1: 29.2 kept, ground at 30.0
    # is 0.8 behind (dropped); detector 2: only misses, nothing.
    assert kept(detector, kind, ranges, 1.0) == [0, 5]
    # With a finer resolution the ground return survives: it is a return.
    assert kept(detector, kind, ranges, 0.5) == [0, 2, 4, 5]


def test_detectors_need_not_come_grouped():
    detector = [7, 2, 7, 2, 7]
    ranges = [3.0, 8.0, 1.0, 8.2, 2.5]
    # detector 7: 1.0 kept, 2.5 kept, 3.0 dropped; detector 2: 8.0 kept, 8.2 dropped.
    assert kept(detector, [VOXEL] * 5, ranges, 1.2) == [1, 2, 4]


def test_equal_ranges_keep_the_earliest_ray():
    assert kept([0, 0, 0], [VOXEL] * 3, [4.0, 4.0, 4.0], 1.0) == [0]
    # Zero resolution keeps every return, equal ranges included.
    assert kept([0, 0, 0], [VOXEL] * 3, [4.0, 4.0, 4.0], 0.0) == [0, 1, 2]


def reference_rule(detector, kind, ranges, depth):
    """A plain re-statement of the rule, one detector at a time."""
    keep = np.zeros(len(detector), dtype=bool)
    rays_of: dict[int, list[int]] = {}
    for i, d in enumerate(detector.tolist()):
        if kind[i] != MISS:
            rays_of.setdefault(d, []).append(i)
    for rays in rays_of.values():
        rays.sort(key=lambda i: (ranges[i], i))
        last = None
        for i in rays:
            if last is None or ranges[i] - last >= depth:
                keep[i] = True
                last = ranges[i]
    return keep


@pytest.mark.parametrize("rays_per_detector", [1, 16, 100])
@pytest.mark.parametrize("shuffle", [False, True])
def test_matches_a_plain_restatement_on_random_scans(rays_per_detector, shuffle):
    rng = np.random.default_rng(rays_per_detector)
    detector = np.repeat(np.arange(40, dtype=np.int32), rays_per_detector)
    n = detector.size
    kind = rng.choice([MISS, VOXEL, GROUND], size=n).astype(np.uint8)
    # Quantised ranges so that ties and exact-resolution gaps occur.
    ranges = np.round(rng.uniform(0, 6, size=n), 1)
    ranges[kind == MISS] = np.inf
    if shuffle:
        order = rng.permutation(n)
        detector, kind, ranges = detector[order], kind[order], ranges[order]
    got = apply_depth_resolution(detector, kind, ranges, 0.5)
    np.testing.assert_array_equal(got, reference_rule(detector, kind, ranges, 0.5))


def test_empty_scan():
    assert apply_depth_resolution(np.zeros(0, np.int32), np.zeros(0, np.uint8), np.zeros(0), 1.0).shape == (
        0,
    )


class FakeTrace:
    def __init__(self, kind, index, ranges):
        self.kind = np.array(kind, dtype=np.uint8)
        self.index = np.array(index, dtype=np.int32).reshape(-1, 3)
        self.range = np.array(ranges, dtype=np.float64)


def test_scan_returns_are_the_kept_voxels_once_each():
    hits = FakeTrace(
        [VOXEL, VOXEL, GROUND, VOXEL, MISS],
        [[1, 2, 3], [1, 2, 4], [5, 5, 0], [1, 2, 3], [-1, -1, -1]],
        [10.0, 10.3, 20.0, 12.0, np.inf],
    )
    # detector 0 keeps (1,2,3) at 10.0 and drops (1,2,4); detector 1 keeps the
    # ground cell and (1,2,3) again at 12.0; the scan returns each voxel once.
    returns = scan_returns(hits, np.array([0, 0, 1, 1, 1]), 1.0)
    assert returns.dtype == np.int32
    assert sorted(map(tuple, returns.tolist())) == [(1, 2, 3), (5, 5, 0)]


def test_fusion_is_the_union_of_the_scans():
    first = np.array([[0, 0, 0], [2, 1, 3]])
    second = np.array([[2, 1, 3], [4, 0, 1], [0, 0, 0]])
    third = np.zeros((0, 3), dtype=np.int32)
    fused = fuse_scans([first, second, third])
    assert sorted(map(tuple, fused.tolist())) == [(0, 0, 0), (2, 1, 3), (4, 0, 1)]
    assert fuse_scans([]).shape == (0, 3)
    assert unique_voxels(np.array([[3, 2, 1], [3, 2, 1]])).tolist() == [[3, 2, 1]]


@pytest.mark.parametrize("rays_per_detector", [1, 16])
def test_a_whole_scan_split_into_parallel_parts_matches_the_plain_restatement(rays_per_detector):
    # Big enough (>= 2**14 rays) for the parts path; detectors of unequal sizes too.
    rng = np.random.default_rng(7 + rays_per_detector)
    sizes = rng.integers(1, 2 * rays_per_detector + 1, size=40_000 // rays_per_detector)
    detector = np.repeat(np.arange(sizes.size, dtype=np.int64), sizes)
    n = detector.size
    assert n >= 2**14
    kind = rng.choice([MISS, VOXEL, GROUND], size=n).astype(np.uint8)
    ranges = np.round(rng.uniform(0, 6, size=n), 1)
    ranges[kind == MISS] = np.inf
    expected = reference_rule(detector, kind, ranges, 0.5)
    np.testing.assert_array_equal(apply_depth_resolution(detector, kind, ranges, 0.5), expected)
    # in ray order within parts, parts in order: the same indices a single pass gives
    kept_rays = kept_returns(detector, kind, ranges, 0.5)
    assert sorted(kept_rays.tolist()) == np.flatnonzero(expected).tolist()
    assert np.all(np.diff(detector[kept_rays]) >= 0)


def test_fusing_sorted_scans_and_unsorted_ones_gives_the_same_union():
    rng = np.random.default_rng(4)
    scans = [unique_voxels(rng.integers(0, 50, size=(400, 3))) for _ in range(6)]
    fused = fuse_scans(scans)  # each sorted: merged
    raw = fuse_scans([s[::-1] for s in scans])  # each reversed: sorted from scratch
    assert np.array_equal(fused, raw)
    assert np.array_equal(fused, np.unique(np.concatenate(scans), axis=0))
