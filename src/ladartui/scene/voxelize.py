"""Target models from triangle meshes (.obj, .stl, .ply), exactly voxelised.

A mesh is read with trimesh, in metres (``scale`` converts other units) with z
up (``up="y"`` for meshes modelled y-up), and its own x and y taken as east
and north at heading 0: a vehicle modelled nose along +y faces ``heading``.

Placement (:class:`Placement`): the point under the middle of the mesh's
bounding box, at its lowest z, goes to scene position (x, y) metres at height
z above the ground (the plane at voxel z = -0.5; 0 rests the mesh on flat
ground), turned by the heading about the vertical through that point. That
is the report's relation of scene and target models: the target sits at the
same x-y location in both (table 2). Without a placement the mesh's
bounding box starts at the corner of voxel (0, 0, 0), resting on the ground.

Voxels (the rules in :mod:`ladartui.scene.voxelize_kernels`):

- surface: every voxel whose interior the surface passes through; a face
  lying exactly on a voxel boundary sets the voxel on its inner side (the
  side its normal points away from), one touching only an edge or corner
  sets nothing;
- solid (closed meshes only): the surface voxels plus every voxel whose
  centre is inside; together, exactly the voxels whose interior meets the
  solid's interior.

So a box whose faces lie on voxel boundaries gives exactly the voxels it
encloses: its outer layer in surface mode, all of them in solid mode. Grid
coordinates within ``SNAP`` (1e-4) of a voxel of a boundary or a centre are
put on it first: mesh files round (an STL holds float32).
"""

from __future__ import annotations

import codecs
import contextlib
import logging
import math
import threading
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ladartui.errors import FieldError, InputFileError, ResourceLimitError, check_cancelled
from ladartui.fileprobe import require_file
from ladartui.number_text import plural
from ladartui.scene.mesh_files import binary_stl, check_obj_lines, check_ply_whole, check_stl_whole
from ladartui.scene.ply_faces import binary_ply_triangles, cut_read_polygons
from ladartui.scene.voxel_arrays import voxel_size_field
from ladartui.scene.voxels import MAX_INDEX

MESH_SUFFIXES = (".obj", ".stl", ".ply")
CANCELLED = "voxelisation cancelled; nothing was written"
# Progress and cancel are checked between kernel calls: each call takes at most
# this many triangles, or this many (triangle, voxel) tests (a few tens of ms).
_CHUNK_TRIANGLES = 8192
_CHUNK_TESTS = 2_000_000
_WRITE_BUFFER = 64 * 2**20  # formatting a million rows: their int64 copy and text


@dataclass(frozen=True)
class Placement:
    """Where the mesh goes in the scene: metres, and degrees clockwise from north."""

    x: float
    y: float
    z: float = 0.0  # height of the mesh's lowest point above the ground
    heading: float = 0.0


@dataclass(frozen=True)
class Mesh:
    """A triangle mesh in metres, z up, with outward normals when it is closed."""

    path: Path
    vertices: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int64
    closed: bool  # watertight and consistently wound
    problem: str  # why it is not closed, in words ("" when it is)
    notes: tuple[str, ...] = ()  # what the reader warned about (textures, metadata)


@dataclass(frozen=True)
class Voxelized:
    """A voxelised mesh: sorted unique scene voxel indices."""

    voxels: np.ndarray  # (N, 3) int32
    surface: int  # how many of them the surface passes through
    inside: int  # solid mode: how many centres lie inside (0 in surface mode)
    solid: bool
    voxel_size: float


