"""Where the terminal chart's point labels go, so that none touches another or a marker.

plotext draws text where it is told, over markers and over other text. Here
the chart is first drawn without labels at the size it will have; its frame
gives the plot area in cells. Each Pareto-front label then takes the first
free place of right, left, above or below its marker, with a blank cell
around it; a label with no free place is left out (the table lists every
setting). Places are returned in data units at cell centres, so plotext puts
each label exactly in the cell chosen.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


def log_seconds(seconds: float) -> float:
    """log10 of a time, a nanosecond at least (a coarse clock can time a scan at 0 s)."""
    return math.log10(max(seconds, 1e-9))


@dataclass(frozen=True)
class PlotArea:
    """The cells inside the chart's frame, and the data range they show (x as log10)."""

    width: int
    height: int
    x_range: tuple[float, float]  # log10 seconds at the first and last column
    y_range: tuple[float, float]  # error points at the bottom and top row

    def column(self, x: float) -> float:
        lo, hi = self.x_range
        return (log_seconds(x) - lo) / (hi - lo) * (self.width - 1)

    def row(self, y: float) -> float:
        lo, hi = self.y_range
        return (hi - y) / (hi - lo) * (self.height - 1)

    def data_at(self, column: int, row: int) -> tuple[float, float]:
        lo, hi = self.x_range
        x = 10 ** (lo + column / (self.width - 1) * (hi - lo))
        y_lo, y_hi = self.y_range
        return x, y_hi - row / (self.height - 1) * (y_hi - y_lo)


def frame_size(text: str) -> tuple[int, int] | None:
    """(columns, rows) inside the plot frame of plotext's text (no colours), if found."""
    lines = text.splitlines()
    top = next((i for i, line in enumerate(lines) if "┌" in line and "┐" in line), None)
    bottom = next((i for i, line in enumerate(lines) if "└" in line and "┘" in line), None)
    if top is None or bottom is None or bottom - top < 2:
        return None
    line = lines[top]
    return line.index("┐") - line.index("┌") - 1, bottom - top - 1


def _cells(value: float) -> set[int]:
    # plotext rounds half up; near a half either neighbour may be drawn
    low = math.floor(value)
    if 0.35 < value - low < 0.65:
        return {low, low + 1}
    return {math.floor(value + 0.5)}


def place_labels(
    area: PlotArea,
    markers: list[tuple[float, float]],
    labels: list[tuple[str, float, float]],
) -> list[tuple[str, float, float]]:
    """(text, x, y) for each label that fits: x, y are data units at the first cell of the text.

    ``markers``: every drawn point (x, y); ``labels``: (text, x, y) of the labelled points.
    """
    taken: set[tuple[int, int]] = set()
    for x, y in markers:
        for c in _cells(area.column(x)):
            for r in _cells(area.row(y)):
                taken.add((c, r))
    placed = []
    for text, x, y in labels:
        column = math.floor(area.column(x) + 0.5)
        row = math.floor(area.row(y) + 0.5)
        n = len(text)
        candidates = [
            (column + 2, row),  # right, one blank cell after the marker
            (column - 1 - n, row),  # left
            (column - n // 2, row - 1),  # above
            (column - n // 2, row + 1),  # below
            (column + 1, row - 1),
            (column + 1, row + 1),
            (column - n, row - 1),
            (column - n, row + 1),
        ]
        for start, r in candidates:
            if start < 0 or start + n > area.width or not 0 <= r < area.height:
                continue
            cells = {(c, r) for c in range(start - 1, start + n + 1)}
            if cells & taken:
                continue
            taken |= {(c, r) for c in range(start, start + n)}
            placed.append((text, *area.data_at(start, r)))
            break
    return placed
