"""Picture widgets: the top view and the 3D views drawn with half-block characters.

The pictures come from the core (``ladartui.render`` for the 3D views,
``ladartui.views.TopView`` for the top view); these widgets only turn them into
terminal cells (upper half block, foreground = top pixel, background = bottom
pixel) in 24-bit colour, or in the xterm-256 palette when the terminal has no
24-bit colour, and turn keys and the mouse into framing requests.
"""

from __future__ import annotations

import textwrap
from typing import Any

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
from ladartui.number_text import top_view_width, zoom_text
from ladartui.render import framing
from ladartui.render.raster import OVERLAYS, Layer, Overlays, render
from ladartui.views import Camera, Picture

UPPER = "\u2580"
# every cell drawn gets a style, blank ones too: Textual's filters (NO_COLOR's
# monochrome) read each segment's style and fail on one without
BLANK = Style.null()
MAX_IMAGE_SIDE = 960  # pixels: the terminal scales the picture up to the view
LOWER = "\u2584"


def picture_strips(picture: Picture, use_256: bool = False) -> list[Strip]:
    """One Strip per cell row: two pixel rows per cell, runs of one style merged."""
    top, top_mask, bottom, bottom_mask = views.half_block_cells(picture)
    top_codes: np.ndarray | None
    bottom_codes: np.ndarray | None
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

    styles: dict = {None: BLANK}
    strips = []
    rows, cols = top_mask.shape
    for r in range(rows):
        segments = []
        run_text = ""
        run_style = None
        for c in range(cols):
            t, b = top_mask[r, c], bottom_mask[r, c]
            key: tuple | None
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
                    style = Style(
                        color=colour(top_codes, top, r, c), bgcolor=colour(bottom_codes, bottom, r, c)
                    )
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


def character_strips(picture: Picture, use_256: bool = False) -> list[Strip]:
    """One Strip per pixel row, each pixel two spaces on its colour (no block glyphs)."""
    codes = views.to_ansi256(picture.rgb) if use_256 else None
    styles: dict = {}
    strips = []
    rows, cols = picture.shape
    for r in range(rows):
        segments = []
        for c in range(cols):
            if not picture.mask[r, c]:
                segments.append(Segment("  ", BLANK))
                continue
            key = int(codes[r, c]) if codes is not None else tuple(int(v) for v in picture.rgb[r, c])
            style = styles.get(key)
            if style is None:
                colour = Color.from_ansi(key) if isinstance(key, int) else Color.from_rgb(*key)
                style = styles[key] = Style(bgcolor=colour)
            segments.append(Segment("  ", style))
        strips.append(Strip(Segment.simplify(segments), cols * 2))
    return strips


# keys every view shares: framing and what is drawn (handled by the view area, for all views)
VIEW_BINDINGS = [
    Binding("t", "view_request('fit_target')", "Zoom to target (every view)", show=False),
    Binding("f", "view_request('fit_scene')", "Fit scene (every view)", show=False),
    Binding("p", "view_request('fit_path')", "Fit flight path (every view)", show=False),
    Binding("c", "view_request('cycle_output_colour')", "Output: classes / height / scans", show=False),
    Binding("g", "view_request('toggle_grey')", "Colour / grey shading", show=False),
    Binding("o", "view_request('cycle_overlays')", "Overlays: all / path / none", show=False),
]


