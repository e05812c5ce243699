"""Directional statistics of covered target voxels (report section 2.2).

The unit vectors from the target's centroid to each covered voxel centre,
their mean, its length (how one-sided the coverage is) and direction, and the
angle between two mean directions (the shift when foliage hides part of the
target).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

_NOISE = 1e-12


@dataclass(frozen=True)
class DirectionStats:
    """Directional statistics of a set of covered target voxels.

    ``count`` voxels contributed a unit vector (centroid to voxel centre);
    ``mean_vector`` is the sample mean of those vectors, ``resultant_length`` its
    length (0..1), ``mean_direction`` the mean vector made unit length.
    """

    count: int = 0
    mean_vector: tuple[float, float, float] | None = None
    resultant_length: float | None = None
    mean_direction: tuple[float, float, float] | None = None

    def to_dict(self) -> dict:
        return {
            "count": self.count,
            "mean_vector": _list_or_none(self.mean_vector),
            "resultant_length": self.resultant_length,
            "mean_direction": _list_or_none(self.mean_direction),
        }


def direction_stats(voxels, centroid) -> DirectionStats:
    """Statistics of the unit vectors from ``centroid`` to each voxel centre (grid units)."""
    v = np.asarray(voxels, dtype=np.float64).reshape(-1, 3) - np.asarray(centroid, dtype=np.float64)
    norms = np.sqrt((v * v).sum(axis=1))
    # A voxel at the centroid has no direction (tolerance far below a voxel).
    keep = norms > 1e-9
    if not keep.any():
        return DirectionStats()
    units = v[keep] / norms[keep, None]
    mean = units.mean(axis=0)
    # Rounding noise of a symmetric coverage (1e-17) would read as a direction.
    mean[np.abs(mean) < _NOISE] = 0.0
    length = float(math.sqrt(float(mean @ mean)))
    direction = _clean(mean / length) if length > 0.0 else None
    return DirectionStats(
        count=int(keep.sum()),
        mean_vector=_clean(mean),
        resultant_length=length,
        mean_direction=direction,
    )


def _clean(vector) -> tuple[float, float, float]:
    x, y, z = (0.0 if abs(c) < _NOISE else float(c) for c in vector)
    return (x, y, z)


def angle_between(a, b) -> float | None:
    """Angle in radians between two unit vectors; None if either is undefined.

    ``atan2(|a x b|, a . b)``: acos of the dot product loses half the digits
    near 0 and pi (a rounding step below 1 read as 1.5e-8 rad).
    """
    if a is None or b is None:
        return None
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    sine = float(np.linalg.norm(np.cross(a, b)))
    return float(math.atan2(sine, float(np.dot(a, b))))


def _list_or_none(vector):
    return None if vector is None else list(vector)
