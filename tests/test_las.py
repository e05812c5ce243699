"""LAS/LAZ import (voxelising) and export (voxel centres)."""

import numpy as np
import pytest

laspy = pytest.importorskip("laspy")

from ladartui.errors import FieldError, InputFileError, OutputFileError, ResourceLimitError  # noqa: E402
from ladartui.scene.las import export_las, import_las  # noqa: E402


def sorted_rows(a):
    a = np.asarray(a)
    return a[np.lexsort(a.T[::-1])]


VOXELS = np.array([[3, 4, 0], [3, 4, 1], [10, 2, 7], [25, 30, 12], [3, 5, 0]], dtype=np.int32)


@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_export_writes_voxel_centres_in_metres(tmp_path, suffix):
    path = tmp_path / f"cloud{suffix}"
    export_las(path, VOXELS, 0.25, origin=(100.0, 200.0, 5.0))
    cloud = laspy.read(path)
    xyz = np.stack([cloud.x, cloud.y, cloud.z], axis=1)
    expected = np.array([100.0, 200.0, 5.0]) + VOXELS * 0.25
    np.testing.assert_allclose(sorted_rows(xyz), sorted_rows(expected), atol=1e-6)
    # LAZ marks compression in the high bit of the header's point-format byte (offset 104).
    assert bool(path.read_bytes()[104] & 0x80) == (suffix == ".laz")


@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_round_trip_with_the_same_origin(tmp_path, suffix):
    path = tmp_path / f"cloud{suffix}"
    export_las(path, VOXELS, 0.1, origin=(10.0, 20.0, 0.0))
    voxels, origin = import_las(path, 0.1, origin=(10.0, 20.0, 0.0))
    np.testing.assert_array_equal(sorted_rows(voxels), sorted_rows(VOXELS))
    np.testing.assert_array_equal(origin, [10.0, 20.0, 0.0])


def test_default_origin_puts_the_lowest_point_in_voxel_zero(tmp_path):
    path = tmp_path / "cloud.laz"
    export_las(path, VOXELS, 0.5)
    voxels, origin = import_las(path, 0.5)
    lowest = VOXELS.min(axis=0)
    np.testing.assert_allclose(origin, lowest * 0.5)
    np.testing.assert_array_equal(sorted_rows(voxels), sorted_rows(VOXELS - lowest))
    assert voxels.min(axis=0).tolist() == [0, 0, 0]


def test_import_voxelises_and_merges_points(tmp_path):
    header = laspy.LasHeader(version="1.2", point_format=0)
    header.scales = [0.001] * 3
    header.offsets = [0, 0, 0]
    cloud = laspy.LasData(header)
    # Voxel size 1 m, origin 0: voxel i spans [i - 0.5, i + 0.5).
    cloud.x = np.array([0.0, 0.2, 0.49, 0.5, 2.4, 2.6])
    cloud.y = np.array([0.0, 0.0, 0.0, 0.0, 1.0, 1.0])
    cloud.z = np.array([0.0, 0.3, 0.0, 0.0, 0.0, 0.0])
    path = tmp_path / "points.las"
    cloud.write(path)
    voxels, _ = import_las(path, 1.0, origin=(0, 0, 0))
    np.testing.assert_array_equal(sorted_rows(voxels), [[0, 0, 0], [1, 0, 0], [2, 1, 0], [3, 1, 0]])


def test_points_below_an_explicit_origin_are_an_error(tmp_path):
    path = tmp_path / "cloud.las"
    export_las(path, VOXELS, 1.0)
    expected = r"origin = \(5\.0, 0\.0, 0\.0\): expected at most half a voxel"
    with pytest.raises(FieldError, match=expected):
        import_las(path, 1.0, origin=(5.0, 0.0, 0.0))


