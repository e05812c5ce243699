"""Exact mesh voxelisation (``ladartui.scene.voxelize``): boxes, spheres, the boundary rule, turns."""

import math
import threading
from pathlib import Path

import numpy as np
import pytest
import trimesh

from ladartui.errors import Cancelled, FieldError, InputFileError, ResourceLimitError
from ladartui.scene import voxelize_kernels as kernels
from ladartui.scene.voxelize import Mesh, Placement, load_mesh, voxelize


def as_mesh(shape: trimesh.Trimesh) -> Mesh:
    return Mesh(Path("made.obj"), np.asarray(shape.vertices, float), np.asarray(shape.faces), True, "")


def voxel_set(voxels) -> set:
    return {tuple(int(v) for v in row) for row in voxels}


def block(xs, ys, zs) -> set:
    return {(x, y, z) for x in xs for y in ys for z in zs}


def test_box_on_voxel_boundaries_gives_exactly_its_voxels():
    box = as_mesh(trimesh.creation.box(extents=(3, 4, 5)))  # starts at voxel (0, 0, 0)'s corner
    solid = voxelize(box, 1.0, solid=True)
    assert voxel_set(solid.voxels) == block(range(3), range(4), range(5))
    assert solid.inside == 60  # every centre is strictly inside
    surface = voxelize(box, 1.0)
    # Faces on boundaries belong to the voxels inside them: the outer layer, not the centre.
    assert voxel_set(surface.voxels) == block(range(3), range(4), range(5)) - block([1], [1, 2], [1, 2, 3])
    assert surface.surface == len(surface.voxels) == 54 and surface.inside == 0


def test_box_faces_through_voxel_centres_set_the_voxels_they_cut():
    # A 2 m cube centred on (5, 5) with its base 0.5 above the ground: every face
    # passes through a layer of voxel centres, so those voxels are cut in half.
    cube = as_mesh(trimesh.creation.box(extents=(2, 2, 2)))
    solid = voxelize(cube, 1.0, Placement(5.0, 5.0, 0.5), solid=True)
    assert voxel_set(solid.voxels) == block([4, 5, 6], [4, 5, 6], [0, 1, 2])
    surface = voxelize(cube, 1.0, Placement(5.0, 5.0, 0.5))
    assert voxel_set(surface.voxels) == block([4, 5, 6], [4, 5, 6], [0, 1, 2]) - {(5, 5, 1)}


