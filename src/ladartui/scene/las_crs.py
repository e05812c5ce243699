"""The units of a point cloud's coordinates, from the coordinate reference system it
names (OGC WKT in LAS 1.4, GeoTIFF keys in LAS 1.2 and 1.3).

Surveys come in metres (UTM) or in feet (many US state planes, in international or
US survey feet); the voxel grid is in metres, so a cloud in feet is scaled to metres
as it is read. Heights take the units of the vertical system where the cloud names
one (a compound CRS, or GeoTIFF's VerticalUnitsGeoKey), else those of the horizontal
one. A cloud that names no system is taken to be in metres. Latitude and longitude, or
earth-centred coordinates, cannot be voxelised and are refused.
"""

from __future__ import annotations

from ladartui.errors import InputFileError

# GeoTIFF's VerticalUnitsGeoKey and the EPSG units it may give: metres in each, and
# the unit in the plural as a report of lengths names it
VERTICAL_UNITS_KEY = 4099
EPSG_LENGTH_UNITS = {9001: (1.0, "m"), 9002: (0.3048, "feet"), 9003: (1200 / 3937, "US survey feet")}


def unit_words(metres: float, name: str | None = None) -> str:
    """A length unit in the plural, by its length in metres: "m", "feet (0.3048 m)";
    one not in ``EPSG_LENGTH_UNITS`` by ``name`` (its coordinate system's), else "units"."""
    if metres == 1.0:
        return "m"
    named = next(
        # pyproj's lengths differ from these in the last bit
        (words for length, words in EPSG_LENGTH_UNITS.values() if abs(metres / length - 1) < 1e-9),
        None,
    )
    return f"{named or name or 'units'} ({metres:.7g} m)"


def metres_per_unit(path, header) -> tuple[float, float, str]:
    """Metres in one unit of the cloud's (x and y, z) coordinates, and the name of its
    x and y unit ("metre", "US survey foot"); (1, 1, "metre") when the cloud names no
    coordinate system."""
    try:
        crs = header.parse_crs()
    except Exception as error:  # pyproj's CRSError, or laspy's on a damaged record
        reason = " ".join(str(error).split()) or type(error).__name__
        raise InputFileError(
            path,
            f"its coordinate reference system cannot be read ({reason[:200]}); expected OGC WKT "
            "or GeoTIFF keys naming a projected system (rewrite the record with the survey's tools)",
        ) from None
    if crs is None:
        return 1.0, 1.0, "metre"
    horizontal_crs, vertical_crs = crs, None
    if crs.is_compound:
        horizontal_crs = next((sub for sub in crs.sub_crs_list if not sub.is_vertical), crs)
        vertical_crs = next((sub for sub in crs.sub_crs_list if sub.is_vertical), None)
    if not horizontal_crs.is_projected:
        kind = "degrees" if horizontal_crs.is_geographic else "earth-centred coordinates"
        raise InputFileError(
            path,
            f"coordinates in {kind} ({horizontal_crs.name}): expected a projected coordinate "
            "system in metres or feet (reproject the cloud, to its UTM zone for one)",
        )
    horizontal = _axis_metres(path, horizontal_crs)
    unit = horizontal_crs.axis_info[0].unit_name
    if vertical_crs is not None:
        return horizontal, _axis_metres(path, vertical_crs), unit
    return horizontal, _geotiff_vertical_metres(header) or horizontal, unit


def _axis_metres(path, crs) -> float:
    factors = {axis.unit_conversion_factor for axis in crs.axis_info}
    units = {axis.unit_name for axis in crs.axis_info}
    if len(factors) != 1 or not all(axis.unit_conversion_factor > 0 for axis in crs.axis_info):
        raise InputFileError(
            path,
            f"coordinate system {crs.name} has axes in {', '.join(sorted(units))}: expected one length unit",
        )
    return float(factors.pop())


def _geotiff_vertical_metres(header) -> float | None:
    """The metres in a height unit that a GeoTIFF key directory names, if it does."""
    for record in header.vlrs.get("GeoKeyDirectoryVlr"):
        for key in record.geo_keys:
            if key.id == VERTICAL_UNITS_KEY and key.tiff_tag_location == 0:
                known = EPSG_LENGTH_UNITS.get(key.value_offset)
                return known[0] if known else None
    return None
