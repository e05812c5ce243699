"""Detect / recognise / identify: the rule on constructed curves, the spatial variant on a
hand-made target, a real tiny run, the [levels] scenario section and the .cmf lines."""

import json
import math
import textwrap

import numpy as np
import pytest

from ladartui.cli import main
from ladartui.cmf import read_cmf
from ladartui.errors import FieldError, InputFileError
from ladartui.levels import (
    NOT_REACHED,
    LevelThresholds,
    levels_from_curves,
    share_curves,
    target_levels,
)
from ladartui.measures import Measures, visible_mask
from ladartui.scenario import load_scenario
from tiny_sweep import write_tiny_scenario

TIMES = [0.0, 2.0, 4.0, 6.0, 8.0]
DISTANCES = [0.0, 60.0, 120.0, 180.0, 240.0]


def reached(result):
    return {item.level: item.scan for item in result.levels}


# -- the rule on constructed curves -----------------------------------------------------


def test_each_level_is_reached_at_the_first_scan_crossing_both_thresholds():
    thresholds = LevelThresholds(0.1, 0.3, 0.5, 0.1, 0.5, 0.75)
    voxels = [0.05, 0.2, 0.35, 0.6, 0.7]
    footprint = [0.1, 0.4, 0.45, 0.5, 0.8]  # holds recognise back to scan 4, identify to 5
    result = levels_from_curves(voxels, footprint, TIMES, DISTANCES, thresholds)
    assert reached(result) == {"detect": 2, "recognise": 4, "identify": 5}
    detect, recognise, identify = result.levels
    assert (detect.flight_time_s, detect.distance_m) == (2.0, 60.0)
    assert (recognise.flight_time_s, recognise.distance_m) == (6.0, 180.0)
    assert (identify.flight_time_s, identify.distance_m) == (8.0, 240.0)
    assert result.visible_share == 0.7 and result.footprint_share == 0.8
    assert identify.describe() == "scan 5, 8.0 s, 240.0 m"
    assert result.highest is identify


def test_counts_in_the_run_tables_have_thousands_separators():
    """The convoy's levels title read 'of 1124 visible voxels', its voxels row '1124 of 2424'."""
    import dataclasses

    from rich.console import Console

    from ladartui.cli.run import levels_table
    from ladartui.measures_table import view_rows

    result = levels_from_curves([0.5], [0.6], [0.0], [0.0])
    result = dataclasses.replace(result, visible_voxels=1124, footprint_cells=1600)
    console = Console(width=200, record=True)
    console.print(levels_table(result))
    title = " ".join(console.export_text().split())  # the title wraps to the table's width
    assert "Levels: 50.0 % of 1,124 visible voxels, 60.0 % of 1,600 footprint cells seen" in title
    measures = Measures(visible_voxels=1124, target_voxels=2424, unobscured_voxels=1001, obscured_voxels=574)
    assert view_rows(measures)[1] == ("Voxels", "1,124 of 2,424", "1,001", "574")


def test_a_share_equal_to_its_threshold_reaches_it_and_the_first_scan_counts_as_one():
    # 3 of 10 voxels: 3 / 10 and the threshold 0.3 meet exactly (and within rounding).
    result = levels_from_curves([3 / 10, 0.5], [1.0, 1.0], [0.0, 1.5], [0.0, 45.0], LevelThresholds())
    assert reached(result) == {"detect": 1, "recognise": 1, "identify": 2}
    assert result.level("detect").flight_time_s == 0.0 and result.level("identify").distance_m == 45.0


def test_never_reached_reads_not_reached_never_nan(tmp_path):
    result = levels_from_curves([0.0, 0.15, 0.2], [0.0, 0.5, 0.5], TIMES[:3], DISTANCES[:3])
    assert reached(result) == {"detect": 2, "recognise": None, "identify": None}
    identify = result.level("identify")
    assert not identify.reached and identify.describe() == NOT_REACHED == "not reached"
    assert identify.flight_time_s is None and identify.distance_m is None
    text = json.dumps(result.to_dict(), allow_nan=False)
    assert "NaN" not in text
    assert json.loads(text)["identify"] == {
        "reached": False,
        "scan": None,
        "flight_time_s": None,
        "distance_m": None,
    }
    assert [row[2] for row in result.rows()] == ["scan 2, 2.0 s, 60.0 m", "not reached", "not reached"]
    assert result.summary() == "reaches detect at scan 2, 2.0 s, 60.0 m; recognise, identify not reached"
    measures = Measures(levels=result)
    cmf = measures.to_cmf()
    assert "identify = not reached" in cmf and "recognise = not reached" in cmf and "nan" not in cmf
    measures.write_cmf(tmp_path / "S.cmf")
    assert read_cmf(tmp_path / "S.cmf") == measures


