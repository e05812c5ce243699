"""LAS/LAZ point clouds in and out of the voxel grid.

Import voxelises points at the scene's voxel size. The *origin* is the
position in metres of voxel (0, 0, 0)'s centre, so a point ``p`` falls in
voxel ``floor((p - origin) / voxel_size + 0.5)``. By default the origin is the
lowest coordinate of the cloud on each axis: the minimum point lands in voxel
0 on every axis and no index is negative. Export writes voxel centres,
``origin + index * voxel_size`` metres. LAZ (compressed) is chosen by the
``.laz`` suffix. A cloud in feet (its coordinate reference system says so) is
read in metres; one in latitude and longitude is refused (``las_crs``).

A target model's target ids travel as each point's ``point_source_id`` (an
unsigned 16-bit field every LAS point format has, hence ids 1..65535):
``export_las(..., ids=...)`` writes them and ``import_las_target`` reads them
back. A cloud whose points all have source id 0 (the usual value) is one
target, id 1. A run's LAS outputs mark target voxels with their id and
every other voxel (foliage, ground) with 0.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ladartui.atomic import atomic_path, write_errors_named
from ladartui.errors import Cancelled, FieldError, InputFileError, LadarError, check_cancelled, described
from ladartui.fileprobe import path_field, require_file
from ladartui.scene.las_crs import metres_per_unit
from ladartui.scene.unique_rows import unique_voxels
from ladartui.scene.voxel_arrays import voxel_list_field, voxel_size_field
from ladartui.scene.voxelize import CANCELLED
from ladartui.scene.voxels import MAX_INDEX, MAX_TARGET_ID

NOISE_CLASSES = (7, 18)  # ASPRS: low point (noise), high noise
READ_POINTS = 1_000_000  # points read at a time: progress and the cancel between them

Progress = Callable[[str, int, int], None]


class AllNoise(InputFileError):
    """Every point of a cloud is noise or withheld; ``keep`` says how to keep them (a
    command passing ``keep_noise`` on from a flag names the flag)."""

    def __init__(self, path, points: int, keep: str = "keep_noise=True"):
        self.points = points
        super().__init__(
            path,
            f"all {points:,} points are noise or withheld (ASPRS classes 7 and 18, or the "
            f"withheld flag); expected ground, vegetation or object points ({keep} takes them)",
        )


@dataclass(frozen=True)
class CloudVoxels:
    """A point cloud voxelised: what ``voxelize_cloud`` gives."""

    voxels: np.ndarray  # (N, 3) int32, unique
    origin: np.ndarray  # (3,) metres: voxel (0, 0, 0)'s centre
    metres_per_unit: tuple[float, float]  # in the cloud's coordinates: x and y, z
    unit: str  # the unit of its x and y, as its coordinate system names it ("metre")
    points: int  # points in the file
    left_out: int  # of them, noise or withheld points left out


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
    # Scaling keeps each axis in order: two points merge only where an axis's distinct
    # stored values do. Each axis is checked alone (a sort of one column); the rows,
    # sorted whole, are counted only where one does.
    if all(_axis_apart(raw[:, axis], points[:, axis]) for axis in range(3)):
        return
    stored, kept = _distinct_rows(raw), _distinct_rows(points)
    if kept < stored:
        raise InputFileError(
            path,
            f"{stored:,} distinct stored points collapse to {kept:,} "
            "once scaled and offset; expected scale factors and offsets that "
            "keep them apart",
        )


def _axis_apart(stored: np.ndarray, scaled: np.ndarray) -> bool:
    """Whether distinct ``stored`` values of an axis stay distinct ``scaled``."""
    _, first = np.unique(stored, return_index=True)
    return len(np.unique(scaled[first])) == len(first)


def _distinct_rows(values: np.ndarray) -> int:
    return len(np.unique(values, axis=0))


def _triple(values) -> str:
    return "(" + ", ".join(f"{v:g}" for v in values) + ")"


def import_las(
    path,
    voxel_size,
    origin=None,
    keep_noise=False,
    *,
    progress: Progress | None = None,
    cancel: threading.Event | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Voxelise a LAS/LAZ file: returns ((N, 3) int32 unique voxels, origin (3,) metres).

    Coordinates in feet, as the cloud's coordinate reference system gives them, are
    read in metres; a cloud in latitude and longitude is refused.

    Points classed as noise (ASPRS classes 7 and 18) and points flagged withheld are
    left out unless ``keep_noise``: a survey's stray return kilometres up would make
    the scene that tall.

    The points are read ``READ_POINTS`` at a time: ``progress("reading", points, of)``
    after each chunk, and a set ``cancel`` raises ``Cancelled`` between them."""
    cloud = voxelize_cloud(path, voxel_size, origin, keep_noise, progress=progress, cancel=cancel)
    return cloud.voxels, cloud.origin