def test_missing_and_foreign_files(tmp_path):
    with pytest.raises(InputFileError, match=r"nope\.las: no such file; expected a LAS or LAZ"):
        import_las(tmp_path / "nope.las", 0.1)
    junk = tmp_path / "junk.las"
    junk.write_text("1,2,3\n")
    with pytest.raises(InputFileError, match=r"junk\.las: not a readable LAS/LAZ point cloud"):
        import_las(junk, 0.1)


def test_a_folder_is_named_as_a_folder(tmp_path):
    # It was "no such file", of a folder that is there.
    with pytest.raises(InputFileError) as caught:
        import_las(tmp_path, 0.1)
    assert str(caught.value) == f"{tmp_path}: is a folder; expected a LAS or LAZ point cloud"


@pytest.mark.parametrize(
    ("voxels", "ids", "message"),
    [
        ([[1, -2, 3]], None, r"^voxels\[0\] = \(1, -2, 3\): expected non-negative voxel indices"),
        ([[1, 2]], None, r"^voxels = \[\[1, 2\]\]: expected an \(N, 3\) array"),
        ([[1, 2, 3]], [70000], r"^ids\[0\] = 70000: expected a target id from 0 \(no target\) to 65535"),
        ([[1, 2, 3]], [1, 2], r"^ids = \[1, 2\]: expected 1 target ids"),
    ],
)
def test_export_refuses_bad_voxels_and_ids_naming_them(tmp_path, voxels, ids, message):
    # A negative index was written as a point below the origin; shapes and ids raised ValueError.
    with pytest.raises(FieldError, match=message):
        export_las(tmp_path / "a.las", voxels, 0.25, ids=ids)
    assert list(tmp_path.iterdir()) == []


def test_export_to_a_place_that_cannot_be_written_names_it(tmp_path):
    # IsADirectoryError or FileNotFoundError named the temporary file beside it.
    with pytest.raises(OutputFileError) as caught:
        export_las(tmp_path, VOXELS, 0.25)
    assert str(caught.value) == f"{tmp_path}: cannot be written (is a directory)"
    with pytest.raises(FieldError, match=r"^path is not set: expected a LAS or LAZ file's path"):
        export_las(None, VOXELS, 0.25)
    with pytest.raises(FieldError, match=r"^path is not set: expected a LAS or LAZ point cloud's path"):
        import_las(None, 0.25)


def test_bad_voxel_size(tmp_path):
    with pytest.raises(FieldError, match="voxel_size = 0: expected a positive number of metres"):
        export_las(tmp_path / "a.las", VOXELS, 0)


def _cloud_file(path, count, point_format=6):
    header = laspy.LasHeader(version="1.4", point_format=point_format)
    header.scales = [0.01] * 3
    header.offsets = [500000.0, 4100000.0, 0.0]  # UTM metres, as surveys give them
    cloud = laspy.LasData(header)
    steps = np.arange(count, dtype=np.float64)
    cloud.x, cloud.y, cloud.z = 500100.0 + steps, 4100200.0 + steps % 7, 120.0 + steps % 3
    cloud.write(path)
    with laspy.open(path) as reader:
        return reader.header


@pytest.mark.parametrize("kept", [50, 50.5], ids=["at-a-point", "inside-a-point"])
def test_a_cloud_cut_short_is_refused_naming_what_it_lacks(tmp_path, kept):
    # Cut at a point's end, the first 50 of 100 points were imported as the whole cloud
    # without a word; cut inside one, "buffer size must be a multiple of element size".
    path = tmp_path / "survey.las"
    header = _cloud_file(path, 100)
    data = path.read_bytes()
    path.write_bytes(data[: header.offset_to_point_data + int(kept * header.point_format.size)])
    with pytest.raises(InputFileError) as caught:
        import_las(path, 0.25)
    assert str(caught.value) == (
        f"{path}: cut short: its header gives 100 points ({len(data):,} bytes), the file has "
        f"{int(len(data) - (100 - kept) * 30):,} bytes; expected the whole file (copied or "
        "downloaded in full)"
    )


