"""A mesh file holding a vertex that is not a finite number is refused, whatever its
format: the reader would drop the triangles using it and voxelise what was left."""

import numpy as np
import pytest
import trimesh

from ladartui.errors import InputFileError
from ladartui.scene.voxelize import load_mesh


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize(
    ("name", "options"), [("box.stl", {}), ("box.ply", {}), ("text.ply", {"encoding": "ascii"})]
)
def test_a_vertex_not_finite_is_refused_not_dropped(tmp_path, name, options, bad):
    """Such a box was read as 'not closed', with fewer triangles, and voxelised."""
    box = trimesh.creation.box(extents=(2.0, 2.0, 2.0))
    vertices = box.vertices.copy()
    vertices[0, 0] = bad
    path = tmp_path / name
    with np.errstate(invalid="ignore"):  # the STL writer's face normals of that corner
        trimesh.Trimesh(vertices, box.faces, process=False).export(path, **options)
    with pytest.raises(InputFileError) as caught:
        load_mesh(path)
    uses = int(np.count_nonzero((box.faces == 0).any(axis=1)))
    assert (
        str(caught.value) == f"{path}: {uses} triangles use a vertex whose coordinates are not finite numbers"
    )


def test_a_stray_vertex_not_finite_is_refused(tmp_path):
    path = tmp_path / "stray.ply"
    box = trimesh.creation.box(extents=(2.0, 2.0, 2.0))
    vertices = np.vstack([box.vertices, [[np.nan, 0.0, 0.0]]])
    trimesh.Trimesh(vertices, box.faces, process=False).export(path, encoding="ascii")
    with pytest.raises(InputFileError) as caught:
        load_mesh(path)
    assert str(caught.value) == f"{path}: 1 vertex has coordinates that are not finite numbers"


def test_a_finite_box_in_each_format_is_read_whole(tmp_path):
    box = trimesh.creation.box(extents=(2.0, 2.0, 2.0))
    for name in ("box.stl", "box.ply", "box.obj"):
        box.export(tmp_path / name)
        mesh = load_mesh(tmp_path / name)
        assert (len(mesh.vertices), len(mesh.faces), mesh.closed) == (8, 12, True)
