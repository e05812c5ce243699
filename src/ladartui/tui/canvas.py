"""Picture widgets: the top view and the 3D views drawn with half-block characters.

The maths lives in ``ladartui.views``; these widgets only turn pictures into
terminal cells (upper half block, foreground = top pixel, background = bottom
pixel) in 24-bit colour, or in the xterm-256 palette when the terminal has no
24-bit colour.
"""

from __future__ import annotations

import numpy as np
from rich.color import Color
from rich.segment import Segment
from rich.style import Style
from textual import events
from textual.binding import Binding
from textual.message import Message
from textual.strip import Strip
from textual.widget import Widget

from ladartui import views
from ladartui.views import Camera, Picture

UPPER = "\u2580"
LOWER = "\u2584"


def picture_strips(picture: Picture, use_256: bool = False) -> list[Strip]:
    """One Strip per cell row: two pixel rows per cell, runs of one style merged."""
    top, top_mask, bottom, bottom_mask = views.half_block_cells(picture)
    if use_256:
        top_codes = views.to_ansi256(top)
        bottom_codes = views.to_ansi256(bottom)

        def colour(codes, rgb, r, c):
            return Color.from_ansi(int(codes[r, c]))
    else:
        top_codes = bottom_codes = None

        def colour(codes, rgb, r, c):
            p = rgb[r, c]
            return Color.from_rgb(int(p[0]), int(p[1]), int(p[2]))

    styles: dict = {}
    strips = []
    rows, cols = top_mask.shape
    for r in range(rows):
        segments = []
        run_text = ""
        run_style = None
        for c in range(cols):
            t, b = top_mask[r, c], bottom_mask[r, c]
            if t and b:
                key = ("tb", tuple(top[r, c]), tuple(bottom[r, c]))
                char = UPPER
            elif t:
                key = ("t", tuple(top[r, c]))
                char = UPPER
            elif b:
                key = ("b", tuple(bottom[r, c]))
                char = LOWER
            else:
                key = None
                char = " "
            style = styles.get(key)
            if style is None and key is not None:
                if t and b:
                    style = Style(color=colour(top_codes, top, r, c),
                                  bgcolor=colour(bottom_codes, bottom, r, c))
                elif t:
                    style = Style(color=colour(top_codes, top, r, c))
                else:
                    style = Style(color=colour(bottom_codes, bottom, r, c))
                styles[key] = style
            if style is run_style:
                run_text += char
            else:
                if run_text:
                    segments.append(Segment(run_text, run_style))
                run_text, run_style = char, style
        if run_text:
            segments.append(Segment(run_text, run_style))
        strips.append(Strip(segments, cols))
    return strips


class PictureWidget(Widget, can_focus=True):
    """Base for views: draws ``make_picture(rows, cols)`` and caches the strips."""

    DEFAULT_CSS = """
    PictureWidget { width: 1fr; height: 1fr; border: round $panel-lighten-2; }
    PictureWidget:focus { border: round $accent; }
    """

    def __init__(self, title: str, **kwargs):
        super().__init__(**kwargs)
        self.border_title = title
        self._strips: list[Strip] | None = None
        self._size_key = None
        self.placeholder = "nothing to show yet"

    def make_picture(self, rows: int, cols: int) -> Picture | None:
        return None

    def invalidate(self) -> None:
        """Redraw from the current data (call after changing it)."""
        self._strips = None
        self.refresh()

    def _use_256(self) -> bool:
        try:
            return self.app.console.color_system in ("256", "standard", "windows")
        except Exception:
            return False

    def render_line(self, y: int) -> Strip:
        width, height = self.size
        if self._strips is None or self._size_key != (width, height):
            self._size_key = (width, height)
            picture = self.make_picture(height * 2, width) if width and height else None
            if picture is None:
                text = self.placeholder[:width]
                blank = [Strip.blank(width)] * height
                if height:
                    blank[height // 2] = Strip([Segment(text.center(width), Style(dim=True))],
                                               width)
                self._strips = blank
            else:
                self._strips = picture_strips(picture, self._use_256())
        if y < len(self._strips):
            return self._strips[y]
        return Strip.blank(width)


class TopViewWidget(PictureWidget):
    """The scene from above, with the flight path, scans and footprints over it."""

    def __init__(self, **kwargs):
        super().__init__("Top view", **kwargs)
        self.top: views.TopView | None = None
        self.path = None
        self.scans = None
        self.footprints = None
        self.frame = None
        self.placeholder = "no scene loaded"

    def set_scene(self, top: views.TopView | None) -> None:
        self.top = top
        self.invalidate()

    def set_overlay(self, path, scans, footprints) -> None:
        """New flight path overlays; the frame grows to hold the scans if needed."""
        self.path, self.scans, self.footprints = path, scans, footprints
        self.frame = self.top.frame_for(scans) if self.top is not None else None
        self.invalidate()

    def make_picture(self, rows, cols):
        if self.top is None:
            return None
        return self.top.render(rows, cols, self.path, self.scans, self.footprints,
                               frame=self.frame)


