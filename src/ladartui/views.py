"""Text-mode views as arrays: height-shaded top view and 3D projections.

Everything here is numpy and returns pixel arrays; the terminal UI turns two
pixel rows into one character cell with the upper half block, so a pixel is
about square on a terminal. Nothing here imports textual, so the maths is
tested on its own and reusable (for example to write images).

Pixel arrays are (rows, cols, 3) uint8 RGB with a separate boolean mask of
drawn pixels; row 0 is the top of the picture (north in the top view).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ladartui.colour import (  # noqa: F401  (the palette, named here too)
    BACKGROUND,
    FOOTPRINT_RGB,
    GREY_LEVELS,
    GROUND_RGB,
    PATH_RGB,
    SCAN_RGB,
    START_RGB,
    TARGET_RGB,
    colour_map,
    grey_map,
    height_map,
    shade_indices,
    target_colour,
)
from ladartui.scene.column_tops import SparseTops

OVERLAYS = ("path", "scans", "footprints")


# -- colour ramps ---------------------------------------------------------


def grey_ramp(levels: int = GREY_LEVELS) -> np.ndarray:
    """The report's grey shades, dark (low) to near white (high): ``colour.grey_map``."""
    return grey_map(levels)


def height_ramp(levels: int = 64) -> np.ndarray:
    """The perceptual height colours of every view: ``colour.height_map``."""
    return height_map(levels)


_CUBE = np.array([0, 95, 135, 175, 215, 255])


def to_ansi256(rgb: np.ndarray) -> np.ndarray:
    """Nearest xterm-256 colour index for each RGB triple (the 6x6x6 cube or the grey ramp).

    Used where a terminal has no 24-bit colour; returns int16 array of shape rgb.shape[:-1].
    """
    rgb = np.asarray(rgb, dtype=np.int32)
    # nearest cube level per channel
    level = np.abs(rgb[..., None] - _CUBE).argmin(axis=-1)
    cube_rgb = _CUBE[level]
    cube_index = 16 + 36 * level[..., 0] + 6 * level[..., 1] + level[..., 2]
    cube_err = ((cube_rgb - rgb) ** 2).sum(axis=-1)
    # nearest of the 24 greys 8, 18, ..., 238
    mean = rgb.mean(axis=-1)
    grey_step = np.clip(np.round((mean - 8) / 10), 0, 23).astype(np.int32)
    grey_value = 8 + 10 * grey_step
    grey_err = ((grey_value[..., None] - rgb) ** 2).sum(axis=-1)
    return np.where(grey_err < cube_err, 232 + grey_step, cube_index).astype(np.int16)


# -- top view -------------------------------------------------------------


@dataclass
class Picture:
    """An RGB picture and the mask of pixels that were drawn (others are background)."""

    rgb: np.ndarray
    mask: np.ndarray

    @classmethod
    def blank(cls, rows: int, cols: int) -> Picture:
        return cls(np.zeros((rows, cols, 3), np.uint8), np.zeros((rows, cols), bool))

    def copy(self) -> Picture:
        return Picture(self.rgb.copy(), self.mask.copy())

    @property
    def shape(self) -> tuple[int, int]:
        return self.mask.shape