class PictureWidget(Widget, can_focus=True):
    """Base for views: draws ``make_picture(rows, cols)`` and caches the strips."""

    DEFAULT_CSS = """
    PictureWidget { width: 1fr; height: 1fr; border: round $panel-lighten-2; }
    /* the title (the camera, the top view's width) in the text colour, not the faint
       border's, which in a light theme is near white on near white */
    PictureWidget { border-title-color: $foreground; }
    PictureWidget:focus { border: round $accent; }
    PictureWidget > .view-image { width: 1fr; height: 1fr; }
    """

    class ViewRequest(Message):
        """A key asked for something that concerns every view (``what`` names a ViewArea
        method)."""

        def __init__(self, what: str) -> None:
            super().__init__()
            self.what = what

    def __init__(self, title: str, **kwargs):
        super().__init__(**kwargs)
        self.border_title = title
        self._strips: list[Strip] | None = None
        self._size_key: tuple[int, int] | None = None
        self.placeholder = "nothing to show yet"
        self.colour_map = "height"
        self.shown_overlays = frozenset(OVERLAYS)
        self.image_mode: str | None = None  # kitty, sixel or iterm: drawn by ``image_view``
        self.image_view: Widget | None = None
        self._cell_pixels: tuple[float, float] = (1, 2)  # picture pixels per cell (x, y)
        self.characters = False  # plain characters: ``character_strips``
        self._image_pending = False

    def on_mount(self) -> None:
        graphics = getattr(self.app, "graphics", None)
        if graphics is not None and graphics.mode == "characters":
            self.characters = True
            self._cell_pixels = (0.5, 1)  # a square pixel is two cells wide
        if graphics is not None and graphics.image:
            from ladartui.tui import terminal_image

            self.image_mode = graphics.mode
            self._cell_pixels = terminal_image.cell_pixels()
            self.image_view = terminal_image.image_widget(graphics.mode, classes="view-image")
            self.image_view.display = False
            self.mount(self.image_view)

    def make_picture(self, rows: int, cols: int) -> Picture | None:
        return None

    def picture_size(self) -> tuple[int, int]:
        """(rows, cols) of the picture at the widget's size: two pixel rows per cell with
        half-blocks, the terminal's pixels (at most MAX_IMAGE_SIDE a side) with images."""
        return self.picture_size_for(self.size.width, self.size.height)

    def picture_size_for(self, width: int, height: int) -> tuple[int, int]:
        px, py = self._cell_pixels
        rows, cols = height * py, int(width * px)
        scale = min(1.0, MAX_IMAGE_SIDE / max(rows, cols, 1))
        return max(1, round(rows * scale)) if rows else 0, max(1, round(cols * scale)) if cols else 0

    def cell_to_pixel(self, x: float, y: float) -> tuple[float, float]:
        """Picture (row, col) of a point given in cells from the content's top left."""
        rows, cols = self.picture_size()
        width, height = self.size
        return y * rows / max(height, 1), x * cols / max(width, 1)

    def invalidate(self) -> None:
        """Redraw from the current data (call after changing it)."""
        self._strips = None
        self._schedule_image()
        self.refresh()

    def on_resize(self, event: events.Resize) -> None:
        self._schedule_image()

    def _schedule_image(self) -> None:
        if self.image_view is not None and not self._image_pending:
            self._image_pending = True
            self.call_after_refresh(self._update_image)

    def _update_image(self) -> None:
        """Draw the picture at the terminal's pixels and hand it to the image widget."""
        self._image_pending = False
        if self.image_view is None:
            return
        from ladartui.tui.terminal_image import to_pil

        width, height = self.size
        picture = self.make_picture(*self.picture_size()) if width and height else None
        if picture is None:
            self.image_view.display = False
            self.image_view.image = None  # type: ignore[attr-defined]
        else:
            self.image_view.image = to_pil(picture.rgb)  # type: ignore[attr-defined]
            self.image_view.display = True
        self._strips = None
        self.refresh()

    def action_view_request(self, what: str) -> None:
        self.post_message(self.ViewRequest(what))

    def _use_256(self) -> bool:
        try:
            return self.app.console.color_system in ("256", "standard", "windows")
        except Exception:
            return False

    def render_line(self, y: int) -> Strip:
        width, height = self.size
        if self._strips is None or self._size_key != (width, height):
            self._size_key = (width, height)
            if self.image_view is not None:  # the image widget draws the picture
                picture = None
            else:
                size = self.picture_size_for(width, height)
                picture = self.make_picture(*size) if width and height and all(size) else None
            if picture is None:
                shown = self.image_view is not None and self.image_view.display
                # wrapped, not cut: "no output yet: F5 run" read as another key's word
                lines = [] if shown or width < 1 else textwrap.wrap(self.placeholder, width)[:height]
                blank = [Strip.blank(width, BLANK)] * height
                top = (height - len(lines)) // 2
                for row, text in enumerate(lines, start=top):
                    blank[row] = Strip([Segment(text.center(width), Style(dim=True))], width)
                self._strips = blank
            else:
                draw = character_strips if self.characters else picture_strips
                self._strips = [s.extend_cell_length(width, BLANK) for s in draw(picture, self._use_256())]
        if y < len(self._strips):
            return self._strips[y]
        return Strip.blank(width, BLANK)


