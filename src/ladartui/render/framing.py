"""Framing: the camera (3D views) or window (top view) that shows a box with a margin.

Boxes are voxel-index ranges ``lo``..``hi`` (inclusive); the voxels' cubes
reach half a voxel beyond them.
"""

from __future__ import annotations

import itertools

import numpy as np

from ladartui.views import Camera, view_axes

MARGIN = 0.05  # of the image on each side


def box_of(voxels) -> tuple[np.ndarray, np.ndarray] | None:
    """The (lo, hi) voxel-index box of (N, 3) points, or None when there are none."""
    pts = np.asarray(voxels, dtype=np.float64).reshape(-1, 3)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if not len(pts):
        return None
    return pts.min(axis=0), pts.max(axis=0)


def fit_camera(
    camera: Camera, box, rows: int, cols: int, bounds, margin: float = MARGIN, points=None
) -> Camera:
    """``camera``'s angles with the zoom and pan that frame ``box`` (and ``points``, (N, 3)
    voxel units, such as a flight's scan positions) in a rows x cols image.

    The box's projected corners fill the image less ``margin`` of it on each side (in
    the tighter direction), centred; with points, their larger side and the box's
    together fill the shorter side, so the camera frames them in a view of any shape.
    """
    lo, hi = (np.asarray(b, float) for b in box)
    corners = np.array(list(itertools.product(*zip(lo - 0.5, hi + 0.5))))
    if points is not None and len(points):
        corners = np.vstack([corners, np.asarray(points, float).reshape(-1, 3)])
    blo, bhi = (np.asarray(b, float) for b in bounds)
    radius = max(float(np.linalg.norm(bhi - blo)) / 2.0, 0.5)
    right, up, _ = view_axes(camera.azimuth, camera.elevation)
    sx = (corners - (lo + hi) / 2.0) @ right
    sy = (corners - (lo + hi) / 2.0) @ up
    # the view turns about the middle of what it frames: for a box alone, its centre
    centre = (lo + hi) / 2.0 + right * (sx.max() + sx.min()) / 2.0 + up * (sy.max() + sy.min()) / 2.0
    width = max(float(np.ptp(sx)), 1e-6)
    height = max(float(np.ptp(sy)), 1e-6)
    if points is not None and len(points):
        # the views share a camera and differ in shape: a flight reaching far from the
        # box fits in any of them when its larger side fits the shorter one
        width = height = max(width, height)
    usable = 1.0 - 2.0 * margin
    scale = min(cols * usable / width, rows * usable / height)  # pixels per voxel unit
    # not held to the zoom keys' range: a flight far wider than a small scene (a lone
    # vehicle, a path kilometres off) needs less than MIN_ZOOM to be seen at all
    zoom = float(scale * 2.0 * radius / max(min(cols, rows), 1))
    return Camera(camera.azimuth, camera.elevation, zoom, 0.0, 0.0, tuple(float(v) for v in centre))


def fit_window(box, margin: float = MARGIN) -> tuple[float, float, float, float]:
    """A top-view frame (x0, y0, x1, y1, cell units) around a voxel box, ``margin`` of its
    size (at least one voxel) on each side."""
    lo, hi = (np.asarray(b, float) for b in box)
    x0, y0, x1, y1 = lo[0], lo[1], hi[0] + 1.0, hi[1] + 1.0
    pad = max(margin * max(x1 - x0, y1 - y0), 1.0)
    return (float(x0 - pad), float(y0 - pad), float(x1 + pad), float(y1 + pad))


def zoom_window(
    frame, factor: float, about=None, min_size: float = 2.0, max_size: float = 1e7
) -> tuple[float, float, float, float]:
    """``frame`` zoomed in by ``factor`` (> 1 shows less) about a point (cell units;
    default its centre), which stays where it was in the window."""
    x0, y0, x1, y1 = frame
    cx, cy = ((x0 + x1) / 2.0, (y0 + y1) / 2.0) if about is None else about
    width = float(np.clip((x1 - x0) / factor, min_size, max_size))
    height = float(np.clip((y1 - y0) / factor, min_size, max_size))
    sx, sy = width / (x1 - x0), height / (y1 - y0)
    return (
        float(cx - (cx - x0) * sx),
        float(cy - (cy - y0) * sy),
        float(cx + (x1 - cx) * sx),
        float(cy + (y1 - cy) * sy),
    )


def pan_window(frame, dx: float, dy: float) -> tuple[float, float, float, float]:
    """``frame`` moved by fractions of its width (east) and height (north)."""
    x0, y0, x1, y1 = frame
    sx, sy = dx * (x1 - x0), dy * (y1 - y0)
    return (x0 + sx, y0 + sy, x1 + sx, y1 + sy)
