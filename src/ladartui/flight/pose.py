"""Scan poses: where the aircraft is and where its sensor looks, and the limits of a flight.

Frame: x east, y north, z up, metres. Heading is degrees clockwise from north;
sensor azimuth degrees clockwise from the aircraft nose; depression degrees
below the horizontal, 1..90 with 90 nadir.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import partial

from ladartui.checks import (
    MAX_COORDINATE,
    number_field,
    point_field,
)
from ladartui.errors import FieldError

MAX_ALTITUDE = 1e5  # metres; any pose (computed ones and cell-space test rays included)
MAX_FLIGHT_ALTITUDE = 20_000.0  # metres a person may ask to fly: above any UAV's ceiling (~18 km)
MAX_SCANS = 10_000
DIRECTIONS = ("left", "right")


def _heading(value):
    # -1e-20 % 360 is 360.0 in floating point: fold that back to 0.
    h = value % 360.0
    return 0.0 if h >= 360.0 else h


def _azimuth(value):
    a = value % 360.0
    return a - 360.0 if a > 180.0 else a


# -- poses ----------------------------------------------------------------------------


@dataclass(frozen=True)
class ScanPose:
    """One scan: aircraft (sensor) position in metres, heading, sensor azimuth and depression.

    Heading is stored in [0, 360) and azimuth in (-180, 180]; depression must be
    1..90 (90 nadir) and the aircraft above the ground (z > 0).
    """

    x: float
    y: float
    z: float
    heading: float = 0.0
    azimuth: float = 0.0
    depression: float = 90.0

    def __post_init__(self):
        set_ = partial(object.__setattr__, self)
        set_("x", number_field("x", self.x, -MAX_COORDINATE, MAX_COORDINATE))
        set_("y", number_field("y", self.y, -MAX_COORDINATE, MAX_COORDINATE))
        set_("z", number_field("z", self.z, 0.0, MAX_ALTITUDE, low_open=True))
        set_("heading", _heading(number_field("heading", self.heading)))
        set_("azimuth", _azimuth(number_field("azimuth", self.azimuth)))
        set_("depression", number_field("depression", self.depression, 1.0, 90.0))

    @property
    def position(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.z)

    def to_dict(self) -> dict:
        return {
            "x": self.x,
            "y": self.y,
            "z": self.z,
            "heading": self.heading,
            "azimuth": self.azimuth,
            "depression": self.depression,
        }


def _forward(heading):
    h = math.radians(heading)
    return math.sin(h), math.cos(h)


def _bearing(dx, dy):
    """Compass bearing of (dx, dy), degrees clockwise from north."""
    return _heading(math.degrees(math.atan2(dx, dy)))


def pose_field(name: str, value) -> ScanPose:
    """``value`` when it is a ScanPose; else a FieldError naming ``name``."""
    if not isinstance(value, ScanPose):
        raise FieldError(name, value, "a ScanPose")
    return value


def aim_at(pose: ScanPose, target_xyz) -> ScanPose:
    """``pose`` with azimuth and depression set so the central ray passes through the target.

    A target straight below gives depression 90 and keeps the pose's azimuth.
    A target less than 1 degree below the horizon cannot be aimed at (FieldError).
    """
    pose = pose_field("pose", pose)
    tx, ty, tz = point_field("aim_at", target_xyz)
    dx, dy, dz = tx - pose.x, ty - pose.y, tz - pose.z
    horizontal = math.hypot(dx, dy)
    if horizontal <= 1e-12 * max(1.0, abs(dz)):
        if dz >= 0:
            raise FieldError("aim_at", target_xyz, "a point below the aircraft")
        return replace(pose, depression=90.0)
    depression = math.degrees(math.atan2(-dz, horizontal))
    if depression < 1.0:
        raise FieldError(
            "aim_at",
            target_xyz,
            f"a point at least 1 degree below the horizon from scan position "
            f"({pose.x:g}, {pose.y:g}, {pose.z:g})",
        )
    return replace(pose, azimuth=_bearing(dx, dy) - pose.heading, depression=min(depression, 90.0))
