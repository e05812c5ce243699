"""The flash LADAR sensor and its rays (report sections 7.1 and 7.2, equations 1 and 2).

Rays are first built for a downward-looking sensor at the origin. Ray (row,
column) of the full (n m) x (n m) ray grid has projected angles equally spaced
across the field of view on each axis, at the centres of equal angular cells:

    a_x = -fov/2 + (column + 1/2) fov / (n m)       (column 0 is the left edge, -x)
    a_y = +fov/2 - (row + 1/2) fov / (n m)          (row 0 is the "up" edge, +y)
    direction ~ (tan a_x, tan a_y, -1)

so the rays diverge and never cross. Their origins lie on the focal plane
(z = 0) at the same positions scaled by the pixel pitch: each detector is one
pitch wide and its m x m rays start at sub-pixel centres. "Up" on the focal
plane is +y of this frame, which the depression tilt turns away from the
aircraft: row 0 of the image is its far edge, column 0 its left edge as seen
looking along the central ray.

The grid is then tilted by Rx(90 - D), turned by Rz(-(H + A)) and moved to
the aircraft. Detectors are numbered row-major (``row * n + column``), and the
m x m rays of one detector are contiguous (sub-rows, then sub-columns).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ladartui.checks import integer_field, number_field
from ladartui.errors import FieldError
from ladartui.flight import ScanPose
from ladartui.flight.pose import pose_field

MAX_GRID = 1024
MAX_RAY_GRID = 16
MAX_DEPTH_RESOLUTION = 1000.0  # metres
MAX_PIXEL_PITCH = 0.01  # metres; the focal plane spans grid * pitch
MIN_PIXEL_PITCH = 1e-7  # metres (0.1 um): below any detector's
# degrees: the narrowest pencil of rays the tracers are tested with (its rays already
# coincide in float64); 1e-300 was taken before
MIN_FOV = 1e-14
# "stabilised": a gimbal holds azimuth and depression against the horizon (the
# report's model, the default); "body-fixed": the rays turn with the aircraft's
# roll and pitch (ladartui.attitude).
MOUNTS = ("stabilised", "body-fixed")


def rotation_x(angle_deg: float) -> np.ndarray:
    """Rotation by ``angle_deg`` about the x axis (report equation 1 with angle 90 - D)."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotation_z(angle_deg: float) -> np.ndarray:
    """Rotation by ``angle_deg`` about the z axis (report equation 2 with angle -(H + A))."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def pose_rotation(pose: ScanPose) -> np.ndarray:
    """Sensor-to-scene rotation for ``pose``: Rz(-(H + A)) @ Rx(90 - D)."""
    return rotation_z(-(pose.heading + pose.azimuth)) @ rotation_x(90.0 - pose.depression)


def scan_rotation(pose: ScanPose, attitude=None) -> np.ndarray:
    """Sensor-to-scene rotation of a scan: ``pose_rotation``, turned by the aircraft's
    (roll, pitch) for a body-fixed sensor (``attitude``; None: stabilised)."""
    rotation = pose_rotation(pose_field("pose", pose))
    if attitude is None:
        return rotation
    angles = _attitude_angles(attitude)
    if not any(angles):  # level flight: the report's rays exactly
        return rotation
    from ladartui.attitude import body_rotation

    return body_rotation(pose.heading, *angles) @ rotation


def _row_span(rows, grid: int) -> tuple[int, int, int]:
    """``rows`` (a slice or range of detector rows, step 1) as (first, stop, 1)."""
    span = None
    if isinstance(rows, (range, slice)):
        try:
            span = slice(rows.start, rows.stop, rows.step).indices(grid)
        except TypeError:  # a bound that is no integer: slice("a", 2)
            span = None
    if span is None or span[2] != 1:
        raise FieldError("rows", rows, "a contiguous range of detector rows")
    return span


def _attitude_angles(attitude) -> tuple[float, ...]:
    """(roll, pitch) or (roll, pitch, yaw) degrees as finite floats, else FieldError."""
    expected = "(roll, pitch) or (roll, pitch, yaw): finite angles in degrees"
    try:
        angles = None if isinstance(attitude, (str, bytes)) else tuple(attitude)
    except TypeError:
        angles = None
    if angles is None or len(angles) not in (2, 3):
        raise FieldError("attitude", attitude, expected)
    try:
        return tuple(number_field("attitude", a) for a in angles)
    except FieldError:
        raise FieldError("attitude", attitude, expected) from None


_KERNEL = None


def _rays_kernel():
    """The compiled loop that builds, turns and moves rays (compiled on first use).

    One nogil loop over the requested detector rows: memory is only the
    output, and no multi-threaded BLAS product is involved (``array @ R.T``
    took 100-300 ms instead of 1 ms while other work ran on the machine).
    numba loads lazily so that reading a scenario does not pay for it.
    """
    global _KERNEL
    if _KERNEL is None:
        import numba

        @numba.njit(nogil=True, cache=True)
        def build(
            n, m, row0, row1, tan_x, tan_y, pos_x, pos_y, rotation, position, origins, directions, detector
        ):
            # R (tx, ty, -1) / |.| = (tx R[:,0] + (ty R[:,1] - R[:,2])) / |.|: one term per
            # column, one per row. Origins likewise: px R[:,0] + (py R[:,1] + position).
            col_dir = np.empty((n * m, 3))
            col_org = np.empty((n * m, 3))
            for kx in range(n * m):
                for k in range(3):
                    col_dir[kx, k] = tan_x[kx] * rotation[k, 0]
                    col_org[kx, k] = pos_x[kx] * rotation[k, 0]
            ray = 0
            for r in range(row0, row1):
                for c in range(n):
                    for i in range(m):
                        ky = r * m + i
                        ty = tan_y[ky]
                        row_x = ty * rotation[0, 1] - rotation[0, 2]
                        row_y = ty * rotation[1, 1] - rotation[1, 2]
                        row_z = ty * rotation[2, 1] - rotation[2, 2]
                        org_x = pos_y[ky] * rotation[0, 1] + position[0]
                        org_y = pos_y[ky] * rotation[1, 1] + position[1]
                        org_z = pos_y[ky] * rotation[2, 1] + position[2]
                        for j in range(m):
                            kx = c * m + j
                            tx = tan_x[kx]
                            inv = 1.0 / np.sqrt(tx * tx + ty * ty + 1.0)
                            directions[ray, 0] = (col_dir[kx, 0] + row_x) * inv
                            directions[ray, 1] = (col_dir[kx, 1] + row_y) * inv
                            directions[ray, 2] = (col_dir[kx, 2] + row_z) * inv
                            origins[ray, 0] = col_org[kx, 0] + org_x
                            origins[ray, 1] = col_org[kx, 1] + org_y
                            origins[ray, 2] = col_org[kx, 2] + org_z
                            detector[ray] = r * n + c
                            ray += 1

        _KERNEL = build
    return _KERNEL


@dataclass(frozen=True)
class Sensor:
    """An n x n detector flash LADAR with m x m rays per detector.

    ``fov`` is the full field of view in degrees (on each axis),
    ``depth_resolution`` metres (two returns on one detector closer than this
    merge), ``pixel_pitch`` metres (report: 100 micrometres), ``mount``
    "stabilised" (default) or "body-fixed" (see ``MOUNTS``).
    """

    grid: int = 128
    ray_grid: int = 4
    fov: float = 10.0
    depth_resolution: float = 1.0
    pixel_pitch: float = 100e-6
    mount: str = "stabilised"

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "grid", integer_field("grid", self.grid, 1, MAX_GRID))
        set_(self, "ray_grid", integer_field("ray_grid", self.ray_grid, 1, MAX_RAY_GRID))
        set_(self, "fov", number_field("fov", self.fov, MIN_FOV, 90.0, high_open=True))
        set_(
            self,
            "depth_resolution",
            number_field("depth_resolution", self.depth_resolution, 0.0, MAX_DEPTH_RESOLUTION),
        )
        set_(
            self,
            "pixel_pitch",
            number_field("pixel_pitch", self.pixel_pitch, MIN_PIXEL_PITCH, MAX_PIXEL_PITCH),
        )
        if not isinstance(self.mount, str) or self.mount not in MOUNTS:
            raise FieldError("mount", self.mount, "one of " + ", ".join(repr(m) for m in MOUNTS))

    @property
    def detectors(self) -> int:
        return self.grid * self.grid

    @property
    def rays_per_scan(self) -> int:
        return (self.grid * self.ray_grid) ** 2

    @property
    def ifov(self) -> float:
        """Angular width of one detector, degrees (projected, at the centre of the view)."""
        return self.fov / self.grid

    @cached_property
    def _axes(self):
        """Per-axis tangents and focal-plane positions of the (n m) ray columns and rows."""
        side = self.grid * self.ray_grid
        cell = (np.arange(side) + 0.5) / side  # 0..1 across the view, cell centres
        tan_x = np.tan(np.radians(self.fov * (cell - 0.5)))
        tan_y = np.tan(np.radians(self.fov * (0.5 - cell)))
        pos_x = (cell - 0.5) * self.grid * self.pixel_pitch
        pos_y = (0.5 - cell) * self.grid * self.pixel_pitch
        return tan_x, tan_y, pos_x, pos_y

    def rays(self, pose: ScanPose, rows: range | slice | None = None, attitude=None):
        """The rays of one scan at ``pose``: (origins, directions, detector).

        ``attitude``: the aircraft's (roll, pitch), or (roll, pitch, yaw), in
        degrees, turning the rays of a body-fixed sensor (None: stabilised, the
        report's rays exactly); anything else is a ``FieldError``.

        origins (N, 3) float64 metres in the scene frame; directions (N, 3)
        float64 unit vectors; detector (N,) int32, row-major; N = (n m)^2, or
        only the detector rows in ``rows`` (a slice of detector rows, for
        tracing a scan in chunks: the result is that contiguous part).
        """
        pose = pose_field("pose", pose)
        row0, row1 = 0, self.grid
        if rows is not None:
            row0, row1, step = _row_span(rows, self.grid)
            row1 = max(row0, row1)
        count = (row1 - row0) * self.grid * self.ray_grid**2
        origins = np.empty((count, 3))
        directions = np.empty((count, 3))
        detector = np.empty(count, dtype=np.int32)
        _rays_kernel()(
            self.grid,
            self.ray_grid,
            row0,
            row1,
            *self._axes,
            scan_rotation(pose, attitude),
            np.array(pose.position, dtype=np.float64),
            origins,
            directions,
            detector,
        )
        return origins, directions, detector

    def central_ray(self, pose: ScanPose, attitude=None):
        """(origin (3,), unit direction (3,)) of the sensor's boresight at ``pose``."""
        rotation = scan_rotation(pose, attitude)
        return np.array(pose.position), rotation @ np.array([0.0, 0.0, -1.0])

    def corner_directions(self, pose: ScanPose, attitude=None) -> np.ndarray:
        """Unit directions (4, 3) of the field-of-view corners: far-left, far-right,
        near-right, near-left (focal-plane corners (-x,+y), (+x,+y), (+x,-y), (-x,-y))."""
        t = math.tan(math.radians(self.fov / 2))
        local = np.array([[-t, t, -1.0], [t, t, -1.0], [t, -t, -1.0], [-t, -t, -1.0]])
        local /= np.linalg.norm(local, axis=1, keepdims=True)
        return local @ scan_rotation(pose, attitude).T

    def footprint(self, pose: ScanPose, ground_z: float = 0.0, attitude=None) -> np.ndarray:
        """Where the four field-of-view corners meet the plane z = ``ground_z``: (4, 3).

        The corners are the edges of the view (angles +-fov/2 on both axes), in
        the order of ``corner_directions``. A corner that never reaches the
        ground (at or above the horizon, or a plane above the sensor) is NaN.
        """
        ground_z = number_field("ground_z", ground_z)
        directions = self.corner_directions(pose, attitude)
        origin = np.array(pose.position)
        drop = origin[2] - ground_z
        with np.errstate(divide="ignore", invalid="ignore"):
            # a plane above the sensor lies behind every downward ray: no corner meets it
            t = np.where((directions[:, 2] < 0) & (drop >= 0), drop / -directions[:, 2], np.nan)
        return origin + t[:, None] * directions
