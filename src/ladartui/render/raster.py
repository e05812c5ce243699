"""Voxels into an RGB image with a depth buffer: the one renderer of every 3D view.

A view is an orthographic camera (``views.Camera``) over fixed ``bounds`` (so
the scene and output views line up). Each voxel is splatted as a square of
its projected size; where squares overlap, the nearest voxel wins (larger
depth is nearer the viewer), and at equal depth the layer drawn later wins
(the target over the scene voxel it shares). Overlays (flight path, scan
positions) are drawn over the voxels, footprints under them (they lie on the
ground), each one switchable.
Nothing here imports textual.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ladartui import colour
from ladartui.views import Camera, Picture, draw_polyline, draw_scan_markers, project_float

MAX_SPLAT_SAMPLES = 6_000_000  # pixel writes per render; squares shrink beyond it
OVERLAYS = ("path", "scans", "footprints")


@dataclass
class Layer:
    """Voxels (N, 3 voxel indices) drawn in one colour ``rgb``, or else shaded with
    ``colour_map`` (None: the view's) by height, or by ``values`` (N,) over
    ``value_range`` when given."""

    voxels: np.ndarray
    rgb: tuple[int, int, int] | None = None
    colour_map: str | None = None
    values: np.ndarray | None = None
    value_range: tuple[float, float] | None = None


@dataclass
class Overlays:
    """What is drawn over the voxels, in voxel units: path and scans (N, 3), footprints
    (list of (K, 3) polygons); ``shown`` names the ones drawn."""

    path: np.ndarray | None = None
    scans: np.ndarray | None = None
    footprints: list = field(default_factory=list)
    shown: frozenset = frozenset(OVERLAYS)


@dataclass
class Rendering(Picture):
    """A rendered view: ``rgb`` (rows, cols, 3) uint8, ``mask`` of pixels that show a
    voxel or an overlay, ``depth`` (rows, cols) float of the voxel shown (-inf where none),
    ``voxel_mask`` of pixels that show a voxel."""

    depth: np.ndarray
    voxel_mask: np.ndarray


def screen_coordinates(points, camera: Camera, rows: int, cols: int, bounds):
    """(N, 3) points -> float pixel row, col, depth and pixels per voxel unit."""
    return project_float(points, camera, rows, cols, bounds)


def splat_side(scale: float, count: int) -> int:
    """Square side in pixels for voxels ``scale`` pixels across (at least 1)."""
    side = max(1, int(np.ceil(scale - 1e-9)))
    while side > 1 and count * side * side > MAX_SPLAT_SAMPLES:
        side -= 1
    return side


def render(
    layers,
    camera: Camera,
    rows: int,
    cols: int,
    bounds,
    *,
    height_range=None,
    colour_map: str = "height",
    overlays: Overlays | None = None,
) -> Rendering:
    """Render voxel layers (later layers win ties) and overlays into an image.

    Heights shade over ``height_range`` (voxel layers, default the bounds' z
    range) with the named colour map (``colour.colour_map``).
    """
    rgb = np.zeros((rows, cols, 3), np.uint8)
    rgb[:] = colour.BACKGROUND
    depth = np.full((rows, cols), -np.inf)
    image = Rendering(rgb, np.zeros((rows, cols), bool), depth, np.zeros((rows, cols), bool))
    if rows <= 0 or cols <= 0:
        return image
    if height_range is None:
        height_range = (float(bounds[0][2]), float(bounds[1][2]))
    parts = []
    for priority, layer in enumerate(layers):
        pts = np.asarray(layer.voxels, dtype=np.float64).reshape(-1, 3)
        if not len(pts):
            continue
        if layer.rgb is None:
            table = colour.colour_map(layer.colour_map or colour_map)
            if layer.values is not None:
                lo, hi = layer.value_range or (np.min(layer.values), np.max(layer.values))
                colours = colour.shade(layer.values, lo, hi, table)
            else:
                colours = colour.shade(pts[:, 2], height_range[0], height_range[1], table)
        else:
            colours = np.broadcast_to(np.array(layer.rgb, np.uint8), (len(pts), 3))
        parts.append((pts, colours, priority))
    if overlays is not None and "footprints" in overlays.shown:
        # footprints lie on the ground: under the voxels, never over the target
        draw_footprints(image, overlays, camera, bounds)
    if parts:
        _splat(image, parts, camera, bounds)
    if overlays is not None:
        draw_flight(image, overlays, camera, bounds)
    return image


def _splat(image: Rendering, parts, camera, bounds) -> None:
    rows, cols = image.shape
    pts = np.concatenate([p[0] for p in parts])
    colours = np.concatenate([p[1] for p in parts])
    priority = np.concatenate([np.full(len(p[0]), p[2], np.int32) for p in parts])
    row, col, depth, scale = screen_coordinates(pts, camera, rows, cols, bounds)
    reach = max(1.0, scale)  # a square reaches half its side beyond the voxel's centre
    near = (row > -reach) & (row < rows + reach) & (col > -reach) & (col < cols + reach)
    if not near.any():
        return
    row, col, depth, colours, priority = (row[near], col[near], depth[near], colours[near], priority[near])
    side = splat_side(scale, len(row))
    # the square's top-left pixel: centred on the voxel's projected centre
    r0 = np.floor(row - side / 2.0 + 0.5).astype(np.int64)
    c0 = np.floor(col - side / 2.0 + 0.5).astype(np.int64)
    offsets = np.arange(side)
    rr = (r0[:, None, None] + offsets[None, :, None]).repeat(side, axis=2).reshape(-1)
    cc = (c0[:, None, None] + offsets[None, None, :]).repeat(side, axis=1).reshape(-1)
    owner = np.repeat(np.arange(len(r0)), side * side)
    inside = (rr >= 0) & (rr < rows) & (cc >= 0) & (cc < cols)
    linear = (rr * cols + cc)[inside]
    if not len(linear):  # near the edge, within a square's reach, yet none lands inside
        return
    owner = owner[inside]
    # nearest first within each pixel, then the later layer; keep the last of each pixel
    order = np.lexsort((priority[owner], depth[owner], linear))
    linear, owner = linear[order], owner[order]
    last = np.r_[linear[1:] != linear[:-1], True]
    linear, owner = linear[last], owner[last]
    image.rgb.reshape(-1, 3)[linear] = colours[owner]
    image.depth.reshape(-1)[linear] = depth[owner]
    image.voxel_mask.reshape(-1)[linear] = True
    image.mask.reshape(-1)[linear] = True


def _pixels(points, camera, image, bounds) -> np.ndarray:
    rows, cols = image.shape
    row, col, _, _ = screen_coordinates(points, camera, rows, cols, bounds)
    return np.stack([row, col], axis=1)


def draw_footprints(image: Rendering, overlays: Overlays, camera: Camera, bounds) -> None:
    """The sensor footprints, closed polygons."""
    for polygon in overlays.footprints or ():
        if polygon is None or len(polygon) < 2:
            continue
        pix = _pixels(polygon, camera, image, bounds)
        draw_polyline(image, np.vstack([pix, pix[:1]]), colour.FOOTPRINT_RGB)


def draw_flight(image: Rendering, overlays: Overlays, camera: Camera, bounds) -> None:
    """The path, then the scans (the first one marked as the start), over everything."""
    shown = overlays.shown
    if "path" in shown and overlays.path is not None and len(overlays.path) >= 2:
        draw_polyline(image, _pixels(overlays.path, camera, image, bounds), colour.PATH_RGB)
    if "scans" in shown and overlays.scans is not None and len(overlays.scans):
        draw_scan_markers(image, _pixels(overlays.scans, camera, image, bounds))
