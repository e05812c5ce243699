"""PLY faces of more than three corners, cut into triangles inside themselves.

The mesh reader fans each polygon from its first corner, which puts triangles
outside a concave one (an L-shaped panel as one six-cornered face), and reads
no binary PLY whose face lists differ in length (triangles with quads, a
six-cornered cap with its quad sides). Concave polygons are cut by
``polygons.concave_cuts``; a file of triangles alone is left as it is."""

from __future__ import annotations

import mmap
from pathlib import Path
from typing import Any

import numpy as np

from ladartui.scene.lazy_kernels import LazyKernels
from ladartui.scene.polygons import concave_cuts

_kernel = LazyKernels(globals())  # numba only once a mixed binary PLY is read

_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip


def polygon_groups(lists) -> dict[int, np.ndarray]:
    """A face element's corner lists (a (P, n) array, or one list a face) by corner count."""
    lists = np.asarray(lists) if not isinstance(lists, np.ndarray) else lists
    if lists.dtype != object:
        return {lists.shape[1]: lists} if lists.ndim == 2 and len(lists) and lists.dtype.kind in "iu" else {}
    lengths = np.fromiter(map(len, lists), np.int64, len(lists))
    return {
        int(n): np.array([list(row) for row in lists[lengths == n]], dtype=np.int64).reshape(-1, int(n))
        for n in np.unique(lengths)
    }


def cut_polygons(vertices: np.ndarray, groups: dict[int, np.ndarray], always: bool = False):
    """The triangles of the polygons ``groups`` (by corner count) over ``vertices``: each
    fanned from its first corner as the reader does, a concave one cut inside itself.
    None when no polygon needed cutting (unless ``always``) or a corner is not a vertex."""
    if any(len(rows) and (rows.min() < 0 or rows.max() >= len(vertices)) for rows in groups.values()):
        return None
    cuts = {n: found for n, rows in groups.items() if n > 3 and (found := concave_cuts(vertices, rows))}
    if not cuts and not always:
        return None
    parts = []
    for n, rows in groups.items():
        if n < 3:
            continue
        fan = np.stack([rows[:, [0, k, k + 1]] for k in range(1, n - 1)], axis=1).astype(np.int64)
        for k, order in cuts.get(n, {}).items():
            fan[k] = rows[k][np.asarray(order)]
        parts.append(fan.reshape(-1, 3))
    return np.concatenate(parts) if parts else np.zeros((0, 3), np.int64)


def cut_read_polygons(part) -> None:
    """Re-cut, in place, the faces of a PLY mesh read unprocessed (its vertices as in the
    file): the reader keeps the file's elements in the mesh's metadata."""
    elements: Any = getattr(part, "metadata", {}).get("_ply_raw")
    try:
        data = elements["face"]["data"]
        count = elements["vertex"]["length"]
    except (KeyError, TypeError):
        return
    names = ("vertex_indices", "vertex_index")
    if isinstance(data, dict):
        lists = next((data[name] for name in names if name in data), None)
    elif isinstance(data, np.ndarray) and data.dtype.names:
        fields = data.dtype.names
        name = fields[0] if len(fields) == 1 else next((n for n in fields if n in names), None)
        lists = data[name]["f1"] if name is not None and data[name].dtype.names else None
    else:
        return
    vertices = np.asarray(part.vertices, dtype=np.float64)
    if lists is None or len(vertices) != count:
        return
    faces = cut_polygons(vertices, polygon_groups(lists))
    if faces is not None and len(faces) == len(part.faces):
        part.faces = faces


def binary_ply_triangles(path: Path) -> bytes | None:
    """A binary PLY whose face lists differ in length (which the reader cannot read),
    rewritten with its faces as triangles (each polygon fanned, a concave one cut
    inside itself); None for any other file, left to the reader as it is."""
    try:
        with path.open("rb") as file:  # mapped, not read: closed once no array views it
            data = mmap.mmap(file.fileno(), 0, access=mmap.ACCESS_READ)
        return _rewritten(data)
    except (OSError, ValueError, KeyError, IndexError):
        return None  # empty, unreadable, not as its header says, a type unknown: the reader tells