def square(z: float, up: bool) -> Mesh:
    """An open 3 x 3 square on the plane z, its normal up (+z) or down."""
    vertices = np.array([[-0.5, -0.5, z], [2.5, -0.5, z], [2.5, 2.5, z], [-0.5, 2.5, z]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    return Mesh(Path("square.obj"), vertices, faces if up else faces[:, ::-1], False, "holes")


def test_a_face_on_a_boundary_belongs_to_the_voxel_behind_it():
    # 2 m above the ground (z = -0.5) is the boundary between layers 1 and 2.
    up = voxelize(square(0.0, up=True), 1.0, Placement(1.0, 1.0, 2.0))
    assert voxel_set(up.voxels) == block(range(3), range(3), [1])  # the normal points away from it
    down = voxelize(square(0.0, up=False), 1.0, Placement(1.0, 1.0, 2.0))
    assert voxel_set(down.voxels) == block(range(3), range(3), [2])
    # Off the boundary the winding does not matter: the plane cuts layer 1.
    for up_or_down in (True, False):
        cut = voxelize(square(0.0, up=up_or_down), 1.0, Placement(1.0, 1.0, 1.8))
        assert voxel_set(cut.voxels) == block(range(3), range(3), [1])


def test_touching_an_edge_or_a_corner_sets_nothing():
    tri = np.zeros((3, 3))
    for corner in (
        [[1.5, 1.5, 1.5], [3.0, 1.5, 3.0], [1.5, 3.0, 3.0]],  # only the corner (1.5, 1.5, 1.5) of voxel 1
        [[1.5, 1.5, 0.0], [1.5, 1.5, 3.0], [3.0, 3.0, 1.0]],  # along the edge x = y = 1.5
    ):
        tri[:] = corner
        assert not kernels.triangle_meets_voxel(tri, 1.0, 1.0, 1.0)
        assert kernels.triangle_meets_voxel(tri, 2.0, 2.0, 2.0)


def clipped_area(tri: np.ndarray, centre) -> float:
    """Area of the triangle clipped to the closed cube at ``centre`` (Sutherland-Hodgman)."""
    polygon = [p - np.asarray(centre, float) for p in tri]
    for axis in range(3):
        for sign in (1.0, -1.0):
            kept = []
            for a, b in zip(polygon, polygon[1:] + polygon[:1]):
                da, db = 0.5 - sign * a[axis], 0.5 - sign * b[axis]
                if da >= 0:
                    kept.append(a)
                if (da >= 0) != (db >= 0):
                    kept.append(a + (b - a) * (da / (da - db)))
            polygon = kept
            if not polygon:
                return 0.0
    area = np.zeros(3)
    for a, b in zip(polygon, polygon[1:] + polygon[:1]):
        area += np.cross(a, b)
    return float(np.linalg.norm(area)) / 2


def test_surface_voxels_agree_with_clipping_on_random_triangles():
    rng = np.random.default_rng(7)
    triangles = rng.uniform(0.3, 5.7, size=(80, 3, 3))
    for tri in triangles:
        grid = np.zeros((7, 7, 7), dtype=np.uint8)
        kernels.mark_surface(tri[None], 0, 1, grid)
        expected = np.zeros_like(grid)
        for i, j, k in np.ndindex(grid.shape):
            expected[i, j, k] = clipped_area(tri, (i, j, k)) > 1e-12
        np.testing.assert_array_equal(grid, expected)


@pytest.mark.parametrize("radius", [20.0, 50.0])
def test_sphere_solid_count_follows_its_volume(radius):
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=radius)
    result = voxelize(as_mesh(sphere), 1.0, Placement(radius + 5, radius + 5, 0.0), solid=True)
    volume = sphere.volume
    # Centres inside sample the volume: within a fraction of a per cent.
    assert abs(result.inside - volume) / volume < 0.005
    # Every voxel the surface touches is set too, so the model is the sphere grown by
    # half a voxel around: its volume with a unit cube added (Steiner), V + 3 pi R^2 + 6 R + 1.
    grown = volume + 3 * math.pi * radius**2 + 6 * radius + 1
    assert abs(len(result.voxels) - grown) / grown < 0.01
    assert len(result.voxels) - result.surface <= volume <= len(result.voxels)
    assert len(np.unique(result.voxels, axis=0)) == len(result.voxels)
    # The half-voxel shell is 9 / (4 R) of the volume: within a few per cent from R = 50 voxels.
    assert abs(len(result.voxels) - volume) / volume < (0.05 if radius >= 50 else 0.13)


def test_inside_centres_of_a_random_convex_mesh_match_its_face_planes():
    # A turned ellipsoid-like polyhedron at a random offset: convex, with no face or
    # edge on a voxel boundary or centre to make ties.
    hull = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    hull.apply_scale([6.3, 4.1, 3.2])
    hull.apply_transform(trimesh.transformations.random_rotation_matrix(np.random.default_rng(3).random(3)))
    hull.apply_translation([0.137, 0.291, 0.417])
    mesh = Mesh(Path("hull.stl"), np.asarray(hull.vertices), np.asarray(hull.faces), True, "")
    result = voxelize(mesh, 1.0, solid=True)
    triangles = np.asarray(hull.vertices)[np.asarray(hull.faces)]
    placed = triangles - triangles.reshape(-1, 3).min(axis=0) - 0.5  # no placement: corner at -0.5
    normals = np.cross(placed[:, 1] - placed[:, 0], placed[:, 2] - placed[:, 0])
    offsets = np.einsum("ij,ij->i", normals, placed[:, 0])
    low = np.floor(placed.reshape(-1, 3).min(axis=0)).astype(int)
    high = np.ceil(placed.reshape(-1, 3).max(axis=0)).astype(int)
    centres = np.stack(
        np.meshgrid(*(np.arange(a, b + 1) for a, b in zip(low, high)), indexing="ij"), axis=-1
    ).reshape(-1, 3)
    inside = np.all(centres @ normals.T < offsets, axis=1)
    assert result.inside == int(np.count_nonzero(inside)) > 100
    assert voxel_set(centres[inside]) <= voxel_set(result.voxels)


@pytest.mark.parametrize("heading", [0.0, 90.0, 180.0, 270.0, -90.0])
def test_quarter_turns_are_exact(heading):
    truck = as_mesh(trimesh.creation.box(extents=(2.0, 4.0, 1.5)))
    result = voxelize(truck, 0.1, Placement(5.05, 5.05, 0.0, heading), solid=True)
    # faces on voxel boundaries whichever way it faces: exactly 20 x 40 x 15 voxels
    assert len(result.voxels) == 20 * 40 * 15
    spans = result.voxels.max(axis=0) - result.voxels.min(axis=0) + 1
    along = (20, 40) if heading % 180 == 0 else (40, 20)
    assert tuple(spans) == (*along, 15)


def columns_meeting_rectangle(centre, half_forward, half_right, heading, size=100) -> set:
    """Voxel columns whose interior meets a turned rectangle's: separating axes in the plane."""
    turn = math.radians(heading)
    forward, right = np.array([math.sin(turn), math.cos(turn)]), np.array([math.cos(turn), -math.sin(turn)])
    i, j = np.meshgrid(np.arange(size), np.arange(size), indexing="ij")
    offset = np.stack([i - centre[0], j - centre[1]], axis=-1)
    meets = np.ones(i.shape, dtype=bool)
    for axis, half in ((forward, half_forward), (right, half_right)):
        meets &= np.abs(offset @ axis) < half + 0.5 * (abs(axis[0]) + abs(axis[1]))
    for k in range(2):
        meets &= np.abs(offset[..., k]) < half_forward * abs(forward[k]) + half_right * abs(right[k]) + 0.5
    return {(int(a), int(b)) for a, b in zip(*np.nonzero(meets))}


@pytest.mark.parametrize("heading", [17.0, 30.0, 45.0, 123.4])
def test_turned_box_gives_exactly_the_voxels_it_meets(heading):
    length, width, height, vs = 4.0, 2.0, 1.5, 0.1
    truck = as_mesh(trimesh.creation.box(extents=(width, length, height)))
    result = voxelize(truck, vs, Placement(5.0, 5.0, 0.0, heading), solid=True)
    columns = columns_meeting_rectangle((50, 50), 20.0, 10.0, heading)
    # Bottom and top lie on voxel boundaries: every column it meets has exactly 15 layers.
    assert voxel_set(result.voxels) == {(i, j, k) for i, j in columns for k in range(15)}
    # Within rounding of its volume: wholly inside voxels fit in it, voxels meeting it cover it.
    volume = length * width * height / vs**3
    assert len(result.voxels) - result.surface <= volume <= len(result.voxels)
    # and close to the expected count of the box grown by a voxel's reach in plan
    # (Steiner): a b + 1 + (a + b)(|cos| + |sin|) cells a layer
    a, b = length / vs, width / vs
    turn = math.radians(heading)
    grown = (a * b + 1 + (a + b) * (abs(math.cos(turn)) + abs(math.sin(turn)))) * 15
    assert abs(len(result.voxels) - grown) / grown < 0.03


def test_heading_turns_clockwise_from_north():
    # A 1 x 6 m bar along the mesh's +y (forward): heading 90 points it east.
    bar = as_mesh(trimesh.creation.box(extents=(1.0, 6.0, 1.0)))
    east = voxelize(bar, 1.0, Placement(10.0, 10.0, 0.0, 90.0))
    spans = east.voxels.max(axis=0) - east.voxels.min(axis=0) + 1
    assert tuple(spans[:2]) == (7, 1)  # 6 m east-west (end faces through centres: 7), 1 m north-south


def test_stl_precision_does_not_add_a_layer(tmp_path):
    # 0.8 m in an STL is 0.800000012 (float32): without snapping that sets an extra layer.
    path = tmp_path / "truck.stl"
    trimesh.creation.box(extents=(0.3, 0.4, 1.6)).export(path)
    result = voxelize(load_mesh(path), 0.1, solid=True)
    assert voxel_set(result.voxels) == block(range(3), range(4), range(16))


def test_up_axis_and_scale(tmp_path):
    path = tmp_path / "tall.obj"
    trimesh.creation.box(extents=(200.0, 600.0, 400.0)).export(path)  # millimetres, y up
    mesh = load_mesh(path, scale=0.001, up="y")
    spans = mesh.vertices.max(axis=0) - mesh.vertices.min(axis=0)
    np.testing.assert_allclose(spans, [0.2, 0.4, 0.6])
    assert mesh.closed
    assert len(voxelize(mesh, 0.1, solid=True).voxels) == 2 * 4 * 6


def test_inside_out_mesh_is_turned_outward(tmp_path):
    shape = trimesh.creation.box(extents=(3, 4, 5))
    shape.faces = shape.faces[:, ::-1]
    path = tmp_path / "inverted.ply"
    shape.export(path)
    mesh = load_mesh(path)
    assert mesh.closed
    assert len(voxelize(mesh, 1.0).voxels) == 54  # the boundary faces still count inward
    assert len(voxelize(mesh, 1.0, solid=True).voxels) == 60


def test_open_mesh_is_refused_in_solid_mode_only(tmp_path):
    shape = trimesh.creation.box(extents=(3, 4, 5))
    shape.faces = shape.faces[:-1]
    path = tmp_path / "open.obj"
    shape.export(path)
    mesh = load_mesh(path)
    assert not mesh.closed
    assert len(voxelize(mesh, 1.0).voxels) > 0
    with pytest.raises(InputFileError, match=r"open\.obj: not a closed mesh: 3 edges border only one"):
        voxelize(mesh, 1.0, solid=True)


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("bad.obj", "v 0 0 0\nv 1 0\nf 1 2 3\n", r"bad\.obj:2: vertex 'v 1 0': expected x, y, z"),
        ("word.obj", "v 0 0 0\nv x 1 0\n", r"word\.obj:2: vertex 'v x 1 0': expected x, y, z as numbers"),
        ("nan.obj", "v 0 0 0\nv nan 1 0\n", r"nan\.obj:2: vertex 'v nan 1 0': expected x, y, z as finite"),
        (
            "far.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
            r"far\.obj:4: face 'f 1 2 9' refers to vertex 9: expected 1 to 3 \(or -1 to -3\)",
        ),
        ("junk.obj", "v 0 0 0\nf 1 a 2\n", r"junk\.obj:2: face 'f 1 a 2': expected vertex numbers"),
        # it said 'expected 1 to 0 (or -1 to -0)'
        (
            "novertex.obj",
            "f 1 2 3\n",
            r"novertex\.obj:1: face 'f 1 2 3' refers to vertex 1: expected vertices \('v x y z'\) in ",
        ),
        # escaped once: its repr wrote 'v 0 1 \\x1b[31m'
        (
            "esc.obj",
            "v 0 0 0\nv 0 1 \x1b[31m\n",
            r"esc\.obj:2: vertex 'v 0 1 \\x1b\[31m': expected x, y, z as numbers$",
        ),
        ("noise.ply", "\x00\x07 definitely not a ply header", "not a readable PLY mesh"),
        ("empty.stl", "", "holds no triangles"),
        ("points.obj", "v 0 0 0\nv 1 0 0\n", "holds no triangles"),
        ("model.dae", "<xml/>", "unsupported mesh type '.dae'"),
    ],
)
def test_malformed_meshes_name_the_file(tmp_path, name, content, message):
    path = tmp_path / name
    path.write_text(content)
    with pytest.raises(InputFileError, match=message) as caught:
        load_mesh(path)
    assert str(caught.value).startswith(str(path))
    assert "\n" not in str(caught.value)


