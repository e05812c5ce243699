"""The report's fixed-step march on the CPU (numba), and its jump over empty nodes.

``march_kernel`` follows docs/architecture.md ("March") step by step; the
shader's ``march_one`` (shaders/trace.wgsl) mirrors it. Most samples of a scan
lie in empty bricks (92 % of the bench's at 45 degrees). A sample in an empty
node (a root cell, region or brick with no voxel) neither hits nor ends the
ray, nor does any later sample while it stays in that node and in the scene's
box ``[0, nx) x [0, ny) x [0, top)``: the march may go on from the last such
sample (``last_sample_in_node``). Which one is found per axis with a margin
(config.MARCH_SKIP_MARGIN, a hundredth of a voxel) far above the rounding of a
sample's position, float32 included, so a skipped sample is one the march
would have passed over: the answers are the same, bit for bit. The shader
takes the same jumps (its ``last_sample_in_node``).
"""

import math

import numpy as np
from numba import njit, prange

from ladartui.tracing.axis import node_slot
from ladartui.tracing.backend import GROUND, MISS, VOXEL
from ladartui.tracing.config import BUNDLE, INF, MARCH_SKIP_MARGIN


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


@njit(parallel=True, nogil=True, cache=True)
def march_kernel(
    orig, dirs, step, zmax, root, regions, tiles, bricks, lo, hi, rorg, rdims, nx, ny, kind, index, tout
):
    """The report's fixed-step march (docs/architecture.md "March") for every ray."""
    n = orig.shape[0]
    chunks = (n + BUNDLE - 1) // BUNDLE
    top = zmax + 1.0
    # From the first sample on, every sample is inside the extent's box or ends the ray.
    limit = np.int64((math.sqrt(nx * nx + ny * ny + top * top) + 2.0) / step) + 2
    for ch in prange(chunks):
        for r in range(ch * BUNDLE, min(n, (ch + 1) * BUNDLE)):
            ox, oy, oz = orig[r, 0], orig[r, 1], orig[r, 2]
            dx, dy, dz = dirs[r, 0], dirs[r, 1], dirs[r, 2]
            result = MISS
            i, j, k, tr = np.int64(-1), np.int64(-1), np.int64(-1), INF
            t_s = 0.0
            if oz > top:
                t_s = (top - oz) * (1.0 / dz) if dz < 0.0 else INF
            samples = limit if t_s < INF else 0
            sample = np.int64(-1)
            while sample + 1 < samples:
                sample += 1
                t = t_s + sample * step
                cx, cy, cz = ox + t * dx, oy + t * dy, oz + t * dz
                inside = 0.0 <= cx < nx and 0.0 <= cy < ny
                if cz < 0.0:
                    if inside:
                        result = GROUND
                        i, j, k, tr = np.int64(math.floor(cx)), np.int64(math.floor(cy)), np.int64(0), t
                    break
                if not inside or (cz >= top and dz >= 0.0):
                    break
                x, y, z = np.int64(math.floor(cx)), np.int64(math.floor(cy)), np.int64(math.floor(cz))
                if x < lo[0] or y < lo[1] or z < lo[2] or x >= hi[0] or y >= hi[1] or z >= hi[2]:
                    continue
                g = root[
                    ((x - rorg[0]) >> 9) + rdims[0] * (((y - rorg[1]) >> 9) + rdims[1] * ((z - rorg[2]) >> 9))
                ]
                empty = 9 if g == 0 else 0
                if g != 0:
                    tl = regions[(np.int64(g) - 1) * 512 + node_slot(x, y, z, 6)]
                    empty = 6 if tl == 0 else 0
                    if tl != 0:
                        br = tiles[(np.int64(tl) - 1) * 512 + node_slot(x, y, z, 3)]
                        empty = 3 if br == 0 else 0
                        if br != 0:
                            bit = node_slot(x, y, z, 0)
                            if (bricks[(np.int64(br) - 1) * 16 + (bit >> 5)] >> (bit & 31)) & 1:
                                result = VOXEL
                                i, j, k, tr = x, y, z, t
                                break
                if empty:  # an empty node: on past its samples (none of them ends the ray)
                    sample = max(
                        sample,
                        last_sample_in_node(
                            x, y, z, empty, ox, oy, oz, dx, dy, dz, t_s, step, nx, ny, top, samples
                        ),
                    )
            kind[r] = result
            index[r, 0], index[r, 1], index[r, 2] = i, j, k
            tout[r] = tr
