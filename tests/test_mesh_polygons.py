"""Faces of more than three corners are cut into triangles inside the polygon:
a concave face (an L-shaped panel) fanned from a corner that cannot see all of
it put triangles outside it, voxels where the mesh has none."""

import pytest

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
    mesh = load_mesh(path)
    assert (mesh.closed, len(mesh.faces)) == (True, 20)
    solid = voxelize(mesh, 0.25, solid=True)
    voxels = {tuple(int(v) for v in row) for row in solid.voxels}
    assert not {(x, y, z) for x, y, z in voxels if x >= 4 and y >= 4}  # the L's empty corner
    assert len(voxels) == solid.inside == 192 and max(z for _, _, z in voxels) == 3  # 3 m3 of 1/64 m3
