"""Measures of effectiveness on hand-made targets with known answers, and the .cmf file."""

import json
import math
import re
import warnings

import numpy as np
import pytest

from ladartui.cmf import read_cmf
from ladartui.errors import FieldError, InputFileError, OutputFileError
from ladartui.measures import CMF_HEADER, Measures, compute_measures, visible_mask


def box(nx, ny, nz, origin=(0, 0, 0)):
    ox, oy, oz = origin
    return np.array(
        [(ox + i, oy + j, oz + k) for i in range(nx) for j in range(ny) for k in range(nz)], dtype=np.int32
    )


def top_layer(voxels):
    return voxels[voxels[:, 2] == voxels[:, 2].max()]


def test_solid_box_seen_from_straight_above():
    target = box(5, 4, 3, origin=(10, 20, 0))
    top = top_layer(target)
    foliage_and_ground = np.array([[0, 0, 0], [10, 20, 7], [30, 30, 0]])
    measures = compute_measures(target, np.vstack([top, foliage_and_ground]), top)
    # The top layer is 5 x 4 of 60 voxels; foliage and ground returns do not count.
    assert measures.obscured_coverage == pytest.approx(20 / 60)
    assert measures.unobscured_coverage == pytest.approx(20 / 60)
    assert measures.obscured_voxels == measures.unobscured_voxels == 20
    # Symmetric roof coverage: the mean direction is straight up.
    assert measures.obscured_directions.mean_direction == pytest.approx((0.0, 0.0, 1.0), abs=1e-12)
    assert measures.direction_shift_rad == pytest.approx(0.0, abs=1e-6)
    assert measures.missed_share == 0.0
    assert measures.coverage_ratio == 1.0


def test_resultant_length_of_the_roof_computed_by_hand():
    # A 3 x 1 x 2 box: centroid (1, 0, 0.5). Roof voxels (0,0,1), (1,0,1), (2,0,1)
    # point along (-1, 0, 0.5), (0, 0, 0.5), (1, 0, 0.5) from it.
    target = box(3, 1, 2)
    measures = compute_measures(target, top_layer(target), top_layer(target))
    side = 0.5 / math.sqrt(1.25)  # z part of the unit vector (+-1, 0, 0.5)
    expected_z = (side + 1.0 + side) / 3
    assert measures.obscured_directions.mean_vector == pytest.approx((0.0, 0.0, expected_z))
    assert measures.obscured_directions.resultant_length == pytest.approx(expected_z)
    assert measures.obscured_directions.count == 3


def test_maximum_coverage_of_a_solid_box_is_its_surface_share():
    nx, ny, nz = 6, 5, 4
    target = box(nx, ny, nz, origin=(3, 3, 0))
    # Hidden voxels are those with all five neighbours (-z excluded) inside:
    # an interior in x and y, and below the top layer.
    hidden = (nx - 2) * (ny - 2) * (nz - 1)
    measures = compute_measures(target, None, None)
    assert measures.visible_voxels == nx * ny * nz - hidden
    assert measures.maximum_coverage == pytest.approx(1 - hidden / (nx * ny * nz))


def test_maximum_coverage_ignores_the_ground_facing_face_and_other_objects():
    # A 3 x 3 x 1 slab floating at z = 5: every voxel shows its top face, so all
    # are visible, although the centre voxel's only open face besides -z is +z.
    slab = box(3, 3, 1, origin=(0, 0, 5))
    assert visible_mask(slab).all()
    # A 3 x 3 x 3 cube hides the centre voxels of its bottom and middle layers;
    # the open -z face of the bottom one does not count.
    cube = box(3, 3, 3)
    hidden = [tuple(v) for v, seen in zip(cube.tolist(), visible_mask(cube)) if not seen]
    assert sorted(hidden) == [(1, 1, 0), (1, 1, 1)]


