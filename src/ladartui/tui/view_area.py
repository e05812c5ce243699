"""The views beside the sidebar: the 3D scene, the 3D output and the top view, in the
report's five layouts, with the flight path drawn over them."""

from __future__ import annotations

import numpy as np
from textual.containers import Container

from ladartui import views
from ladartui.errors import LadarError
from ladartui.tui.canvas import ProjectionWidget, TopViewWidget

SCENE_POINTS = 80_000  # voxels drawn in the 3D scene view, whatever the scene size
OUTPUT_POINTS = 80_000
MAX_FOOTPRINTS = 400

LAYOUTS = {
    1: "3D scene + top view",
    2: "3D scene + 3D output",
    3: "3D scene, full",
    4: "3D output, full",
    5: "3D scene + 3D output + top view",
}


def prepare_views(scene) -> dict:
    """View data that depends only on the scene: top view, 3D sample, bounds (worker thread)."""
    heights = scene.top_height_map()
    top = views.TopView(heights, scene.voxel_size,
                        target_columns=np.unique(scene.target[:, :2], axis=0))
    sample = views.subsample(scene.voxels, SCENE_POINTS, seed=0)
    points = np.concatenate([sample, views.surface_points(heights, SCENE_POINTS // 3)])
    nx, ny, nz = scene.shape
    top_z = int(heights.max()) if heights.size and heights.max() >= 0 else nz - 1
    bounds = (np.zeros(3), np.array([nx - 1, ny - 1, max(top_z, 1)], float))
    top.scene_layer(48, 96)  # warm the cache at a typical size
    return {"top": top, "points": points, "bounds": bounds,
            "target_m": tuple(float(v) for v in scene.target_centre_m())}


class ViewArea(Container):
    """Owns the three views and which of them the layout shows."""

    def __init__(self, **kwargs):
        super().__init__(classes="layout-1", **kwargs)
        self.layout_number = 1
        self.prepared: dict | None = None
        self.voxel_size = 1.0

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
        self.query_one(TopViewWidget).set_scene(prepared["top"])
        for widget in self.query(ProjectionWidget):
            widget.height_top = float(prepared["bounds"][1][2])
        self.query_one("#scene3d", ProjectionWidget).set_points(
            prepared["points"], prepared["bounds"], voxel_size)

    def rescale(self, voxel_size: float, target_m) -> None:
        """The same voxels at another size (the scenario's voxel size changed)."""
        self.voxel_size = voxel_size
        if self.prepared is not None:
            self.prepared["top"].voxel_size = voxel_size
            self.prepared["target_m"] = target_m

    def draw_path(self, scenario) -> None:
        """The scans and their footprints over the top view, and markers in the 3D views."""
        top = self.query_one(TopViewWidget)
        if scenario is None:
            top.set_overlay(None, None, None)
            return
        poses = scenario.poses()
        scans = np.array([[p.x, p.y] for p in poses]) if poses else None
        footprints = []
        step = max(1, len(poses) // MAX_FOOTPRINTS)
        for pose in poses[::step]:
            try:
                footprints.append(scenario.sensor.footprint(pose)[:, :2])
            except LadarError:
                pass
        top.set_overlay(scans, scans, footprints)
        if self.prepared is not None and poses:
            markers = np.array([p.position for p in poses]) / self.voxel_size
            lo, hi = self.prepared["bounds"]
            bounds = (np.minimum(lo, markers.min(axis=0)), np.maximum(hi, markers.max(axis=0)))
            for widget in self.query(ProjectionWidget):
                widget.set_markers(markers, bounds)

    def show_output(self, voxels, threshold: float | None, limit: int = OUTPUT_POINTS) -> None:
        widget = self.query_one("#output3d", ProjectionWidget)
        title = "3D output"
        if threshold is not None:
            title += f" <= {threshold:g} m"
        widget.base_title = title
        widget._update_title()
        if voxels is None or self.prepared is None:
            widget.placeholder = "no output yet: F5 runs"
            widget.set_points(None)
            return
        shown = views.threshold_points(voxels, self.voxel_size, threshold)
        widget.placeholder = "nothing below the threshold" if len(voxels) else "no returns"
        widget.set_points(views.subsample(shown, limit, seed=0),
                          widget.bounds if widget.bounds is not None else self.prepared["bounds"],
                          self.voxel_size)

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
                widget._update_title()
                widget.invalidate()