def load_mesh(path, scale: float = 1.0, up: str = "z") -> Mesh:
    """Read a mesh file; ``InputFileError`` naming the file for anything unreadable or empty."""
    path = Path(path)
    if not (scale > 0 and math.isfinite(scale)):
        raise FieldError("scale", scale, "a positive number of metres per mesh unit")
    if up not in ("y", "z"):
        raise FieldError("up", up, "'z' or 'y'")
    kind = path.suffix.lower()
    if path.is_dir():
        raise InputFileError(path, "is a folder; expected a mesh file (.obj, .stl or .ply)")
    if kind not in MESH_SUFFIXES:
        raise InputFileError(path, f"unsupported mesh type {path.suffix!r}; expected .obj, .stl or .ply")
    require_file(path, f"expected a mesh file ({kind})")
    source, resolver = _mesh_source(path, kind)
    import trimesh

    try:
        # a vertex far out (1e30) makes trimesh's merging warn of a cast: the check
        # below names the mesh's span instead
        with _trimesh_notes() as notes, warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            # Vertices merged by position alone, so that closedness is checked on the
            # shared edges: an STL repeats a vertex per triangle, an OBJ keeps one apart
            # per texture coordinate or normal, and per material or object (its parts,
            # each merged on reading, are joined without merging).
            # Read unprocessed: processing drops a vertex that is not finite, and the
            # triangles using it, where it is to be refused
            # a PLY's vertices as in the file (not parted by texture coordinates), for
            # its polygons to be cut again where the reader's fans leave them
            options: dict[str, Any] = {"fix_texture": False} if kind == ".ply" else {}
            scene = trimesh.load_scene(
                source, file_type=kind[1:], resolver=resolver, process=False, **options
            )
            _refuse_not_finite(path, scene.geometry.values())
            if kind == ".ply":
                for part in scene.geometry.values():
                    cut_read_polygons(part)
            collapsed = 0
            for part in scene.geometry.values():
                if isinstance(part, trimesh.Trimesh):  # not a point cloud
                    collapsed += _drop_collapsed(part)
                    part.process(merge_tex=True, merge_norm=True)
            loaded = scene.to_mesh()
            if len(scene.graph.nodes_geometry) > 1:
                loaded.merge_vertices(merge_tex=True, merge_norm=True)
    except InputFileError:
        raise
    except Exception as error:  # trimesh's parsers raise many kinds on malformed text
        raise InputFileError(
            path, f"not a readable {kind[1:].upper()} mesh ({type(error).__name__}: {error})"
        ) from None
    faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64).reshape(-1, 3)
    vertices = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=np.float64).reshape(-1, 3)
    if len(faces) == 0:
        raise InputFileError(path, "holds no triangles; expected a triangle mesh")
    if collapsed:
        notes.append(
            f"left out {plural(collapsed, 'collapsed triangle')} (corners at the same point: no area)"
        )
    problem = _closed_problem(loaded, len(vertices))
    if not problem and _signed_volume(vertices, faces) < 0:
        faces = faces[:, ::-1].copy()  # wound inside out: turn the normals outward
    with np.errstate(over="ignore"):  # past the float range: inf, refused below
        vertices = vertices * scale
    if not np.all(np.isfinite(vertices)):
        raise InputFileError(
            path, f"scaled by {scale:g} its vertices pass the largest number (about 1.8e308 m)"
        )
    if up == "y":
        vertices = np.column_stack([vertices[:, 0], -vertices[:, 2], vertices[:, 1]])
    return Mesh(path, vertices, faces, not problem, problem, tuple(notes))


def _drop_collapsed(mesh) -> int:
    """Leave out the triangles two of whose corners are the very same point (an
    exporter's slivers rounded to float32), before the vertices are merged: they have
    no area, and once merged their edges would read as holes and as edges shared by
    more than two triangles. Compared exactly: merging rounds, and far out (1e308)
    it would join distinct corners. How many."""
    corners = np.asarray(mesh.vertices, dtype=np.float64)[np.asarray(mesh.faces, dtype=np.int64)]
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    same = lambda p, q: np.all(p == q, axis=1)  # noqa: E731
    keep = ~(same(a, b) | same(b, c) | same(a, c))
    dropped = int(np.count_nonzero(~keep))
    if dropped:
        mesh.update_faces(keep)
    return dropped


