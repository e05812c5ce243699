"""Charts as files (SVG and PNG) drawn with matplotlib's headless Agg canvas.

Each figure is a ``matplotlib.figure.Figure`` with its own canvas, never pyplot's
global state, so charts can be drawn from worker threads. plotext keeps drawing
the same charts in the terminal (``ladartui.study.chart``).
"""

from __future__ import annotations

import contextlib
import io
import re
import warnings
from collections.abc import Iterator
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ladartui.atomic import write_bytes_atomic

DPI = 100
FORMATS = ("svg", "png")
# matplotlib's warning for a character none of its fonts has (it draws a box instead)
_MISSING_GLYPH = re.compile(r"Glyph (\d+) .*missing from font")


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


def coverage_axis(axes, peak: float, unseen: str, *, from_zero: bool) -> None:
    """A coverage axis (in %) never below 0, starting at 0 when ``from_zero``. With
    ``peak``, the highest coverage drawn, at 0 (nothing seen) it runs 0 to 100 % and
    says ``unseen``: matplotlib's own axis around a flat 0 would run from -0.05 % to
    0.05 %, a precision no run has."""
    if peak > 0:
        bottom, top = axes.get_ylim()
        axes.set_ylim(0.0 if from_zero else max(bottom, 0.0), top)
    else:
        axes.set_ylim(0, 100)
        axes.text(0.5, 0.5, unseen, ha="center", transform=axes.transAxes)


@contextlib.contextmanager
def undrawn_characters() -> Iterator[list[str]]:
    """The characters no font has (each drawn as a box) in the charts made and written
    inside, in the order drawn, gathered into the list yielded rather than warned of on stderr, with
    matplotlib's own source lines. Other warnings are shown as they would have been."""
    missing: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        # every one, not only the first from each line: laying out and saving both warn
        warnings.filterwarnings("always", message=_MISSING_GLYPH.pattern, category=UserWarning)
        try:
            yield missing
        finally:
            others = [warning for warning in caught if not _missing_glyph(warning, missing)]
    for warning in others:
        warnings.showwarning(warning.message, warning.category, warning.filename, warning.lineno)


def _missing_glyph(warning: warnings.WarningMessage, missing: list[str]) -> bool:
    """Whether ``warning`` says a character is missing from the fonts; it goes into ``missing``."""
    found = _MISSING_GLYPH.match(str(warning.message))
    if found is None or not issubclass(warning.category, UserWarning):
        return False
    character = chr(int(found.group(1)))
    if character not in missing:
        missing.append(character)
    return True