def test_voxelize_given_a_path_asks_for_a_loaded_mesh(tmp_path):
    # A mesh file's path raised AttributeError ('str' object has no attribute 'vertices').
    with pytest.raises(FieldError) as caught:
        voxelize(str(tmp_path / "truck.stl"), 0.1)
    assert caught.value.field == "mesh"
    assert str(caught.value).endswith("expected a Mesh, as load_mesh(path) reads it")


def test_a_folder_is_not_a_mesh(tmp_path):
    with pytest.raises(InputFileError) as caught:
        load_mesh(tmp_path)
    assert str(caught.value) == f"{tmp_path}: is a folder; expected a mesh file (.obj, .stl or .ply)"


def test_placement_below_ground_or_off_the_grid_is_refused():
    cube = as_mesh(trimesh.creation.box(extents=(2, 2, 2)))
    with pytest.raises(FieldError, match="reaches x = -0.600 m"):
        voxelize(cube, 1.0, Placement(0.4, 5.0))
    with pytest.raises(FieldError, match="above the ground"):
        voxelize(cube, 1.0, Placement(5.0, 5.0, -0.1))
    assert len(voxelize(cube, 1.0, Placement(0.5, 0.5, 0.0), solid=True).voxels) == 8  # on the edge


def test_too_fine_a_voxel_size_is_refused_up_front(monkeypatch):
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(2**20))
    sphere = as_mesh(trimesh.creation.icosphere(subdivisions=2, radius=1.0))
    with pytest.raises(ResourceLimitError, match=r"voxel size 0.01 m makes a 201 x 201 x 201 voxel box"):
        voxelize(sphere, 0.01, solid=True)