def test_single_voxel_target():
    target = np.array([[4, 4, 2]])
    measures = compute_measures(target, target, target)
    assert measures.maximum_coverage == 1.0
    assert measures.obscured_coverage == measures.unobscured_coverage == 1.0
    # The only voxel is the centroid: it has no direction.
    assert measures.obscured_directions.count == 0
    assert measures.obscured_directions.mean_direction is None
    assert measures.direction_shift_rad is None


def test_nothing_seen_and_empty_target_are_undefined_without_warnings():
    target = box(2, 2, 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        nothing = compute_measures(target, np.zeros((0, 3)), np.zeros((0, 3)))
        empty = compute_measures(
            np.zeros((0, 3)),
            np.zeros((0, 3)),
            np.zeros((0, 3)),
            scene_per_scan=[np.zeros((0, 3))],
            target_per_scan=[np.zeros((0, 3))],
        )
    assert nothing.obscured_coverage == 0.0
    assert nothing.obscured_directions.mean_direction is None
    assert nothing.missed_share is None and nothing.coverage_ratio is None
    assert nothing.direction_shift_rad is None
    assert empty.maximum_coverage is None and empty.obscured_coverage is None
    assert empty.obscured_after_scan is None
    for measures in (nothing, empty):
        text = json.dumps(measures.to_dict(), allow_nan=False)
        assert "NaN" not in text
        assert "undefined" in measures.to_cmf()


def test_difference_from_the_ideal_and_direction_shift():
    target = box(4, 4, 2)
    roof = top_layer(target)
    east_side = target[(target[:, 0] == 3)]
    unobscured = np.vstack([roof, east_side])
    obscured = roof[roof[:, 0] >= 2]  # the eastern half of the roof only
    measures = compute_measures(target, obscured, unobscured)
    n_unobscured = len({tuple(v) for v in unobscured.tolist()})
    assert measures.unobscured_voxels == n_unobscured
    assert measures.obscured_voxels == 8
    assert measures.missed_share == pytest.approx((n_unobscured - 8) / n_unobscured)
    assert measures.coverage_ratio == pytest.approx(8 / n_unobscured)
    # The shift is the angle between the two mean directions.
    u = np.array(measures.unobscured_directions.mean_direction)
    o = np.array(measures.obscured_directions.mean_direction)
    assert measures.direction_shift_rad == pytest.approx(math.acos(float(u @ o)))
    assert measures.direction_shift_rad > 0.05
    # Both lean east (+x), since the coverage lies east of the centroid.
    assert u[0] > 0 and o[0] > 0


def test_coverage_after_each_scan_is_cumulative():
    target = box(2, 2, 1)  # four voxels
    scans = [
        np.array([[0, 0, 0], [9, 9, 0]]),
        np.array([[0, 0, 0], [1, 0, 0]]),
        np.zeros((0, 3)),
        np.array([[0, 1, 0], [1, 1, 0]]),
    ]
    ideal = [target, target, target, target]
    measures = compute_measures(
        target,
        np.vstack(scans),
        target,
        scene_per_scan=scans,
        target_per_scan=ideal,
        path_length_m=1200.0,
        flight_time_s=30.0,
    )
    assert measures.obscured_after_scan == (0.25, 0.5, 0.5, 1.0)
    assert measures.unobscured_after_scan == (1.0, 1.0, 1.0, 1.0)
    assert measures.scans == 4
    # 90 % of the final coverage is first reached after the fourth scan.
    assert measures.scans_for_enough == 4
    assert measures.path_length_m == 1200.0 and measures.flight_time_s == 30.0


@pytest.mark.parametrize(
    ("new_per_scan", "after", "enough"),
    [
        # 9 of 10 at scan 2 is exactly 90 % of the final 10 of 10: scan 2, not 3.
        ((4, 5, 1), (0.4, 0.9, 1.0), 2),
        # The goal is 90 % of the final 5 of 10 (4.5 voxels), not of the whole target.
        ((2, 2, 1, 0), (0.2, 0.4, 0.5, 0.5), 3),
        # Reached at the first scan, later scans adding little.
        ((19, 0, 1), None, 1),
    ],
)
def test_scans_for_enough_is_the_first_scan_reaching_90_percent_of_the_final_coverage(
    new_per_scan, after, enough
):
    size = sum(new_per_scan)
    target = box(20 if after is None else 10, 1, 1)
    seen = iter(target.tolist())
    scans = [np.array([next(seen) for _ in range(n)]).reshape(-1, 3) for n in new_per_scan]
    measures = compute_measures(
        target, np.vstack(scans), target, scene_per_scan=scans, target_per_scan=[target] * len(scans)
    )
    counted = np.cumsum(new_per_scan) / len(target)
    assert measures.obscured_after_scan == pytest.approx(tuple(counted))
    if after is not None:
        assert measures.obscured_after_scan == pytest.approx(after)
    # By hand: the first k whose count reaches 0.9 of the final count.
    assert enough == next(k for k, c in enumerate(np.cumsum(new_per_scan), 1) if c >= 0.9 * size)
    assert measures.scans_for_enough == enough
    nothing = compute_measures(
        target, None, target, scene_per_scan=[np.zeros((0, 3))] * 2, target_per_scan=[target] * 2
    )
    assert nothing.obscured_after_scan == (0.0, 0.0) and nothing.scans_for_enough is None


def test_cmf_round_trip(tmp_path):
    target = box(4, 3, 3)
    scans = [top_layer(target)[:5], target[target[:, 1] == 0]]
    measures = compute_measures(
        target,
        np.vstack(scans),
        target[target[:, 2] >= 1],
        scene_per_scan=scans,
        target_per_scan=[target[target[:, 2] >= 1], np.zeros((0, 3))],
        path_length_m=314.159,
        flight_time_s=12.5,
        voxel_size=0.25,
    )
    path = tmp_path / "S.cmf"
    measures.write_cmf(path)
    text = path.read_text()
    assert text.splitlines()[0] == CMF_HEADER
    assert "[3d target model]" in text and "[obscured 3d target output]" in text
    assert "maximum_target_coverage = " in text
    after = measures.obscured_after_scan[1], measures.unobscured_after_scan[1]
    assert f"scan_2 = {after[0]!r}, {after[1]!r}" in text.splitlines()
    assert read_cmf(path) == measures
    empty = compute_measures(np.zeros((0, 3)), None, None)
    empty.write_cmf(path)
    assert read_cmf(path) == empty


def test_a_cmf_that_cannot_be_written_is_named_as_itself(tmp_path):
    # The errors named the temporary file beside it ('.x.cmf.w02usrzc.tmp'), as plain OSErrors.
    measures = compute_measures(box(2, 2, 2), None, None)
    with pytest.raises(OutputFileError) as caught:
        measures.write_cmf(tmp_path)
    assert str(caught.value) == f"{tmp_path}: cannot be written (is a directory)"
    (tmp_path / "file").write_text("")
    with pytest.raises(OutputFileError) as caught:
        measures.write_cmf(tmp_path / "file" / "S.cmf")
    assert str(caught.value) == f"{tmp_path / 'file' / 'S.cmf'}: cannot be written (file exists)"
    assert [p.name for p in tmp_path.iterdir()] == ["file"]


def test_a_cmf_path_that_is_no_path_is_a_field_error():
    # They raised TypeError from pathlib.
    with pytest.raises(FieldError, match=r"^path is not set: expected a measures file's path \(\.cmf\)"):
        compute_measures(box(2, 2, 2), None, None).write_cmf(None)
    with pytest.raises(FieldError, match=r"^path = 3: expected a measures file's path \(\.cmf\)"):
        read_cmf(3)


def test_bad_cmf_names_the_line(tmp_path):
    path = tmp_path / "bad.cmf"
    good = (
        compute_measures(
            box(2, 2, 2),
            box(2, 2, 2),
            box(2, 2, 2),
            scene_per_scan=[box(2, 2, 2)] * 2,
            target_per_scan=[box(2, 2, 2)] * 2,
        )
        .to_cmf()
        .splitlines()
    )
    bad = [line if not line.startswith("target_voxels") else "target_voxels = many" for line in good]
    path.write_text("\n".join(bad) + "\n")
    with pytest.raises(InputFileError) as error:
        read_cmf(path)
    line = bad.index("target_voxels = many") + 1
    assert f"bad.cmf:{line}:" in str(error.value) and "target_voxels" in str(error.value)
    skipped = [line for line in good if not line.startswith("scan_1 ")]
    path.write_text("\n".join(skipped) + "\n")
    with pytest.raises(InputFileError, match="scan_1 missing"):
        read_cmf(path)
    path.write_text("something else\n")
    with pytest.raises(InputFileError, match="bad.cmf:1:"):
        read_cmf(path)


def test_a_cut_off_cmf_names_the_file_line_and_what_it_lacks(tmp_path):
    """A .cmf cut short (a copy stopped part-way) read as a whole run: what it lacked
    showed as 'undefined' in Compare, and a file cut before its first section as a
    target of 0 voxels."""
    two = [box(2, 2, 2)] * 2
    measures = compute_measures(
        box(2, 2, 2),
        box(2, 2, 2),
        box(2, 2, 2),
        scene_per_scan=two,
        target_per_scan=two,
        path_length_m=10.0,
        flight_time_s=0.5,
        voxel_size=0.25,
    )
    lines = measures.to_cmf().splitlines(keepends=True)
    path = tmp_path / "cut.cmf"
    for end in range(1, len(lines)):  # cut after every line but the last
        path.write_text("".join(lines[:end]))
        with pytest.raises(InputFileError, match=rf"^{re.escape(str(path))}:\d+: "):
            read_cmf(path)
    header = lines.index("[comparison]\n") + 1
    path.write_text("".join(lines[: header + 2]))  # its header, the shift and the missed share
    with pytest.raises(InputFileError) as error:
        read_cmf(path)
    assert str(error.value) == f"{path}:{header}: [comparison] lacks coverage_ratio, obscured_only_voxels"
    path.write_text("".join(lines[:7]))  # the first line and the notes under it
    with pytest.raises(InputFileError) as error:
        read_cmf(path)
    assert str(error.value) == f"{path}:7: lacks the [3d target model] section"
    path.write_text("".join(line for line in lines if not line.startswith("scan_1 ")))
    with pytest.raises(InputFileError, match="scan_1 missing"):  # named first, as before
        read_cmf(path)
    path.write_text("".join(line for line in lines if not line.startswith("scan_2 ")))
    with pytest.raises(InputFileError) as error:
        read_cmf(path)
    scans_line = next(i for i, line in enumerate(lines) if line.startswith("scans = ")) + 1
    assert (
        str(error.value)
        == f"{path}:{scans_line}: [coverage after each scan] scans = 2 but 1 scan_k line follows"
    )


@pytest.mark.parametrize(
    ("key", "written", "said"),
    [
        ("target_voxels", "many", "target_voxels: expected an integer, got 'many'"),
        (
            "scans_for_90_percent_of_final",
            "1.5",
            "scans_for_90_percent_of_final: expected an integer, got '1.5'",
        ),
        ("maximum_target_coverage", "most", "maximum_target_coverage: expected a number, got 'most'"),
        ("sample_mean_vector", "1, 2, z", "sample_mean_vector: expected a number, got 'z'"),
        ("scan_2", "a, 0.5", "scan_2: expected a number, got 'a'"),
    ],
)
def test_a_bad_cmf_value_says_what_was_expected(tmp_path, key, written, said):
    """A value that is no number read 'target_voxels: invalid literal for int() with base
    10: 'many'', Python's words, where the levels section says 'expected int, got ...'."""
    good = compute_measures(
        box(2, 2, 2),
        box(2, 2, 2),
        box(2, 2, 2),
        scene_per_scan=[box(2, 2, 2)] * 2,
        target_per_scan=[box(2, 2, 2)] * 2,
    ).to_cmf()
    lines = [f"{key} = {written}" if line.startswith(f"{key} =") else line for line in good.splitlines()]
    path = tmp_path / "bad.cmf"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputFileError) as error:
        read_cmf(path)
    number = lines.index(f"{key} = {written}") + 1
    assert str(error.value) == f"{path}:{number}: {said}"


