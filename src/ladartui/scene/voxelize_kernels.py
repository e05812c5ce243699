"""Compiled kernels of mesh voxelisation (see :mod:`ladartui.scene.voxelize`).

Coordinates are grid units: voxel (i, j, k) is the cube of side 1 centred on
(i, j, k). Triangles come as a (T, 3, 3) float64 array, relative to the grid
whose voxel (0, 0, 0) is ``origin`` in scene indices; the kernels mark a dense
uint8 grid over the mesh's bounding box.

Surface rule: a voxel is set when the triangle meets the voxel's open interior,
with the triangle pushed an infinitesimal distance against its normal (the
separating axis test below, ties broken by the normal's sign). So a face
lying exactly on a voxel boundary belongs to the voxel on its inner side, the
side its normal points away from; touching an edge or a corner sets nothing.

Solid rule: a voxel centre is inside when the winding number of the mesh
about it is not zero, found per column from the signed crossings above the
centre. A column passing exactly through an edge or a vertex is decided as if
moved by (eps, eps**2) in x and y (simulation of simplicity), so every
column crosses a closed mesh's surface a consistent number of times.

Numerical policy: comparisons are exact in float64 on coordinates relative
to each voxel's centre; vertex coordinates with a few significant bits (a
box on half-voxel boundaries) give exact ties, and other inputs can differ
from exact arithmetic only for surfaces that merely touch a voxel.
"""

from __future__ import annotations

import math

import numba


@numba.njit(nogil=True, cache=True)
def _separated(p0, p1, p2, lx, ly, lz, nx, ny, nz):
    """Whether axis L separates the (pushed-in) triangle from the open unit cube at the origin."""
    if lx == 0.0 and ly == 0.0 and lz == 0.0:
        return False  # not an axis (parallel edges): it separates nothing
    r = 0.5 * (abs(lx) + abs(ly) + abs(lz))
    lo = min(p0, min(p1, p2))
    hi = max(p0, max(p1, p2))
    ln = lx * nx + ly * ny + lz * nz  # the push moves the projection by -eps * ln
    if hi < -r or (hi == -r and ln >= 0.0):
        return True
    if lo > r or (lo == r and ln <= 0.0):
        return True
    return False


@numba.njit(nogil=True, cache=True)
def triangle_meets_voxel(tri, cx, cy, cz):
    """True when triangle ``tri`` (3, 3) meets the interior of the voxel centred on (cx, cy, cz)."""
    ax, ay, az = tri[0, 0] - cx, tri[0, 1] - cy, tri[0, 2] - cz
    bx, by, bz = tri[1, 0] - cx, tri[1, 1] - cy, tri[1, 2] - cz
    qx, qy, qz = tri[2, 0] - cx, tri[2, 1] - cy, tri[2, 2] - cz
    e0x, e0y, e0z = bx - ax, by - ay, bz - az
    e1x, e1y, e1z = qx - bx, qy - by, qz - bz
    e2x, e2y, e2z = ax - qx, ay - qy, az - qz
    nx = e0y * (qz - az) - e0z * (qy - ay)
    ny = e0z * (qx - ax) - e0x * (qz - az)
    nz = e0x * (qy - ay) - e0y * (qx - ax)
    # The cube's face normals.
    if _separated(ax, bx, qx, 1.0, 0.0, 0.0, nx, ny, nz):
        return False
    if _separated(ay, by, qy, 0.0, 1.0, 0.0, nx, ny, nz):
        return False
    if _separated(az, bz, qz, 0.0, 0.0, 1.0, nx, ny, nz):
        return False
    # The triangle's normal.
    d = nx * ax + ny * ay + nz * az
    if _separated(d, d, d, nx, ny, nz, nx, ny, nz):
        return False
    # Each cube axis crossed with each triangle edge.
    for ex, ey, ez in ((e0x, e0y, e0z), (e1x, e1y, e1z), (e2x, e2y, e2z)):
        # x cross e = (0, -ez, ey)
        if _separated(-ez * ay + ey * az, -ez * by + ey * bz, -ez * qy + ey * qz, 0.0, -ez, ey, nx, ny, nz):
            return False
        # y cross e = (ez, 0, -ex)
        if _separated(ez * ax - ex * az, ez * bx - ex * bz, ez * qx - ex * qz, ez, 0.0, -ex, nx, ny, nz):
            return False
        # z cross e = (-ey, ex, 0)
        if _separated(-ey * ax + ex * ay, -ey * bx + ex * by, -ey * qx + ex * qy, -ey, ex, 0.0, nx, ny, nz):
            return False
    return True