def _refuse_not_finite(path: Path, parts) -> None:
    """``InputFileError`` when a vertex of the mesh as read is not a finite number,
    counting the triangles that use one."""
    bad_triangles = bad_vertices = 0
    for part in parts:
        vertices = np.asarray(getattr(part, "vertices", np.zeros((0, 3))), dtype=np.float64)
        bad = ~np.all(np.isfinite(vertices.reshape(-1, 3)), axis=1)
        if bad.any():
            bad_vertices += int(np.count_nonzero(bad))
            faces = np.asarray(getattr(part, "faces", np.zeros((0, 3))), dtype=np.int64).reshape(-1, 3)
            bad_triangles += int(np.count_nonzero(bad[faces].any(axis=1)))
    if bad_triangles:
        uses = "1 triangle uses" if bad_triangles == 1 else f"{bad_triangles:,} triangles use"
        raise InputFileError(path, f"{uses} a vertex whose coordinates are not finite numbers")
    if bad_vertices:
        what = "1 vertex has" if bad_vertices == 1 else f"{bad_vertices:,} vertices have"
        raise InputFileError(path, f"{what} coordinates that are not finite numbers")


def _mesh_source(path: Path, kind: str):
    """What trimesh reads, and where it finds the files a mesh names (an OBJ's
    materials): a PLY by its path; an OBJ or STL read here once, its bytes serving
    the checks of its lines or length and then the reader."""
    import io

    if kind == ".ply":
        check_ply_whole(path)
        rewritten = binary_ply_triangles(path)  # face lists of differing lengths
        return (str(path) if rewritten is None else io.BytesIO(rewritten)), None
    try:
        data = path.read_bytes()
    except OSError as error:
        raise InputFileError(path, f"cannot be read ({error.strerror or error})") from None
    if kind == ".stl":
        check_stl_whole(path, data)
        if binary_stl(data):
            return io.BytesIO(data), None
    if data.startswith(codecs.BOM_UTF8):  # saved by a Windows editor: no part of the first line
        data = data[len(codecs.BOM_UTF8) :]
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:  # exporters write names in Latin-1, and trimesh would
        text = data.decode("latin-1")  # guess the encoding with a package not installed here
        data = text.encode("utf-8")
    if kind == ".obj":  # the reader drops a nan vertex's faces and takes face index 0
        checked = check_obj_lines(path, text)
        if checked is not text:  # concave faces cut into triangles
            data = checked.encode("utf-8")
    from trimesh.resolvers import FilePathResolver

    return io.BytesIO(data), FilePathResolver(str(path))