class TopViewWidget(PictureWidget):
    """The scene from above, with the flight path, scans and footprints over it.

    The window follows the flight path until the view is zoomed, panned or
    framed on the scene or the target; 0 goes back to following the path.
    """

    BINDINGS = [
        Binding("plus,equals_sign", "zoom(1.25)", "Zoom in", show=False),
        Binding("minus", "zoom(0.8)", "Zoom out", show=False),
        Binding("w", "pan(0, 0.1)", "Pan north", show=False),
        Binding("s", "pan(0, -0.1)", "Pan south", show=False),
        Binding("a", "pan(-0.1, 0)", "Pan west", show=False),
        Binding("d", "pan(0.1, 0)", "Pan east", show=False),
        Binding("0", "reset_view", "Follow the flight path", show=False),
        *VIEW_BINDINGS,
    ]

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("Top view", **kwargs)
        self.top: views.TopView | None = None
        self.path = None
        self.scans = None
        self.footprints = None
        self.frame: tuple[float, float, float, float] | None = None
        self.framing = "path"  # "path" (follows it), "scene", "target" or "manual"
        self.target_box = None
        self.placeholder = "no scene loaded"

    def set_scene(self, top: views.TopView | None, target_box=None) -> None:
        self.top = top
        self.target_box = target_box
        self.framing = "path"
        self._reframe()
        self.invalidate()  # (retitled: a zoom's "m across" is the old scene's)

    def set_overlay(self, path, scans, footprints) -> None:
        """New flight path overlays; the window grows to hold the path if it follows it."""
        self.path, self.scans, self.footprints = path, scans, footprints
        self._reframe()
        self.invalidate()

    def _reframe(self) -> None:
        if self.top is None:
            self.frame = None
        elif self.framing == "path":
            self.frame = self.top.frame_for(self.scans if self.path is None else self.path)
        elif self.framing == "scene":
            self.frame = self.top.scene_frame()
        elif self.framing == "target" and self.target_box is not None:
            self.frame = framing.fit_window(self.target_box)

    def fit(self, what: str) -> None:
        """Frame the ``"path"``, the ``"scene"`` or the ``"target"``."""
        self.framing = what
        self._reframe()
        self.invalidate()

    def invalidate(self) -> None:
        """Redraw, and title the view again: its width follows the frame, the view's size
        and the voxel size (a new one leaves the frame's voxels where they were)."""
        self._update_title()
        super().invalidate()

    def on_resize(self, event: events.Resize) -> None:
        super().on_resize(event)
        self._update_title()

    def _update_title(self) -> None:
        """ "Top view", and once zoomed or fitted how wide it is, put shorter where the
        border is narrow (at 80 columns "Top view 3.07e+0…" was cut inside the number)."""
        title = "Top view"
        if self.top is not None and self.frame is not None and self.framing != "path":
            width = top_view_width(self.shown_width())
            titles = (f"{title} {width} across", f"{title} {width}", f"Top {width}")
            room = self.size.width - 4  # the border's corners and a space each side
            title = next((t for t in titles if len(t) <= room), titles[0] if room <= 0 else titles[-1])
        self.border_title = title

    def shown_width(self) -> float:
        """Metres across the picture: the frame's width, or more where the view is wider
        than the frame (its height then sets the scale, and the picture shows more
        beside it)."""
        assert self.top is not None and self.frame is not None
        rows, cols = self.picture_size()
        if not rows or not cols:
            return (self.frame[2] - self.frame[0]) * self.top.voxel_size
        scale, _, _ = self.top.fit(rows, cols, self.frame)  # cells per pixel
        return scale * cols * self.top.voxel_size

    def action_zoom(self, factor: float, about=None) -> None:
        if self.top is None or self.frame is None:
            return
        self.frame = framing.zoom_window(self.frame, factor, about)
        self.framing = "manual"
        self.invalidate()

    def action_pan(self, dx: float, dy: float) -> None:
        if self.top is None or self.frame is None:
            return
        self.frame = framing.pan_window(self.frame, dx, dy)
        self.framing = "manual"
        self.invalidate()

    def action_reset_view(self) -> None:
        self.fit("path")

    def _wheel(self, event, factor: float) -> None:
        # the wheel zooms about the point under the pointer
        event.stop()
        offset = event.get_content_offset(self)
        about = None
        if offset is not None and self.top is not None and self.frame is not None:
            rows, cols = self.picture_size()
            row, col = self.cell_to_pixel(offset.x + 0.5, offset.y + 0.5)
            about = self.top.to_cells(row, col, rows, cols, self.frame)
        self.action_zoom(factor, about)

    def on_mouse_scroll_up(self, event: events.MouseScrollUp) -> None:
        self._wheel(event, 1.25)

    def on_mouse_scroll_down(self, event: events.MouseScrollDown) -> None:
        self._wheel(event, 0.8)

    def make_picture(self, rows, cols):
        if self.top is None:
            return None
        self.top.colour_map = self.colour_map
        return self.top.render(
            rows, cols, self.path, self.scans, self.footprints, frame=self.frame, shown=self.shown_overlays
        )


