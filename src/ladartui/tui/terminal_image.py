"""The textual-image widgets that put a view's pixels on the terminal.

Imported only in an image mode (``tui.graphics``): importing textual-image asks
the terminal what it shows. Kitty graphics and Sixel are textual-image's own
widgets; iTerm2 inline images (OSC 1337, a PNG sized in cells) go through its
Sixel widget's placement, with the PNG in place of the Sixel data.
"""

from __future__ import annotations

import base64
import io

from PIL import Image as PILImage
from textual.widget import Widget
from textual_image._terminal import get_cell_size
from textual_image.widget import SixelImage, TGPImage
from textual_image.widget.sixel import _ImageSixelImpl, _NoopRenderable


def cell_pixels() -> tuple[int, int]:
    """(width, height) of a terminal cell in pixels (asked once, before the app starts)."""
    size = get_cell_size()
    return size.width, size.height


def iterm_sequence(image: PILImage.Image, cols: int, rows: int) -> str:
    """The OSC 1337 inline image: ``image`` as PNG stretched over cols x rows cells."""
    buffer = io.BytesIO()
    image.convert("RGB").save(buffer, format="PNG")
    data = base64.b64encode(buffer.getvalue()).decode("ascii")
    size = len(buffer.getvalue())
    return (
        f"\x1b]1337;File=inline=1;size={size};width={cols};height={rows};"
        f"preserveAspectRatio=0;doNotMoveCursor=1:{data}\x07"
    )


class _ITermImpl(_ImageSixelImpl):
    def _image_to_sixels(self, image, sixel_options=None, background=None) -> str:
        width, height = cell_pixels()
        cols = max(1, round(image.width / width))
        rows = max(1, round(image.height / height))
        return iterm_sequence(image, cols, rows)


class ITermImage(SixelImage, Renderable=_NoopRenderable):
    """An image drawn with iTerm2's inline image protocol."""

    def compose(self):
        yield _ITermImpl(self.image, self._sixel_options)


WIDGETS: dict[str, type[Widget]] = {"kitty": TGPImage, "sixel": SixelImage, "iterm": ITermImage}


def image_widget(mode: str, **kwargs) -> Widget:
    """An empty image widget for ``mode`` (kitty, sixel or iterm)."""
    return WIDGETS[mode](**kwargs)


def to_pil(rgb) -> PILImage.Image:
    return PILImage.fromarray(rgb, "RGB")
