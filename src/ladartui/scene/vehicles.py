"""The vehicles of a generated scene: where they stand, their solid voxels, the clearing
around each (free of plants) and the camouflage net over the first.

Sizes are metres; the grid is voxel indices (see ``scene.generate``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ladartui.errors import FieldError

if TYPE_CHECKING:
    from ladartui.scene.generate import SceneParams


@dataclass(frozen=True)
class Vehicle:
    """Where a vehicle stands and how large it is."""

    cx: float  # centre, grid units
    cy: float
    base: int  # first voxel layer of the vehicle (on the ground or terrain)
    heading: float  # radians, clockwise from north (+y)
    size: tuple[float, float, float]


def place_vehicles(p: SceneParams, nx, ny, ground, rng) -> list[Vehicle]:
    vs = p.voxel_size
    length = p.vehicle_size[0]
    vehicles: list[Vehicle] = []
    for index in range(p.vehicles):
        heading = rng.uniform(0, 2 * np.pi)
        if index == 0:
            cx, cy = nx / 2, ny / 2
        else:  # others somewhere else, clear of the others and of the border
            margin = (length + 2) / vs
            for _ in range(100):
                cx, cy = rng.uniform(margin, nx - margin), rng.uniform(margin, ny - margin)
                if all(math.hypot(cx - v.cx, cy - v.cy) * vs > 2 * length + 4 for v in vehicles):
                    break
            else:  # no room left: overlapping vehicles would overwrite each other
                raise FieldError(
                    "vehicles",
                    p.vehicles,
                    f"at most {index} vehicles kept apart ({2 * length + 4:g} m between centres) "
                    f"in a {p.width:g} x {p.depth:g} m scene",
                )
        reach = int(math.ceil(length / 2 / vs))
        x0, x1 = max(int(cx) - reach, 0), min(int(cx) + reach + 1, nx)
        y0, y1 = max(int(cy) - reach, 0), min(int(cy) + reach + 1, ny)
        base = int(ground[x0:x1, y0:y1].max())
        size_l, size_w, size_h = p.vehicle_size  # a list from a file is a 3-tuple here
        vehicles.append(Vehicle(cx, cy, base, heading, (size_l, size_w, size_h)))
    return vehicles


def _local_frame(vehicle: Vehicle, voxels, vs):
    """Voxel centres in the vehicle frame: u forward, v to the right, w up from its base (m)."""
    dx = (voxels[:, 0] - vehicle.cx) * vs
    dy = (voxels[:, 1] - vehicle.cy) * vs
    sin, cos = math.sin(vehicle.heading), math.cos(vehicle.heading)
    u = dx * sin + dy * cos
    v = dx * cos - dy * sin
    w = (voxels[:, 2] - vehicle.base + 0.5) * vs
    return u, v, w


def box_shape(reach_m: float, top_m: float, vs: float) -> tuple[int, int]:
    """(cells either side of a vehicle's centre, cells up from its base) of the box it
    is cut from: ``reach_m`` and ``top_m`` at voxel size ``vs``, a cell to spare."""
    return int(math.ceil(reach_m / vs)) + 1, int(math.ceil(top_m / vs)) + 1


def _box_grid(vehicle: Vehicle, reach_m, top_m, vs):
    reach, top = box_shape(reach_m, top_m, vs)
    xs = np.arange(int(vehicle.cx) - reach, int(vehicle.cx) + reach + 1)
    ys = np.arange(int(vehicle.cy) - reach, int(vehicle.cy) + reach + 1)
    zs = np.arange(vehicle.base, vehicle.base + top)
    grid = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    return grid[(grid[:, 0] >= 0) & (grid[:, 1] >= 0)].astype(np.int32)


def vehicle_voxels(vehicle: Vehicle, p: SceneParams) -> np.ndarray:
    """A solid hull on four wheels with a cabin and sloped windscreen, proportions of a
    truck (not clipped to the grid)."""
    vs = p.voxel_size
    length, width, height = vehicle.size
    grid = _box_grid(vehicle, math.hypot(length, width) / 2, height, vs)
    u, v, w = _local_frame(vehicle, grid, vs)
    half_l, half_w = length / 2, width / 2
    clearance = 0.2 * height
    hull_top = 0.6 * height
    wheel_r = 0.2 * height
    chamfer = 0.1 * length
    hull = (
        (np.abs(u) <= half_l)
        & (np.abs(v) <= half_w)
        & (w >= clearance)
        & (w <= hull_top)
        & (u + (w - clearance) <= half_l + (hull_top - clearance) - chamfer)
    )
    wheel_x = np.array([-0.3, 0.3]) * length
    near_side = (np.abs(v) >= half_w - 0.15 * width) & (np.abs(v) <= half_w - 0.02 * width)
    wheels = np.zeros_like(hull)
    for axle in wheel_x:
        wheels |= near_side & ((u - axle) ** 2 + (w - wheel_r) ** 2 <= wheel_r**2)
    cabin_back, cabin_front = 0.02 * length, 0.34 * length
    slope = 0.4  # the windscreen leans back this far per metre of rise
    cabin = (
        (u >= cabin_back)
        & (u <= cabin_front - slope * (w - hull_top))
        & (np.abs(v) <= half_w - 0.08 * width)
        & (w > hull_top)
        & (w <= height)
    )
    return grid[hull | wheels | cabin]


def in_clearing(voxels, vehicle: Vehicle, vs, margin=0.3, headroom=0.5) -> np.ndarray:
    """Indices of the voxels inside the box around a vehicle: it stands in a clearing,
    free of plants."""
    length, width, height = vehicle.size
    reach = (math.hypot(length, width) / 2 + margin) / vs + 1
    top = vehicle.base + (height + headroom) / vs + 1
    # Candidates by whole-voxel bounds a voxel wider each way (integer compares, no
    # float columns over millions of voxels); the tests in metres then decide.
    x, y = voxels[:, 0], voxels[:, 1]
    near = np.flatnonzero(
        (x >= math.floor(vehicle.cx - reach) - 1)
        & (x <= math.ceil(vehicle.cx + reach) + 1)
        & (y >= math.floor(vehicle.cy - reach) - 1)
        & (y <= math.ceil(vehicle.cy + reach) + 1)
        & (voxels[:, 2] <= math.floor(top))  # (the same test for whole numbers)
    )
    near = near[
        (np.abs(voxels[near, 0] - vehicle.cx) <= reach) & (np.abs(voxels[near, 1] - vehicle.cy) <= reach)
    ]
    u, v, w = _local_frame(vehicle, voxels[near], vs)
    inside = (np.abs(u) <= length / 2 + margin) & (np.abs(v) <= width / 2 + margin) & (w <= height + headroom)
    return near[inside]


def net_voxels(vehicle: Vehicle, p: SceneParams, ground, rng) -> np.ndarray:
    """A patchy net: flat just above the vehicle, draped down to the ground around it."""
    vs = p.voxel_size
    length, width, height = vehicle.size
    rim = 1.0  # metres of net between the vehicle's side and the ground
    roof = height + 0.25
    nx, ny = ground.shape
    reach = int(math.ceil((math.hypot(length, width) / 2 + rim) / vs)) + 1
    xs = np.arange(max(int(vehicle.cx) - reach, 0), min(int(vehicle.cx) + reach + 1, nx))
    ys = np.arange(max(int(vehicle.cy) - reach, 0), min(int(vehicle.cy) + reach + 1, ny))
    cols = np.stack(np.meshgrid(xs, ys, indexing="ij"), axis=-1).reshape(-1, 2)
    zeros = np.zeros((len(cols), 1), dtype=np.int64)
    u, v, _ = _local_frame(vehicle, np.hstack([cols, zeros + vehicle.base]), vs)
    outside = np.maximum(np.abs(u) - length / 2 - 0.1, np.abs(v) - width / 2 - 0.1)
    keep = outside <= rim
    # Garnish patches: a coarse random field (0.4 m cells) thresholded to the coverage.
    cell = max(1, round(0.4 / vs))
    coarse = rng.random(((nx + cell - 1) // cell + 1, (ny + cell - 1) // cell + 1))
    keep &= coarse[cols[:, 0] // cell, cols[:, 1] // cell] < p.net_coverage
    cols, outside = cols[keep], outside[keep]
    lift = roof * np.clip(1 - np.maximum(outside, 0) / rim, 0, 1)
    floor = ground[cols[:, 0], cols[:, 1]]
    top = np.maximum(vehicle.base + np.floor(lift / vs).astype(np.int64), floor)
    # Steep drape: fill down by the slope so rays cannot slip between layers.
    drop = np.where(outside > 0, np.ceil(roof / rim), 0).astype(np.int64)
    bottom = np.maximum(top - drop, floor)
    counts = top - bottom + 1
    column = np.repeat(np.arange(len(cols)), counts)
    starts = np.cumsum(counts) - counts
    z = bottom[column] + (np.arange(column.size) - starts[column])
    return np.stack([cols[column, 0], cols[column, 1], z], axis=1).astype(np.int32)
