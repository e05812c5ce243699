"""Faces of more than three corners are cut into triangles inside the polygon:
a concave face (an L-shaped panel) fanned from a corner that cannot see all of
it put triangles outside it, voxels where the mesh has none."""

import struct

import numpy as np
import pytest

from ladartui.scene.ply_faces import binary_ply_triangles
from ladartui.scene.voxelize import load_mesh, voxelize

L_SHAPE = [(2, 1), (1, 1), (1, 2), (0, 2), (0, 0), (2, 0)]  # counter-clockwise, 3 m2


def l_prism_obj(start: int, texture: bool) -> str:
    """An L-shaped prism 1 m tall, its caps one six-cornered face each, listed from
    corner ``start`` (``/vt`` indices on every corner when ``texture``)."""
    corners = L_SHAPE[start:] + L_SHAPE[:start]
    n = len(corners)
    lines = [f"v {x} {y} 0" for x, y in corners] + [f"v {x} {y} 1" for x, y in corners]
    lines += ["vt 0 0"] if texture else []
    word = (lambda i: f"{i}/1") if texture else str
    lines.append("f " + " ".join(word(i + 1) for i in reversed(range(n))))  # the bottom, facing down
    lines.append("f " + " ".join(word(-n + i) for i in range(n)))  # the top, counted back
    lines += [f"f {i + 1} {(i + 1) % n + 1} {(i + 1) % n + 1 + n} {i + 1 + n}" for i in range(n)]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("start", range(6))
@pytest.mark.parametrize("texture", [False, True])
def test_a_concave_face_is_cut_inside_itself(tmp_path, start, texture):
    """Listed from (2, 1), the fan put 26 of 218 voxels in the L's empty corner."""
    path = tmp_path / "l.obj"
    path.write_text(l_prism_obj(start, texture))
    assert_l_prism(path)


def l_prism_faces(start: int) -> tuple[list[tuple[int, int, int]], list[list[int]]]:
    """The same prism's corners and faces (0-based, outward): two six-cornered caps, six quads."""
    corners = L_SHAPE[start:] + L_SHAPE[:start]
    n = len(corners)
    vertices = [(x, y, 0) for x, y in corners] + [(x, y, 1) for x, y in corners]
    faces = [list(reversed(range(n))), [n + i for i in range(n)]]
    faces += [[i, (i + 1) % n, (i + 1) % n + n, i + n] for i in range(n)]
    return vertices, faces


PLY_COUNTS = {"uchar": "B", "uint8": "B", "int": "i", "int32": "i", "uint": "I", "uint32": "I"}


def ply_bytes(
    vertices, faces, encoding: str, count: str = "uchar", extra: bool = False, comment: bool = False
) -> bytes:
    """A PLY of ``vertices`` and polygon ``faces`` (lists of their corners, counted as
    ``count``); with ``extra``, each face also has a flags byte before its list and a
    quality float after it; with ``comment``, a comment line opens the face element."""
    header = ["ply", f"format {encoding} 1.0", f"element vertex {len(vertices)}"]
    header += [f"property float {axis}" for axis in "xyz"]
    header += [f"element face {len(faces)}"] + (["comment exported by X"] if comment else [])
    header += ["property uchar flags"] if extra else []
    header += [f"property list {count} int vertex_indices"] + (["property float quality"] if extra else [])
    head = ("\n".join([*header, "end_header"]) + "\n").encode()
    if encoding == "ascii":
        rows = [" ".join(map(str, vertex)) for vertex in vertices]
        rows += [" ".join(["7"] * extra + [str(len(f)), *map(str, f)] + ["0.5"] * extra) for f in faces]
        return head + ("\n".join(rows) + "\n").encode()
    body = b"".join(struct.pack("<3f", *vertex) for vertex in vertices)
    for f in faces:
        body += b"\x07" * extra + struct.pack(f"<{PLY_COUNTS[count]}{len(f)}i", len(f), *f)
        body += struct.pack("<f", 0.5) * extra
    return head + body


