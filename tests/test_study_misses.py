"""The miss classes' shares: over the differing rays a class can describe, as the
shares of all voxel hits they are set against are."""

from __future__ import annotations

import csv
import io

from ladartui.study import MissSummary, Setting, StudyResult, StudyRow


def _march_misses() -> MissSummary:
    # 10 rays, every one diagonal; 8 hit a voxel. 4 differ, 2 of them ground or miss on
    # both sides (no feature voxel, so no class): both of the other 2 are thin.
    return MissSummary(
        rays=10,
        voxel_rays=8,
        differing=4,
        later=4,
        no_voxel=2,
        classes={"thin": 2, "diagonal": 2, "grazing": 0, "edge": 1},
        base={"thin": 4, "diagonal": 8, "grazing": 0, "edge": 1},
    )


def test_a_class_share_counts_the_differing_rays_that_have_a_feature_voxel():
    """docs/study.md read 'thin 34 % against 34 %' for the march at step 1 and concluded it
    errs wherever samples fall, and every ray was diagonal yet diagonal read 73 % against
    100 %: the differing rays with no voxel on either side, which no class can hold,
    counted in the share and not in the one it is set against."""
    misses = _march_misses()
    said = misses.describe()
    assert "thin 100% (all rays 50%)" in said and "diagonal 100% (all rays 100%)" in said
    row = StudyRow(Setting("numba", "march", "f64", 1.0, 1), rays_per_scan=10, scans=1, misses=misses)
    (record,) = csv.DictReader(io.StringIO(StudyResult([row]).to_csv()))
    assert float(record["thin_share"]) == 1.0 and float(record["diagonal_share"]) == 1.0
    assert float(record["thin_all_rays_share"]) == 0.5 and float(record["diagonal_all_rays_share"]) == 1.0
    assert misses.class_share("edge") == 0.5 and misses.base_share("edge") == 0.125


def test_no_class_share_where_no_differing_ray_has_a_feature_voxel():
    misses = MissSummary(rays=4, voxel_rays=0, differing=2, no_voxel=2)
    assert misses.class_share("thin") is None and misses.base_share("thin") is None
    row = StudyRow(Setting("numba", "march", "f64", 1.0, 1), rays_per_scan=4, scans=1, misses=misses)
    (record,) = csv.DictReader(io.StringIO(StudyResult([row]).to_csv()))
    assert record["thin_share"] == "" and record["thin_all_rays_share"] == ""