def test_a_mesh_in_millimetres_too_large_for_the_memory_is_named_by_its_span(monkeypatch):
    """A CAD model in mm read as metres was refused with 'use a larger --voxel-size' alone."""
    monkeypatch.setenv("LADARTUI_MAX_MEMORY", str(2**30))
    truck = as_mesh(trimesh.creation.box(extents=(2500.0, 5000.0, 2200.0)))
    with pytest.raises(ResourceLimitError) as caught:
        voxelize(truck, 0.1)
    assert str(caught.value).startswith(
        "made.obj: the mesh spans 2500 x 5000 x 2200 m; voxel size 0.1 m makes "
    )
    assert str(caught.value).endswith(
        "check its units (--scale 0.001 for millimetres) or use a larger --voxel-size"
    )


def test_progress_and_cancel():
    sphere = as_mesh(trimesh.creation.icosphere(subdivisions=5, radius=10.0))  # 20,480 triangles
    seen = []
    voxelize(sphere, 1.0, solid=True, progress=lambda *report: seen.append(report))
    stages = [stage for stage, _, _ in seen]
    assert stages == sorted(stages, key=["surface", "inside", "filling", "collecting"].index)
    assert ("surface", 20480, 20480) in seen and ("inside", 20480, 20480) in seen
    assert seen[-1][0] == "collecting" and seen[-1][1] == seen[-1][2] == 21  # x slabs of the grid
    cancel = threading.Event()

    def stop_at(stage):
        def report(name, done, total):
            if name == stage:
                cancel.set()

        return report

    for stage in ("surface", "inside", "filling"):
        cancel.clear()
        with pytest.raises(Cancelled, match="nothing was written"):
            voxelize(sphere, 1.0, solid=True, progress=stop_at(stage), cancel=cancel)


