"""LAS/LAZ point clouds in and out of the voxel grid.

Import voxelises points at the scene's voxel size. The *origin* is the
position in metres of voxel (0, 0, 0)'s centre, so a point ``p`` falls in
voxel ``floor((p - origin) / voxel_size + 0.5)``. By default the origin is the
lowest coordinate of the cloud on each axis: the minimum point lands in voxel
0 on every axis and no index is negative. Export writes voxel centres,
``origin + index * voxel_size`` metres. LAZ (compressed) is chosen by the
``.laz`` suffix.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ladartui.atomic import atomic_path
from ladartui.errors import FieldError, InputFileError
from ladartui.scene.voxels import MAX_INDEX, unique_voxels


def import_las(path, voxel_size, origin=None) -> tuple[np.ndarray, np.ndarray]:
    """Voxelise a LAS/LAZ file: returns ((N, 3) int32 unique voxels, origin (3,) metres)."""
    import laspy

    path = Path(path)
    size = _check_voxel_size(voxel_size)
    if not path.is_file():
        raise InputFileError(path, "no such file; expected a LAS or LAZ point cloud")
    try:
        cloud = laspy.read(path)
    except Exception as error:  # laspy raises several kinds for a damaged or foreign file
        raise InputFileError(path, f"not a readable LAS/LAZ point cloud ({error})") from None
    points = np.stack([np.asarray(cloud.x), np.asarray(cloud.y), np.asarray(cloud.z)], axis=1)
    if not len(points):
        raise InputFileError(path, "holds no points; expected a LAS or LAZ point cloud")
    lowest = points.min(axis=0)
    if origin is None:
        origin = lowest
    origin = np.asarray(origin, dtype=np.float64).reshape(-1)
    if origin.shape != (3,) or not np.all(np.isfinite(origin)):
        raise FieldError("origin", tuple(origin.tolist()), "three finite coordinates in metres")
    indices = np.floor((points - origin) / size + 0.5)
    if indices.min() < 0:
        raise FieldError("origin", tuple(origin.tolist()),
                         f"at most half a voxel above the lowest point {tuple(lowest.tolist())}",
                         source=str(path))
    if indices.max() > MAX_INDEX:
        raise FieldError("voxel_size", voxel_size, "large enough for the cloud's extent",
                         source=str(path))
    voxels, _ = unique_voxels(indices.astype(np.int32))
    return voxels, origin


def export_las(path, voxels, voxel_size, origin=(0.0, 0.0, 0.0)) -> None:
    """Write voxel centres (metres) as a LAS 1.2 file, or LAZ for a ``.laz`` path, atomically."""
    import laspy

    path = Path(path)
    size = _check_voxel_size(voxel_size)
    voxels = np.asarray(voxels)
    if voxels.size and (voxels.ndim != 2 or voxels.shape[1] != 3):
        raise ValueError(f"voxels must be an (N, 3) array, got shape {voxels.shape}")
    origin = np.asarray(origin, dtype=np.float64).reshape(3)
    centres = origin + voxels.reshape(-1, 3).astype(np.float64) * size
    header = laspy.LasHeader(version="1.2", point_format=0)
    # A scale well below the voxel size keeps every centre recoverable exactly.
    scale = min(0.001, size / 1000)
    header.scales = np.full(3, scale)
    header.offsets = np.floor(centres.min(axis=0)) if len(centres) else np.zeros(3)
    cloud = laspy.LasData(header)
    cloud.x, cloud.y, cloud.z = centres[:, 0], centres[:, 1], centres[:, 2]
    compress = path.suffix.lower() == ".laz"
    # Write to a stream: given a path, laspy picks compression from the suffix (.tmp here).
    with atomic_path(path) as tmp, open(tmp, "wb+") as stream:
        cloud.write(stream, do_compress=compress)


def _check_voxel_size(voxel_size) -> float:
    try:
        size = float(voxel_size)
    except (TypeError, ValueError):
        size = math.nan
    if not (size > 0 and math.isfinite(size)):
        raise FieldError("voxel_size", voxel_size, "a positive number of metres")
    return size