def assert_l_prism(path) -> None:
    mesh = load_mesh(path)
    assert (mesh.closed, len(mesh.faces)) == (True, 20)
    solid = voxelize(mesh, 0.25, solid=True)
    voxels = {tuple(int(v) for v in row) for row in solid.voxels}
    assert not {(x, y, z) for x, y, z in voxels if x >= 4 and y >= 4}  # the L's empty corner
    assert len(voxels) == solid.inside == 192 and max(z for _, _, z in voxels) == 3  # 3 m3 of 1/64 m3


@pytest.mark.parametrize("start", range(6))
@pytest.mark.parametrize("encoding", ["ascii", "binary_little_endian"])
def test_a_concave_ply_face_is_cut_inside_itself(tmp_path, start, encoding):
    """The PLY reader fans polygons too: 218 voxels from (2, 1), 26 in the empty corner;
    a binary one, its faces lists of 6 and 4 corners, it could not read at all."""
    path = tmp_path / "l.ply"
    path.write_bytes(ply_bytes(*l_prism_faces(start), encoding))
    assert_l_prism(path)


@pytest.mark.parametrize("count", ["uchar", "uint8", "int", "int32", "uint", "uint32"])
@pytest.mark.parametrize("encoding", ["ascii", "binary_little_endian"])
def test_a_concave_ply_face_is_cut_whatever_counts_its_lists(tmp_path, count, encoding):
    path = tmp_path / "l.ply"
    path.write_bytes(ply_bytes(*l_prism_faces(0), encoding, count, extra=True))
    assert_l_prism(path)


@pytest.mark.parametrize("extra", [False, True])
@pytest.mark.parametrize("encoding", ["ascii", "binary_little_endian"])
def test_a_comment_among_the_face_properties_is_kept_apart(tmp_path, extra, encoding):
    """A comment line after ``element face`` took a property line's place when the binary
    file was rewritten: 'not a readable PLY mesh (ValueError: PLY is unexpected length!)'."""
    path = tmp_path / "l.ply"
    path.write_bytes(ply_bytes(*l_prism_faces(0), encoding, extra=extra, comment=True))
    assert_l_prism(path)
    if encoding != "ascii":
        header = binary_ply_triangles(path).split(b"end_header")[0].decode().splitlines()
        face = header[header.index("element face 20") :]
        assert face == ["element face 20", "property list uchar int vertex_indices", "comment exported by X"]


# A dart: a concave quad of 1 m2, its reflex corner (0.5, 0.5) third when listed from (0, 0)
DART = [(0, 0), (2, 0), (0.5, 0.5), (0, 2)]


@pytest.mark.parametrize("start", range(4))
@pytest.mark.parametrize("encoding", ["ascii", "binary_little_endian"])
def test_a_ply_of_concave_quads_alone_is_cut(tmp_path, start, encoding):
    """Every face a quad (one list length, read at once): a dart-shaped prism 1 m tall,
    its caps 1 m2, its sides 2 + 2 + 2 x 2.5 ** 0.5 m2 (the fan from (2, 0) or (0, 2)
    covered 2 m2 a cap, 1 m2 of it twice, where the dart is notched)."""
    corners = DART[start:] + DART[:start]
    vertices = [(x, y, 0) for x, y in corners] + [(x, y, 1) for x, y in corners]
    faces = [[3, 2, 1, 0], [4, 5, 6, 7]] + [[i, (i + 1) % 4, (i + 1) % 4 + 4, i + 4] for i in range(4)]
    path = tmp_path / "dart.ply"
    path.write_bytes(ply_bytes(vertices, faces, encoding, extra=True))
    mesh = load_mesh(path)
    assert (mesh.closed, len(mesh.faces)) == (True, 12)
    a, b, c = (mesh.vertices[mesh.faces[:, k]] for k in range(3))
    area = np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2
    assert area == pytest.approx(2 + 4 + 2 * 2.5**0.5)