def test_measures_dict_is_json_safe():
    measures = compute_measures(box(3, 3, 2), top_layer(box(3, 3, 2)), box(3, 3, 2))
    data = json.loads(json.dumps(measures.to_dict(), allow_nan=False))
    assert data["obscured_directions"]["mean_direction"] == pytest.approx([0.0, 0.0, 1.0])
    assert isinstance(Measures(), Measures)


def test_voxel_keys_round_trip_at_the_limits():
    from ladartui.errors import FieldError
    from ladartui.scene.keys import keys_to_voxels, voxel_keys

    voxels = np.array([[0, 0, 0], [2**22 - 2, 5, 2**19 - 2], [7, 2**22 - 2, 3], [1, 2, 3]])
    keys = voxel_keys(voxels)
    np.testing.assert_array_equal(keys_to_voxels(keys), voxels)
    # Keys sort like the voxels, x first.
    assert np.argsort(keys).tolist() == [0, 3, 2, 1]
    with pytest.raises(FieldError, match="voxel index"):
        voxel_keys(np.array([[0, 0, 2**19 - 1]]))


def test_a_huge_figure_is_written_with_an_exponent_not_hundreds_of_digits():
    """A speed of 1e-300 m/s made a flight time of 4e301 s, shown as 300 digits that the
    Results table cut to what read as about 4e13."""
    from ladartui.levels import LevelReached
    from ladartui.measures_compare import format_value
    from ladartui.measures_table import format_number
    from ladartui.number_text import fixed

    huge = 4.0543261909900e301
    assert fixed(huge, 1) == "4.054e+301" and fixed(-huge, 3) == "-4.054e+301"
    assert fixed(12.34, 1) == "12.3" and fixed(9_999_999_999.0, 1) == "9999999999.0"
    assert format_value(huge, "num1") == "4.054e+301" and format_value(huge, "x") == "4.054e+301"
    assert format_number(huge, 1, "s") == "4.054e+301 s"
    reached = LevelReached("detect", True, scan=2, flight_time_s=huge, distance_m=62.8)
    assert reached.describe() == "scan 2, 4.054e+301 s, 62.8 m"