def test_a_mesh_setting_no_voxel_is_refused():
    flat = square(0.0, up=True)  # on the ground plane, its normal up: the voxel behind is below ground
    with pytest.raises(InputFileError, match=r"square\.obj: sets no voxels at 1 m"):
        voxelize(flat, 1.0)
    assert len(voxelize(flat, 1.0, Placement(1.0, 1.0, 0.3)).voxels) == 9  # lifted into layer 0


def test_reader_warnings_become_notes_not_stderr(capsys):
    import logging

    from ladartui.scene.voxelize import _trimesh_notes

    with _trimesh_notes() as notes:
        logging.getLogger("trimesh.exchange.ply").warning("unable to load image!")
    assert notes == ["unable to load image!"]
    assert capsys.readouterr().err == ""
    assert not logging.getLogger("trimesh").handlers


def test_work_is_split_by_voxel_tests_for_progress_and_cancel(monkeypatch):
    from ladartui.scene import voxelize as module

    monkeypatch.setattr(module, "_CHUNK_TESTS", 100)
    monkeypatch.setattr(module, "_CHUNK_TRIANGLES", 4)
    tests = np.array([10, 10, 500, 10, 10, 10, 10, 10, 10, 10, 10, 10], dtype=float)
    # the big triangle alone; at most 4 triangles a call otherwise
    assert module._chunk_bounds(tests) == [0, 2, 3, 7, 11, 12]