def test_nothing_visible_reaches_nothing():
    result = target_levels(np.zeros((0, 3), np.int32), [np.zeros((0, 3))], [0.0], [0.0])
    assert not any(item.reached for item in result.levels)
    assert result.visible_share is None and result.summary() == "not detected (no level reached)"
    assert json.loads(json.dumps(result.to_dict(), allow_nan=False))["visible_share"] is None


def test_curves_must_match_the_scans():
    with pytest.raises(FieldError, match=r"^len\(visible_share\) = 3: expected one per scan time \(2\)"):
        levels_from_curves([0.1, 0.2, 0.3], [0.1, 0.2], [0.0, 1.0], [0.0, 1.0])
    with pytest.raises(FieldError, match=r"^len\(scan_distances\) = 1: expected one per scan time \(2\)"):
        levels_from_curves([0.1, 0.2], [0.1, 0.2], [0.0, 1.0], [0.0])
    with pytest.raises(FieldError, match=r"^scan_times\[1\] = nan: expected a number >= 0"):
        levels_from_curves([0.1, 0.2], [0.1, 0.2], [0.0, math.nan], [0.0, 1.0])


def test_bad_voxel_lists_are_refused_not_reshaped_into_other_voxels():
    target = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    with pytest.raises(FieldError, match=r"^target_voxels is an array of shape \(4, 2\)"):
        target_levels(target[:, :2], [target], [0.0], [0.0])
    with pytest.raises(FieldError, match=r"^per_scan_returns\[0\] is an array of float64"):
        target_levels(target, [target + 0.5], [0.0], [0.0])


def test_scan_distances_follow_the_path_and_end_at_its_length():
    from ladartui.flight import FlightPlan, Manual, ScanPose, Straight, Turn

    start = ScanPose(0.0, 0.0, 100.0, heading=90.0, depression=45.0)
    plan = FlightPlan(start, [Straight(300.0, 3), Turn(50.0, 180.0, "left", 3), Straight(100.0, 2)])
    arc = 50.0 * math.radians(60.0)
    # 2 x 100 m straight, three 60-degree arcs (the first from the turn's start), 2 x 50 m.
    expected = [0.0, 100.0, 200.0, 200.0 + arc, 200.0 + 2 * arc, 200.0 + 3 * arc]
    expected += [expected[-1] + 50.0, expected[-1] + 100.0]
    distances = plan.scan_distances()
    assert distances == pytest.approx(expected, abs=1e-9) and len(distances) == len(plan.poses())
    assert distances[-1] == plan.path_length()
    assert plan.scan_times(25.0) == [d / 25.0 for d in distances]
    jump = FlightPlan(
        None, [Manual([ScanPose(0, 0, 50)]), Manual([ScanPose(30, 40, 50), ScanPose(30, 40, 50)])]
    )
    assert jump.scan_distances() == [0.0, 50.0, 50.0]


# -- the spatial variant on a hand-made target ------------------------------------------


def box(x, y, z):
    return np.array([(i, j, k) for i in range(x) for j in range(y) for k in range(z)], np.int32)