def test_bad_voxel_lists_and_figures_are_field_errors_not_a_wrong_answer():
    """A (K, 2) or float list was reshaped or truncated into other voxels and scored."""
    from ladartui.errors import FieldError

    target = box(3, 2, 1)
    with pytest.raises(FieldError, match=r"^target_model is an array of shape \(6, 2\)"):
        compute_measures(target[:, :2], target, target)
    with pytest.raises(FieldError, match=r"^scene_output is an array of float64"):
        compute_measures(target, target + 0.5, target)
    with pytest.raises(FieldError, match=r"^target_per_scan\[1\] is an array of shape \(1, 2\)"):
        compute_measures(target, target, target, [target, target], [target, target[:1, :2]])
    with pytest.raises(
        FieldError, match=r"^len\(target_per_scan\) = 1: expected as many scans as scene_per_scan \(2\)"
    ):
        compute_measures(target, target, target, [target, target], [target])
    with pytest.raises(FieldError, match=r"^path_length_m = nan"):
        compute_measures(target, target, target, path_length_m=float("nan"))
    with pytest.raises(FieldError, match=r"^voxel_size = -1"):
        compute_measures(target, target, target, voxel_size=-1)


def test_the_same_coverage_in_both_views_has_no_shift():
    """Two voxels of a 5 x 3 x 2 box, seen in both views: the shift read 1.49e-08 rad,
    acos of a dot product a rounding step below 1."""
    from ladartui.directions import angle_between

    target = box(5, 3, 2)
    seen = np.array([[0, 0, 0], [0, 0, 1]])
    measures = compute_measures(target, seen, seen)
    assert measures.direction_shift_rad == 0.0
    # Small angles come out as they are (acos gave 0 for 1e-9 rad, 9.996e-08 for 1e-07).
    for angle in (1e-9, 1e-7, 1e-4, 1.0, math.pi / 2, 3.0):
        tilted = (math.cos(angle), math.sin(angle), 0.0)
        assert angle_between((1.0, 0.0, 0.0), tilted) == pytest.approx(angle, rel=1e-12)
    assert angle_between((0.0, 0.0, 1.0), (0.0, 0.0, -1.0)) == pytest.approx(math.pi, rel=1e-15)