class ProjectionWidget(PictureWidget):
    """A 3D view of voxel points: arrows rotate, + and - zoom, w a s d pan, 0 resets."""

    BINDINGS = [
        Binding("left", "rotate(-15, 0)", "Rotate left", show=False),
        Binding("right", "rotate(15, 0)", "Rotate right", show=False),
        Binding("up", "rotate(0, 10)", "Tilt up", show=False),
        Binding("down", "rotate(0, -10)", "Tilt down", show=False),
        Binding("plus,equals_sign", "zoom(1.25)", "Zoom in", show=False),
        Binding("minus", "zoom(0.8)", "Zoom out", show=False),
        Binding("w", "pan(0, 0.05)", "Pan up", show=False),
        Binding("s", "pan(0, -0.05)", "Pan down", show=False),
        Binding("a", "pan(-0.05, 0)", "Pan left", show=False),
        Binding("d", "pan(0.05, 0)", "Pan right", show=False),
        Binding("0", "reset_view", "Reset view", show=False),
    ]

    class CameraChanged(Message):
        def __init__(self, widget: "ProjectionWidget") -> None:
            super().__init__()
            self.widget = widget

    def __init__(self, title: str, **kwargs):
        super().__init__(title, **kwargs)
        self.base_title = title
        self.points = None  # (N, 3) voxel indices, already downsampled
        self.bounds = None
        self.markers = None  # (M, 3) scan positions in voxel units, drawn over the points
        self.voxel_size = 1.0
        self.camera = Camera()
        self.height_top = None  # top of the height shading (voxel layers), shared by views
        self._drag = None
        self.placeholder = "nothing to show yet"
        self._update_title()

    def set_points(self, points, bounds=None, voxel_size=1.0) -> None:
        self.points = None if points is None else np.asarray(points)
        self.bounds = bounds
        self.voxel_size = voxel_size
        self.invalidate()

    def set_markers(self, markers, bounds=None) -> None:
        """Scan positions (voxel units) drawn as a path over the points."""
        self.markers = None if markers is None else np.asarray(markers, float)
        if bounds is not None:
            self.bounds = bounds
        self.invalidate()

    def set_camera(self, camera: Camera) -> None:
        self.camera = camera
        self._update_title()
        self.invalidate()
        self.post_message(self.CameraChanged(self))

    def _update_title(self) -> None:
        c = self.camera
        self.border_title = f"{self.base_title} az {c.azimuth:.0f} el {c.elevation:.0f}"
        if abs(c.zoom - 1.0) > 1e-9:
            self.border_title += f" x{c.zoom:.2g}"

    def make_picture(self, rows, cols):
        if self.points is None or len(self.points) == 0:
            return None
        bounds = self.bounds
        shade, _ = views.render_points(self.points, self.camera, rows, cols, bounds=bounds,
                                       height_range=self._height_range())
        picture = views.shade_picture(shade)
        if self.markers is not None and len(self.markers):
            row, col, _ = views.project(self.markers, self.camera, rows, cols, bounds)
            pixels = np.stack([row, col], axis=1).astype(float)
            if len(pixels) > 1:
                views.draw_polyline(picture, pixels + 0.5, views.PATH_RGB)
            views.draw_points(picture, pixels, views.SCAN_RGB)
            views.draw_points(picture, pixels[:1], views.START_RGB)
        return picture

    def _height_range(self):
        # shade by the scene's heights, not by a box stretched up to the aircraft
        if self.points is None or not len(self.points):
            return None
        return (0.0, float(np.asarray(self.points)[:, 2].max()) if self.height_top is None
                else self.height_top)

    def action_rotate(self, d_azimuth: float, d_elevation: float) -> None:
        self.set_camera(self.camera.rotated(d_azimuth, d_elevation))

    def action_zoom(self, factor: float) -> None:
        self.set_camera(self.camera.zoomed(factor))

    def action_pan(self, dx: float, dy: float) -> None:
        self.set_camera(self.camera.panned(dx, dy))

    def action_reset_view(self) -> None:
        self.set_camera(Camera())

    def on_mouse_down(self, event: events.MouseDown) -> None:
        self._drag = (event.screen_x, event.screen_y)
        self.capture_mouse()

    def on_mouse_up(self, event: events.MouseUp) -> None:
        self._drag = None
        self.release_mouse()

    def on_mouse_move(self, event: events.MouseMove) -> None:
        if self._drag is None:
            return
        dx = event.screen_x - self._drag[0]
        dy = event.screen_y - self._drag[1]
        if dx or dy:
            self._drag = (event.screen_x, event.screen_y)
            self.set_camera(self.camera.rotated(5.0 * dx, 5.0 * dy))

    def on_mouse_scroll_up(self, event: events.MouseScrollUp) -> None:
        event.stop()
        self.action_zoom(1.25)

    def on_mouse_scroll_down(self, event: events.MouseScrollDown) -> None:
        event.stop()
        self.action_zoom(0.8)
