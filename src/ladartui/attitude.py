"""Platform attitude (optional; the stabilised sensor stays the default).

Frames: the level body frame L is forward, right, down (FRD) at the pose's
heading ``h`` (clockwise from north, x east, y north, z up), so its axes in
the scene frame are ``f = (sin h, cos h, 0)``, ``r = (cos h, -sin h, 0)``,
``d = (0, 0, -1)`` and ``B = [f r d]`` (columns). The report's equations 1
and 2 give the stabilised ray directions (azimuth and depression relative to
the horizon). A body-fixed sensor turns them with the aircraft:

    d_world = B Rz(yaw) Ry(pitch) Rx(roll) B^T d_stabilised

(aerospace order: yaw, then pitch, then roll; roll positive right wing down,
pitch positive nose up, yaw positive to the right, all in degrees). A
coordinated turn of radius ``r`` at speed ``v`` banks by
``roll = atan(v^2 / (g r))``.
"""

from __future__ import annotations

import math

import numpy as np

from ladartui.checks import number_field
from ladartui.errors import FieldError, described

STANDARD_GRAVITY = 9.80665


def coordinated_turn_roll(speed: float, radius: float, g: float = STANDARD_GRAVITY) -> float:
    """Bank angle (degrees) of a coordinated level turn at ``speed`` m/s on ``radius`` metres.

    A speed below 0, a radius not above 0 or a value that is no finite number is a
    ``FieldError`` naming it.
    """
    speed = number_field("speed", speed, 0.0)
    radius = number_field("radius", radius, 0.0, low_open=True)
    return math.degrees(math.atan(speed * speed / (g * radius)))


def _level_frame(heading_deg: float) -> np.ndarray:
    h = math.radians(heading_deg)
    return np.array([[math.sin(h), math.cos(h), 0.0], [math.cos(h), -math.sin(h), 0.0], [0.0, 0.0, -1.0]]).T


def attitude_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Rz(yaw) Ry(pitch) Rx(roll), body FRD to level FRD, degrees."""
    cr, sr = math.cos(math.radians(roll)), math.sin(math.radians(roll))
    cp, sp = math.cos(math.radians(pitch)), math.sin(math.radians(pitch))
    cy, sy = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def body_rotation(heading: float, roll: float = 0.0, pitch: float = 0.0, yaw: float = 0.0) -> np.ndarray:
    """``B Rz(yaw) Ry(pitch) Rx(roll) B^T``: stabilised to body-fixed, scene frame."""
    b = _level_frame(heading)
    return b @ attitude_matrix(roll, pitch, yaw) @ b.T


def body_fixed_directions(
    directions, heading: float, roll: float = 0.0, pitch: float = 0.0, yaw: float = 0.0
) -> np.ndarray:
    """Stabilised ray directions (N, 3) turned with the aircraft's attitude (degrees).

    Directions of another shape, or an angle that is no finite number, are a
    ``FieldError`` naming the argument.
    """
    angles = {"heading": heading, "roll": roll, "pitch": pitch, "yaw": yaw}
    heading, roll, pitch, yaw = (number_field(name, value) for name, value in angles.items())
    try:
        array = np.asarray(directions, dtype=np.float64)
    except (TypeError, ValueError):
        raise FieldError("directions", described(directions), "an (N, 3) array of numbers") from None
    if array.ndim != 2 or array.shape[1] != 3:
        raise FieldError("directions", described(directions), "an (N, 3) array of numbers")
    rotation = body_rotation(heading, roll, pitch, yaw)
    return array @ rotation.T


def segment_attitudes(segment, poses, speed: float) -> list[tuple[float, float]]:
    """(roll, pitch) in degrees at each of a segment's scans.

    Turns and orbits bank as coordinated turns at ``speed`` (right turns roll
    right, positive); a recorded flight log gives its own roll and pitch;
    every other segment flies wings level.
    """
    from ladartui.flight import Orbit, Turn

    if hasattr(segment, "attitudes"):  # a recorded log knows its own
        return list(segment.attitudes())
    if isinstance(segment, (Turn, Orbit)):
        roll = coordinated_turn_roll(speed, segment.radius)
        return [(roll if segment.direction == "right" else -roll, 0.0)] * len(poses)
    return [(0.0, 0.0)] * len(poses)


def plan_attitudes(plan, speed: float, sensor) -> list:
    """Per scan of ``plan``: (roll, pitch) for a body-fixed sensor, None for a stabilised one."""
    segment_poses = plan.segment_poses()
    if sensor.mount != "body-fixed":
        return [None] * sum(len(p) for p in segment_poses)
    return [
        a
        for segment, poses in zip(plan.segments, segment_poses)
        for a in segment_attitudes(segment, poses, speed)
    ]


def scan_footprints(scenario, ground_z: float = 0.0) -> list[np.ndarray]:
    """Each scan's field-of-view corners on the ground (4, 3), as they fall with attitude.

    For a stabilised sensor these are ``Sensor.footprint(pose)``; a body-fixed
    one's swing with the bank of turns and orbits and a log's roll and pitch.
    """
    sensor = scenario.sensor
    attitudes = plan_attitudes(scenario.flight, scenario.speed, sensor)
    return [sensor.footprint(pose, ground_z, attitude) for pose, attitude in zip(scenario.poses(), attitudes)]