@contextlib.contextmanager
def _trimesh_notes() -> Iterator[list[str]]:
    """Collect what trimesh logs while reading (a texture it could not load), as one-line notes.

    Left alone, its warnings would reach stderr with tracebacks through
    logging's last-resort handler.
    """
    notes: list[str] = []

    class Collect(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            notes.append(record.getMessage())

    logger = logging.getLogger("trimesh")
    handler = Collect(logging.WARNING)
    propagate = logger.propagate
    logger.addHandler(handler)
    logger.propagate = False
    try:
        yield notes
    finally:
        logger.removeHandler(handler)
        logger.propagate = propagate


def _signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """Volume enclosed by a closed mesh; negative when its normals point inward."""
    a, b, c = (vertices[faces[:, n]] - vertices[0] for n in range(3))
    return float(np.einsum("ij,ij->", a, np.cross(b, c))) / 6.0


def _closed_problem(mesh, vertex_count: int) -> str:
    """Why the mesh does not bound a solid, in words; "" when it does."""
    edges = np.sort(np.asarray(mesh.edges, dtype=np.int64), axis=1)
    _, uses = np.unique(edges[:, 0] * vertex_count + edges[:, 1], return_counts=True)
    open_edges = int(np.count_nonzero(uses == 1))
    shared = int(np.count_nonzero(uses > 2))
    if open_edges or shared:
        parts = []
        if open_edges:
            verb = "borders" if open_edges == 1 else "border"
            parts.append(f"{plural(open_edges, 'edge')} {verb} only one triangle (holes)")
        if shared:
            verb = "is" if shared == 1 else "are"
            parts.append(f"{plural(shared, 'edge')} {verb} shared by more than two triangles")
        return "; ".join(parts)
    if not mesh.is_winding_consistent:
        return "its triangles are not wound consistently (some face inward)"
    return ""


def require_closed(mesh: Mesh) -> None:
    """Solid voxelisation needs a closed mesh: ``InputFileError`` saying why this one is not."""
    if not mesh.closed:
        raise InputFileError(
            mesh.path,
            f"not a closed mesh: {mesh.problem}; solid voxelisation needs a closed surface "
            "(repair the mesh, or leave out --solid for a surface model)",
        )


def grid_triangles(mesh: Mesh, voxel_size: float, placement: Placement | None = None) -> np.ndarray:
    """The mesh's triangles as (T, 3, 3) float64 in scene grid units, placed.

    Raises ``FieldError`` on ``placement`` when part of the mesh would fall
    below the ground or at negative voxel indices.
    """
    vs = voxel_size_field(voxel_size)
    vertices = mesh.vertices
    used = vertices[np.unique(mesh.faces)]  # stray vertices in no triangle do not move the mesh
    low, high = used.min(axis=0), used.max(axis=0)
    with np.errstate(over="ignore"):  # a side past the float range is inf
        sides = high - low
    # The mesh first, then where it goes: from here on no sum or quotient overflows.
    if float(sides.max()) / vs >= MAX_INDEX - 1:
        raise InputFileError(
            mesh.path,
            f"the mesh spans {_span_text(sides)} m: at voxel size {vs:g} m its voxel indices would pass "
            f"{MAX_INDEX}; check its units (--scale) and its farthest vertices, or use a coarser "
            "--voxel-size",
        )
    if placement is None:
        grid = _snap((vertices - low) / vs - 0.5)
    else:
        if not all(math.isfinite(v) for v in (placement.x, placement.y, placement.z, placement.heading)):
            raise FieldError("at", placement, "finite x, y, z metres and heading degrees")
        if placement.z < 0:
            raise FieldError("at", placement.z, "a height of 0 m or more above the ground (z)")
        if max(abs(placement.x), abs(placement.y), placement.z) / vs >= MAX_INDEX - 1:
            raise _past_the_grid(placement)
        centre = np.array([low[0] + sides[0] / 2, low[1] + sides[1] / 2, low[2]])
        local = vertices - centre
        cos, sin = _turn(placement.heading)
        # Clockwise from north: the mesh's +y (forward) goes to (sin h, cos h).
        east = local[:, 0] * cos + local[:, 1] * sin
        north = local[:, 1] * cos - local[:, 0] * sin
        grid = _snap(
            np.column_stack(
                [
                    (placement.x + east) / vs,
                    (placement.y + north) / vs,
                    (placement.z + local[:, 2]) / vs - 0.5,
                ]
            )
        )
        lowest = grid.min(axis=0)
        for axis, name, way in ((0, "x", "east"), (1, "y", "north")):
            if lowest[axis] < -0.5:
                short = (-0.5 - lowest[axis]) * vs
                raise FieldError(
                    "at",
                    f"{placement.x:g},{placement.y:g},{placement.z:g}",
                    f"a position keeping the mesh inside the scene: at heading {placement.heading:g} "
                    f"it reaches {name} = {lowest[axis] * vs:.3f} m, {short:.3f} m past the scene's "
                    f"edge at {name} = {-0.5 * vs:g} m (voxel indices start at 0); move it {way}",
                )
    if placement is not None and grid.max() > MAX_INDEX - 1:  # the mesh fits; where it goes does not
        raise _past_the_grid(placement)
    return np.ascontiguousarray(grid[mesh.faces])


def _span_text(sides) -> str:
    """A mesh's sides in metres, "2500 x 5000 x 2200": units mistaken show."""
    return " x ".join(f"{side:.4g}" for side in sides)


def _past_the_grid(placement) -> FieldError:
    """The refusal of a placement whose voxel indices would pass MAX_INDEX."""
    return FieldError(
        "at",
        f"{placement.x:g},{placement.y:g},{placement.z:g}",
        f"a position within the scene's grid: voxel indices there would pass {MAX_INDEX}",
    )


# Grid coordinates within this much of a voxel of a voxel boundary or centre (a
# multiple of 0.5) are put on it. Mesh files are not exact: an STL holds float32
# (0.8 m is 0.800000012 m) and 1.6 m / 0.1 m is 16.000000000000004 in float64; a
# box 1.6 m tall must not set a layer of voxels 2e-7 of a voxel above its top.
# 1e-4 of a 0.1 m voxel is 10 micrometres, below anything a mesh means.
SNAP = 1e-4


def _snap(grid: np.ndarray) -> np.ndarray:
    halves = np.round(grid * 2.0) / 2.0
    return np.where(np.abs(grid - halves) <= SNAP, halves, grid)


def _turn(heading: float) -> tuple[float, float]:
    """cos and sin of a heading in degrees; exact at quarter turns (no 6e-17 residue)."""
    quarter = heading / 90.0
    if quarter == round(quarter):
        return ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[int(round(quarter)) % 4]
    radians = math.radians(heading)
    return math.cos(radians), math.sin(radians)


@dataclass(frozen=True)
class _Grid:
    """The dense working grid over the triangles' bounding box, in scene indices."""

    origin: np.ndarray  # (3,) int64, scene index of the grid's voxel (0, 0, 0)
    shape: tuple[int, int, int]


def _working_grid(triangles: np.ndarray) -> _Grid:
    flat = triangles.reshape(-1, 3)
    lo = np.maximum(np.ceil(flat.min(axis=0) - 0.5), 0).astype(np.int64)
    hi = np.floor(flat.max(axis=0) + 0.5).astype(np.int64)
    nx, ny, nz = (int(n) for n in np.maximum(hi - lo + 1, 1))
    return _Grid(lo, (nx, ny, nz))


def estimate_bytes(triangles: np.ndarray, solid: bool) -> int:
    """Peak bytes of voxelising ``triangles`` and writing the result.

    The dense grid, the crossings (solid), the voxel list and its text; the
    voxel count is bounded by the grid (solid) or the triangle-voxel tests.
    """
    grid = _working_grid(triangles)
    cells = math.prod(grid.shape)
    # surface mode sets at most one voxel per (triangle, candidate voxel) test
    filled = cells if solid else min(cells, int(_candidate_tests(triangles).sum()))
    crossings = 4 * grid.shape[0] * grid.shape[1] * (grid.shape[2] + 1) if solid else 0
    # Per voxel: the int32 list; it is written a million rows at a time.
    return cells + crossings + 12 * filled + _WRITE_BUFFER


def _candidate_tests(triangles: np.ndarray) -> np.ndarray:
    """Per triangle, how many voxels its bounding box touches: the surface pass's tests."""
    lo = np.ceil(triangles.min(axis=1) - 0.5)
    hi = np.floor(triangles.max(axis=1) + 0.5)
    return np.prod(np.maximum(hi - lo + 1, 0), axis=1)  # float64: no overflow


def _chunk_bounds(tests: np.ndarray) -> list[int]:
    """Triangle indices splitting the work into calls of bounded size."""
    cumulative = np.cumsum(tests)
    bounds = [0]
    while bounds[-1] < len(tests):
        start = bounds[-1]
        before = cumulative[start - 1] if start else 0.0
        stop = int(np.searchsorted(cumulative, before + _CHUNK_TESTS, side="right"))
        bounds.append(min(max(stop, start + 1), start + _CHUNK_TRIANGLES, len(tests)))
    return bounds


def voxelize(
    mesh: Mesh,
    voxel_size: float,
    placement: Placement | None = None,
    solid: bool = False,
    progress: Callable[[str, int, int], None] | None = None,
    cancel: threading.Event | None = None,
) -> Voxelized:
    """Voxelise ``mesh`` exactly (see the module's rules) at ``voxel_size`` metres.

    ``progress(stage, done, total)`` is called from this thread between
    chunks of each stage ("surface" and "inside" count triangles, "filling"
    and "collecting" x slabs of the grid); a set ``cancel`` stops with
    ``Cancelled``. Work whose memory
    would exceed the machine is refused up front with ``ResourceLimitError``.
    """
    from ladartui.resources import available_memory, gib

    if not isinstance(mesh, Mesh):
        raise FieldError("mesh", mesh, "a Mesh, as load_mesh(path) reads it")
    if solid:
        require_closed(mesh)
    triangles = grid_triangles(mesh, voxel_size, placement)
    need = estimate_bytes(triangles, solid)
    limit = available_memory()
    grid = _working_grid(triangles)
    if need > limit:
        nx, ny, nz = grid.shape
        used = mesh.vertices[np.unique(mesh.faces)]
        span = _span_text(used.max(axis=0) - used.min(axis=0))
        raise ResourceLimitError(
            f"{mesh.path}: the mesh spans {span} m; voxel size {voxel_size:g} m makes a "
            f"{nx:,} x {ny:,} x {nz:,} voxel box needing about {gib(need)}, more than the "
            f"{gib(limit)} of memory available; check its units (--scale 0.001 for millimetres) "
            "or use a larger --voxel-size"
        )
    from ladartui.scene import voxelize_kernels as kernels

    local = triangles - grid.origin.astype(np.float64)  # exact: whole numbers
    marks = np.zeros(grid.shape, dtype=np.uint8)

    def stage(name: str, bounds: list[int], step: Callable[[int, int], object]) -> None:
        for start, stop in zip(bounds, bounds[1:]):
            check_cancelled(cancel, CANCELLED)
            step(start, stop)
            if progress is not None:
                progress(name, stop, bounds[-1])

    triangle_chunks = _chunk_bounds(_candidate_tests(local))
    stage("surface", triangle_chunks, lambda a, b: kernels.mark_surface(local, a, b, marks))
    surface = int(np.count_nonzero(marks))
    if surface == 0:
        raise InputFileError(
            mesh.path,
            f"sets no voxels at {voxel_size:g} m: its surface only lies on or touches voxel "
            "boundaries (a face on a boundary counts for the voxel behind it, away from its normal)",
        )
    slabs = _slab_bounds(grid.shape)
    inside = 0
    if solid:
        crossings = np.zeros((*grid.shape[:2], grid.shape[2] + 1), dtype=np.int32)
        stage("inside", triangle_chunks, lambda a, b: kernels.add_crossings(local, a, b, crossings))
        counts: list[int] = []
        stage("filling", slabs, lambda a, b: counts.append(kernels.fill_inside(crossings, marks, a, b)))
        inside = int(sum(counts))
        del crossings
    voxels = np.empty((int(np.count_nonzero(marks)), 3), dtype=np.int32)
    rows = [0]
    origin = grid.origin.astype(np.int32)
    stage(
        "collecting",
        slabs,
        lambda a, b: rows.append(kernels.collect_voxels(marks, a, b, origin, voxels, rows[-1])),
    )
    return Voxelized(voxels, surface, inside, solid, float(voxel_size))


def _slab_bounds(shape: tuple[int, int, int]) -> list[int]:
    """x indices splitting a grid pass into calls of about ``_CHUNK_TESTS`` cells."""
    per_slab = max(shape[1] * shape[2], 1)
    step = max(1, _CHUNK_TESTS // per_slab)
    return [*range(0, shape[0], step), shape[0]]


def merge_voxels(*lists: np.ndarray) -> np.ndarray:
    """The union of voxel lists, sorted by (x, y, z) like the files this project writes."""
    from ladartui.errors import FieldError
    from ladartui.scene.keys import keys_to_voxels, sorted_unique, voxel_keys

    stacked = np.concatenate([np.asarray(v, dtype=np.int32).reshape(-1, 3) for v in lists])
    if len(stacked) == 0:
        return np.zeros((0, 3), dtype=np.int32)
    try:
        keys = voxel_keys(stacked)
    except FieldError:  # indices too large to pack: the slower row-wise unique
        return np.unique(stacked, axis=0).astype(np.int32)
    return keys_to_voxels(sorted_unique(keys))