@dataclass
class TopView:
    """The height-shaded top view of a scene, with a cached scene layer.

    ``heights`` is the scene's top height map, (nx, ny) voxel layers with a
    negative value where a column is empty (bare ground), whose entry (0, 0)
    is column ``origin`` (the map spans the voxels' columns, not the grid from
    (0, 0)), or the same columns kept sparsely (``SparseTops``: a wide box holding
    few columns), which draws the same pictures; ``voxel_size`` converts metres to
    voxels. A *frame* is the window shown, in cell units (x0, y0, x1, y1) where voxel i spans [i, i + 1); by
    default the map's extent. Overlays (flight path, scans, footprints) are drawn on a copy of
    the cached layer, so changing parameters never re-renders the scene; only
    a new picture size or frame does.
    """

    heights: np.ndarray | SparseTops
    voxel_size: float = 1.0
    origin: tuple[int, int] = (0, 0)  # the column of heights[0, 0]
    # The ground plane's (nx, ny) from (0, 0), drawn as bare ground where the map
    # holds no columns (None: the map's own columns only).
    ground: tuple[int, int] | None = None
    target_columns: np.ndarray | None = None  # (K, 2) voxel x, y of target voxels
    target_column_rgb: np.ndarray | None = None  # (K, 3) colour of each (default TARGET_RGB)
    colour_map: str = "height"  # or "grey": the report's 56 shades
    _cache: dict = field(default_factory=dict, repr=False)
    renders: int = 0  # how many times the scene layer was drawn (the cache's effect)

    @property
    def extent(self) -> tuple[int, int]:
        return int(self.heights.shape[0]), int(self.heights.shape[1])

    def scene_frame(self) -> tuple[float, float, float, float]:
        nx, ny = self.extent
        x0, y0 = (float(v) for v in self.origin)
        return (x0, y0, x0 + nx, y0 + ny)

    def frame_for(self, xy_metres=None, margin: float = 0.05) -> tuple[float, float, float, float]:
        """A frame holding the scene and the given points (metres), padded by ``margin``.

        Edges snap outward to an eighth of the scene size, so small changes to
        a flight path keep the same frame (and the cached scene layer).
        """
        x0, y0, x1, y1 = self.scene_frame()
        if xy_metres is not None and len(xy_metres):
            cells = np.asarray(xy_metres, float).reshape(-1, 2) / self.voxel_size + 0.5
            cells = cells[np.all(np.isfinite(cells), axis=1)]
            if len(cells):
                x0, y0 = min(x0, cells[:, 0].min()), min(y0, cells[:, 1].min())
                x1, y1 = max(x1, cells[:, 0].max()), max(y1, cells[:, 1].max())
        pad = margin * max(x1 - x0, y1 - y0)
        snap = max(self.extent) / 8.0 or 1.0
        return (
            float(np.floor((x0 - pad) / snap) * snap),
            float(np.floor((y0 - pad) / snap) * snap),
            float(np.ceil((x1 + pad) / snap) * snap),
            float(np.ceil((y1 + pad) / snap) * snap),
        )

    def fit(self, rows: int, cols: int, frame=None) -> tuple[float, float, float]:
        """Scale (cells per pixel) and pixel offsets that fit the frame, aspect kept."""
        fx0, fy0, fx1, fy1 = frame or self.scene_frame()
        scale = max((fx1 - fx0) / max(cols, 1), (fy1 - fy0) / max(rows, 1), 1e-9)
        off_c = (cols - (fx1 - fx0) / scale) / 2.0
        off_r = (rows - (fy1 - fy0) / scale) / 2.0
        return scale, off_c, off_r

    def to_pixels(self, xy_metres, rows: int, cols: int, frame=None) -> np.ndarray:
        """(N, 2) metres -> (N, 2) float pixel (row, col); north is up."""
        frame = frame or self.scene_frame()
        cells = np.asarray(xy_metres, dtype=np.float64).reshape(-1, 2) / self.voxel_size + 0.5
        scale, off_c, off_r = self.fit(rows, cols, frame)
        col = (cells[:, 0] - frame[0]) / scale + off_c
        row = (frame[3] - cells[:, 1]) / scale + off_r
        return np.stack([row, col], axis=1)

    def to_cells(self, row: float, col: float, rows: int, cols: int, frame=None):
        """The cell-space (x, y) under a pixel position (the inverse of ``to_pixels``)."""
        frame = frame or self.scene_frame()
        scale, off_c, off_r = self.fit(rows, cols, frame)
        return frame[0] + (col - off_c) * scale, frame[3] - (row - off_r) * scale

    def scene_layer(self, rows: int, cols: int, frame=None) -> Picture:
        """The height-shaded scene at this pixel size and frame (cached; do not modify)."""
        frame = tuple(frame or self.scene_frame())
        key = (rows, cols, frame, self.colour_map)
        if key not in self._cache:
            self._cache.clear()
            self._cache[key] = self._render(rows, cols, frame)
            self.renders += 1
        return self._cache[key]

    def _render(self, rows: int, cols: int, frame) -> Picture:
        picture = Picture.blank(rows, cols)
        nx, ny = self.extent
        if rows <= 0 or cols <= 0 or nx == 0 or ny == 0:
            return picture
        fx0, fy0, fx1, fy1 = frame
        scale, off_c, off_r = self.fit(rows, cols, frame)
        c = np.arange(cols)
        r = np.arange(rows)
        # each pixel shows the highest voxel of the columns whose centres it covers, or
        # zoomed in (none covered), of the column under its centre, as overlays are placed
        centre_x = fx0 + (c + 0.5 - off_c) * scale
        centre_y = fy1 - (r + 0.5 - off_r) * scale
        if self.ground is not None:
            on_ground = (
                _within(centre_y, 0, self.ground[1])[:, None] & _within(centre_x, 0, self.ground[0])[None, :]
            )
            picture.rgb[on_ground] = GROUND_RGB
            picture.mask[on_ground] = True
        # counted from the map's column (0, 0): a map far from the origin draws alike
        ox, oy = self.origin
        local_x = (fx0 - ox) + (c + 0.5 - off_c) * scale
        local_y = (fy1 - oy) - (r + 0.5 - off_r) * scale
        inside = _within(local_y, 0, ny)[:, None] & _within(local_x, 0, nx)[None, :]
        if not inside.any():
            return picture
        x_lo, x_hi = _columns_covered(local_x - scale / 2, scale, local_x)
        y_lo, y_hi = _columns_covered(local_y - scale / 2, scale, local_y)
        heights = self.heights
        pooled = _block_max(heights, x_lo, x_hi, y_lo, y_hi)
        top = max(int(heights.max()), 1)
        ramp = colour_map(self.colour_map)
        shade = ramp[shade_indices(pooled, 0, top, len(ramp))]
        ground = pooled < 0
        rgb = np.where(ground[..., None], np.array(GROUND_RGB, np.uint8), shade)
        picture.rgb[inside] = rgb[inside]
        picture.mask[inside] = True
        return picture

    def draw_target(self, picture: Picture, frame) -> None:
        """Fill each target column's cell (at least one pixel) in the target colour."""
        if self.target_columns is None or not len(self.target_columns):
            return
        rows, cols = picture.shape
        cells = np.asarray(self.target_columns, dtype=np.float64)[:, :2]
        # cell corners (x - 0.5, y + 0.5) and (x + 0.5, y - 0.5) in metres
        corner_a = self.to_pixels((cells + [-0.5, 0.5]) * self.voxel_size, rows, cols, frame)
        corner_b = self.to_pixels((cells + [0.5, -0.5]) * self.voxel_size, rows, cols, frame)
        # the pixels whose centres lie in the cell [x, x + 1) x [y, y + 1), as the scene
        # layer shows it (rows run south: a centre on the cell's north edge is not in it)
        r0 = np.floor(corner_a[:, 0] + 0.5).astype(np.int64)
        c0 = np.ceil(corner_a[:, 1] - 0.5).astype(np.int64)
        r1 = np.maximum(np.floor(corner_b[:, 0] + 0.5).astype(np.int64), r0 + 1)
        c1 = np.maximum(np.ceil(corner_b[:, 1] - 0.5).astype(np.int64), c0 + 1)
        rgb = self.target_column_rgb
        for k, (ra, rb, ca, cb) in enumerate(
            zip(np.clip(r0, 0, rows), np.clip(r1, 0, rows), np.clip(c0, 0, cols), np.clip(c1, 0, cols))
        ):
            picture.rgb[ra:rb, ca:cb] = TARGET_RGB if rgb is None else rgb[k]
            picture.mask[ra:rb, ca:cb] = True

    def render(
        self, rows: int, cols: int, path=None, scans=None, footprints=None, frame=None, shown=OVERLAYS
    ) -> Picture:
        """The scene layer, the footprints, the target, then the flight path and scans.

        ``path`` and ``scans`` are (N, 2) x, y metres (the first scan is marked
        as the start); ``footprints`` a list of (K, 2) ground polygons in metres;
        ``shown`` names the overlays drawn. The target is drawn over the
        footprints so that they never hide it.
        """
        frame = frame or self.scene_frame()
        picture = self.scene_layer(rows, cols, frame).copy()
        path = path if "path" in shown else None
        scans = scans if "scans" in shown else None
        footprints = footprints if "footprints" in shown else None
        for polygon in footprints or ():
            if polygon is None or len(polygon) < 2:
                continue
            pix = self.to_pixels(np.asarray(polygon, float)[:, :2], rows, cols, frame)
            closed = np.vstack([pix, pix[:1]])
            draw_polyline(picture, closed, FOOTPRINT_RGB)
        self.draw_target(picture, frame)
        if path is not None and len(path) >= 2:
            draw_polyline(picture, self.to_pixels(path, rows, cols, frame), PATH_RGB)
        if scans is not None and len(scans):
            draw_scan_markers(picture, self.to_pixels(scans, rows, cols, frame))
        return picture


