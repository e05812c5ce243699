"""Defaults a new scenario takes: the sensor, and an orbit around the target.

Pure data and geometry, below ``scenario.py`` (which uses them). The user's
folders and the built-in default scenario materialised there live above it,
in ``user_data.py``.
"""

from __future__ import annotations

import math

import numpy as np

from ladartui.errors import FieldError
from ladartui.flight import MAX_FLIGHT_ALTITUDE, FlightPlan, Orbit
from ladartui.sensor import Sensor

# 64 x 64 detectors with 2 x 2 rays: 16,384 rays per scan, a few seconds for a
# full orbit on two cores. An 8 degree view from ~85 m slant range covers about
# 12 m across (17 m along the look direction at 45 degrees depression): a
# vehicle with a generous margin for a cue that is a few metres off.
DEFAULT_SENSOR = Sensor(grid=64, ray_grid=2, fov=8.0, depth_resolution=1.0, pixel_pitch=100e-6)
DEFAULT_SCANS = 24
DEFAULT_DEPRESSION = 45.0
MIN_SLANT_RANGE = 85.0  # metres
VIEW_MARGIN = 1.5  # footprint width over the target's horizontal size


def target_centre(target_voxels, voxel_size) -> tuple[float, float, float]:
    """Centroid of the target voxel centres in metres."""
    x, y, z = np.asarray(target_voxels, dtype=np.float64).mean(axis=0) * float(voxel_size)
    return (float(x), float(y), float(z))


def to_millimetres(point) -> tuple[float, ...]:
    """A point (metres) as scenario files write the points the program chooses: to the
    millimetre, as a person would (29.881, not 29.88051470588235)."""
    return tuple(round(float(v), 3) for v in point)


def default_flight(target_voxels, voxel_size, sensor: Sensor = DEFAULT_SENSOR) -> FlightPlan:
    """A 24-scan clockwise orbit at 45 degrees depression around the target's centre.

    The slant range is at least 85 m and far enough that the sensor's view is
    ``VIEW_MARGIN`` times the target's horizontal size, but never so far that the
    orbit climbs past ``MAX_FLIGHT_ALTITUDE``: large voxels make large scenes.
    A target centred at or above that altitude is a FieldError on the voxel size.
    """
    voxels = np.asarray(target_voxels)
    centre = target_centre(voxels, voxel_size)
    span = (voxels.max(axis=0) - voxels.min(axis=0) + 1) * float(voxel_size)
    size = math.hypot(span[0], span[1])
    slant = max(MIN_SLANT_RANGE, VIEW_MARGIN * size / (2 * math.tan(math.radians(sensor.fov / 2))))
    slant = min(slant, _highest_slant(centre[2], voxel_size))
    radius = slant * math.cos(math.radians(DEFAULT_DEPRESSION))
    altitude = min(centre[2] + slant * math.sin(math.radians(DEFAULT_DEPRESSION)), MAX_FLIGHT_ALTITUDE)
    orbit = Orbit(
        centre=to_millimetres(centre),
        radius=round(radius, 1),
        altitude=round(altitude, 1),
        scans=DEFAULT_SCANS,
    )
    return FlightPlan(None, (orbit,))


def _highest_slant(target_height: float, voxel_size) -> float:
    """The slant range at which the default depression reaches ``MAX_FLIGHT_ALTITUDE``."""
    room = MAX_FLIGHT_ALTITUDE - target_height
    if room < 1.0:  # an orbit a metre across at most is no flight
        raise FieldError(
            "voxel_size",
            voxel_size,
            f"a voxel size that puts the target's centre below {MAX_FLIGHT_ALTITUDE:.0f} m, "
            f"the highest a flight may go (it is at {target_height:.0f} m)",
        )
    return room / math.sin(math.radians(DEFAULT_DEPRESSION))
