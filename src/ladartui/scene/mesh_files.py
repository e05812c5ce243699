"""Checks of mesh files before the mesh reader takes them: a binary STL's length, a
text PLY's lines, an OBJ's vertex and face lines. Each raises ``InputFileError``
naming the file (and the line) where the reader would read past the fault (a
mesh with holes, a vertex dropped, index 0 taken) or fail naming nothing."""

from __future__ import annotations

import math
from array import array
from functools import partial
from pathlib import Path

import numpy as np

from ladartui.errors import InputFileError
from ladartui.fileprobe import text_lines
from ladartui.scene.polygons import concave_cuts
from ladartui.textsafe import one_line


def _stl_head(data: bytes) -> tuple[int, int, bytes] | None:
    """(file size, the triangle count a binary header gives, the first 584 bytes); None
    when it is shorter than a header."""
    size = len(data)
    return (size, int.from_bytes(data[80:84], "little"), data[: 84 + 50 * 10]) if size >= 84 else None


def binary_stl(data: bytes) -> bool:
    """Whether ``data`` is sized as a binary STL: an 84-byte header, 50 bytes a triangle."""
    head = _stl_head(data)
    return head is not None and head[0] == 84 + 50 * head[1]


# Control bytes a text STL never holds, where a binary one's floats and attribute
# words (usually zero) hold some in every triangle.
_BINARY_BYTES = frozenset(range(32)) - frozenset(b"\t\n\v\f\r")


def check_stl_whole(path: Path, data: bytes) -> None:
    """``InputFileError`` for a binary STL shorter or longer than its header's triangle
    count says (not sized as binary, it would be read as text and hold no triangles)."""
    read = _stl_head(data)
    if read is None:
        return
    size, count, head = read
    need = 84 + 50 * count
    if count == 0 or size == need or (size > 84 and not _BINARY_BYTES & set(head[84:])):
        return  # whole, or text: an ASCII STL (a bare header holds no triangle either way)
    what = "cut short" if size < need else "longer than its header says"
    raise InputFileError(
        path,
        f"a binary STL {what}: its header counts {count:,} triangles ({need:,} bytes), "
        f"the file has {size:,} bytes",
    )


def check_ply_whole(path: Path) -> None:
    """``InputFileError`` for a text PLY with fewer lines after its header than the
    elements the header counts (one a line, as the reader takes them): cut short,
    it would read as a mesh with holes, or none. Read in blocks: counts only."""
    try:
        with path.open("rb") as file:
            if file.readline().rstrip() != b"ply":
                return  # the reader says what it is not
            counts: list[tuple[str, int]] = []
            text = False
            for line in iter(file.readline, b""):
                words = line.split()
                if words[:1] == [b"format"]:
                    text = words[1:2] == [b"ascii"]
                elif words[:1] == [b"element"] and len(words) == 3 and words[2].isdigit():
                    counts.append((words[1].decode("latin-1"), int(words[2])))
                elif words[:1] == [b"end_header"]:
                    break
            else:
                return  # no end to the header: the reader refuses it
            need = sum(count for _, count in counts)
            if not text or not need:
                return
            have, last = 0, b"\n"
            while block := file.read(2**22):  # CR LF, LF or CR alone ends a line
                have += max(block.count(b"\n"), block.count(b"\r"))
                last = block[-1:]
            have += last not in (b"\n", b"\r")  # a last line without its end
    except OSError as error:
        raise InputFileError(path, f"cannot be read ({error.strerror or error})") from None
    if have < need:
        named = " and ".join(f"{count:,} {one_line(name)}" for name, count in counts if count)
        raise InputFileError(
            path,
            f"a text PLY cut short: its header counts {named} elements "
            f"(a line each, {need:,} lines), the file has {have:,} after its header",
        )


def check_obj_lines(path: Path, text: str) -> str:
    """``InputFileError`` at the first vertex or face line of an OBJ file's ``text`` that
    is malformed: a vertex without three finite numbers, a face whose vertex numbers
    are not integers or lie outside the file's vertices (1..V, or -1..-V counting
    back from the latest). Called before the mesh reader, which reads past such
    lines (a nan vertex's faces dropped, index 0 taken) or fails naming none.

    Returns the text for the reader: as it is, or with each face of more than three
    corners that a fan from its first corner would not cover (a concave one) cut
    into triangles inside it (the reader fans every face)."""
    lines = text_lines(text)
    records = ("v ", "v\t", "f ", "f\t")

    def record(line: str) -> str:
        """'v', 'f' or '' (another record); the common case without splitting the line."""
        if line[:2] in records:
            return line[0]
        if line[:1] in (" ", "\t"):  # indented
            first = line.split(maxsplit=1)[:1]
            return first[0] if first in (["v"], ["f"]) else ""
        return ""

    total = sum(1 for line in lines if record(line) == "v")
    seen = 0
    points = array("d")  # every vertex's x, y, z
    # faces of n > 3 corners, by n: their line indices, their vertex indices in a row
    polygons: dict[int, tuple[array, array]] = {}
    isfinite = math.isfinite
    for number, line in enumerate(lines, 1):
        if not record(line):
            continue
        words = line.split()
        shown = partial(_shown_line, words)  # made only for a message: millions of lines pass
        if words[0] == "v":
            seen += 1
            try:
                xyz = [float(w) for w in words[1:4]]
            except ValueError:
                raise InputFileError(
                    path, f"vertex '{shown()}': expected x, y, z as numbers", number
                ) from None
            if len(xyz) < 3:
                raise InputFileError(path, f"vertex '{shown()}': expected x, y, z", number)
            if not (isfinite(xyz[0]) and isfinite(xyz[1]) and isfinite(xyz[2])):
                raise InputFileError(path, f"vertex '{shown()}': expected x, y, z as finite numbers", number)
            points.extend(xyz[:3])
            continue
        corners = []
        for word in words[1:]:
            try:
                index = int(word.split("/", 1)[0])
            except ValueError:
                raise InputFileError(path, f"face '{shown()}': expected vertex numbers", number) from None
            if not (1 <= index <= total or -seen <= index <= -1):
                if not total:  # no vertex at all: no range to name
                    expected = "vertices ('v x y z') in the file; it has none"
                else:
                    expected = f"1 to {total}" + (f" (or -1 to -{seen})" if seen else "")
                raise InputFileError(
                    path, f"face '{shown()}' refers to vertex {index}: expected {expected}", number
                )
            corners.append(index - 1 if index > 0 else seen + index)
        if len(corners) > 3:
            at, indices = polygons.setdefault(len(corners), (array("q"), array("q")))
            at.append(number - 1)
            indices.extend(corners)
    cut = False
    vertices = np.asarray(points).reshape(-1, 3)
    for n, (at, indices) in polygons.items():
        for k, order in concave_cuts(vertices, np.asarray(indices).reshape(-1, n)).items():
            words = lines[at[k]].split()[1:]
            lines[at[k]] = "\n".join("f " + " ".join(words[c] for c in triangle) for triangle in order)
            cut = True
    return "\n".join(lines) + "\n" if cut else text


def _shown_line(words: list[str]) -> str:
    return one_line(" ".join(words))[:80]
