"""Cell arithmetic shared by the tracers (numba kernels, bundle starts): per axis,
and the slot of a cell in its node of the occupancy.

Every boundary parameter comes from one formula, ``boundary_t``, so cells
and ties agree wherever they are computed. The WGSL shader has the same
functions under the same names (shaders/axis.wgsl; ``node_slot`` is trace.wgsl's ``slot``).
"""

import math

import numpy as np
from numba import njit

from ladartui.tracing.config import INF


@njit(nogil=True, cache=True, inline="always")
def boundary_t(b, o, inv):
    # The one formula for boundary parameters (the reference tracer writes the same).
    return (b - o) * inv


@njit(nogil=True, cache=True, inline="always")
def cell_at(o, d, inv, t):
    """Cell index on one axis just after parameter ``t``, exact against ``boundary_t``."""
    c = math.floor(o + t * d)
    if d > 0.0:
        if boundary_t(c + 1.0, o, inv) <= t:
            c += 1.0
        elif boundary_t(c, o, inv) > t:
            c -= 1.0
    elif d < 0.0:
        if boundary_t(c, o, inv) <= t:
            c -= 1.0
        elif boundary_t(c + 1.0, o, inv) > t:
            c += 1.0
    return np.int64(c)


@njit(nogil=True, cache=True, inline="always")
def clamp(v, lo, hi):
    return lo if v < lo else (hi if v > hi else v)


@njit(nogil=True, cache=True, inline="always")
def slab(o, d, inv, lo, hi):
    """Entry and exit parameters of [lo, hi) on one axis; (inf, -inf) when never inside."""
    if d > 0.0:
        return boundary_t(lo, o, inv), boundary_t(hi, o, inv)
    if d < 0.0:
        return boundary_t(hi, o, inv), boundary_t(lo, o, inv)
    if lo < o < hi:
        return -INF, INF
    return INF, -INF


@njit(nogil=True, cache=True, inline="always")
def cube_start(ox, oy, oz, dx, dy, dz, ix, iy, iz, x, y, z):
    """(start, leave): where the ray enters the cell at (x, y, z), from t = 0 on, and
    leaves it (the reference tracer's slab test of the cell's open interior; ``i*``
    are ``1 / d``, inf for 0). It meets the cell if start < leave. An origin on the
    face it enters by gives an entry of -0.0 (``(b - o) * inv`` with ``b == o`` and
    ``d < 0``); 0.0 comes first in the clamp so that such a start is +0.0, as the
    exact kernel's."""
    ex, lx = slab(ox, dx, ix, x, x + 1.0)
    ey, ly = slab(oy, dy, iy, y, y + 1.0)
    ez, lz = slab(oz, dz, iz, z, z + 1.0)
    return max(0.0, max(ex, max(ey, ez))), min(lx, min(ly, lz))


@njit(nogil=True, cache=True, inline="always")
def node_slot(x, y, z, shift):
    """Which of its node's 8 x 8 x 8 children holds cell (x, y, z), the children
    being ``1 << shift`` cells a side: the slot in the occupancy's regions (6),
    tiles (3) and brick bits (0)."""
    return ((x >> shift) & 7) | (((y >> shift) & 7) << 3) | (((z >> shift) & 7) << 6)