def test_rounding_at_the_scene_edge_is_not_a_refusal():
    # (1.05 - 1.1) / 0.1 is -0.5000000000000004: the west face is on the edge, not past it.
    slab = as_mesh(trimesh.creation.box(extents=(2.2, 0.6, 0.6)))
    result = voxelize(slab, 0.1, Placement(1.05, 1.05, 0.0), solid=True)
    assert voxel_set(result.voxels) == block(range(22), range(8, 14), range(6))


def test_stray_vertices_do_not_move_the_mesh():
    box = trimesh.creation.box(extents=(3, 4, 5))
    vertices = np.vstack([box.vertices, [[-40.0, -40.0, -40.0]]])  # in no triangle
    mesh = Mesh(Path("stray.obj"), vertices, np.asarray(box.faces), True, "")
    assert voxel_set(voxelize(mesh, 1.0, solid=True).voxels) == block(range(3), range(4), range(5))


def test_voxelize_modules_do_not_import_textual():
    import subprocess
    import sys

    probe = (
        "import sys\n"
        "import ladartui.scene.voxelize, ladartui.scene.voxelize_kernels, ladartui.scene.insertion\n"
        "import ladartui.cli.voxelize\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] == 'textual'))\n"
    )
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


TRIANGLE_STL = (
    b"facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\n"
)


