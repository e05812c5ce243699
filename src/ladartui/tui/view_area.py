"""The views beside the sidebar: the 3D scene, the 3D output and the top view, in the
report's five layouts, with the flight path drawn over them, and the requests that
concern every view at once (zoom to target, fits, colouring, overlays)."""

from __future__ import annotations

from typing import Any

import numpy as np
from textual.containers import Container

from ladartui import views
from ladartui.attitude import plan_attitudes
from ladartui.errors import LadarError
from ladartui.render import framing, png
from ladartui.render.output import COLOUR_MODES, classify, output_layers, scene_layers
from ladartui.render.raster import OVERLAYS
from ladartui.tui.canvas import PictureWidget, ProjectionWidget, TopViewWidget
from ladartui.views import Camera

SCENE_POINTS = 150_000  # voxels drawn in the 3D scene view (all of the small scene)
OUTPUT_POINTS = 80_000
MAX_FOOTPRINTS = 400
# the overlay sets the 'o' key steps through
OVERLAY_CYCLE: tuple[frozenset[str], ...] = (frozenset(OVERLAYS), frozenset({"path", "scans"}), frozenset())

LAYOUTS = {
    1: "3D scene + top view",
    2: "3D scene + 3D output",
    3: "3D scene, full",
    4: "3D output, full",
    5: "3D scene + 3D output + top view",
}