def _columns_covered(low_edges, size: float, centres) -> tuple[np.ndarray, np.ndarray]:
    """[lo, hi) of the columns whose centres (i + 0.5) lie in [edge, edge + size) of each
    pixel, else the column holding the pixel's centre."""
    lo = np.ceil(low_edges - 0.5).astype(np.int64)
    hi = np.ceil(low_edges + size - 0.5).astype(np.int64)
    none = hi <= lo
    lo = np.where(none, np.floor(centres).astype(np.int64), lo)
    return lo, np.where(none, lo + 1, hi)


def _within(centres, lo: float, hi: float) -> np.ndarray:
    return (centres >= lo) & (centres < hi)


def _block_max(heights, x0, x1, y_lo, y_hi):
    """Max of ``heights`` over the block [x0, x1) x [y_lo, y_hi) for each pixel (clipped).
    A sparse map pools the columns of the window only (``SparseTops.block_max``)."""
    nx, ny = heights.shape
    xa = np.clip(x0, 0, nx - 1)
    xb = np.maximum(np.clip(x1, 1, nx), xa + 1)
    ya = np.clip(y_lo, 0, ny - 1)
    yb = np.maximum(np.clip(y_hi, 1, ny), ya + 1)
    if isinstance(heights, SparseTops):
        return heights.block_max(xa, xb, ya, yb)
    # one slice per picture column, then one per picture row: a few hundred
    # numpy reductions, fast even for a 1500 x 1500 height map
    by_col = np.stack([heights[a:b].max(axis=0) for a, b in zip(xa, xb)])  # (cols, ny)
    pooled = np.stack([by_col[:, a:b].max(axis=1) for a, b in zip(ya, yb)])  # (rows, cols)
    return pooled