def voxelize_cloud(
    path,
    voxel_size,
    origin=None,
    keep_noise=False,
    *,
    progress: Progress | None = None,
    cancel: threading.Event | None = None,
) -> CloudVoxels:
    """``import_las`` with what a report of it needs: the cloud's units (to give the
    origin in its own coordinates) and how many points were read and left out."""
    indices, _, found = _voxel_indices(path, voxel_size, origin, keep_noise, progress, cancel)
    check_cancelled(cancel, CANCELLED)
    voxels, _ = unique_voxels(indices)  # in the cloud's order, first point first
    return CloudVoxels(voxels, **found._asdict())


def import_las_target(
    path, voxel_size, origin=None, keep_noise=False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Voxelise a LAS/LAZ target model with its ids.

    Returns ((N, 3) int32 unique voxels, (N,) int32 target ids, origin). The id
    is each point's ``point_source_id``; all 0 reads as one target (id 1). A
    voxel holding points of two targets is refused (a smaller voxel size
    keeps them apart), as is a source id 0 beside labelled points. Noise and
    withheld points are left out unless ``keep_noise``, as ``import_las`` does.
    """
    path = path_field("path", path, "a LAS or LAZ point cloud's path")
    indices, source_ids, found = _voxel_indices(path, voxel_size, origin, keep_noise)
    origin = found.origin
    ids = source_ids.astype(np.int32)
    if not ids.any():
        ids[:] = 1
    elif not ids.all():
        raise InputFileError(
            path,
            f"{int(np.count_nonzero(ids == 0)):,} points have point_source_id 0 beside labelled "
            f"points; expected every point's target id in 1..{MAX_TARGET_ID}",
        )
    _, first, inverse = np.unique(indices, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    conflict = np.flatnonzero(ids != ids[first[inverse]])
    if len(conflict):
        row = int(conflict[0])
        x, y, z = (int(c) for c in indices[row])
        raise InputFileError(
            path,
            f"voxel {x},{y},{z} holds points of targets {int(ids[first[inverse[row]]])} and "
            f"{int(ids[row])} at voxel size {float(voxel_size):g} m; expected each voxel in one "
            "target (try a smaller voxel size)",
        )
    keep = np.sort(first)
    return indices[keep], ids[keep], origin


class CloudFound(NamedTuple):
    """What voxelising a cloud found besides its voxels (``CloudVoxels``'s other fields)."""

    origin: np.ndarray
    metres_per_unit: tuple[float, float]
    unit: str
    points: int
    left_out: int


def _voxel_indices(
    path, voxel_size, origin, keep_noise, progress=None, cancel=None
) -> tuple[np.ndarray, np.ndarray, CloudFound]:
    """Each point's voxel ((P, 3) int32), its point_source_id (P,), and what else was
    found: the origin, the metres in a unit, the unit's name, the points read and those
    left out."""
    path = path_field("path", path, "a LAS or LAZ point cloud's path")
    size = voxel_size_field(voxel_size)
    if not isinstance(keep_noise, bool | np.bool_):  # "no" is true
        raise FieldError("keep_noise", keep_noise, "True or False")
    require_file(path, "expected a LAS or LAZ point cloud")
    cloud, (horizontal, vertical, unit) = _read_cloud(path, progress, cancel)
    if progress is not None:
        progress("voxelising", 0, 1)
    points = np.stack([np.asarray(cloud.x), np.asarray(cloud.y), np.asarray(cloud.z)], axis=1)
    if not len(points):
        raise InputFileError(path, "holds no points; expected a LAS or LAZ point cloud")
    _check_no_collapse(path, cloud, points)
    check_cancelled(cancel, CANCELLED)
    if (horizontal, vertical) != (1.0, 1.0):  # a survey in feet
        points = points * np.array([horizontal, horizontal, vertical])
    source_ids = np.asarray(cloud.point_source_id)
    read = len(points)
    if not keep_noise:
        kept = ~(np.isin(np.asarray(cloud.classification), NOISE_CLASSES) | np.asarray(cloud.withheld, bool))
        if not kept.any():
            raise AllNoise(path, len(points))
        if not kept.all():
            points, source_ids = points[kept], source_ids[kept]
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
        span = points.max(axis=0) - np.minimum(origin, lowest)
        # the highest index, floor(span / size + 0.5), must stay within MAX_INDEX
        least = float(span.max()) / (MAX_INDEX + 0.5)
        digits = 2 - math.floor(math.log10(least))
        least = math.ceil(least * 10**digits) / 10**digits  # three figures, rounded up
        raise FieldError(
            "voxel_size",
            voxel_size,
            f"at least {least:g} m for the cloud's extent ({' x '.join(f'{s:.4g}' for s in span)} m; "
            f"at most {MAX_INDEX + 1:,} voxels a side)",
            source=str(path),
        )
    found = CloudFound(origin, (horizontal, vertical), unit, read, read - len(points))
    return indices.astype(np.int32), source_ids, found


def _read_cloud(path, progress=None, cancel=None):
    """The whole cloud and its units (``metres_per_unit``), refused in one line when damaged,
    foreign or cut short; read ``READ_POINTS`` at a time, with ``progress`` and ``cancel``
    between them. What the header alone refuses (its scales and offsets, a coordinate
    system in degrees) is refused before a point is read."""
    import laspy

    try:
        with laspy.open(path) as reader:
            header = reader.header  # with its VLRs and EVLRs: the coordinate system
            _check_header(path, header)
            units = metres_per_unit(path, header)
            if not header.are_points_compressed:
                _check_length(path, header)
            _check_memory(path, header)
            total = header.point_count
            # one array filled chunk by chunk: no second copy of the cloud to join them
            array = np.empty(total, dtype=header.point_format.dtype())
            done = 0
            while done < total:
                check_cancelled(cancel, CANCELLED)
                wanted = min(READ_POINTS, total - done)
                chunk = reader.read_points(wanted).array
                array[done : done + len(chunk)] = chunk
                done += len(chunk)
                if progress is not None:
                    progress("reading", done, total)
                if len(chunk) < wanted:  # the file ended early: laspy reads what there is
                    break
            check_cancelled(cancel, CANCELLED)
            points = laspy.ScaleAwarePointRecord(
                array[:done], header.point_format, header.scales, header.offsets
            )
            cloud = laspy.LasData(header=header, points=points)
    except (LadarError, Cancelled):
        raise
    except Exception as error:  # laspy raises several kinds for a damaged or foreign file
        reason = str(error) or type(error).__name__
        raise InputFileError(path, f"not a readable LAS/LAZ point cloud ({reason})") from None
    if done < header.point_count:
        raise InputFileError(
            path,
            f"cut short: its header gives {header.point_count:,} points, the file holds "
            f"{done:,}; expected the whole file (copied or downloaded in full)",
        )
    return cloud, units


def _check_length(path, header) -> None:
    """An uncompressed cloud must hold every point its header counts."""
    needed = header.offset_to_point_data + header.point_count * header.point_format.size
    size = Path(path).stat().st_size
    if size < needed:
        raise InputFileError(
            path,
            f"cut short: its header gives {header.point_count:,} points ({needed:,} bytes), the "
            f"file has {size:,} bytes; expected the whole file (copied or downloaded in full)",
        )


# Bytes a point takes beyond its record while it is voxelised: its coordinates scaled
# (float64) and stored (int32), the copies the distinct-point checks sort, its voxel
# (float64, then int32). /usr/bin/time -v: 5 M points of 30 bytes peaked at 115 bytes
# a point, from a LAS file or a LAZ one.
POINT_WORK_BYTES = 96


def _check_memory(path, header) -> None:
    """``ResourceLimitError`` before a cloud too large for the memory is read."""
    from ladartui.errors import ResourceLimitError
    from ladartui.resources import available_memory, gib

    record = header.point_format.size
    need = header.point_count * (record + POINT_WORK_BYTES)
    limit = available_memory()
    if need > limit:
        raise ResourceLimitError(
            f"{path}: {header.point_count:,} points of {record} bytes need about {gib(need)} to "
            f"voxelise, more than the {gib(limit)} of memory available; split the cloud into "
            "tiles or thin it"
        )


def export_las(path, voxels, voxel_size, origin=(0.0, 0.0, 0.0), ids=None) -> None:
    """Write voxel centres (metres) as a LAS 1.2 file, or LAZ for a ``.laz`` path, atomically.

    ``ids`` (one target id 1..65535 per voxel, or 0 for a voxel of no target)
    are written as point_source_id.
    """
    path = path_field("path", path, "a LAS or LAZ file's path")
    cloud = _voxel_cloud(voxels, voxel_size, origin, ids)
    with write_errors_named(path), atomic_path(path) as tmp:
        _write_cloud(tmp, cloud, compressed_suffix(path))


def write_las(path, voxels, voxel_size, origin=(0.0, 0.0, 0.0), ids=None, *, compress: bool) -> None:
    """``export_las`` into ``path`` itself: a temporary its caller swaps in (an output set's),
    so LAZ or not is said by ``compress``, not by the suffix."""
    _write_cloud(path, _voxel_cloud(voxels, voxel_size, origin, ids), compress)


def las_writer(path, voxels, voxel_size, scene=None) -> Callable[[Path], None]:
    """An output set's writer of ``voxels`` for ``path`` (LAZ for a ``.laz`` name): it
    writes the temporary it is given; with the loaded ``scene``, each point carries its
    target id (0: not a target)."""
    compress = compressed_suffix(path)

    def write(tmp: Path) -> None:
        ids = None if scene is None else scene.target_ids_of(voxels)
        write_las(tmp, voxels, voxel_size, ids=ids, compress=compress)

    return write


def compressed_suffix(path) -> bool:
    """True for a ``.laz`` name: LAZ, else plain LAS."""
    return Path(path).suffix.lower() == ".laz"


# The largest stored coordinate a scale is chosen for: under the 32-bit limit, with room
# for the rounding of a centre to the nearest step.
_LARGEST_STORED = 2**31 - 2


def _voxel_cloud(voxels, voxel_size, origin, ids):
    """The voxel centres (metres) as a laspy cloud, ``ids`` as point source ids."""
    import laspy

    size = voxel_size_field(voxel_size)
    voxels = voxel_list_field("voxels", voxels, MAX_INDEX)
    origin = np.asarray(origin, dtype=np.float64).reshape(3)
    centres = origin + voxels.reshape(-1, 3).astype(np.float64) * size
    header = laspy.LasHeader(version="1.2", point_format=0)
    offsets = np.floor(centres.min(axis=0)) if len(centres) else np.zeros(3)
    # A scale well below the voxel size keeps every centre recoverable exactly; coarser,
    # where the cloud is too wide for it, so the coordinates fit their 32-bit integers.
    span = float((centres.max(axis=0) - offsets).max()) if len(centres) else 0.0
    scale = max(min(0.001, size / 1000), span / _LARGEST_STORED)
    header.scales = np.full(3, scale)
    header.offsets = offsets
    cloud = laspy.LasData(header)
    cloud.x, cloud.y, cloud.z = centres[:, 0], centres[:, 1], centres[:, 2]
    if ids is not None:
        given, ids = ids, np.asarray(ids)
        if ids.shape != (len(centres),):
            raise FieldError("ids", described(given), f"{len(centres)} target ids, one per voxel")
        wrong = np.flatnonzero((ids < 0) | (ids > MAX_TARGET_ID))
        if len(wrong):
            row = int(wrong[0])
            raise FieldError(
                f"ids[{row}]", int(ids[row]), f"a target id from 0 (no target) to {MAX_TARGET_ID}"
            )
        cloud.point_source_id = ids.astype(np.uint16)
    return cloud


def _write_cloud(path, cloud, compress: bool) -> None:
    # Write to a stream: given a path, laspy picks compression from the suffix (.tmp here).
    with open(path, "wb+") as stream:
        cloud.write(stream, do_compress=compress)
