"""Charts as files (SVG and PNG) drawn with matplotlib's headless Agg canvas.

Each figure is a ``matplotlib.figure.Figure`` with its own canvas, never pyplot's
global state, so charts can be drawn from worker threads. plotext keeps drawing
the same charts in the terminal (``ladartui.study.chart``).
"""

from __future__ import annotations

import io
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ladartui.atomic import write_bytes_atomic

DPI = 100
FORMATS = ("svg", "png")


def new_figure(width_px: int = 900, height_px: int = 560) -> Figure:
    """A figure of the given pixel size (at DPI) on an Agg canvas."""
    figure = Figure(figsize=(width_px / DPI, height_px / DPI), dpi=DPI)
    FigureCanvasAgg(figure)
    return figure


def figure_bytes(figure: Figure, fmt: str) -> bytes:
    if fmt not in FORMATS:
        raise ValueError(f"chart format {fmt!r}: expected one of {', '.join(FORMATS)}")
    buffer = io.BytesIO()
    # svg.hashsalt and no date: the same chart gives the same file.
    metadata = {"Date": None} if fmt == "svg" else {"Software": None}
    figure.savefig(buffer, format=fmt, dpi=DPI, metadata=metadata)
    return buffer.getvalue()


def save_figure(figure: Figure, path) -> Path:
    """Write ``figure`` atomically; the format follows the suffix (.svg or .png)."""
    path = Path(path)
    write_bytes_atomic(path, figure_bytes(figure, path.suffix.lower().lstrip(".")))
    return path
