"""The march's jump over an empty node: the last of its samples a ray must take there.

The report's march (docs/architecture.md, "March") samples every half voxel, and
most samples of a scan lie in empty bricks (92 % of the bench's at 45 degrees).
A sample in an empty node (a root cell, region or brick with no voxel) neither
hits nor ends the ray, nor does any later sample while it stays in that node
and in the scene's box ``[0, nx) x [0, ny) x [0, top)``: the march may go on
from the last such sample. Which one is found per axis with a margin
(config.MARCH_SKIP_MARGIN, a hundredth of a voxel) far above the rounding of a
sample's position, float32 included, so a skipped sample is one the march would have passed over: the
answers are the same, bit for bit. numba's march and the shader's
(shaders/trace.wgsl, ``last_sample_in_node``) take the same jumps.
"""

from numba import njit

from ladartui.tracing.config import MARCH_SKIP_MARGIN


@njit(nogil=True, cache=True, inline="always")
def last_sample_on_axis(o, d, lo_face, hi_face, t_s, step, cap):
    """The last sample ``t_s + k * step`` (as a float, at most ``cap``) whose position
    ``o + t d`` is certainly in ``[lo_face, hi_face)`` on one axis, for a ray whose
    current sample is in it."""
    if d > 0.0:
        return min(cap, ((hi_face - MARCH_SKIP_MARGIN - o) / d - t_s) / step)
    if d < 0.0:
        return min(cap, ((lo_face + MARCH_SKIP_MARGIN - o) / d - t_s) / step)
    return cap


@njit(nogil=True, cache=True, inline="always")
def last_sample_in_node(x, y, z, shift, ox, oy, oz, dx, dy, dz, t_s, step, nx, ny, top, samples):
    """The last sample certain to stay in the empty node of ``1 << shift`` cells a side
    holding cell (x, y, z) and in the scene's box (as an int; below the current
    sample when no later one is certain)."""
    size = float(1 << shift)
    bx, by, bz = float((x >> shift) << shift), float((y >> shift) << shift), float((z >> shift) << shift)
    cap = float(samples - 1)
    kx = last_sample_on_axis(ox, dx, max(bx, 0.0), min(bx + size, nx), t_s, step, cap)
    ky = last_sample_on_axis(oy, dy, max(by, 0.0), min(by + size, ny), t_s, step, cap)
    kz = last_sample_on_axis(oz, dz, max(bz, 0.0), min(bz + size, top), t_s, step, cap)
    last = min(kx, min(ky, kz))
    return int(last) - 1 if last >= 1.0 else -1
