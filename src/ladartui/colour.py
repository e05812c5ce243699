"""Colour maps and palette of the rendered views, and the WCAG contrast they are held to.

The height map is perceptually uniform by construction: OKLab lightness rises
linearly from dark blue-violet through teal and green to pale yellow (the path
viridis takes), computed once. It starts light enough that every shade keeps
a WCAG contrast of at least 3 against the black background, so a thresholded
output never disappears into it. The report's 56 grey shades stay an option.
"""

from __future__ import annotations

import functools

import numpy as np

GREY_LEVELS = 56  # the report's grey scale for 3D point plots (section 3.4.1)
RAMP_LEVELS = 64
BACKGROUND = (0, 0, 0)
GROUND_RGB = (58, 46, 34)
PATH_RGB = (255, 215, 0)
SCAN_RGB = (255, 60, 60)
START_RGB = (255, 255, 255)
FOOTPRINT_RGB = (255, 150, 50)  # outside the height colours, and not the target
TARGET_RGB = (255, 0, 255)  # the target, in every view
# Several targets: one colour each, in id order (the first is TARGET_RGB), apart from
# the height colours, the ground, the overlays and HIDDEN_RGB, in 24-bit and 256 colours.
TARGET_PALETTE = (TARGET_RGB, (150, 90, 255), (255, 175, 255), (200, 0, 80), (255, 255, 255))


def target_colour(index: int) -> tuple[int, int, int]:
    """The colour of the ``index``-th target (0-based, in id order), cycling the palette."""
    return TARGET_PALETTE[index % len(TARGET_PALETTE)]


HIDDEN_RGB = (0, 235, 255)  # target voxels seen only without foliage: what it hid
SCENE_GREY = (110, 215)  # grey range of scene voxels beside a coloured target


def _oklab_to_srgb(lab: np.ndarray) -> np.ndarray:
    """OKLab (..., 3) to sRGB 0..1 (unclipped), Ottosson's published matrices."""
    m1 = np.array(
        [
            [1.0, 0.3963377774, 0.2158037573],
            [1.0, -0.1055613458, -0.0638541728],
            [1.0, -0.0894841775, -1.2914855480],
        ]
    )
    m2 = np.array(
        [
            [4.0767416621, -3.3077115913, 0.2309699292],
            [-1.2684380046, 2.6097574011, -0.3413193965],
            [-0.0041960863, -0.7034186147, 1.7076147010],
        ]
    )
    lms = (lab @ m1.T) ** 3
    linear = lms @ m2.T
    return np.where(
        linear <= 0.0031308, 12.92 * linear, 1.055 * np.abs(linear) ** (1 / 2.4) * np.sign(linear) - 0.055
    )


@functools.cache
def height_map(levels: int = RAMP_LEVELS) -> np.ndarray:
    """``levels`` colours, low to high, (levels, 3) uint8; do not modify (cached).

    Lightness L rises linearly 0.52 -> 0.95 and hue turns 285 -> 100 degrees;
    chroma is as high as the sRGB gamut allows up to 0.15, so equal height
    steps are equal lightness steps.
    """
    t = np.linspace(0.0, 1.0, levels)
    lightness = 0.52 + 0.43 * t
    hue = np.radians(285.0 - 185.0 * t)
    out = np.zeros((levels, 3))
    for n in range(levels):
        for chroma in np.linspace(0.15, 0.0, 31):
            rgb = _oklab_to_srgb(np.array([lightness[n], chroma * np.cos(hue[n]), chroma * np.sin(hue[n])]))
            if np.all(rgb >= -1e-6) and np.all(rgb <= 1 + 1e-6):
                break
        out[n] = rgb
    table = np.clip(out * 255.0, 0, 255).round().astype(np.uint8)
    table.flags.writeable = False
    return table


@functools.cache
def grey_map(levels: int = GREY_LEVELS) -> np.ndarray:
    """The report's grey shades, dark (low) to near white (high), (levels, 3) uint8.

    The report ran from near white to black on a white page; a terminal is
    usually dark, so the ramp runs the other way and stops where its darkest
    shade still has a contrast of 3 against black.
    """
    values = np.linspace(100, 245, levels).round().astype(np.uint8)
    table = np.repeat(values[:, None], 3, axis=1)
    table.flags.writeable = False
    return table


@functools.cache
def scene_grey_map(levels: int = GREY_LEVELS) -> np.ndarray:
    """Greys for scene voxels drawn beside coloured target classes (a narrower range)."""
    values = np.linspace(*SCENE_GREY, levels).round().astype(np.uint8)
    table = np.repeat(values[:, None], 3, axis=1)
    table.flags.writeable = False
    return table


COLOUR_MAPS = ("height", "grey")


def colour_map(name: str) -> np.ndarray:
    """``"height"`` (perceptual colour), ``"grey"`` (the report's 56 shades) or
    ``"scene-grey"`` (scene voxels under a classified output)."""
    if name == "grey":
        return grey_map()
    if name == "scene-grey":
        return scene_grey_map()
    if name == "height":
        return height_map()
    raise ValueError(f"unknown colour map {name!r}; expected 'height' or 'grey'")


def shade_indices(heights, lo: float, hi: float, levels: int) -> np.ndarray:
    """Map heights to integer shade indices 0..levels-1 linearly over [lo, hi]."""
    heights = np.asarray(heights, dtype=np.float64)
    span = max(float(hi) - float(lo), 1e-9)
    index = np.floor((heights - lo) / span * levels)
    return np.clip(index, 0, levels - 1).astype(np.int32)


def shade(heights, lo: float, hi: float, table: np.ndarray) -> np.ndarray:
    """(N, 3) uint8 colours of ``heights`` over [lo, hi] in ``table``."""
    return table[shade_indices(heights, lo, hi, len(table))]


def relative_luminance(rgb) -> np.ndarray:
    """WCAG 2 relative luminance of sRGB uint8 colours (..., 3)."""
    c = np.asarray(rgb, dtype=np.float64) / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return linear @ np.array([0.2126, 0.7152, 0.0722])


def contrast_ratio(a, b) -> np.ndarray:
    """WCAG 2 contrast ratio (1..21) between colours ``a`` and ``b`` (broadcast)."""
    la, lb = relative_luminance(a), relative_luminance(b)
    return (np.maximum(la, lb) + 0.05) / (np.minimum(la, lb) + 0.05)
