"""Text-mode views as arrays: height-shaded top view and 3D projections.

Everything here is numpy and returns pixel arrays; the terminal UI turns two
pixel rows into one character cell with the upper half block, so a pixel is
about square on a terminal. Nothing here imports textual, so the maths is
tested on its own and reusable (for example to write images).

Pixel arrays are (rows, cols, 3) uint8 RGB with a separate boolean mask of
drawn pixels; row 0 is the top of the picture (north in the top view).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

GREY_LEVELS = 56  # the report's grey scale for 3D point plots (section 3.4.1)
BACKGROUND = (0, 0, 0)
GROUND_RGB = (58, 46, 34)
PATH_RGB = (255, 215, 0)
SCAN_RGB = (255, 60, 60)
START_RGB = (255, 255, 255)
FOOTPRINT_RGB = (0, 215, 255)
TARGET_RGB = (255, 0, 255)


# -- colour ramps ---------------------------------------------------------

def grey_ramp(levels: int = GREY_LEVELS) -> np.ndarray:
    """``levels`` grey shades from dark (low) to near white (high), (levels, 3) uint8.

    The report ran from near white to black on a white page; a terminal is
    usually dark, so the ramp runs the other way and stops short of black.
    """
    values = np.linspace(48, 245, levels).round().astype(np.uint8)
    return np.repeat(values[:, None], 3, axis=1)


def height_ramp(levels: int = 64) -> np.ndarray:
    """A terrain-like ramp for the top view: dark green (low) to pale (high)."""
    anchors = np.array([[20, 70, 30], [40, 120, 40], [130, 170, 60], [220, 220, 170]], float)
    positions = np.linspace(0.0, 1.0, len(anchors))
    t = np.linspace(0.0, 1.0, levels)
    ramp = np.stack([np.interp(t, positions, anchors[:, c]) for c in range(3)], axis=1)
    return ramp.round().astype(np.uint8)


def shade_indices(heights: np.ndarray, lo: float, hi: float, levels: int) -> np.ndarray:
    """Map heights to integer shade indices 0..levels-1 linearly over [lo, hi]."""
    heights = np.asarray(heights, dtype=np.float64)
    span = max(float(hi) - float(lo), 1e-9)
    index = np.floor((heights - lo) / span * levels)
    return np.clip(index, 0, levels - 1).astype(np.int32)


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
    def blank(cls, rows: int, cols: int) -> "Picture":
        return cls(np.zeros((rows, cols, 3), np.uint8), np.zeros((rows, cols), bool))

    def copy(self) -> "Picture":
        return Picture(self.rgb.copy(), self.mask.copy())

    @property
    def shape(self) -> tuple[int, int]:
        return self.mask.shape


@dataclass
class TopView:
    """The height-shaded top view of a scene, with a cached scene layer.

    ``heights`` is the scene's top height map, (nx, ny) voxel layers with a
    negative value where a column is empty (bare ground); ``voxel_size``
    converts metres to voxels. A *frame* is the window shown, in cell units
    (x0, y0, x1, y1) where voxel i spans [i, i + 1); by default the scene's
    extent. Overlays (flight path, scans, footprints) are drawn on a copy of
    the cached layer, so changing parameters never re-renders the scene; only
    a new picture size or frame does.
    """

    heights: np.ndarray
    voxel_size: float = 1.0
    target_columns: np.ndarray | None = None  # (K, 2) voxel x, y of target voxels
    _cache: dict = field(default_factory=dict, repr=False)
    renders: int = 0  # how many times the scene layer was drawn (the cache's effect)

    @property
    def extent(self) -> tuple[int, int]:
        return int(self.heights.shape[0]), int(self.heights.shape[1])

    def scene_frame(self) -> tuple[float, float, float, float]:
        nx, ny = self.extent
        return (0.0, 0.0, float(nx), float(ny))

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
        return (float(np.floor((x0 - pad) / snap) * snap), float(np.floor((y0 - pad) / snap) * snap),
                float(np.ceil((x1 + pad) / snap) * snap), float(np.ceil((y1 + pad) / snap) * snap))

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

    def scene_layer(self, rows: int, cols: int, frame=None) -> Picture:
        """The height-shaded scene at this pixel size and frame (cached; do not modify)."""
        frame = tuple(frame or self.scene_frame())
        key = (rows, cols, frame)
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
        # each pixel covers a block of voxel columns and shows its highest voxel
        x_lo = np.floor(fx0 + (c - off_c) * scale).astype(np.int64)
        x_hi = np.maximum(np.floor(fx0 + (c + 1 - off_c) * scale).astype(np.int64), x_lo + 1)
        y_lo = np.floor(fy1 - (r + 1 - off_r) * scale).astype(np.int64)
        y_hi = np.maximum(np.floor(fy1 - (r - off_r) * scale).astype(np.int64), y_lo + 1)
        centre_x = fx0 + (c + 0.5 - off_c) * scale
        centre_y = fy1 - (r + 0.5 - off_r) * scale
        inside_c = (centre_x >= 0) & (centre_x < nx)
        inside_r = (centre_y >= 0) & (centre_y < ny)
        inside = inside_r[:, None] & inside_c[None, :]
        if not inside.any():
            return picture
        heights = self.heights
        pooled = _block_max(heights, x_lo, x_hi, y_lo, y_hi)
        top = max(int(heights.max()), 1)
        ramp = height_ramp()
        shade = ramp[shade_indices(pooled, 0, top, len(ramp))]
        ground = pooled < 0
        rgb = np.where(ground[..., None], np.array(GROUND_RGB, np.uint8), shade)
        picture.rgb[inside] = rgb[inside]
        picture.mask[inside] = True
        if self.target_columns is not None and len(self.target_columns):
            tc = np.asarray(self.target_columns, dtype=np.float64)[:, :2] * self.voxel_size
            pix = np.floor(self.to_pixels(tc, rows, cols, frame)).astype(np.int64)
            ok = (pix[:, 0] >= 0) & (pix[:, 0] < rows) & (pix[:, 1] >= 0) & (pix[:, 1] < cols)
            pix = pix[ok]
            # a magenta tint shows where the hidden target is
            tint = picture.rgb[pix[:, 0], pix[:, 1]].astype(np.int32)
            picture.rgb[pix[:, 0], pix[:, 1]] = ((tint + np.array(TARGET_RGB)) // 2).astype(np.uint8)
        return picture

    def render(self, rows: int, cols: int, path=None, scans=None, footprints=None,
               frame=None) -> Picture:
        """The scene layer with the flight path, scan positions and footprints drawn over it.

        ``path`` and ``scans`` are (N, 2) x, y metres (the first scan is marked
        as the start); ``footprints`` a list of (K, 2) ground polygons in metres.
        """
        frame = frame or self.scene_frame()
        picture = self.scene_layer(rows, cols, frame).copy()
        for polygon in footprints or ():
            if polygon is None or len(polygon) < 2:
                continue
            pix = self.to_pixels(np.asarray(polygon, float)[:, :2], rows, cols, frame)
            closed = np.vstack([pix, pix[:1]])
            draw_polyline(picture, closed, FOOTPRINT_RGB)
        if path is not None and len(path) >= 2:
            draw_polyline(picture, self.to_pixels(path, rows, cols, frame), PATH_RGB)
        if scans is not None and len(scans):
            pix = self.to_pixels(scans, rows, cols, frame)
            draw_points(picture, pix, SCAN_RGB)
            draw_points(picture, pix[:1], START_RGB)
        return picture


def _block_max(heights, x0, x1, y_lo, y_hi):
    """Max of ``heights`` over the block [x0, x1) x [y_lo, y_hi) for each pixel (clipped)."""
    nx, ny = heights.shape
    xa = np.clip(x0, 0, nx - 1)
    xb = np.maximum(np.clip(x1, 1, nx), xa + 1)
    ya = np.clip(y_lo, 0, ny - 1)
    yb = np.maximum(np.clip(y_hi, 1, ny), ya + 1)
    # one slice per picture column, then one per picture row: a few hundred
    # numpy reductions, fast even for a 1500 x 1500 height map
    by_col = np.stack([heights[a:b].max(axis=0) for a, b in zip(xa, xb)])  # (cols, ny)
    pooled = np.stack([by_col[:, a:b].max(axis=1) for a, b in zip(ya, yb)])  # (rows, cols)
    return pooled


def draw_points(picture: Picture, pixels, rgb) -> None:
    """Set each (row, col) pixel that falls inside the picture."""
    pix = np.floor(np.asarray(pixels, float)).astype(np.int64).reshape(-1, 2)
    rows, cols = picture.shape
    ok = (pix[:, 0] >= 0) & (pix[:, 0] < rows) & (pix[:, 1] >= 0) & (pix[:, 1] < cols)
    pix = pix[ok]
    picture.rgb[pix[:, 0], pix[:, 1]] = rgb
    picture.mask[pix[:, 0], pix[:, 1]] = True


def line_pixels(a, b) -> np.ndarray:
    """Pixels (row, col) on the segment from a to b, one per step of the longer axis."""
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    steps = int(np.ceil(np.abs(b - a).max())) + 1
    steps = min(steps, 100_000)
    t = np.linspace(0.0, 1.0, max(steps, 2))
    return a + (b - a) * t[:, None]


def draw_polyline(picture: Picture, pixels, rgb) -> None:
    """Draw the segments joining consecutive (row, col) points."""
    pixels = np.asarray(pixels, float)
    rows, cols = picture.shape
    limit = 4.0 * (rows + cols)
    for a, b in zip(pixels[:-1], pixels[1:]):
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            continue
        # clamp far-away ends so a path far outside the scene stays cheap
        a = np.clip(a, -limit, limit)
        b = np.clip(b, -limit, limit)
        draw_points(picture, line_pixels(a, b), rgb)


# -- 3D projection --------------------------------------------------------

@dataclass(frozen=True)
class Camera:
    """An orthographic view: azimuth and elevation in degrees, zoom and pan.

    Azimuth is the compass bearing (clockwise from north) the viewer looks
    *from*; elevation is the angle above the horizon (90 looks straight
    down). Pan moves the picture by fractions of its width and height.
    """

    azimuth: float = 210.0
    elevation: float = 30.0
    zoom: float = 1.0
    pan_x: float = 0.0
    pan_y: float = 0.0

    def rotated(self, d_azimuth=0.0, d_elevation=0.0) -> "Camera":
        return Camera((self.azimuth + d_azimuth) % 360.0,
                      float(np.clip(self.elevation + d_elevation, -90.0, 90.0)),
                      self.zoom, self.pan_x, self.pan_y)

    def zoomed(self, factor: float) -> "Camera":
        return Camera(self.azimuth, self.elevation,
                      float(np.clip(self.zoom * factor, 0.1, 100.0)), self.pan_x, self.pan_y)

    def panned(self, dx=0.0, dy=0.0) -> "Camera":
        return Camera(self.azimuth, self.elevation, self.zoom,
                      self.pan_x + dx / self.zoom, self.pan_y + dy / self.zoom)


def view_axes(azimuth: float, elevation: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Screen right, screen up and toward-viewer unit vectors in the scene frame."""
    az = np.radians(azimuth)
    el = np.radians(elevation)
    # direction from the scene toward the viewer (bearing az clockwise from north)
    toward = np.array([np.sin(az) * np.cos(el), np.cos(az) * np.cos(el), np.sin(el)])
    right = np.array([-np.cos(az), np.sin(az), 0.0])
    up = np.cross(toward, right)
    return right, up, toward