class ProjectionWidget(PictureWidget):
    """A 3D view of voxels: arrows rotate, + and - zoom, w a s d pan, 0 resets."""

    BINDINGS = [
        Binding("left", "rotate(-15, 0)", "Rotate left", show=False),
        Binding("right", "rotate(15, 0)", "Rotate right", show=False),
        Binding("up", "rotate(0, 10)", "Tilt up", show=False),
        Binding("down", "rotate(0, -10)", "Tilt down", show=False),
        Binding("plus,equals_sign", "zoom(1.25)", "Zoom in", show=False),
        Binding("minus", "zoom(0.8)", "Zoom out", show=False),
        # the view moves, its picture the other way (as the top view's window does)
        Binding("w", "pan(0, -0.05)", "Pan up", show=False),
        Binding("s", "pan(0, 0.05)", "Pan down", show=False),
        Binding("a", "pan(0.05, 0)", "Pan left", show=False),
        Binding("d", "pan(-0.05, 0)", "Pan right", show=False),
        Binding("0", "reset_view", "Reset view", show=False),
        *VIEW_BINDINGS,
    ]

    class CameraChanged(Message):
        def __init__(self, widget: ProjectionWidget) -> None:
            super().__init__()
            self.widget = widget

    def __init__(self, title: str, **kwargs):
        super().__init__(title, **kwargs)
        self.base_title = title
        self.short_title = ""  # the title where the border is narrow ("Out <=12.5 scans"); "" the same
        self.points = None  # (N, 3) voxel indices of the drawn voxels, already downsampled
        self.voxel_layers: list[Layer] = []
        self.height_range = None  # voxel layers shaded from bottom to top colour
        self.bounds = None
        self.overlays = Overlays()  # in voxel units
        self.voxel_size = 1.0
        self.camera = Camera()
        self.height_top: float | None = None  # top of the height shading (voxel layers), shared by views
        # the box and points the camera frames, framed again for each new picture size
        # (a view first drawn, or resized) until the camera is moved (None: the analyst's
        # own camera, kept as it is); framed_for: the (rows, cols) it was framed for
        self.fitted = None
        self.framed_for: tuple[int, int] | None = None
        self._drag: tuple[int, int] | None = None
        self.placeholder = "nothing to show yet"
        self._update_title()

    @property
    def markers(self):
        return self.overlays.scans

    def set_points(self, points, bounds=None, voxel_size=1.0) -> None:
        """Voxels (N, 3) shaded by height."""
        points = None if points is None else np.asarray(points)
        self.set_layers(None if points is None else [Layer(points)], points, bounds, voxel_size)

    def set_layers(self, layers, points, bounds=None, voxel_size=1.0, height_range=None) -> None:
        """Layers to draw (later ones win ties), the voxels they show, and the shading range."""
        self.voxel_layers = layers or []
        self.points = points
        if bounds is not None:  # kept when cleared, so the views stay lined up
            self.bounds = bounds
        self.voxel_size = voxel_size
        self.height_range = height_range
        self.invalidate()

    def set_markers(self, markers, bounds=None, footprints=None, path=None) -> None:
        """Scan positions (voxel units) over the voxels, the ``path`` flown through them
        (by default straight from scan to scan), and footprints."""
        markers = None if markers is None else np.asarray(markers, float)
        path = markers if path is None else np.asarray(path, float)
        self.overlays = Overlays(path, markers, list(footprints or []), self.shown_overlays)
        if bounds is not None:
            self.bounds = bounds
        self.invalidate()

    def set_camera(self, camera: Camera) -> None:
        self.camera = camera
        self.fitted = self.framed_for = None
        self._update_title()
        self.invalidate()
        self.post_message(self.CameraChanged(self))

    def fit_box(self, box, points=None) -> None:
        """Frame ``box`` (voxel-index lo, hi) and ``points`` (voxel units) now, or when the
        widget is first drawn."""
        rows, cols = self.picture_size()
        if self.bounds is None or box is None:
            return
        if rows and cols:
            self.set_camera(framing.fit_camera(self.camera, box, rows, cols, self.bounds, points=points))
            self.framed_for = (rows, cols)
        else:  # framed when first drawn
            self.framed_for = None
            self.invalidate()
        self.fitted = (box, points)

    def fit_path(self) -> None:
        """Frame the scene and the flight path (``p``; how a new scene opens)."""
        path = self.overlays.path
        self.fit_box(self.bounds, self.markers if path is None else path)

    def on_resize(self, event: events.Resize) -> None:
        super().on_resize(event)
        self._update_title()

    def _update_title(self) -> None:
        """The view's name and camera, put shorter where the border is narrow (at 80
        columns "3D scene az 210 el 30" was cut before the elevation)."""
        c = self.camera
        zoom = f" x{zoom_text(c.zoom)}" if abs(c.zoom - 1.0) > 1e-9 else ""
        az, el = f"{c.azimuth:.0f}", f"{c.elevation:.0f}"
        room = self.size.width - 4  # the border's corners and a space each side
        base, short = self.base_title, self.short_title or self.base_title
        titles = (
            f"{base} az {az} el {el}{zoom}",
            f"{base} {az}/{el}{zoom}",
            f"{short} {az}/{el}{zoom}",
            f"{short} {az}/{el}",  # the zoom goes before the camera
            short,
        )
        # else the short name and colouring ("Out <=12.5 scans"), cut at the edge, before the camera
        self.border_title = next((t for t in titles if len(t) <= room), titles[0] if room <= 0 else short)

    def make_picture(self, rows, cols, refit: bool = False):
        """The picture at rows x cols; ``refit`` (a picture saved in another shape) frames
        what a fitted view frames in that shape, leaving the view's camera as it is."""
        if not self.voxel_layers or self.bounds is None:
            return None
        camera = self.camera
        # a fit made for another shape can cut off what it framed in this one (a tall box
        # fitted in a narrow view): framed again, at the same angles
        if self.fitted is not None and (refit or self.framed_for != (rows, cols)):
            box, points = self.fitted
            camera = framing.fit_camera(camera, box, rows, cols, self.bounds, points=points)
            if not refit:  # the view itself, first drawn or resized
                self.camera, self.framed_for = camera, (rows, cols)
                self._update_title()
        self.overlays.shown = self.shown_overlays
        return render(
            self.voxel_layers,
            camera,
            rows,
            cols,
            self.bounds,
            height_range=self._height_range(),
            colour_map=self.colour_map,
            overlays=self.overlays,
        )

    def _height_range(self):
        # shade by the scene's heights, not by a box stretched up to the aircraft
        if self.height_range is not None:
            return self.height_range
        if self.points is None or not len(self.points):
            return None
        return (
            0.0,
            float(np.asarray(self.points)[:, 2].max()) if self.height_top is None else self.height_top,
        )

    def action_rotate(self, d_azimuth: float, d_elevation: float) -> None:
        self.set_camera(self.camera.rotated(d_azimuth, d_elevation))

    def action_zoom(self, factor: float) -> None:
        self.set_camera(self.camera.zoomed(factor))

    def action_pan(self, dx: float, dy: float) -> None:
        self.set_camera(self.camera.panned(dx, dy))

    def action_reset_view(self) -> None:
        """0: the view a scene opens with, the default angles framing the scene and the
        flight path (zoom 1 on the scene alone cut off the far side of an orbit)."""
        self.set_camera(Camera())
        self.fit_path()

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
