"""The Sensor tab: detector grid, rays per detector, field of view, depth and pitch."""

from __future__ import annotations

from textual.widgets import Static

from ladartui.tui import bridge
from ladartui.tui.params import ParamPanel
from ladartui.tui.plain_text import PlainStatic


class SensorPanel(ParamPanel):
    def compose(self):
        for param in bridge.SENSOR_PARAMS:
            yield self.param_row(param)
        yield PlainStatic("", id="sensor-info", classes="info")

    def show(self, scenario) -> None:
        self.fill_fields(scenario)
        s = scenario.sensor
        self.query_one("#sensor-info", Static).update(
            # a line each: at 80 columns 'IFOV 125' and 'mdeg' fell on two lines
            f"{s.grid}x{s.grid} detectors, {s.ray_grid}x{s.ray_grid} rays each\n"
            f"{s.rays_per_scan:,} rays per scan\nIFOV {ifov_text(s.ifov)}"
        )


def ifov_text(degrees: float) -> str:
    """A detector's field of view: millidegrees below a degree, degrees from one up
    (a 90 degree view on 64 detectors read '1.41e+03 mdeg')."""
    return f"{degrees:.3g} deg" if degrees >= 1 else f"{degrees * 1000:.3g} mdeg"