def test_a_roof_patch_reaches_the_voxel_share_but_not_the_footprint_share():
    # A 6 x 4 x 2 box: 24 footprint cells; its 8 inner voxels of layer 0 are closed in,
    # so 40 voxels can be seen. Scan 1 sees the roof over the first two columns in x
    # (8 voxels: 20 % of the visible voxels, a third of the footprint), plus foliage;
    # scan 2 the rest of the roof.
    target = box(6, 4, 2)
    assert visible_mask(target).sum() == 40
    patch = np.array([(i, j, 1) for i in range(2) for j in range(4)])
    rest = np.array([(i, j, 1) for i in range(2, 6) for j in range(4)])
    foliage = np.array([(0, 0, 7), (3, 3, 9)])
    per_scan = [np.vstack([patch, foliage]), rest]
    voxel_curve, footprint_curve, visible, cells = share_curves(target, per_scan)
    assert (visible, cells) == (40, 24)
    assert voxel_curve == [8 / 40, 24 / 40] and footprint_curve == [8 / 24, 24 / 24]

    thresholds = LevelThresholds(0.1, 0.2, 0.5, 0.1, 0.5, 0.75)
    result = target_levels(target, per_scan, [0.0, 3.0], [0.0, 90.0], thresholds)
    # Recognise: 20 % of the voxels at scan 1, but a third of the footprint is not half.
    assert reached(result) == {"detect": 1, "recognise": 2, "identify": 2}
    spatial_off = LevelThresholds(0.1, 0.2, 0.5, 0.0, 0.0, 0.0)
    assert reached(target_levels(target, per_scan, [0.0, 3.0], [0.0, 90.0], spatial_off))["recognise"] == 1


def test_a_tall_end_seen_whole_is_many_voxels_over_little_footprint():
    # A 2 x 4 x 6 cab on a 6 x 4 x 1 bed: seeing the cab whole (roof and walls) is most
    # of the visible voxels over a third of the footprint; identify waits for the bed.
    cab = box(2, 4, 6)
    bed = box(8, 4, 1)[box(8, 4, 1)[:, 0] >= 2]
    target = np.vstack([cab, bed])
    visible = visible_mask(target)
    cab_seen = cab[visible_mask(cab)]
    voxel_curve, footprint_curve, count, cells = share_curves(target, [cab_seen, bed])
    assert cells == 32 and count == int(visible.sum())
    assert voxel_curve[0] >= 0.5 and footprint_curve[0] == 8 / 32
    result = target_levels(target, [cab_seen, bed], [0.0, 1.0], [0.0, 30.0])
    assert reached(result) == {"detect": 1, "recognise": 2, "identify": 2}


# -- a real tiny run ----------------------------------------------------------------------


def first_scan_by_hand(target, per_scan, share):
    """First 1-based scan after which ``share`` of the target's visible voxels were returned."""
    visible = {tuple(v) for v in target[visible_mask(target)].tolist()}
    seen = set()
    for k, returns in enumerate(per_scan, start=1):
        seen |= {tuple(v) for v in np.asarray(returns).tolist()} & visible
        if len(seen) >= share * len(visible):
            return k
    return None


def test_a_tiny_run_reports_the_scan_time_and_distance_where_coverage_crosses(tmp_path, capsys):
    from ladartui.simulation import simulate

    base = write_tiny_scenario(tmp_path)
    # The spatial check off and identify at half the visible voxels.
    thresholds = LevelThresholds(0.1, 0.3, 0.5, 0.0, 0.0, 0.0)
    scenario = base.with_changes(levels=thresholds).save()
    result = simulate(scenario)
    scene = scenario.load_scene()
    k = first_scan_by_hand(scene.target, result.scene_per_scan, 0.5)
    assert k is not None and 1 < k < result.scans  # the test means something: it crosses midway
    identify = result.measures.levels.level("identify")
    assert identify.scan == k
    # A 4-scan full orbit of radius 20 m at 30 m/s: each leg is a quarter circle.
    leg = math.radians(90.0) * 20.0
    distance = 0.0
    for _ in range(k - 1):
        distance += leg
    assert identify.distance_m == distance and identify.flight_time_s == distance / 30.0
    assert read_cmf(scenario.measures_file).levels == result.measures.levels

    assert main(["run", str(scenario.path), "--json", "--no-write"]) == 0
    out = json.loads(capsys.readouterr().out)["measures"]["levels"]["identify"]
    assert out == {"reached": True, "scan": k, "flight_time_s": distance / 30.0, "distance_m": distance}
    assert main(["run", str(scenario.path), "--no-write"]) == 0
    text = capsys.readouterr().out
    assert f"scan {k}, {distance / 30.0:.1f} s, {distance:.1f} m" in text

    never = scenario.with_changes(levels=LevelThresholds(0.1, 0.3, 1.0, 0.0, 0.0, 0.0)).save()
    assert main(["run", str(never.path), "--no-write"]) == 0
    assert "not reached" in capsys.readouterr().out