def project(points, camera: Camera, rows: int, cols: int, bounds=None):
    """Orthographic projection of (N, 3) points to pixel (row, col) and depth.

    ``bounds`` ((3,) lo, (3,) hi) fixes the framing so that several views of
    one scene (scene and output) line up; by default the points' own box.
    Returns (row, col) int arrays and depth (larger is nearer the viewer).
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if bounds is None:
        lo, hi = (pts.min(axis=0), pts.max(axis=0)) if len(pts) else (np.zeros(3), np.ones(3))
    else:
        lo, hi = (np.asarray(b, float) for b in bounds)
    centre = (lo + hi) / 2.0
    radius = max(float(np.linalg.norm(hi - lo)) / 2.0, 0.5)
    right, up, toward = view_axes(camera.azimuth, camera.elevation)
    rel = pts - centre
    sx = rel @ right
    sy = rel @ up
    depth = rel @ toward
    scale = camera.zoom * min(cols, rows) / (2.0 * radius)
    col = cols / 2.0 + (sx + camera.pan_x * 2.0 * radius) * scale
    row = rows / 2.0 - (sy + camera.pan_y * 2.0 * radius) * scale
    return np.floor(row).astype(np.int64), np.floor(col).astype(np.int64), depth


def render_points(points, camera: Camera, rows: int, cols: int, *, bounds=None,
                  levels: int = GREY_LEVELS, height_range=None) -> tuple[np.ndarray, np.ndarray]:
    """Height-shaded projection of voxel points with a depth buffer.

    Returns ``shade`` (rows, cols) int16 (-1 where nothing is drawn, else a
    shade 0..levels-1 of the nearest point's height) and ``depth`` (float,
    -inf where empty). Heights shade over ``height_range`` (default the
    bounds' z range), so scene and output share one scale.
    """
    shade = np.full((rows, cols), -1, np.int16)
    depth_buffer = np.full((rows, cols), -np.inf)
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) == 0 or rows <= 0 or cols <= 0:
        return shade, depth_buffer
    row, col, depth = project(pts, camera, rows, cols, bounds)
    ok = (row >= 0) & (row < rows) & (col >= 0) & (col < cols)
    if not ok.any():
        return shade, depth_buffer
    row, col, depth, z = row[ok], col[ok], depth[ok], pts[ok, 2]
    if height_range is None:
        height_range = ((bounds[0][2], bounds[1][2]) if bounds is not None
                        else (pts[:, 2].min(), pts[:, 2].max()))
    linear = row * cols + col
    # depth buffer: the nearest point of each pixel wins; ties go to the higher shade
    flat_depth = depth_buffer.reshape(-1)
    np.maximum.at(flat_depth, linear, depth)
    winners = depth >= flat_depth[linear]
    shades = shade_indices(z[winners], height_range[0], height_range[1], levels).astype(np.int16)
    np.maximum.at(shade.reshape(-1), linear[winners], shades)
    return shade, depth_buffer


def shade_picture(shade: np.ndarray, ramp: np.ndarray | None = None) -> Picture:
    """Turn a shade-index image into a Picture with the given ramp (grey by default)."""
    ramp = grey_ramp() if ramp is None else ramp
    mask = shade >= 0
    rgb = np.zeros(shade.shape + (3,), np.uint8)
    rgb[mask] = ramp[np.clip(shade[mask], 0, len(ramp) - 1)]
    return Picture(rgb, mask)


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


def surface_points(heights: np.ndarray, limit: int = 250_000) -> np.ndarray:
    """Top surface voxels (x, y, top z) from a height map, strided to at most ``limit``.

    The canopy top is what an overhead view sees; adding it to a random voxel
    sample keeps the 3D scene view solid at any sample size.
    """
    heights = np.asarray(heights)
    stride = max(1, int(np.ceil(np.sqrt(heights.size / max(limit, 1)))))
    sub = heights[::stride, ::stride]
    xs, ys = np.nonzero(sub >= 0)
    return np.stack([xs * stride, ys * stride, sub[xs, ys]], axis=1).astype(np.int32)


def threshold_points(voxels, voxel_size: float, max_height_m: float | None) -> np.ndarray:
    """Voxels whose centre height (metres) is at most ``max_height_m`` (None: all).

    The report's output threshold (section 3.5.2): the output replotted up to a height.
    """
    voxels = np.asarray(voxels)
    if max_height_m is None or len(voxels) == 0:
        return voxels
    return voxels[voxels[:, 2] * voxel_size <= max_height_m]


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