def test_a_cloud_larger_than_the_memory_is_refused_before_it_is_read(tmp_path, monkeypatch):
    # laspy was asked to read it all: on this machine "not a readable LAS/LAZ point cloud ()"
    # (a MemoryError) of a sound file; on a larger one a process killed halfway.
    path = tmp_path / "survey.laz"
    _cloud_file(path, 1000)
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(64 * 1024))
    with pytest.raises(ResourceLimitError) as caught:
        import_las(path, 0.25)
    assert str(caught.value) == (
        f"{path}: 1,000 points of 30 bytes need about 123 KiB to voxelise, more than the "
        "64 KiB of memory available; split the cloud into tiles or thin it"
    )
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(126_000))
    voxels, _ = import_las(path, 0.25)
    assert len(voxels) == 1000


def test_a_cloud_wider_than_the_finest_scale_allows_round_trips(tmp_path):
    # 220 km at 0.1 m: at the scale of a ten-thousandth of a voxel the x integers passed 2**31
    # and laspy raised OverflowError ("Values given do not fit after applying offset and scale").
    voxels = np.array([[0, 0, 0], [2_200_000, 3, 1], [1_100_000, 7, 2]], dtype=np.int32)
    path = tmp_path / "corridor.laz"
    export_las(path, voxels, 0.1, origin=(500000.0, 4100000.0, 50.0))
    back, _ = import_las(path, 0.1, origin=(500000.0, 4100000.0, 50.0))
    np.testing.assert_array_equal(sorted_rows(back), sorted_rows(voxels))


@pytest.mark.parametrize("version, point_format", [("1.2", 0), ("1.4", 6)])
def test_noise_and_withheld_points_are_left_out_unless_asked_for(tmp_path, version, point_format):
    """A survey's one noise point 3 km up (class 18, or 7) made the scene 12,001 voxels
    tall: points classed as noise, and points flagged withheld, were voxelised as foliage."""
    header = laspy.LasHeader(version=version, point_format=point_format)
    header.scales = [0.01] * 3
    header.offsets = [0, 0, 0]
    cloud = laspy.LasData(header)
    cloud.x = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    cloud.y = np.zeros(5)
    cloud.z = np.array([0.0, 1.0, 3000.0, -40.0, 2.0])
    noise = 18 if point_format >= 6 else 7  # high noise needs the 1.4 formats' 8-bit classes
    cloud.classification = np.array([2, 5, noise, 7, 5])
    cloud.withheld = np.array([0, 0, 0, 0, 1], dtype=bool)
    path = tmp_path / "survey.las"
    cloud.write(path)
    voxels, origin = import_las(path, 1.0)
    assert sorted_rows(voxels).tolist() == [[0, 0, 0], [1, 0, 1]]
    np.testing.assert_array_equal(origin, [0.0, 0.0, 0.0])
    voxels, origin = import_las(path, 1.0, keep_noise=True)
    assert len(voxels) == 5 and origin[2] == -40.0
    # a cloud of noise alone says so rather than 'holds no points'
    cloud.classification = np.full(5, 7)
    cloud.write(path)
    with pytest.raises(InputFileError, match=r"survey\.las: all 5 points are noise or withheld"):
        import_las(path, 1.0)


def test_a_cloud_too_wide_for_the_voxel_size_says_its_extent_and_the_smallest_size(tmp_path, monkeypatch):
    """'voxel_size = 0.25: expected large enough for the cloud's extent' gave neither."""
    import ladartui.scene.las as las

    monkeypatch.setattr(las, "MAX_INDEX", 999)  # a 1,000-voxel grid side for the test
    header = laspy.LasHeader(version="1.2", point_format=0)
    header.scales = [0.01] * 3
    header.offsets = [0, 0, 0]
    cloud = laspy.LasData(header)
    cloud.x, cloud.y, cloud.z = np.array([0.0, 600.0]), np.array([0.0, 20.0]), np.array([0.0, 5.0])
    path = tmp_path / "corridor.las"
    cloud.write(path)
    with pytest.raises(FieldError) as caught:
        import_las(path, 0.25)
    assert str(caught.value) == (
        f"{path}: voxel_size = 0.25: expected at least 0.601 m for the cloud's extent "
        "(600 x 20 x 5 m; at most 1,000 voxels a side)"
    )
    assert len(import_las(path, 0.601)[0]) == 2