# -- the [levels] scenario section --------------------------------------------------------

LEVELS_TEXT = textwrap.dedent("""\

    [levels]  # tracked vehicles, from the trial imagery
    detect = 0.05
    recognise = 0.25     # the analysts' call
    identify = 0.6
    detect_footprint = 0.0
    recognise_footprint = 0.4
    identify_footprint = 0.8
    """)


def test_levels_section_round_trips_and_keeps_the_analysts_comments(tmp_path):
    base = write_tiny_scenario(tmp_path)
    assert base.levels is None and base.level_thresholds == LevelThresholds()
    assert "[levels]" not in base.path.read_text()  # absent stays absent
    base.path.write_text(base.path.read_text() + LEVELS_TEXT)
    loaded = load_scenario(base.path)
    assert loaded.levels == LevelThresholds(0.05, 0.25, 0.6, 0.0, 0.4, 0.8)
    assert "identify 60% / 80%" in loaded.summary()
    changed = loaded.with_changes(levels=LevelThresholds(0.05, 0.25, 0.7, 0.0, 0.4, 0.8)).save()
    text = changed.path.read_text()
    assert "# the analysts' call" in text and "# tracked vehicles" in text and "identify = 0.7" in text
    assert load_scenario(changed.path) == changed
    fresh = changed.save(tmp_path / "copy.toml")
    assert load_scenario(fresh.path).levels == changed.levels


def test_summary_says_thresholds_as_written_as_the_run_table_does(tmp_path):
    """validate said 'detect 12% / 0%' and 'identify 50% / 88%' for thresholds of 0.125,
    0.004 and 0.875, which the run's levels table gives as 12.5 %, 0.4 % and 87.5 %."""
    base = write_tiny_scenario(tmp_path)
    thresholds = LevelThresholds(0.125, 0.3, 0.5, 0.004, 0.5, 0.875)
    scenario = base.with_changes(levels=thresholds).save()
    line = next(s for s in load_scenario(scenario.path).summary().splitlines() if s.startswith("levels"))
    assert "detect 12.5% / 0.4%" in line
    assert "recognise 30% / 50%" in line
    assert "identify 50% / 87.5%" in line
    result = levels_from_curves([1.0], [1.0], [0.0], [0.0], thresholds)
    table = {level.lower(): needs for level, needs, _ in result.rows()}
    assert table["detect"] == "12.5 % / 0.4 %" and table["identify"] == "50 % / 87.5 %"


BAD_LEVELS = [
    ("identify = 0.6", "identify = 1.5", "levels.identify = 1.5", "from levels.recognise (0.25) to 1"),
    ("detect = 0.05", "detect = 0", "levels.detect = 0", "visible voxels greater than 0 and at most 1"),
    (
        "detect = 0.05",
        'detect = "high"',
        "levels.detect = 'high'",
        "visible voxels greater than 0 and at most 1",
    ),
    ("recognise = 0.25 ", "recognise = 0.01 ", "levels.recognise = 0.01", "from levels.detect (0.05) to 1"),
    (
        "detect_footprint = 0.0",
        "detect_footprint = -0.1",
        "levels.detect_footprint = -0.1",
        "footprint cells from 0 to 1",
    ),
    ("identify = 0.6", "identify = true", "levels.identify = True", "from levels.recognise (0.25) to 1"),
]


@pytest.mark.parametrize("old,new,head,expected", BAD_LEVELS, ids=[row[2] for row in BAD_LEVELS])
def test_bad_levels_name_the_file_line_field_value_and_range(tmp_path, old, new, head, expected):
    base = write_tiny_scenario(tmp_path)
    text = base.path.read_text() + LEVELS_TEXT.replace(old, new)
    base.path.write_text(text)
    with pytest.raises(FieldError) as caught:
        load_scenario(base.path)
    message = str(caught.value)
    line = text.splitlines().index(next(s for s in text.splitlines() if s.startswith(new.strip()))) + 1
    assert message.startswith(f"{base.path}:{line}: {head}: expected ")
    assert expected in message and "\n" not in message