def test_a_cmf_that_is_not_utf8_is_named_on_its_line(tmp_path):
    """It raised UnicodeDecodeError, no LadarError: opening a scenario whose earlier
    measures file was damaged stopped the loading (it should only be noted)."""
    path = tmp_path / "bad.cmf"
    path.write_bytes(CMF_HEADER.encode() + b"\n\n[3d target model]\ntarget_voxels = 8\xff\n")
    with pytest.raises(InputFileError) as error:
        read_cmf(path)
    assert str(error.value).startswith(f"{path}:4: not UTF-8 text (byte 0xff)")


def test_coverage_after_each_scan_never_reads_0_for_a_glimpse_nor_100_short_of_all():
    """The convoy's netted truck read '0 0 0 ... 0 1': 3 of its 816 voxels (0.37 %) were
    seen from scan 2 on, and an analyst read the zeros as never hit."""
    from ladartui.measures_table import comparison_rows
    from ladartui.target_measures import PerTarget, TargetMeasures, after_scan_rows

    curve = (0.0, 3 / 816, 0.005, 0.01, 0.5, 0.99, 0.995, 0.999, 1.0)
    said = "0 <1 <1 1 50 99 >99 >99 100"
    measures = Measures(obscured_after_scan=curve, unobscured_after_scan=curve)
    rows = dict(comparison_rows(measures))
    assert rows["Obscured coverage after each scan"] == said + " (%)"
    assert rows["Unobscured coverage after each scan"] == said + " (%)"
    per_target = PerTarget((TargetMeasures(1, "truck", measures),))
    assert dict(after_scan_rows(per_target))["1 truck"] == said