def _cloud_in(path, crs, x, z, *, geotiff_vertical_units=None):
    """A cloud at ``x`` (and y 0) and heights ``z``, in the units ``crs`` (a pyproj CRS)
    gives: a LAS 1.4 cloud names it in WKT, a 1.2 cloud in GeoTIFF keys."""
    from laspy.vlrs.geotiff import GeoKeyEntryStruct

    header = laspy.LasHeader(version="1.2" if geotiff_vertical_units else "1.4", point_format=3)
    header.scales, header.offsets = [0.01] * 3, [0.0] * 3
    header.add_crs(crs, keep_compatibility=geotiff_vertical_units is not None)
    if geotiff_vertical_units:  # VerticalUnitsGeoKey: the heights' own unit (9001 metre)
        keys = header.vlrs.get("GeoKeyDirectoryVlr")[0]
        entry = GeoKeyEntryStruct()
        entry.id, entry.tiff_tag_location, entry.count, entry.value_offset = (
            4099,
            0,
            1,
            geotiff_vertical_units,
        )
        keys.geo_keys.append(entry)
        keys.geo_keys_header.number_of_keys += 1
    cloud = laspy.LasData(header)
    cloud.x, cloud.y, cloud.z = np.asarray(x, float), np.zeros(len(x)), np.asarray(z, float)
    cloud.write(path)
    return path


def test_a_cloud_in_feet_is_voxelised_in_metres(tmp_path):
    """A survey in US survey feet (a US state plane) was voxelised as if in metres: its
    forest came out 3.28 times wider and taller than it is. The units are read from the
    cloud's coordinate reference system, in WKT (LAS 1.4) or GeoTIFF keys (LAS 1.2)."""
    import pyproj

    foot = 1200 / 3937  # metres in a US survey foot
    feet = [0.0, 10.0, 20.0, 30.0]
    metres = [value * foot for value in feet]
    for crs in ("EPSG:2263", "EPSG:2263+6360"):  # NY Long Island (ftUS), with NAVD88 height (ftUS)
        for compatible in (False, True):
            if compatible and "+" in crs:
                continue  # GeoTIFF keys name a projected CRS alone
            path = _cloud_in(
                tmp_path / "ft.las",
                pyproj.CRS(crs),
                feet,
                feet,
                geotiff_vertical_units=9003 if compatible else None,
            )
            voxels, origin = import_las(path, 1.0, origin=(0.0, 0.0, 0.0))
            assert sorted_rows(voxels).tolist() == [[0, 0, 0], [3, 0, 3], [6, 0, 6], [9, 0, 9]], crs
            voxels, origin = import_las(path, 1.0)
            np.testing.assert_allclose(origin, [0.0, 0.0, 0.0])
    # heights in metres under a horizontal CRS in feet: only x and y are converted
    path = _cloud_in(tmp_path / "mixed.las", pyproj.CRS("EPSG:2263+5703"), feet, metres)
    assert sorted_rows(import_las(path, 1.0, origin=(0, 0, 0))[0]).tolist() == [
        [0, 0, 0],
        [3, 0, 3],
        [6, 0, 6],
        [9, 0, 9],
    ]
    path = _cloud_in(
        tmp_path / "mixed12.las", pyproj.CRS("EPSG:2263"), feet, metres, geotiff_vertical_units=9001
    )
    assert sorted_rows(import_las(path, 1.0, origin=(0, 0, 0))[0]).tolist() == [
        [0, 0, 0],
        [3, 0, 3],
        [6, 0, 6],
        [9, 0, 9],
    ]
    # a cloud in metres (UTM) is read as it is
    path = _cloud_in(tmp_path / "utm.las", pyproj.CRS("EPSG:32618"), metres, metres)
    assert sorted_rows(import_las(path, 1.0, origin=(0, 0, 0))[0]).tolist() == [
        [0, 0, 0],
        [3, 0, 3],
        [6, 0, 6],
        [9, 0, 9],
    ]


