"""Polygons of more than three corners cut into triangles inside themselves.

The mesh readers fan each polygon from its first corner, which puts triangles
outside a concave one (an L-shaped panel as one six-cornered face). The few
polygons such a fan may not cover are found at once, a chunk at a time (a mesh
of quads has millions), and each is cut by clipping ears in its plane."""

from __future__ import annotations

import numpy as np

_CHUNK = 2**16  # polygons looked at together: a mesh of quads has millions


def concave_cuts(vertices: np.ndarray, rows: np.ndarray) -> dict[int, list[tuple[int, int, int]]]:
    """The triangles (corner numbers, in the polygon's winding) of each polygon of
    ``rows`` (P, n corner indices into ``vertices``) whose fan from its first corner
    would not cover it, by row; a polygon the fan covers, or one not simple, is left out."""
    cuts: dict[int, list[tuple[int, int, int]]] = {}
    for start in range(0, len(rows), _CHUNK):
        corners = vertices[rows[start : start + _CHUNK]]
        normals = np.cross(corners, np.roll(corners, -1, axis=1)).sum(axis=1)  # Newell's
        for k in _fans_short(corners, normals):
            order = _polygon_triangles(corners[k], normals[k])
            if order is not None:
                cuts[start + int(k)] = order
    return cuts


def _fans_short(corners: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Which of the polygons ``corners`` (P, n, 3), facing ``normals``, a fan from their
    first corner may not cover (a fan triangle not turning with the polygon): the few
    to look at one by one, all found at once."""
    first = corners[:, :1]
    turns = np.einsum("pkc,pc->pk", np.cross(corners[:, 1:-1] - first, corners[:, 2:] - first), normals)
    return np.flatnonzero(~np.all(turns > 0, axis=1))


def _polygon_triangles(corners: np.ndarray, normal: np.ndarray) -> list[tuple[int, int, int]] | None:
    """Triangles (corner numbers, in the polygon's winding) covering a planar polygon
    facing ``normal`` whose fan from corner 0 may not: None for one of no area (nothing
    to cover) or not simple (left to the reader's fan). Cut by clipping ears in the
    polygon's plane."""
    if not np.any(normal):
        return None
    axis = int(np.argmax(np.abs(normal)))  # seen along the axis the plane faces most,
    u, v = (axis + 1) % 3, (axis + 2) % 3  # counter-clockwise when it faces that axis
    flat = np.column_stack([corners[:, u], corners[:, v] * (1.0 if normal[axis] > 0 else -1.0)])
    left = list(range(len(corners)))
    triangles = []
    while len(left) > 3:
        for k in range(len(left)):
            i, j, m = left[k - 1], left[k], left[(k + 1) % len(left)]
            if _cross2(flat[i], flat[j], flat[m]) <= 0:
                continue  # a reflex corner: no ear
            others = [q for q in left if q not in (i, j, m)]
            if any(_inside2(flat[q], flat[i], flat[j], flat[m]) for q in others):
                continue
            triangles.append((i, j, m))
            left.pop(k)
            break
        else:
            return None
    triangles.append((left[0], left[1], left[2]))
    return triangles


def _cross2(a, b, c) -> float:
    return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


def _inside2(p, a, b, c) -> bool:
    """Whether ``p`` lies in the counter-clockwise triangle a, b, c or on its sides."""
    return _cross2(a, b, p) >= 0 and _cross2(b, c, p) >= 0 and _cross2(c, a, p) >= 0