@pytest.mark.parametrize("per_scan, shown", [(5, "5"), ("abc", "'abc'")])
def test_per_scan_returns_that_are_no_list_are_named(per_scan, shown):
    # 5 raised TypeError: 'int' object is not iterable; text was read letter by letter.
    target = np.array([[0, 0, 0], [1, 0, 0]])
    with pytest.raises(FieldError) as caught:
        compute_measures(target, target, target, scene_per_scan=per_scan)
    assert str(caught.value) == (
        f"scene_per_scan = {shown}: expected a list of each scan's returns, (K, 3) voxel index arrays"
    )


def test_a_figure_halfway_between_two_shown_values_rounds_up_everywhere():
    """A coverage of 5 voxels in 8 (62.5 %) read '62' in the per-scan row beside '62.5 %':
    Python's formatting rounds an exact half to the even digit, so 12.5 showed as 12
    and 61.25 as 61.2. Halves now round away from zero, as a reader rounds them."""
    from ladartui.measures_table import format_number
    from ladartui.number_text import coverage_steps, fixed, fixed_or_tiny

    assert coverage_steps([0.625, 0.125, 0.875, 0.5]) == "63 13 88 50"
    assert fixed(61.25, 1) == "61.3" and fixed(62.5, 0) == "63" and fixed(-0.125, 2) == "-0.13"
    assert fixed(2.675, 2) == "2.67"  # 2.675 is 2.67499999... in binary: no half there
    assert fixed(0.0, 1) == "0.0" and fixed(-0.01, 1) == "-0.0" and fixed(float("nan"), 1) == "nan"
    assert fixed_or_tiny(1234.25, 1, grouped=True) == "1,234.3"
    assert format_number(37.5, 0, "%") == "38 %"