def prepare_views(scene) -> dict:
    """View data that depends only on the scene: top view, 3D sample, bounds (worker thread)."""
    origin, heights = scene.view_columns()
    columns, column_rgb = views.target_columns(scene.target, scene.target_ids)
    top = views.TopView(
        heights,
        scene.voxel_size,
        origin=origin,
        ground=(scene.shape[0], scene.shape[1]),
        target_columns=columns,
        target_column_rgb=column_rgb,
    )
    sample = views.subsample(scene.voxels, SCENE_POINTS, seed=0)
    points = np.concatenate([sample, views.surface_points(heights, SCENE_POINTS // 3, origin)])
    top_z = int(heights.max()) if heights.max() >= 0 else scene.shape[2] - 1
    # the voxels' own columns, heights from the ground (z = 0) up
    x0, y0 = origin
    nx, ny = heights.shape
    bounds = (np.array([x0, y0, 0.0]), np.array([x0 + nx - 1, y0 + ny - 1, max(top_z, 1)], float))
    top.scene_layer(48, 96)  # warm the cache at a typical size
    return {
        "top": top,
        "points": points,
        "bounds": bounds,
        "target": np.asarray(scene.target, np.int32),
        "target_ids": np.asarray(scene.target_ids),
        "target_box": framing.box_of(scene.target),
        "target_m": tuple(float(v) for v in scene.target_centre_m()),
    }


class ViewArea(Container):
    """Owns the three views, which of them the layout shows, and how they are drawn."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(classes="layout-1", **kwargs)
        self.layout_number = 1
        self.prepared: dict | None = None
        self.voxel_size = 1.0
        self.scenario = None
        self.output_mode = "class"  # or "height": see render.output
        self.colour_map = "height"  # or "grey": the report's 56 shades
        self.overlays = OVERLAY_CYCLE[0]
        self.markers: np.ndarray | None = None  # scan positions, voxel units
        self.path_unframed = False  # a new scene's 3D views frame its path when first drawn
        self._output_args: tuple[Any, float | None, int, Any, Any] = (None, None, OUTPUT_POINTS, None, None)
        self.per_scan_known = False  # the output shown has per-scan returns ("scans" mode)
        self.no_output = "no output yet: F5 runs"  # the app's words, with its run key

    def compose(self):
        yield ProjectionWidget("3D scene", id="scene3d")
        yield ProjectionWidget("3D output", id="output3d")
        yield TopViewWidget(id="topview")

    def set_layout(self, number: int) -> None:
        self.layout_number = int(number)
        for n in LAYOUTS:
            self.set_class(n == self.layout_number, f"layout-{n}")

    def set_scene(self, prepared: dict, voxel_size: float) -> None:
        self.prepared = prepared
        self.voxel_size = voxel_size
        self.query_one(TopViewWidget).set_scene(prepared["top"], prepared.get("target_box"))
        top = float(prepared["bounds"][1][2])
        for widget in self.query(ProjectionWidget):
            widget.height_top = top
            # a new scene: keep the angles, frame the scene again (a centre or a pending
            # fit of the old one would point elsewhere), and its path once it is drawn
            widget.camera = Camera(widget.camera.azimuth, widget.camera.elevation)
            widget.fitted = widget.framed_for = None
            widget._update_title()
        self.path_unframed = True
        self.query_one("#scene3d", ProjectionWidget).set_layers(
            scene_layers(prepared["points"], prepared["target"], prepared.get("target_ids")),
            prepared["points"],
            prepared["bounds"],
            voxel_size,
            height_range=(0.0, top),
        )

    def rescale(self, voxel_size: float, target_m) -> None:
        """The same voxels at another size (the scenario's voxel size changed)."""
        self.voxel_size = voxel_size
        if self.prepared is not None:
            self.prepared["top"].voxel_size = voxel_size
            self.prepared["target_m"] = target_m

    def draw_path(self, scenario) -> None:
        """The scans and their footprints over the top view, and over the 3D views."""
        self.scenario = scenario
        top = self.query_one(TopViewWidget)
        if scenario is None:
            top.set_overlay(None, None, None)
            return
        poses = scenario.poses()
        scans = np.array([[p.x, p.y] for p in poses]) if poses else None
        footprints = []
        try:  # a body-fixed sensor's footprints swing with the aircraft's bank
            attitudes = plan_attitudes(scenario.flight, scenario.speed, scenario.sensor)
        except LadarError:
            attitudes = [None] * len(poses)
        step = max(1, len(poses) // MAX_FOOTPRINTS)
        for pose, attitude in list(zip(poses, attitudes))[::step]:
            try:
                footprints.append(scenario.sensor.footprint(pose, 0.0, attitude))
            except LadarError:
                pass
        # the path as flown (along a turn's or an orbit's arc), not chords between scans
        path = np.array(scenario.flight.path_points()).reshape(-1, 3)
        top.set_overlay(path[:, :2] if poses else None, scans, [f[:, :2] for f in footprints])
        frame, self.path_unframed = self.path_unframed and self.prepared is not None, False
        if self.prepared is not None and poses:
            markers = np.array([p.position for p in poses]) / self.voxel_size
            self.markers = markers
            ground = [f / self.voxel_size for f in footprints]
            # the views open on the scene and its path (as the top view does), and stay
            # put as the path is edited (it may leave them: p fits it)
            for widget in self.query(ProjectionWidget):
                widget.set_markers(markers, self.prepared["bounds"], ground, path / self.voxel_size)
                if frame:
                    widget.fit_path()

    # -- the output view -----------------------------------------------------------

    def show_output(
        self, voxels, threshold: float | None, limit: int = OUTPUT_POINTS, target_output=None, per_scan=None
    ) -> None:
        """The scene output after the threshold, coloured by ``output_mode``.

        ``target_output`` (the target traced without foliage) marks what the
        foliage hid; when not given it is taken from the app's last run, or
        from the scenario's target output file when the output came from disk.
        ``per_scan`` (each scan's scene returns) counts the scans that saw each
        target voxel; when not given it is the app's last run's, if that run
        made this output (files on disk do not keep it).
        """
        self._output_args = (voxels, threshold, limit, target_output, per_scan)
        if per_scan is None:
            per_scan = self._known_per_scan(voxels)
        self.per_scan_known = per_scan is not None
        if self.output_mode == "scans" and per_scan is None:
            self.output_mode = "class"
        widget = self.query_one("#output3d", ProjectionWidget)
        title, short = "3D output", "Out"  # the short title where the border is narrow
        if threshold is not None:
            title += f" <= {threshold:g} m"
            short += f" <={threshold:g}"
        if self.output_mode == "height":
            title += " (height)"
            short += " height"
        elif self.output_mode == "scans":
            title += " (target: scans that saw it)"
            short += " scans"
        widget.base_title, widget.short_title = title, short
        widget._update_title()
        if voxels is None or self.prepared is None:
            widget.placeholder = self.no_output
            widget.set_points(None)
            return
        if target_output is None:
            target_output = self._known_target_output(voxels)
        scene, seen, hidden = classify(voxels, self.prepared["target"], target_output)
        scene = views.subsample(scene, limit, seed=0)
        layers, heights = output_layers(
            np.concatenate([scene, seen]),
            self.prepared["target"],
            hidden,
            mode=self.output_mode,
            voxel_size=self.voxel_size,
            threshold_m=threshold,
            per_scan=per_scan,
            target_ids=self.prepared.get("target_ids"),
        )
        shown = views.threshold_points(np.concatenate([scene, seen]), self.voxel_size, threshold)
        widget.placeholder = "nothing below the threshold" if len(voxels) else "no returns"
        if not any(len(layer.voxels) for layer in layers):
            widget.set_points(None)
            return
        widget.set_layers(
            layers,
            shown,
            widget.bounds if widget.bounds is not None else self.prepared["bounds"],
            self.voxel_size,
            height_range=heights,
        )

    def _known_per_scan(self, voxels):
        result = getattr(self.app, "result", None)
        if voxels is not None and result is not None and result.scene_output is voxels:
            return result.scene_per_scan
        return None

    def _known_target_output(self, voxels):
        # the run's own target output, or the one read from disk with the scene output
        result = getattr(self.app, "result", None)
        if result is not None and result.scene_output is voxels:
            return result.target_output
        scene_output, target_output = getattr(self.app, "disk_outputs", (None, None))
        return target_output if voxels is not None and scene_output is voxels else None

    def _redraw_output(self) -> None:
        self.show_output(*self._output_args)

    # -- requests for every view (keys t f p c g o in any view) --------------------

    def fit_target(self) -> None:
        """Frame the target in every view at once; footprints go (at that scale their
        edges would band the views), the path and scans stay."""
        if self.prepared is None or self.prepared.get("target_box") is None:
            return
        self.show_overlays(OVERLAY_CYCLE[1])
        for widget in self.query(ProjectionWidget):
            widget.fit_box(self.prepared["target_box"])
        self.query_one(TopViewWidget).fit("target")

    def fit_scene(self) -> None:
        if self.prepared is None:
            return
        self.show_overlays(OVERLAY_CYCLE[0])
        for widget in self.query(ProjectionWidget):
            widget.fit_box(self.prepared["bounds"])
        self.query_one(TopViewWidget).fit("scene")

    def fit_path(self) -> None:
        if self.prepared is None:
            return
        self.show_overlays(OVERLAY_CYCLE[0])
        for widget in self.query(ProjectionWidget):
            widget.fit_path()
        self.query_one(TopViewWidget).fit("path")

    def cycle_output_colour(self) -> None:
        """Output coloured by voxel class, by height, or by scans that saw the target (when
        the output came from a run in this session)."""
        modes = [m for m in COLOUR_MODES if m != "scans" or self.per_scan_known]
        index = modes.index(self.output_mode) if self.output_mode in modes else -1
        self.output_mode = modes[(index + 1) % len(modes)]
        self._redraw_output()

    def toggle_grey(self) -> None:
        """Height shading in colour, or in the report's 56 greys (every view)."""
        self.colour_map = "grey" if self.colour_map == "height" else "height"
        for widget in self.query(PictureWidget):
            widget.colour_map = self.colour_map
            widget.invalidate()

    def cycle_overlays(self) -> None:
        """All overlays, then path and scans only, then none (every view)."""
        index = OVERLAY_CYCLE.index(self.overlays) if self.overlays in OVERLAY_CYCLE else -1
        self.show_overlays(OVERLAY_CYCLE[(index + 1) % len(OVERLAY_CYCLE)])

    def show_overlays(self, names) -> None:
        """Draw these overlays (of "path", "scans", "footprints") in every view."""
        self.overlays = frozenset(names)
        for widget in self.query(PictureWidget):
            widget.shown_overlays = self.overlays
            widget.invalidate()

    def on_picture_widget_view_request(self, message: PictureWidget.ViewRequest) -> None:
        message.stop()
        if message.what in (
            "fit_target",
            "fit_scene",
            "fit_path",
            "cycle_output_colour",
            "toggle_grey",
            "cycle_overlays",
        ):
            getattr(self, message.what)()

    # -- pictures ------------------------------------------------------------------

    def current_view(self, focused=None) -> PictureWidget:
        """The focused view, else the first one the layout shows."""
        if isinstance(focused, PictureWidget):
            return focused
        shown = [w for w in self.query(PictureWidget) if w.display and w.size.width]
        return shown[0] if shown else self.query_one("#scene3d", PictureWidget)

    def save_png(self, path, width: int = 1200, height: int = 800, view=None):
        """Write a view (a widget or its id; default the current one) as a width x height PNG.

        The view is drawn again at that size with the same framing. Returns the
        path; a bad size or an empty view raises a one-line LadarError.
        """
        width, height = png.check_size(width, height)
        widget = (
            self.query_one(f"#{view}", PictureWidget) if isinstance(view, str) else self.current_view(view)
        )
        if isinstance(widget, ProjectionWidget):  # a fitted view frames the same in the PNG's shape
            picture = widget.make_picture(height, width, refit=True)
        else:
            picture = widget.make_picture(height, width)
        if picture is None:
            raise LadarError(f"{widget.border_title}: nothing to draw yet")
        return png.write_png(picture.rgb, path)

    def focused_projection(self, focused) -> ProjectionWidget:
        if isinstance(focused, ProjectionWidget):
            return focused
        if self.layout_number == 4:
            return self.query_one("#output3d", ProjectionWidget)
        return self.query_one("#scene3d", ProjectionWidget)

    def on_projection_widget_camera_changed(self, message: ProjectionWidget.CameraChanged):
        # scene and output views turn together, so they stay comparable
        for widget in self.query(ProjectionWidget):
            if widget is not message.widget and widget.camera != message.widget.camera:
                widget.camera = message.widget.camera
                widget.fitted = message.widget.fitted  # framed again when resized, or not
                widget.framed_for = widget.picture_size()  # (as it is: the camera shared)
                widget._update_title()
                widget.invalidate()