def test_a_text_mesh_in_latin_1_is_read(tmp_path):
    """CAD exporters write names in Latin-1: such an ASCII STL was refused with
    'ModuleNotFoundError: No module named charset_normalizer'."""
    stl = tmp_path / "caf\u00e9.stl"
    stl.write_bytes(b"solid caf\xe9\n" + TRIANGLE_STL + b"endsolid caf\xe9\n")
    assert load_mesh(stl).faces.shape == (1, 3)
    obj = tmp_path / "tri.obj"
    obj.write_bytes(b"# modell \xfcber alles\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert load_mesh(obj).faces.shape == (1, 3)
    noise = tmp_path / "noise.stl"
    noise.write_bytes(bytes(range(256)) * 3)
    with pytest.raises(InputFileError) as caught:
        load_mesh(noise)
    assert "module" not in str(caught.value).lower()


@pytest.mark.parametrize("header", [b"solid exported by CAD", b"binary"])
def test_a_binary_stl_cut_short_says_so(tmp_path, header):
    """A binary STL whose header begins 'solid' and which was cut short was read as text:
    'holds no triangles'."""
    whole = tmp_path / "whole.stl"
    trimesh.creation.box(extents=(1.0, 2.0, 3.0)).export(whole)
    data = header.ljust(80, b" ") + whole.read_bytes()[80:]
    cut = tmp_path / "cut.stl"
    for size in (84 + 50 * 5 + 20, 84):  # cut inside the triangles, or right after the header
        cut.write_bytes(data[:size])
        with pytest.raises(InputFileError) as caught:
            load_mesh(cut)
        assert str(caught.value) == (
            f"{cut}: a binary STL cut short: its header counts 12 triangles (684 bytes), "
            f"the file has {size} bytes"
        )


@pytest.mark.parametrize("header", [b"solid exported by CAD", b"binary"])
@pytest.mark.parametrize("extra", [1, 20, 50])
def test_a_binary_stl_longer_than_its_header_says_so(tmp_path, header, extra):
    """Bytes past a binary STL's triangles made it read as text: 'holds no triangles'."""
    whole = tmp_path / "whole.stl"
    trimesh.creation.box(extents=(1.0, 2.0, 3.0)).export(whole)
    long = tmp_path / "long.stl"
    long.write_bytes(header.ljust(80, b" ") + whole.read_bytes()[80:] + b"\0" * extra)
    with pytest.raises(InputFileError) as caught:
        load_mesh(long)
    assert str(caught.value) == (
        f"{long}: a binary STL longer than its header says: its header counts 12 triangles "
        f"(684 bytes), the file has {684 + extra} bytes"
    )


CUBE_OBJ = "".join(f"v {x} {y} {z}\n" for x in (0, 1) for y in (0, 1) for z in (0, 1)) + "".join(
    f"f {a} {b} {c}\n"
    for a, b, c in [
        (1, 3, 2), (2, 3, 4), (5, 6, 7), (6, 8, 7), (1, 2, 5), (2, 6, 5),
        (3, 7, 4), (4, 7, 8), (1, 5, 3), (3, 5, 7), (2, 4, 6), (4, 8, 6),
    ]
)  # fmt: skip


@pytest.mark.parametrize(
    ("change", "said"),
    [
        (("v 0 0 1\n", "v nan 0 1\n"), ":2: vertex 'v nan 0 1': expected x, y, z as finite numbers"),
        (("f 1 3 2\n", "f 0 3 2\n"), ":9: face 'f 0 3 2' refers to vertex 0: expected 1 to 8"),
        (("v 0 0 1\n", "v 0 0\n"), ":2: vertex 'v 0 0': expected x, y, z"),
    ],
)
def test_a_bad_obj_line_is_named_even_where_the_reader_gets_past_it(tmp_path, change, said):
    """A nan vertex lost its faces without a word, a face index 0 was taken, and a
    vertex of two numbers ended in 'cannot reshape array' (the reader read on)."""
    path = tmp_path / "cube.obj"
    assert change[0] in CUBE_OBJ
    path.write_text(CUBE_OBJ.replace(change[0], change[1], 1))
    with pytest.raises(InputFileError) as caught:
        load_mesh(path)
    assert str(caught.value).startswith(f"{path}{said}")


@pytest.mark.parametrize("name", [b"caf\xe9 \x85 2", "dune\u2028buggy".encode()])
def test_a_bad_obj_line_is_named_on_its_own_line_after_a_name_holding_a_line_break_character(tmp_path, name):
    """An object name in Latin-1 ('...' is byte 0x85 in Windows' code page, a line
    break once read) or holding U+2028 counted as two lines: every line below was
    named one too far on."""
    path = tmp_path / "cube.obj"
    path.write_bytes(b"o " + name + b"\n" + CUBE_OBJ.replace("f 1 3 2\n", "f 0 3 2\n", 1).encode())
    with pytest.raises(InputFileError) as caught:
        load_mesh(path)
    assert str(caught.value).startswith(f"{path}:10: face 'f 0 3 2' refers to vertex 0")


def test_an_obj_saved_with_a_byte_order_mark_is_read_whole(tmp_path):
    """Saved with a UTF-8 byte order mark (as Windows editors may), the mark hid the
    first vertex: "face 'f 6 8 7' refers to vertex 8: expected 1 to 7"."""
    path = tmp_path / "cube.obj"
    path.write_text(CUBE_OBJ, encoding="utf-8-sig")
    mesh = load_mesh(path)
    assert mesh.faces.shape == (12, 3) and mesh.closed
    assert sorted(map(tuple, mesh.vertices.tolist())) == [
        (x, y, z) for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)
    ]