@numba.njit(nogil=True, cache=True)
def mark_surface(triangles, start, stop, grid):
    """Set ``grid[i, j, k]`` for every voxel the triangles ``start:stop`` pass through."""
    gx, gy, gz = grid.shape
    for t in range(start, stop):
        tri = triangles[t]
        lo_i = max(int(math.ceil(min(tri[0, 0], min(tri[1, 0], tri[2, 0])) - 0.5)), 0)
        hi_i = min(int(math.floor(max(tri[0, 0], max(tri[1, 0], tri[2, 0])) + 0.5)), gx - 1)
        lo_j = max(int(math.ceil(min(tri[0, 1], min(tri[1, 1], tri[2, 1])) - 0.5)), 0)
        hi_j = min(int(math.floor(max(tri[0, 1], max(tri[1, 1], tri[2, 1])) + 0.5)), gy - 1)
        lo_k = max(int(math.ceil(min(tri[0, 2], min(tri[1, 2], tri[2, 2])) - 0.5)), 0)
        hi_k = min(int(math.floor(max(tri[0, 2], max(tri[1, 2], tri[2, 2])) + 0.5)), gz - 1)
        for i in range(lo_i, hi_i + 1):
            for j in range(lo_j, hi_j + 1):
                for k in range(lo_k, hi_k + 1):
                    if grid[i, j, k] == 0 and triangle_meets_voxel(tri, float(i), float(j), float(k)):
                        grid[i, j, k] = 1


@numba.njit(nogil=True, cache=True)
def _edge_side(ax, ay, bx, by, px, py):
    """Sign of cross(b - a, p' - a) for p' = p + (eps, eps**2): never 0 for a proper edge.

    Evaluated with the edge's ends in one fixed order, so the two triangles
    sharing an edge get exactly opposite signs whatever the rounding: a column
    on the edge is inside exactly one of them.
    """
    if ax > bx or (ax == bx and ay > by):
        return -_ordered_edge_side(bx, by, ax, ay, px, py)
    return _ordered_edge_side(ax, ay, bx, by, px, py)


@numba.njit(nogil=True, cache=True)
def _ordered_edge_side(ax, ay, bx, by, px, py):
    value = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
    if value != 0.0:
        return 1 if value > 0.0 else -1
    dy = by - ay
    if dy != 0.0:
        return 1 if -dy > 0.0 else -1
    dx = bx - ax
    if dx != 0.0:
        return 1 if dx > 0.0 else -1
    return 0


@numba.njit(nogil=True, cache=True)
def add_crossings(triangles, start, stop, crossings):
    """Add each triangle's signed crossings of the voxel columns to ``crossings``.

    ``crossings`` is (gx, gy, gz + 1) int32: a triangle crossing column (i, j)
    at height z adds the sign of its normal's z at layer ceil(z) (clipped), so
    the winding number at centre k is the sum over layers above k.
    """
    gx, gy, layers = crossings.shape
    for t in range(start, stop):
        ax, ay, az = triangles[t, 0, 0], triangles[t, 0, 1], triangles[t, 0, 2]
        bx, by, bz = triangles[t, 1, 0], triangles[t, 1, 1], triangles[t, 1, 2]
        qx, qy, qz = triangles[t, 2, 0], triangles[t, 2, 1], triangles[t, 2, 2]
        nx = (by - ay) * (qz - az) - (bz - az) * (qy - ay)
        ny = (bz - az) * (qx - ax) - (bx - ax) * (qz - az)
        nz = (bx - ax) * (qy - ay) - (by - ay) * (qx - ax)
        if nz == 0.0:
            continue  # seen edge-on from above: crosses no column
        sign = 1 if nz > 0.0 else -1
        lo_i = max(int(math.ceil(min(ax, min(bx, qx)))), 0)
        hi_i = min(int(math.floor(max(ax, max(bx, qx)))), gx - 1)
        lo_j = max(int(math.ceil(min(ay, min(by, qy)))), 0)
        hi_j = min(int(math.floor(max(ay, max(by, qy)))), gy - 1)
        for i in range(lo_i, hi_i + 1):
            px = float(i)
            for j in range(lo_j, hi_j + 1):
                py = float(j)
                if (
                    _edge_side(ax, ay, bx, by, px, py) != sign
                    or _edge_side(bx, by, qx, qy, px, py) != sign
                    or _edge_side(qx, qy, ax, ay, px, py) != sign
                ):
                    continue
                z = az - (nx * (px - ax) + ny * (py - ay)) / nz
                layer = min(max(int(math.ceil(z)), 0), layers - 1)
                crossings[i, j, layer] += sign


@numba.njit(nogil=True, cache=True)
def fill_inside(crossings, grid, start, stop):
    """Set ``grid[start:stop]`` where the winding number (crossings above the centre) is not zero.

    Returns how many centres there are inside.
    """
    gz = grid.shape[2]
    inside = 0
    for i in range(start, stop):
        for j in range(grid.shape[1]):
            winding = crossings[i, j, gz]
            for k in range(gz - 1, -1, -1):
                if winding != 0:
                    grid[i, j, k] = 1
                    inside += 1
                winding += crossings[i, j, k]
    return inside


@numba.njit(nogil=True, cache=True)
def collect_voxels(grid, start, stop, origin, out, row):
    """Write the indices of set voxels of ``grid[start:stop]`` (plus ``origin``) from ``out[row]``.

    Returns the next free row. In (x, y, z) order, like the files this project writes.
    """
    for i in range(start, stop):
        for j in range(grid.shape[1]):
            for k in range(grid.shape[2]):
                if grid[i, j, k]:
                    out[row, 0] = origin[0] + i
                    out[row, 1] = origin[1] + j
                    out[row, 2] = origin[2] + k
                    row += 1
    return row
