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


def _check_header(path, header):
    """Refuse scale factors and offsets that cannot give distinct, finite coordinates."""
    scales = np.asarray(header.scales, dtype=np.float64)
    offsets = np.asarray(header.offsets, dtype=np.float64)
    if not np.all(np.isfinite(scales)) or np.any(scales == 0):
        raise InputFileError(
            path, f"header scale factors {_triple(scales)}: expected finite non-zero numbers (such as 0.001)"
        )
    if not np.all(np.isfinite(offsets)):
        raise InputFileError(path, f"header offsets {_triple(offsets)}: expected finite numbers")
    # Beyond this, adding the offset rounds away the scaled coordinate: points merge.
    lossy = np.spacing(np.abs(offsets)) * 2 > scales
    if np.any(lossy):
        raise InputFileError(
            path,
            f"header offsets {_triple(offsets)} are too large for the "
            f"scale factors {_triple(scales)}: points would merge; expected "
            "offsets near the data",
        )


def _check_no_collapse(path, cloud, points):
    """Distinct stored points must stay distinct once scaled and offset."""
    if not np.all(np.isfinite(points)):
        raise InputFileError(path, "coordinates overflow once scaled and offset; expected finite coordinates")
    raw = np.stack([np.asarray(cloud.X), np.asarray(cloud.Y), np.asarray(cloud.Z)], axis=1)
    stored = len(np.unique(raw, axis=0))
    kept = len(np.unique(points, axis=0))
    if kept < stored:
        raise InputFileError(
            path,
            f"{stored:,} distinct stored points collapse to {kept:,} "
            "once scaled and offset; expected scale factors and offsets that "
            "keep them apart",
        )


def _triple(values) -> str:
    return "(" + ", ".join(f"{v:g}" for v in values) + ")"


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
    _check_header(path, cloud.header)
    points = np.stack([np.asarray(cloud.x), np.asarray(cloud.y), np.asarray(cloud.z)], axis=1)
    if not len(points):
        raise InputFileError(path, "holds no points; expected a LAS or LAZ point cloud")
    _check_no_collapse(path, cloud, points)
    lowest = points.min(axis=0)
    if origin is None:
        origin = lowest
    origin = np.asarray(origin, dtype=np.float64).reshape(-1)
    if origin.shape != (3,) or not np.all(np.isfinite(origin)):
        raise FieldError("origin", tuple(origin.tolist()), "three finite coordinates in metres")
    indices = np.floor((points - origin) / size + 0.5)
    if indices.min() < 0:
        raise FieldError(
            "origin",
            tuple(origin.tolist()),
            f"at most half a voxel above the lowest point {tuple(lowest.tolist())}",
            source=str(path),
        )
    if indices.max() > MAX_INDEX:
        raise FieldError("voxel_size", voxel_size, "large enough for the cloud's extent", source=str(path))
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