def test_a_good_obj_cube_is_read_whole(tmp_path):
    path = tmp_path / "cube.obj"
    path.write_text(CUBE_OBJ)
    mesh = load_mesh(path)
    assert mesh.faces.shape == (12, 3) and mesh.closed


def count_opens(monkeypatch, path: Path) -> list[str]:
    """Every opening of ``path`` (by pathlib or by trimesh), its mode each."""
    import builtins
    import io

    opened: list[str] = []
    real_open = io.open

    def spy(file, mode="r", *args, **kwargs):
        if isinstance(file, (str, Path)) and Path(file).resolve() == path.resolve():
            opened.append(mode)
        return real_open(file, mode, *args, **kwargs)

    monkeypatch.setattr(io, "open", spy)
    monkeypatch.setattr(builtins, "open", spy)
    return opened


@pytest.mark.parametrize(
    ("name", "content", "triangles"),
    [
        ("cube.obj", CUBE_OBJ.encode(), 12),
        ("cube.obj", b"# modell \xfcber alles\n" + CUBE_OBJ.encode(), 12),  # Latin-1
        ("tri.stl", b"solid tri\n" + TRIANGLE_STL + b"endsolid tri\n", 1),
        ("box.stl", trimesh.creation.box(extents=(1.0, 2.0, 3.0)).export(file_type="stl"), 12),
    ],
)
def test_a_mesh_file_is_read_from_disk_once(tmp_path, monkeypatch, name, content, triangles):
    """An OBJ was opened three times (its line check, the encoding check, the mesh
    reader), an STL four (its header twice, then as text, then by the reader): one
    read now serves the checks and the reader."""
    path = tmp_path / name
    path.write_bytes(content)
    opened = count_opens(monkeypatch, path)
    assert len(load_mesh(path).faces) == triangles
    assert opened == ["rb"]


def test_a_textured_obj_read_from_memory_is_the_mesh_read_from_its_path(tmp_path):
    """Handed over as bytes, a textured OBJ with its material file beside it gives the
    vertices (merged by position across texture seams) that trimesh gives opening
    the file itself."""
    folder = tmp_path / "model"
    folder.mkdir()
    (folder / "cube.mtl").write_text("newmtl paint\nKd 0.8 0.1 0.1\n")
    uvs = "".join(f"vt {u} {v}\n" for u in (0, 1) for v in (0, 1))
    faces = "".join(
        f"f {line.split()[1]}/1 {line.split()[2]}/2 {line.split()[3]}/3\n"
        for line in CUBE_OBJ.splitlines()
        if line.startswith("f ")
    )
    vertices = "".join(line + "\n" for line in CUBE_OBJ.splitlines() if line.startswith("v "))
    path = folder / "cube.obj"
    path.write_text(f"mtllib cube.mtl\n{vertices}{uvs}usemtl paint\n{faces}")
    mesh = load_mesh(path)
    expected = trimesh.load(str(path), force="mesh", process=False).process(merge_tex=True, merge_norm=True)
    np.testing.assert_array_equal(mesh.vertices, expected.vertices)
    assert mesh.closed and bool(expected.is_watertight) and mesh.notes == ()