def _rewritten(data) -> bytes | None:
    end = data.find(b"end_header")
    if data[:3] != b"ply" or end < 0:
        return None
    newline = data.find(b"\n", end)
    if newline < 0:
        return None
    header = data[:newline].decode("latin-1").splitlines()
    body = newline + 1
    order = None
    elements: list[tuple[str, int, list[list[str]], list[int]]] = []  # name, count, properties, header lines
    for at, line in enumerate(header):
        words = line.split()
        if words[:1] == ["format"] and len(words) > 1:
            order = {"binary_little_endian": "<", "binary_big_endian": ">"}.get(words[1])
        elif words[:1] == ["element"] and len(words) == 3 and words[2].isdigit():
            elements.append((words[1], int(words[2]), [], [at]))
        elif words[:1] == ["property"] and elements:
            elements[-1][2].append(words[1:])
            elements[-1][3].append(at)
    if order is None or not any(name == "face" for name, *_ in elements):
        return None
    offset, vertices, face = body, None, None
    for name, count, properties, places in elements:
        if any(p[:1] == ["list"] for p in properties):
            if sum(p[:1] == ["list"] for p in properties) > 1:
                return None
            read = _list_rows(data, offset, count, properties, order)
            if read is None:
                return None
            size, groups = read
            if name == "face" and groups is not None:
                face = (offset, offset + size, groups, places)
            offset += size
            continue
        dtype = np.dtype([(f"p{k}", order + _TYPES[p[0]]) for k, p in enumerate(properties)])
        if name == "vertex":
            names = [p[-1] for p in properties]
            if not all(axis in names for axis in "xyz"):
                return None
            rows = np.frombuffer(data, dtype, count, offset)
            vertices = np.column_stack([rows[f"p{names.index(axis)}"].astype(np.float64) for axis in "xyz"])
        offset += count * dtype.itemsize
    if face is None or vertices is None:
        return None
    start, stop, groups, dropped = face
    triangles = cut_polygons(vertices, groups, always=True)
    if triangles is None:
        return None
    at = dropped[0]  # the element's line, then its properties' (comments among them kept)
    lines = header[:at] + [f"element face {len(triangles)}", "property list uchar int vertex_indices"]
    lines += [line for k, line in enumerate(header[at + 1 :], at + 1) if k not in dropped]
    packed = np.zeros(len(triangles), dtype=[("n", "u1"), ("v", order + "i4", (3,))])
    packed["n"], packed["v"] = 3, triangles
    return ("\n".join(lines) + "\n").encode("latin-1") + data[body:start] + packed.tobytes() + data[stop:]


def _list_rows(data, offset: int, count: int, properties: list[list[str]], order: str):
    """(bytes, the lists by length as ``polygon_groups`` gives them when they differ in
    length, else None) of an element of one list property at ``offset``; None when it
    runs past the end of the file or counts its lists as floats."""
    sizes = [np.dtype(_TYPES[p[0]]).itemsize for p in properties if p[0] != "list"]
    at = next(k for k, p in enumerate(properties) if p[0] == "list")
    before = sum(sizes[:at])
    after = sum(sizes) - before
    counter = np.dtype(order + _TYPES[properties[at][1]])
    item = np.dtype(order + _TYPES[properties[at][2]])
    if count == 0:
        return 0, None
    first = int(np.frombuffer(data, counter, 1, offset + before)[0])
    row = before + counter.itemsize + first * item.itemsize + after
    if offset + count * row <= len(data):
        counts = np.ndarray((count,), counter, data, offset + before, (row,))
        if np.all(counts == first):
            return count * row, None  # one length: the reader reads it
    if counter.kind not in "iu":
        return None  # counts as floats: left to the reader
    buffer = np.frombuffer(data, np.uint8)
    starts, counts, end = _scan_lists(
        buffer,
        offset,
        count,
        before,
        counter.itemsize,
        counter.kind == "i",
        order == ">",
        item.itemsize,
        after,
    )
    if end < 0:
        return None
    groups = {}
    for n in np.unique(counts):
        rows = _gather_rows(buffer, starts[counts == n], int(n) * item.itemsize)
        groups[int(n)] = rows.view(item).reshape(len(rows), int(n)).astype(np.int64)
    return end - offset, groups


@_kernel
def _scan_lists(buffer, offset, count, before, size, signed, big, item, after):
    """(where each row's list starts, its length, where the element ends) of ``count``
    rows of a list property from ``offset`` in ``buffer``: ``before`` bytes, a
    ``size``-byte count, its items of ``item`` bytes, ``after`` bytes; the end -1 when
    a count is negative or the rows run past the buffer."""
    starts = np.empty(count, np.int64)
    counts = np.empty(count, np.int64)
    position = offset
    for r in range(count):
        at = position + before
        if at + size > len(buffer):
            return starts, counts, -1
        n = 0
        for b in range(size):
            n |= np.int64(buffer[at + (b if big else size - 1 - b)]) << (8 * (size - 1 - b))
        if signed and n >= np.int64(1) << (8 * size - 1):
            n -= np.int64(1) << (8 * size)
        if n < 0:
            return starts, counts, -1
        starts[r], counts[r] = at + size, n
        position = at + size + n * item + after
    return starts, counts, position if position <= len(buffer) else -1


@_kernel
def _gather_rows(buffer, starts, width):
    """The ``width`` bytes from each of ``starts`` in ``buffer``, a row each."""
    rows = np.empty((len(starts), width), np.uint8)
    for r in range(len(starts)):
        rows[r] = buffer[starts[r] : starts[r] + width]
    return rows