def test_a_cloud_in_degrees_or_an_unreadable_crs_is_refused_naming_it(tmp_path):
    """A cloud in latitude and longitude was voxelised as metres: a whole survey fell in
    one voxel column. It is refused, as is a coordinate system that cannot be read."""
    import pyproj

    path = _cloud_in(tmp_path / "geo.las", pyproj.CRS("EPSG:4326"), [10.0, 10.001], [5.0, 6.0])
    with pytest.raises(InputFileError) as caught:
        import_las(path, 1.0)
    said = str(caught.value)
    assert said.startswith(f"{path}: coordinates in degrees (WGS 84): expected a projected coordinate system")
    assert "\n" not in said
    header = laspy.LasHeader(version="1.4", point_format=6)
    header.vlrs.append(laspy.vlrs.known.WktCoordinateSystemVlr('PROJCS["broken'))
    header.global_encoding.wkt = True
    cloud = laspy.LasData(header)
    cloud.x, cloud.y, cloud.z = np.array([0.0, 1.0]), np.zeros(2), np.zeros(2)
    cloud.write(tmp_path / "broken.las")
    with pytest.raises(
        InputFileError, match=r"broken\.las: its coordinate reference system cannot be read \("
    ):
        import_las(tmp_path / "broken.las", 1.0)


def test_what_the_header_refuses_is_refused_before_the_points_are_read(tmp_path, monkeypatch):
    """A cloud in degrees was read whole (and its points sorted) before its coordinate
    system was looked at: a large one waited, or was told to split into tiles for the
    memory, before being told it is in degrees."""
    import pyproj

    import ladartui.scene.las as las

    path = _cloud_in(tmp_path / "geo.las", pyproj.CRS("EPSG:4326"), [10.0, 10.001], [5.0, 6.0])
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", "16")  # the points alone would be refused
    monkeypatch.setattr(las, "_check_no_collapse", lambda *_: pytest.fail("the points were read"))
    with pytest.raises(InputFileError, match=r"coordinates in degrees \(WGS 84\)"):
        import_las(path, 1.0)


def test_a_clean_cloud_is_checked_for_merged_points_axis_by_axis(tmp_path, monkeypatch):
    """The check that no points merge once scaled sorted every point twice as rows: 13 of
    the 15 s a 3 M-point survey took to voxelise, none of it stoppable by Ctrl-C. Scaling
    keeps each axis in order, so points can merge only where an axis's values do; the
    row-by-row count is left for a cloud where one does."""
    import ladartui.scene.las as las

    rows = []
    real = las._distinct_rows
    monkeypatch.setattr(las, "_distinct_rows", lambda values: rows.append(len(values)) or real(values))
    path = tmp_path / "survey.las"
    _cloud_file(path, 500)
    voxels, _ = import_las(path, 0.25)
    assert rows == [] and len(voxels) == 500
    cloud = laspy.read(path)
    points = np.stack([cloud.x, cloud.y, cloud.z], axis=1)
    points[:, 0] = np.floor(points[:, 0] / 100)  # x merged to 5 values: 5 x 21 (y, z) points left
    with pytest.raises(InputFileError, match=r"500 distinct stored points collapse to 105 once"):
        las._check_no_collapse(path, cloud, points)
    assert rows == [500, 500]
