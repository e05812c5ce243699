"""Rendered views as PNG files (Pillow), written atomically."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from ladartui.atomic import write_bytes_atomic
from ladartui.errors import FieldError

MAX_SIDE = 8192  # pixels: a larger picture is refused before it is drawn


def check_size(width, height) -> tuple[int, int]:
    """The requested picture size as ints, or a FieldError naming ``width`` or ``height``."""
    sides = []
    for name, value in (("width", width), ("height", height)):
        expected = f"a whole number of pixels from 16 to {MAX_SIDE}"
        try:
            side = int(value)
        except (TypeError, ValueError):
            raise FieldError(name, value, expected) from None
        if not 16 <= side <= MAX_SIDE:
            raise FieldError(name, side, expected)
        sides.append(side)
    return sides[0], sides[1]


def png_bytes(rgb: np.ndarray) -> bytes:
    """(rows, cols, 3) uint8 RGB as PNG bytes."""
    from PIL import Image  # imported here: only pictures need Pillow

    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8), "RGB").save(buffer, "PNG")
    return buffer.getvalue()


def write_png(rgb: np.ndarray, path) -> Path:
    """Write the picture to ``path`` (atomically: an earlier file stays until it is whole)."""
    path = Path(path)
    write_bytes_atomic(path, png_bytes(rgb))
    return path
