"""Closedness and voxels of meshes whose files keep a vertex apart per texture
coordinate, normal, material or object: only the geometry counts."""

import pytest
import trimesh

from ladartui.errors import InputFileError
from ladartui.scene.voxelize import load_mesh, voxelize

# A 2 m cube: its 8 corners and 12 outward-wound triangles.
CORNERS = [(x, y, z) for x in (0, 2) for y in (0, 2) for z in (0, 2)]
TRIANGLES = [
    (1, 3, 2), (2, 3, 4), (5, 6, 7), (6, 8, 7), (1, 2, 5), (2, 6, 5),
    (3, 7, 4), (4, 7, 8), (1, 5, 3), (3, 5, 7), (2, 4, 6), (4, 8, 6),
]  # fmt: skip
STYLES = ("plain", "vt", "vn", "vt/vn", "materials", "objects")


def cube_obj(style: str, triangles=TRIANGLES) -> str:
    """The cube as OBJ text: "vt" gives each triangle corner its own texture
    coordinate, "vn" each triangle its own normal, "materials" and "objects" put
    half the triangles in a second material or object."""
    lines = [f"v {x} {y} {z}" for x, y, z in CORNERS]
    if style == "materials":
        lines.insert(0, "mtllib paint.mtl")
    if "vt" in style or style == "objects":
        lines += [f"vt {n / 36:.4f} {(n % 6) / 6:.4f}" for n in range(36)]
    if "vn" in style or style == "objects":
        lines += ["vn 0 0 1", "vn 0 0 -1"]
    for t, corners in enumerate(triangles):
        if t in (0, len(triangles) // 2):
            lines += {"materials": [f"usemtl paint{t}"], "objects": [f"o part{t}"]}.get(style, [])
        words = []
        for k, v in enumerate(corners):
            uv, normal = 3 * t + k + 1, t % 2 + 1
            words.append(
                {"vt": f"{v}/{uv}", "vn": f"{v}//{normal}", "vt/vn": f"{v}/{uv}/{normal}"}.get(
                    style, f"{v}/{uv}/{normal}" if style == "objects" else f"{v}"
                )
            )
        lines.append("f " + " ".join(words))
    return "\n".join(lines) + "\n"


def write_cube(folder, style: str, triangles=TRIANGLES):
    (folder / "paint.mtl").write_text("newmtl paint0\nKd 1 0 0\nnewmtl paint6\nKd 0 0 1\n")
    path = folder / f"cube_{style.replace('/', '_')}.obj"
    path.write_text(cube_obj(style, triangles))
    return path


def voxel_set(result) -> set:
    return {tuple(int(v) for v in row) for row in result.voxels}


@pytest.mark.parametrize("style", STYLES)
def test_a_closed_cube_is_closed_whatever_its_file_keeps_per_corner(tmp_path, style):
    """A cube with per-corner texture coordinates was '36 edges border only one
    triangle (holes)' and refused in solid mode; one in two materials, 16 edges."""
    mesh = load_mesh(write_cube(tmp_path, style))
    assert (mesh.closed, mesh.problem) == (True, "")
    assert len(mesh.vertices) == 8 and len(mesh.faces) == 12
    solid = voxelize(mesh, 0.5, solid=True)
    assert voxel_set(solid) == {(x, y, z) for x in range(4) for y in range(4) for z in range(4)}
    assert (solid.surface, solid.inside) == (56, 64)  # every centre is inside
    plain = load_mesh(write_cube(tmp_path, "plain"))
    assert voxel_set(voxelize(mesh, 0.5)) == voxel_set(voxelize(plain, 0.5))
    assert voxel_set(voxelize(mesh, 0.3, solid=True)) == voxel_set(voxelize(plain, 0.3, solid=True))


@pytest.mark.parametrize("style", STYLES)
def test_an_open_cube_is_refused_as_before_whatever_its_file_keeps(tmp_path, style):
    """One triangle missing: the three open edges of the plain cube (per-corner
    texture coordinates made them 33), and its surface still voxelised."""
    open_plain = load_mesh(write_cube(tmp_path, "plain", TRIANGLES[:-1]))
    mesh = load_mesh(write_cube(tmp_path, style, TRIANGLES[:-1]))
    assert not mesh.closed
    assert mesh.problem == open_plain.problem == "3 edges border only one triangle (holes)"
    with pytest.raises(InputFileError) as caught:
        voxelize(mesh, 0.5, solid=True)
    assert str(caught.value) == (
        f"{mesh.path}: not a closed mesh: 3 edges border only one triangle (holes); solid voxelisation "
        "needs a closed surface (repair the mesh, or leave out --solid for a surface model)"
    )
    assert voxel_set(voxelize(mesh, 0.5)) == voxel_set(voxelize(open_plain, 0.5))


def stl_bytes(shape: trimesh.Trimesh, file_type: str) -> bytes:
    data = shape.export(file_type=file_type)  # text for an ASCII STL
    return data.encode() if isinstance(data, str) else data


@pytest.mark.parametrize("file_type", ["stl", "stl_ascii"])
def test_an_stl_repeating_its_vertices_per_facet_is_the_same_cube(tmp_path, file_type):
    """An STL writes each triangle's three corners (36 for a cube): merged, it is
    the cube of the OBJ, closed; with a facet left out, open as the OBJ."""
    plain = load_mesh(write_cube(tmp_path, "plain"))
    box = trimesh.creation.box(extents=(2.0, 2.0, 2.0))
    path = tmp_path / "box.stl"
    path.write_bytes(stl_bytes(box, file_type))
    assert path.read_bytes().startswith(b"solid") == (file_type == "stl_ascii")
    mesh = load_mesh(path)
    assert (mesh.closed, len(mesh.vertices), len(mesh.faces)) == (True, 8, 12)
    for solid in (False, True):
        assert voxel_set(voxelize(mesh, 0.5, solid=solid)) == voxel_set(voxelize(plain, 0.5, solid=solid))
    box.faces = box.faces[:-1]
    path.write_bytes(stl_bytes(box, file_type))
    mesh = load_mesh(path)
    assert (mesh.closed, mesh.problem) == (False, "3 edges border only one triangle (holes)")
    with pytest.raises(InputFileError, match="not a closed mesh: 3 edges border only one triangle"):
        voxelize(mesh, 0.5, solid=True)


def test_a_ply_with_texture_coordinates_per_corner_is_the_same_cube(tmp_path):
    box = trimesh.creation.box(extents=(2.0, 2.0, 2.0))
    box.unmerge_vertices()  # 36 vertices, each with its own texture coordinate
    box.visual = trimesh.visual.TextureVisuals(uv=[[n / 36, (n % 6) / 6] for n in range(36)])
    path = tmp_path / "box.ply"
    box.export(path)
    assert b"property double s" in path.read_bytes()[:400]
    mesh = load_mesh(path)
    assert (mesh.closed, len(mesh.vertices), len(mesh.faces)) == (True, 8, 12)
    plain = load_mesh(write_cube(tmp_path, "plain"))
    assert voxel_set(voxelize(mesh, 0.5, solid=True)) == voxel_set(voxelize(plain, 0.5, solid=True))


@pytest.mark.parametrize("file_type", ["stl", "stl_ascii", "obj"])
def test_collapsed_triangles_leave_a_closed_mesh_closed(tmp_path, file_type):
    """An export's collapsed triangles (two or three corners the same point: no area,
    no surface) made a closed cube '1 edges border only one triangle (holes); 2 edges
    are shared by more than two triangles' and refused it in solid mode; they are
    left out, with a note, and the cube is the cube."""
    box = trimesh.creation.box(extents=(2.0, 2.0, 2.0))
    a, b = box.faces[0][:2]
    box.faces = list(box.faces) + [[a, a, b], [b, b, b]]
    path = tmp_path / f"box.{file_type[:3]}"
    path.write_bytes(
        stl_bytes(box, file_type) if file_type != "obj" else box.export(file_type="obj").encode()
    )
    mesh = load_mesh(path)
    assert (mesh.closed, mesh.problem, len(mesh.faces)) == (True, "", 12)
    assert mesh.notes == ("left out 2 collapsed triangles (corners at the same point: no area)",)
    plain = load_mesh(write_cube(tmp_path, "plain"))
    solid = voxelize(mesh, 0.5, solid=True)
    assert voxel_set(solid) == voxel_set(voxelize(plain, 0.5, solid=True))
    assert voxel_set(voxelize(mesh, 0.5)) == voxel_set(voxelize(plain, 0.5))
