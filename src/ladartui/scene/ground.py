"""The ground a vehicle inserted into a scene rests on.

A scene's ground is read from its voxels: the lowest voxel of each column (a
survey's ground returns, a generated terrain's skin). Under a vehicle's
footprint, a column's lowest voxel counts as ground when it lies less than the
vehicle's height above the lowest voxel within ``MARGIN_M`` around the
footprint: higher ones are overhead (a crown, a survey column with no ground
return), which the vehicle stands under, not on. When such ground holds at
least a quarter of the footprint's columns, the vehicle is raised whole
layers to rest on the top of its highest voxel there; otherwise (no ground
found, as in a generated flat scene, whose ground is the floor and holds no
voxels) it stays on the floor: the plane at the bottom of voxel layer 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ladartui.errors import LadarError
from ladartui.scene.voxels import MAX_INDEX

MARGIN_M = 5.0  # metres around the footprint in which the lowest ground is looked for
GROUND_SHARE = 0.25  # of the footprint's columns: enough ground found to rest on


@dataclass(frozen=True)
class Resting:
    """Where an inserted vehicle was set, in voxel layers."""

    lift: int  # layers the vehicle was raised from the floor placement
    columns: int  # its footprint's columns
    ground_columns: int  # of them, those whose ground was found
    covered: int  # footprint columns with scene voxels less than its height over its top
    height: int  # the vehicle's height in layers
    found: tuple[int, int] | None = None  # the lowest and highest ground voxel found, rested on or not
    top: int = 0  # the vehicle's top layer where it was set

    @property
    def on_ground(self) -> bool:
        """Raised onto the ground found (voxel indices start at 0: a lift of at least one)."""
        return self.lift > 0

    @property
    def beneath(self) -> bool:
        """Left on the floor under ground too sparse to rest on: all of it above the vehicle."""
        return not self.on_ground and self.found is not None and self.found[0] > self.top

    @property
    def buried(self) -> bool:
        """Most of the footprint covered from above within the vehicle's height."""
        return 2 * self.covered > self.columns

    def describe(self, voxel_size: float, above: float = 0.0) -> str:
        """Where it rests, in scene metres (z 0 at voxel layer 0's centre); ``above``:
        the height given for it (--at X,Y,Z), over the ground or else the floor."""
        vs = voxel_size
        if not self.on_ground or self.found is None:
            found = (
                f"too little ground under the vehicle's footprint to rest on ({self.ground_columns} "
                f"of its {self.columns} columns; a quarter are needed)"
                if self.ground_columns
                else f"no ground found under the vehicle's footprint (0 of its {self.columns} columns)"
            )
            floor = f"z {-0.5 * vs:g} m, the bottom of voxel layer 0"
            if above:
                return f"{found}: it is set {above:g} m above the scene's floor ({floor})"
            return (
                f"{found}: it is set on the scene's floor at {floor}, as on flat ground; on steep "
                "ground give its height with --at X,Y,Z"
            )
        ground_low, ground_high = self.found
        top = (ground_high + 0.5) * vs
        return (
            f"the vehicle is resting on the ground under its footprint at z {top:g} m "
            f"(ground voxels there span z {(ground_low - 0.5) * vs:g}..{top:g} m, "
            f"found in {self.ground_columns} of its {self.columns} columns)"
        )

    def warning(self, voxel_size: float) -> str:
        return (
            f"warning: scene voxels lie less than the vehicle's height ({self.height * voxel_size:g} m) "
            f"over {self.covered} of its {self.columns} footprint columns: check that it is not "
            "buried under the ground (move it with --at)"
        )

    def beneath_warning(self, voxel_size: float, at: tuple[float, float]) -> str:
        """The ground found over a vehicle left on the floor, and the ``--at`` that sets it there."""
        if self.found is None:
            raise ValueError("no ground was found")
        vs = voxel_size
        low, high = (self.found[0] - 0.5) * vs, (self.found[1] + 0.5) * vs
        return (
            f"warning: the ground found under it (z {low:g}..{high:g} m) lies above the vehicle's top "
            f"(z {(self.top + 0.5) * vs:g} m): it is buried; --at {at[0]:g},{at[1]:g},{high + 0.5 * vs:g} "
            "sets it on that ground"
        )


def _columns(voxels: np.ndarray, x0: int, y0: int, width: int) -> np.ndarray:
    return (voxels[:, 0].astype(np.int64) - x0) * width + (voxels[:, 1].astype(np.int64) - y0)


def rest_on_ground(scene: np.ndarray, vehicle: np.ndarray, voxel_size: float) -> tuple[np.ndarray, Resting]:
    """``vehicle`` (placed on the floor) raised to rest on the scene's ground under it, and how.

    ``LadarError`` when the raised vehicle would pass the largest voxel index.
    """
    vehicle = np.asarray(vehicle, dtype=np.int32).reshape(-1, 3)
    if len(vehicle) == 0:
        return vehicle, Resting(0, 0, 0, 0, 0)
    margin = int(np.ceil(MARGIN_M / voxel_size))
    low, high = vehicle.min(axis=0).astype(np.int64), vehicle.max(axis=0).astype(np.int64)
    x0, y0 = low[0] - margin, low[1] - margin
    width = int(high[1] + margin - y0 + 1)
    near = scene[
        (scene[:, 0] >= x0)
        & (scene[:, 0] <= high[0] + margin)
        & (scene[:, 1] >= y0)
        & (scene[:, 1] <= high[1] + margin)
    ]
    footprint = np.unique(_columns(vehicle, x0, y0, width))
    height = int(high[2] - low[2] + 1)
    keys = _columns(near, x0, y0, width)
    order = np.lexsort((near[:, 2], keys))
    keys, z = keys[order], near[order, 2].astype(np.int64)
    first = np.r_[True, keys[1:] != keys[:-1]] if len(keys) else np.zeros(0, dtype=bool)
    column_keys, lowest = keys[first], z[first]
    where = np.searchsorted(column_keys, footprint)
    found = where < len(column_keys)
    found[found] = column_keys[where[found]] == footprint[found]
    under = lowest[where[found]]  # the lowest voxel of each footprint column holding any
    ground = under[under < lowest.min() + height] if len(under) else under
    lift = 0
    if len(ground) and len(ground) >= GROUND_SHARE * len(footprint):
        ground_high = int(ground.max())
        lift = ground_high + 1
        if int(high[2]) + lift > MAX_INDEX:
            raise LadarError(
                f"the ground under the vehicle is at voxel layer {ground_high}: resting on it, the "
                f"vehicle would pass voxel index {MAX_INDEX}"
            )
        vehicle = vehicle + np.array([0, 0, lift], dtype=np.int32)
    # Covered: a scene voxel over the vehicle's top in the column, less than its height above.
    top = int(high[2]) + lift
    over = near[(near[:, 2] > top) & (near[:, 2] <= top + height)]
    covered = int(np.count_nonzero(np.isin(footprint, _columns(over, x0, y0, width))))
    ground_span = (int(ground.min()), int(ground.max())) if len(ground) else None
    resting = Resting(lift, len(footprint), len(ground), covered, height, ground_span, top)
    return vehicle, resting