@pytest.mark.parametrize(
    ("written", "head", "expected"),
    [
        ("detect = 0.6", "levels.detect = 0.6", "at most levels.recognise (0.3, its default"),
        (
            "detect_footprint = 0.9",
            "levels.detect_footprint = 0.9",
            "at most levels.recognise_footprint (0.5, its default",
        ),
    ],
)
def test_a_level_above_the_default_of_the_next_names_the_key_written(tmp_path, written, head, expected):
    """'detect = 0.6' alone was reported as 'levels.recognise = 0.3', a key not in the file,
    on the [levels] line."""
    base = write_tiny_scenario(tmp_path)
    text = base.path.read_text() + f"\n[levels]\n{written}\n"
    base.path.write_text(text)
    with pytest.raises(FieldError) as caught:
        load_scenario(base.path)
    line = text.splitlines().index(written) + 1
    message = str(caught.value)
    assert message.startswith(f"{base.path}:{line}: {head}: expected ") and expected in message


def test_unknown_levels_key_is_named(tmp_path):
    base = write_tiny_scenario(tmp_path)
    base.path.write_text(base.path.read_text() + "\n[levels]\nidentfy = 0.5\n")
    with pytest.raises(InputFileError, match=r"unknown key 'levels.identfy' \(allowed: detect, "):
        load_scenario(base.path)


def test_bad_levels_lines_in_a_cmf_name_the_line(tmp_path):
    result = levels_from_curves([0.2, 0.6], [0.5, 1.0], [0.0, 1.0], [0.0, 30.0])
    good = Measures(levels=result).to_cmf()
    for old, new, says in [
        ("identify = 2, 1.0, 30.0", "identify = 2, soon, 30.0", "identify: expected scan, flight time"),
        ("identify = 2, 1.0, 30.0", "identify = 0, 1.0, 30.0", "identify: expected a scan number >= 1"),
        ("scans = 2\nvisible", "scans = lots\nvisible", "scans: expected int"),
        ("identify_threshold = 0.5, 0.75", "identify_threshold = 0.2, 0.75", "levels.identify = 0.2"),
        ("footprint_share = 1.0", "footprint_shares = 1.0", "unknown key 'footprint_shares'"),
    ]:
        assert old in good
        text = good.replace(old, new)
        path = tmp_path / "bad.cmf"
        path.write_text(text)
        line = text.splitlines().index(new.split("\n")[0]) + 1
        with pytest.raises(InputFileError) as caught:
            read_cmf(path)
        assert str(caught.value).startswith(f"{path}:{line}: ") and says in str(caught.value)


def test_coverage_chart_marks_the_scan_of_each_level_reached(tmp_path):
    import re
    import xml.etree.ElementTree as ET

    from ladartui.charts import save_figure
    from ladartui.charts.coverage import coverage_figure

    levels = levels_from_curves([0.15, 0.35, 0.4, 0.45], [0.2, 0.6, 0.6, 0.6], TIMES[:4], DISTANCES[:4])
    measures = Measures(obscured_after_scan=(0.1, 0.3, 0.35, 0.4), levels=levels)
    path = save_figure(coverage_figure(measures), tmp_path / "c.svg")
    groups = {g.get("id"): g for g in ET.parse(path).iter("{http://www.w3.org/2000/svg}g") if g.get("id")}

    def xs(gid):
        d = next(groups[gid].iter("{http://www.w3.org/2000/svg}path")).get("d")
        numbers = [float(n) for n in re.findall(r"-?\d+(?:\.\d+)?", d)]
        return numbers[0::2]

    scan_x = xs("series-obscured")  # one vertex per scan
    assert "level-identify" not in groups  # 45 % never reaches 50 %
    for level, scan in (("detect", 1), ("recognise", 2)):
        assert reached(levels)[level] == scan
        assert xs(f"level-{level}") == pytest.approx([scan_x[scan - 1]] * 2, abs=0.01)
