"""A text PLY cut short (a copy or download stopped) is refused naming what its
header counts, not read as a mesh with holes."""

import pytest
import trimesh

from ladartui.errors import InputFileError
from ladartui.scene.voxelize import load_mesh


def box_ply(tmp_path) -> bytes:
    path = tmp_path / "whole.ply"
    trimesh.creation.box(extents=(1.0, 2.0, 3.0)).export(path, encoding="ascii")
    data = path.read_bytes()
    assert b"format ascii" in data and b"element vertex 8\n" in data and b"element face 12\n" in data
    return data


@pytest.mark.parametrize("lines_left", [1, 3, 11, 19])
def test_a_text_ply_cut_short_says_so(tmp_path, lines_left):
    """Three face lines missing read as '9 triangles, not closed' (and --solid
    refused for holes); the vertices cut short, as 'holds no triangles'."""
    data = box_ply(tmp_path)
    header, body = data.split(b"end_header\n")
    assert len(body.splitlines()) == 20
    cut = tmp_path / "cut.ply"
    cut.write_bytes(header + b"end_header\n" + b"".join(body.splitlines(keepends=True)[:lines_left]))
    with pytest.raises(InputFileError) as caught:
        load_mesh(cut)
    assert str(caught.value) == (
        f"{cut}: a text PLY cut short: its header counts 8 vertex and 12 face elements "
        f"(a line each, 20 lines), the file has {lines_left} after its header"
    )


@pytest.mark.parametrize("ending", [b"\n", b"\r\n"])
def test_a_whole_text_ply_is_read_whatever_its_line_ends(tmp_path, ending):
    data = box_ply(tmp_path).replace(b"\n", ending)
    for tail in (b"", ending):  # its last line ended or not, a blank line after it
        path = tmp_path / "box.ply"
        path.write_bytes(data.rstrip() + tail)
        mesh = load_mesh(path)
        assert (mesh.closed, len(mesh.faces)) == (True, 12)