MARKER_PIXELS = 160  # a picture's shorter side over this: pixels on a scan marker's side


def marker_side(rows: int, cols: int) -> int:
    """The side of a scan's square marker: one pixel at the terminal's sizes (half a
    cell), more in a large picture (5 in a 1200 x 800 PNG), where one would be lost."""
    return max(1, min(rows, cols) // MARKER_PIXELS)


def draw_scan_markers(picture: Picture, pixels) -> None:
    """The scans' square markers at ``pixels`` ((N, 2) row, col), the first one marked
    as the start, sized for the picture (``marker_side``)."""
    side = marker_side(*picture.shape)
    draw_points(picture, pixels, SCAN_RGB, side)
    draw_points(picture, pixels[:1], START_RGB, side)


def draw_points(picture: Picture, pixels, rgb, side: int = 1) -> None:
    """Set each (row, col) pixel that falls inside the picture, or the square of ``side``
    pixels centred on it."""
    pix = np.floor(np.asarray(pixels, float)).astype(np.int64).reshape(-1, 2)
    if side > 1:
        steps = np.arange(side) - (side - 1) // 2
        square = np.stack(np.meshgrid(steps, steps, indexing="ij"), axis=-1).reshape(-1, 2)
        pix = (pix[:, None, :] + square[None, :, :]).reshape(-1, 2)
    rows, cols = picture.shape
    ok = (pix[:, 0] >= 0) & (pix[:, 0] < rows) & (pix[:, 1] >= 0) & (pix[:, 1] < cols)
    pix = pix[ok]
    picture.rgb[pix[:, 0], pix[:, 1]] = rgb
    picture.mask[pix[:, 0], pix[:, 1]] = True


MOST_LINE_STEPS = 100_000  # pixels on one segment at most
POLYLINE_BATCH = 1_000_000  # pixels made at once: a 10,000-scan path in a few numpy passes


def _line_steps(a, b) -> np.ndarray:
    """Pixels on each segment from ``a`` to ``b`` ((N, 2) each): one per step of the
    longer axis, at least both ends."""
    steps = np.ceil(np.abs(b - a).max(axis=1)).astype(np.int64) + 1
    return np.maximum(np.minimum(steps, MOST_LINE_STEPS), 2)


def line_pixels(a, b) -> np.ndarray:
    """Pixels (row, col) on the segment from a to b, one per step of the longer axis."""
    a = np.asarray(a, float).reshape(1, 2)
    b = np.asarray(b, float).reshape(1, 2)
    return _segments_pixels(a, b, _line_steps(a, b))


def _segments_pixels(a, b, steps) -> np.ndarray:
    """The pixels of every segment in turn, ``steps`` each, as ``np.linspace`` spaces
    them (its step times the index, the last one exactly at the end)."""
    segment = np.repeat(np.arange(len(a)), steps)
    index = np.arange(int(steps.sum())) - np.repeat(np.cumsum(steps) - steps, steps)
    last = steps[segment] - 1
    t = index * (1.0 / last)
    t[index == last] = 1.0
    return a[segment] + (b[segment] - a[segment]) * t[:, None]


def draw_polyline(picture: Picture, pixels, rgb) -> None:
    """Draw the segments joining consecutive (row, col) points; a segment with an end
    that is not finite is left out. Drawn whole, a batch of segments at a time."""
    pixels = np.asarray(pixels, float).reshape(-1, 2)
    if len(pixels) < 2:
        return
    a, b = pixels[:-1], pixels[1:]
    kept = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
    rows, cols = picture.shape
    limit = 4.0 * (rows + cols)  # far-away ends clamped: a path far outside stays cheap
    a, b = np.clip(a[kept], -limit, limit), np.clip(b[kept], -limit, limit)
    steps = _line_steps(a, b)
    first = 0
    while first < len(a):
        made = np.cumsum(steps[first:])
        end = first + max(1, int(np.searchsorted(made, POLYLINE_BATCH, side="right")))
        draw_points(picture, _segments_pixels(a[first:end], b[first:end], steps[first:end]), rgb)
        first = end


# -- 3D projection --------------------------------------------------------


@dataclass(frozen=True)
class Camera:
    """An orthographic view: azimuth and elevation in degrees, zoom, pan and centre.

    Azimuth is the compass bearing (clockwise from north) the viewer looks
    *from*; elevation is the angle above the horizon (90 looks straight
    down). The view turns about ``centre`` (voxel units; None: the centre of
    the view's bounds), so a view framed on the target keeps it in sight while
    it turns. Pan moves the picture by fractions of its width and height.
    """

    azimuth: float = 210.0
    elevation: float = 30.0
    zoom: float = 1.0
    pan_x: float = 0.0
    pan_y: float = 0.0
    centre: tuple | None = None

    def at_angle(self, azimuth: float, elevation: float) -> Camera:
        return replace(self, azimuth=float(azimuth) % 360.0, elevation=float(np.clip(elevation, -90.0, 90.0)))

    def rotated(self, d_azimuth=0.0, d_elevation=0.0) -> Camera:
        return self.at_angle(self.azimuth + d_azimuth, self.elevation + d_elevation)

    def zoomed(self, factor: float) -> Camera:
        """Zoomed by ``factor`` within MIN_ZOOM..MAX_ZOOM; a fit beyond them (a flight far
        wider than its scene) zooms on from there, never back the other way."""
        lo, hi = min(MIN_ZOOM, self.zoom), max(MAX_ZOOM, self.zoom)
        return replace(self, zoom=float(np.clip(self.zoom * factor, lo, hi)))

    def panned(self, dx=0.0, dy=0.0) -> Camera:
        return replace(self, pan_x=self.pan_x + dx / self.zoom, pan_y=self.pan_y + dy / self.zoom)


MIN_ZOOM, MAX_ZOOM = 0.1, 1000.0


def view_axes(azimuth: float, elevation: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Screen right, screen up and toward-viewer unit vectors in the scene frame."""
    az = np.radians(azimuth)
    el = np.radians(elevation)
    # direction from the scene toward the viewer (bearing az clockwise from north)
    toward = np.array([np.sin(az) * np.cos(el), np.cos(az) * np.cos(el), np.sin(el)])
    right = np.array([-np.cos(az), np.sin(az), 0.0])
    up = np.cross(toward, right)
    return right, up, toward


def project_float(points, camera: Camera, rows: int, cols: int, bounds=None):
    """Orthographic projection of (N, 3) points: float pixel row, col, depth, and scale.

    ``bounds`` ((3,) lo, (3,) hi) fixes the framing so that several views of
    one scene (scene and output) line up; by default the points' own box. At
    zoom 1 the bounds' sphere fills the shorter side; ``scale`` is pixels per
    voxel unit. A pixel (r, c) covers [r, r + 1) x [c, c + 1); depth is larger
    nearer the viewer.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if bounds is None:
        lo, hi = (pts.min(axis=0), pts.max(axis=0)) if len(pts) else (np.zeros(3), np.ones(3))
    else:
        lo, hi = (np.asarray(b, float) for b in bounds)
    centre = (lo + hi) / 2.0 if camera.centre is None else np.asarray(camera.centre, float)
    radius = max(float(np.linalg.norm(hi - lo)) / 2.0, 0.5)
    right, up, toward = view_axes(camera.azimuth, camera.elevation)
    rel = pts - centre
    scale = camera.zoom * min(cols, rows) / (2.0 * radius)
    col = cols / 2.0 + (rel @ right + camera.pan_x * 2.0 * radius) * scale
    row = rows / 2.0 - (rel @ up + camera.pan_y * 2.0 * radius) * scale
    return row, col, rel @ toward, scale


def project(points, camera: Camera, rows: int, cols: int, bounds=None):
    """The pixel (row, col) ints each point falls in, and its depth (``project_float``)."""
    row, col, depth, _ = project_float(points, camera, rows, cols, bounds)
    return np.floor(row).astype(np.int64), np.floor(col).astype(np.int64), depth


def subsample(voxels, limit: int, seed: int = 0) -> np.ndarray:
    """At most ``limit`` rows of ``voxels``, a seeded random choice (deterministic).

    Keeps views fast for scenes of millions of voxels; order is preserved.
    """
    voxels = np.asarray(voxels)
    if len(voxels) <= limit:
        return voxels
    rng = np.random.default_rng(seed)
    chosen = np.sort(rng.choice(len(voxels), size=limit, replace=False))
    return voxels[chosen]


def surface_points(heights: np.ndarray, limit: int = 250_000, origin=(0, 0)) -> np.ndarray:
    """Top surface voxels (x, y, top z) from a height map, strided to at most ``limit``.

    The canopy top is what an overhead view sees; adding it to a random voxel
    sample keeps the 3D scene view solid at any sample size. ``origin`` is the
    column of ``heights[0, 0]``; a sparse map gives the same points.
    """
    if not isinstance(heights, SparseTops):
        heights = np.asarray(heights)
    stride = max(1, int(np.ceil(np.sqrt(heights.size / max(limit, 1)))))
    if isinstance(heights, SparseTops):
        x, y, z = heights.surface(stride)
    else:
        sub = heights[::stride, ::stride]
        xs, ys = np.nonzero(sub >= 0)
        x, y, z = xs * stride, ys * stride, sub[xs, ys]
    return np.stack([x + origin[0], y + origin[1], z], axis=1).astype(np.int32)


def threshold_points(voxels, voxel_size: float, max_height_m: float | None) -> np.ndarray:
    """Voxels whose centre height (metres) is at most ``max_height_m`` (None: all).

    The report's output threshold (section 3.5.2): the output replotted up to a height.
    """
    voxels = np.asarray(voxels)
    if max_height_m is None or len(voxels) == 0:
        return voxels
    return voxels[voxels[:, 2] * voxel_size <= max_height_m]


def target_columns(target, target_ids=None) -> tuple[np.ndarray, np.ndarray | None]:
    """The x-y columns of the target voxels, and each column's colour when ``target_ids``
    names several targets (the colour of the column's highest voxel: what the top view sees)."""
    target = np.asarray(target).reshape(-1, 3)
    ids = None if target_ids is None else np.asarray(target_ids).reshape(-1)
    if ids is None or len(np.unique(ids)) < 2:
        return np.unique(target[:, :2], axis=0), None
    order = np.lexsort((target[:, 2], target[:, 1], target[:, 0]))
    cols = target[order, :2]
    last = np.ones(len(cols), bool)
    last[:-1] = np.any(cols[1:] != cols[:-1], axis=1)  # the highest voxel of each column
    rank = {int(t): i for i, t in enumerate(np.unique(ids))}
    rgb = np.array([target_colour(rank[int(t)]) for t in ids[order][last]], dtype=np.uint8)
    return cols[last], rgb


def half_block_cells(picture: Picture):
    """Pair pixel rows into character cells: (top_rgb, top_mask, bottom_rgb, bottom_mask).

    Each is (cells_rows, cols[, 3]); an odd last row gets an empty bottom half.
    """
    rows, cols = picture.shape
    pad = rows % 2
    rgb = picture.rgb
    mask = picture.mask
    if pad:
        rgb = np.concatenate([rgb, np.zeros((1, cols, 3), np.uint8)])
        mask = np.concatenate([mask, np.zeros((1, cols), bool)])
    return rgb[0::2], mask[0::2], rgb[1::2], mask[1::2]
