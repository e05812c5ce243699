"""Synthetic forest scenes with a vehicle under the canopy.

``generate_scene(preset, seed, **overrides)`` builds a scene model and its
target model, the same every time for the same seed and parameters:

- trees: a trunk (a hollow tapering tube: only its skin can be seen), a few
  branches, and a crown that is a shell of leaf clumps with real gaps
  between them (broadleaf ellipsoids and conifer cones). ``density`` is the
  share of a crown's surface covered by clumps, so ``1 - density`` is roughly
  the gap a ray finds when it crosses the crown's skin. Clumps are small
  flattened blobs a few voxels across, which keeps occupied voxels gathered
  in few 8x8x8 bricks the way real foliage is.
- terrain (optional): a gentle height field, one watertight skin of voxels.
- vehicles: solid models (hull on wheels, cabin with a sloped windscreen);
  the first stands at the scene centre under overhanging crowns, each with a
  random heading.
- a camouflage net (optional) draped over the first vehicle: a patchy layer
  that belongs to the scene, not to the target.

The target list holds the vehicle voxels only, at the same x-y as in the
scene (report table 2). Each vehicle is its own target: vehicle k (the first,
netted one is 1) has target id k. With more than one vehicle the target model
is written as ``x,y,z,id`` lines; with one it keeps the report's ``x,y,z``.
All sizes are metres; the grid is voxel indices.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ladartui.errors import FieldError
from ladartui.scene.voxels import save_voxels


@dataclass(frozen=True)
class SceneParams:
    """Everything that shapes a generated scene (metres unless stated)."""

    voxel_size: float = 0.25
    width: float = 60.0  # x extent
    depth: float = 60.0  # y extent
    height: float | None = None  # z extent of the grid; None: tallest voxel + 1
    trees: int = 48  # all trees, including up to three that shade the first vehicle
    tree_height: tuple[float, float] = (10.0, 18.0)
    crown_radius: tuple[float, float] = (2.5, 4.5)
    trunk_radius: tuple[float, float] = (0.15, 0.3)
    conifer_share: float = 0.3
    density: float = 0.6  # share of each crown's surface covered by leaf clumps
    clump_radius: tuple[float, float] = (0.25, 0.5)
    shell_depth: float = 0.3  # share of the crown radius holding foliage
    branches: int = 6  # per broadleaf tree
    terrain: bool = False
    terrain_relief: float = 1.5  # peak-to-trough height of the terrain
    vehicles: int = 1
    vehicle_size: tuple[float, float, float] = (5.0, 2.5, 2.2)  # length, width, height
    camouflage: bool = False
    net_coverage: float = 0.6  # share of the net's area that holds material


PRESETS = {
    # Tests and the default scenario: 240 x 240 voxels, a few dozen trees.
    "small": SceneParams(),
    # The report's figure-11 scale: 1500 x 1500 x 900 voxels, about 3.8 M voxels.
    "reference": SceneParams(
        voxel_size=0.1,
        width=150.0,
        depth=150.0,
        height=90.0,
        trees=186,
        tree_height=(14.0, 26.0),
        crown_radius=(2.5, 5.0),
        trunk_radius=(0.15, 0.35),
        density=0.55,
        clump_radius=(0.2, 0.4),
        branches=8,
    ),
}


@dataclass
class GeneratedScene:
    """A generated scene model and its target model, ready to write or to use."""

    voxels: np.ndarray
    target: np.ndarray
    voxel_size: float
    shape: tuple[int, int, int]
    target_centre: np.ndarray | None  # metres; None without vehicles
    params: SceneParams
    seed: int
    preset: str
    parts: dict[str, int] = field(default_factory=dict)  # voxels per part, before merging
    target_ids: np.ndarray | None = None  # target id per target voxel: vehicle k is k; None: all 1

    def ids(self) -> np.ndarray:
        """The target id of each target voxel (all 1 without labels)."""
        if self.target_ids is None:
            return np.ones(len(self.target), dtype=np.int32)
        return self.target_ids

    def write(self, stem) -> tuple[Path, Path]:
        """Write ``stem.txt`` and ``stem_Target.txt`` (each atomically); returns both paths.

        The target model carries an id column when there is more than one vehicle.
        """
        scene_path, target_path = output_paths(stem)
        save_voxels(scene_path, self.voxels)
        labelled = self.params.vehicles > 1
        save_voxels(target_path, self.target, ids=self.ids() if labelled else None)
        return scene_path, target_path

    def to_scene(self, name=None, path=None):
        """This scene as a :class:`ladartui.scene.model.Scene`."""
        from ladartui.scene.model import Scene

        return Scene(
            self.voxels,
            self.target,
            self.voxel_size,
            shape=self.shape,
            name=name or f"{self.preset}-{self.seed}",
            path=path,
            target_ids=self.ids(),
        )


def output_paths(stem) -> tuple[Path, Path]:
    """``dir/name`` or ``dir/name.txt`` -> (``dir/name.txt``, ``dir/name_Target.txt``)."""
    stem = Path(stem)
    if stem.suffix.lower() == ".txt":
        stem = stem.with_suffix("")
    return stem.with_name(stem.name + ".txt"), stem.with_name(stem.name + "_Target.txt")


MAX_TREES = 100_000


def scene_params(preset="small", **overrides) -> SceneParams:
    """The preset's parameters with ``overrides`` applied and checked."""
    if preset not in PRESETS:
        raise FieldError("preset", preset, "one of " + ", ".join(PRESETS))
    names = {f.name for f in dataclasses.fields(SceneParams)}
    for key in overrides:
        if key not in names:
            raise FieldError(key, overrides[key], "a scene parameter: " + ", ".join(sorted(names)))
    params = dataclasses.replace(PRESETS[preset], **overrides)
    _check(params)
    return params


def generate_scene(preset="small", seed=0, **overrides) -> GeneratedScene:
    """Build a scene from a preset ("small" or "reference"), deterministic from ``seed``.

    ``overrides`` replace fields of :class:`SceneParams`, e.g. ``density=0.8``,
    ``vehicles=0``, ``terrain=True``, ``camouflage=True``.
    """
    params = scene_params(preset, **overrides)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise FieldError("seed", seed, "a non-negative whole number")
    rng = np.random.default_rng(int(seed))
    vs = params.voxel_size
    nx, ny = round(params.width / vs), round(params.depth / vs)

    ground = _terrain(params, nx, ny, rng)  # (nx, ny) int32: first free layer per column
    parts: dict[str, np.ndarray] = {}
    if params.terrain:
        parts["terrain"] = _terrain_voxels(ground - 1)

    vehicles = _place_vehicles(params, nx, ny, ground, rng)
    vehicle_voxels = [_vehicle_voxels(v, params, nx, ny) for v in vehicles]
    trees = _place_trees(params, nx, ny, ground, vehicles, rng)
    parts["trunks"] = _trunk_voxels(trees, vs)
    parts["branches"] = _branch_voxels(trees, params, rng)
    parts["foliage"] = _foliage_voxels(trees, params, rng)
    for name in ("trunks", "branches", "foliage"):
        parts[name] = _clip(parts[name], nx, ny)
        for vehicle in vehicles:
            parts[name] = _carve_clearance(parts[name], vehicle, vs)
    if params.camouflage and vehicles:
        parts["net"] = _clip(_net_voxels(vehicles[0], params, ground, rng), nx, ny)
    target, target_ids = _merge_labelled(vehicle_voxels)
    parts["vehicles"] = target
    voxels = _merge(list(parts.values()))

    top = int(voxels[:, 2].max()) + 1 if len(voxels) else 1
    nz = max(top, round(params.height / vs) if params.height else 0)
    centre = target.astype(np.float64).mean(axis=0) * vs if len(target) else None
    return GeneratedScene(
        voxels=voxels,
        target=target,
        voxel_size=vs,
        shape=(nx, ny, nz),
        target_centre=centre,
        params=params,
        seed=int(seed),
        preset=preset,
        parts={name: len(v) for name, v in parts.items()},
        target_ids=target_ids,
    )


# ---- checks -------------------------------------------------------------------


def _check(p: SceneParams):
    def positive(name, value):
        if not (
            isinstance(value, (int, float))
            and not isinstance(value, bool)
            and value > 0
            and math.isfinite(value)
        ):
            raise FieldError(name, value, "a positive number")

    def share(name, value, top=1.0):
        if not (isinstance(value, (int, float)) and 0 <= value <= top):
            raise FieldError(name, value, f"a number from 0 to {top}")

    def count(name, value):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
            raise FieldError(name, value, "a whole number, 0 or more")

    def span(name, value):
        if (
            not isinstance(value, (tuple, list))
            or len(value) != 2
            or not all(isinstance(v, (int, float)) and v > 0 for v in value)
            or value[0] > value[1]
        ):
            raise FieldError(name, value, "(low, high) positive metres with low <= high")

    for name in ("voxel_size", "width", "depth", "terrain_relief"):
        positive(name, getattr(p, name))
    if p.height is not None:
        positive("height", p.height)
    for name in ("tree_height", "crown_radius", "trunk_radius", "clump_radius"):
        span(name, getattr(p, name))
    for name in ("conifer_share", "net_coverage", "shell_depth"):
        share(name, getattr(p, name))
    share("density", p.density, 0.99)
    for name in ("trees", "branches", "vehicles"):
        count(name, getattr(p, name))
    # Each tree costs tens of kilobytes while it is built; refuse before allocating.
    if p.trees > MAX_TREES:
        raise FieldError(
            "trees",
            p.trees,
            f"at most {MAX_TREES:,} trees ({p.trees:,} would "
            f"need about {p.trees * 50e3 / 2**30:.3g} GiB to build)",
        )
    if (
        not isinstance(p.vehicle_size, (tuple, list))
        or len(p.vehicle_size) != 3
        or not all(isinstance(v, (int, float)) and v > 0 for v in p.vehicle_size)
    ):
        raise FieldError("vehicle_size", p.vehicle_size, "(length, width, height) positive metres")
    cells = (p.width / p.voxel_size) * (p.depth / p.voxel_size)
    if cells > 1e8:
        raise FieldError("voxel_size", p.voxel_size, "a size giving at most 1e8 ground cells")
    if p.vehicles and min(p.width, p.depth) < max(p.vehicle_size[:2]) + 4:
        raise FieldError("width", p.width, "room for the vehicle and 2 m around it")


# ---- terrain -------------------------------------------------------------------


def _terrain(p: SceneParams, nx, ny, rng) -> np.ndarray:
    """First free layer per column: 0 on flat ground, else one above the terrain skin."""
    if not p.terrain:
        return np.zeros((nx, ny), dtype=np.int32)
    vs = p.voxel_size
    x = np.arange(nx) * vs
    y = np.arange(ny) * vs
    surface = np.zeros((nx, ny))
    for _ in range(4):  # a few long, gentle waves (30 to 90 m)
        wavelength = rng.uniform(30.0, 90.0)
        angle = rng.uniform(0, 2 * np.pi)
        phase = rng.uniform(0, 2 * np.pi)
        kx, ky = np.cos(angle) * 2 * np.pi / wavelength, np.sin(angle) * 2 * np.pi / wavelength
        surface += np.sin(kx * x[:, None] + ky * y[None, :] + phase)
    span = surface.max() - surface.min()
    surface = (surface - surface.min()) / (span if span > 0 else 1.0) * p.terrain_relief
    return np.floor(surface / vs).astype(np.int32) + 1


def _terrain_voxels(top: np.ndarray) -> np.ndarray:
    """A watertight skin: each column filled down to its lowest neighbour's top."""
    padded = np.pad(top, 1, mode="edge")
    lowest = np.minimum.reduce(
        [padded[:-2, 1:-1], padded[2:, 1:-1], padded[1:-1, :-2], padded[1:-1, 2:], top]
    )
    bottom = np.minimum(lowest + 1, top)
    counts = (top - bottom + 1).ravel()
    xs, ys = np.meshgrid(np.arange(top.shape[0]), np.arange(top.shape[1]), indexing="ij")
    column = np.repeat(np.arange(counts.size), counts)
    starts = np.cumsum(counts) - counts
    z = bottom.ravel()[column] + (np.arange(column.size) - starts[column])
    return np.stack([xs.ravel()[column], ys.ravel()[column], z], axis=1).astype(np.int32)


# ---- vehicles -----------------------------------------------------------------


@dataclass(frozen=True)
class _Vehicle:
    cx: float  # centre, grid units
    cy: float
    base: int  # first voxel layer of the vehicle (on the ground or terrain)
    heading: float  # radians, clockwise from north (+y)
    size: tuple[float, float, float]


def _place_vehicles(p: SceneParams, nx, ny, ground, rng) -> list[_Vehicle]:
    vs = p.voxel_size
    length = p.vehicle_size[0]
    vehicles: list[_Vehicle] = []
    for index in range(p.vehicles):
        heading = rng.uniform(0, 2 * np.pi)
        if index == 0:
            cx, cy = nx / 2, ny / 2
        else:  # others somewhere else, clear of the first and of the border
            margin = (length + 2) / vs
            cx, cy = nx / 2, ny / 2
            for _ in range(100):
                cx, cy = rng.uniform(margin, nx - margin), rng.uniform(margin, ny - margin)
                if all(math.hypot(cx - v.cx, cy - v.cy) * vs > 2 * length + 4 for v in vehicles):
                    break
        reach = int(math.ceil(length / 2 / vs))
        x0, x1 = max(int(cx) - reach, 0), min(int(cx) + reach + 1, nx)
        y0, y1 = max(int(cy) - reach, 0), min(int(cy) + reach + 1, ny)
        base = int(ground[x0:x1, y0:y1].max())
        size_l, size_w, size_h = p.vehicle_size  # a list from a file is a 3-tuple here
        vehicles.append(_Vehicle(cx, cy, base, heading, (size_l, size_w, size_h)))
    return vehicles


def _local_frame(vehicle: _Vehicle, voxels, vs):
    """Voxel centres in the vehicle frame: u forward, v to the right, w up from its base (m)."""
    dx = (voxels[:, 0] - vehicle.cx) * vs
    dy = (voxels[:, 1] - vehicle.cy) * vs
    sin, cos = math.sin(vehicle.heading), math.cos(vehicle.heading)
    u = dx * sin + dy * cos
    v = dx * cos - dy * sin
    w = (voxels[:, 2] - vehicle.base + 0.5) * vs
    return u, v, w


def _box_grid(vehicle: _Vehicle, reach_m, top_m, vs):
    reach = int(math.ceil(reach_m / vs)) + 1
    xs = np.arange(int(vehicle.cx) - reach, int(vehicle.cx) + reach + 1)
    ys = np.arange(int(vehicle.cy) - reach, int(vehicle.cy) + reach + 1)
    zs = np.arange(vehicle.base, vehicle.base + int(math.ceil(top_m / vs)) + 1)
    grid = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    return grid[(grid[:, 0] >= 0) & (grid[:, 1] >= 0)].astype(np.int32)


def _vehicle_voxels(vehicle: _Vehicle, p: SceneParams, nx, ny) -> np.ndarray:
    """A solid hull on four wheels with a cabin and sloped windscreen, proportions of a truck."""
    vs = p.voxel_size
    length, width, height = vehicle.size
    grid = _box_grid(vehicle, math.hypot(length, width) / 2, height, vs)
    u, v, w = _local_frame(vehicle, grid, vs)
    half_l, half_w = length / 2, width / 2
    clearance = 0.2 * height
    hull_top = 0.6 * height
    wheel_r = 0.2 * height
    chamfer = 0.1 * length
    hull = (
        (np.abs(u) <= half_l)
        & (np.abs(v) <= half_w)
        & (w >= clearance)
        & (w <= hull_top)
        & (u + (w - clearance) <= half_l + (hull_top - clearance) - chamfer)
    )
    wheel_x = np.array([-0.3, 0.3]) * length
    near_side = (np.abs(v) >= half_w - 0.15 * width) & (np.abs(v) <= half_w - 0.02 * width)
    wheels = np.zeros_like(hull)
    for axle in wheel_x:
        wheels |= near_side & ((u - axle) ** 2 + (w - wheel_r) ** 2 <= wheel_r**2)
    cabin_back, cabin_front = 0.02 * length, 0.34 * length
    slope = 0.4  # the windscreen leans back this far per metre of rise
    cabin = (
        (u >= cabin_back)
        & (u <= cabin_front - slope * (w - hull_top))
        & (np.abs(v) <= half_w - 0.08 * width)
        & (w > hull_top)
        & (w <= height)
    )
    solid = grid[hull | wheels | cabin]
    return _clip(solid, nx, ny)


def _carve_clearance(voxels, vehicle: _Vehicle, vs, margin=0.3, headroom=0.5):
    """Drop plant voxels inside the box around a vehicle: it stands in a clearing."""
    if not len(voxels):
        return voxels
    length, width, height = vehicle.size
    reach = (math.hypot(length, width) / 2 + margin) / vs + 1
    near = np.nonzero(
        (np.abs(voxels[:, 0] - vehicle.cx) <= reach)
        & (np.abs(voxels[:, 1] - vehicle.cy) <= reach)
        & (voxels[:, 2] <= vehicle.base + (height + headroom) / vs + 1)
    )[0]
    u, v, w = _local_frame(vehicle, voxels[near], vs)
    inside = (np.abs(u) <= length / 2 + margin) & (np.abs(v) <= width / 2 + margin) & (w <= height + headroom)
    keep = np.ones(len(voxels), dtype=bool)
    keep[near[inside]] = False
    return voxels[keep]


def _net_voxels(vehicle: _Vehicle, p: SceneParams, ground, rng) -> np.ndarray:
    """A patchy net: flat just above the vehicle, draped down to the ground around it."""
    vs = p.voxel_size
    length, width, height = vehicle.size
    rim = 1.0  # metres of net between the vehicle's side and the ground
    roof = height + 0.25
    nx, ny = ground.shape
    reach = int(math.ceil((math.hypot(length, width) / 2 + rim) / vs)) + 1
    xs = np.arange(max(int(vehicle.cx) - reach, 0), min(int(vehicle.cx) + reach + 1, nx))
    ys = np.arange(max(int(vehicle.cy) - reach, 0), min(int(vehicle.cy) + reach + 1, ny))
    cols = np.stack(np.meshgrid(xs, ys, indexing="ij"), axis=-1).reshape(-1, 2)
    zeros = np.zeros((len(cols), 1), dtype=np.int64)
    u, v, _ = _local_frame(vehicle, np.hstack([cols, zeros + vehicle.base]), vs)
    outside = np.maximum(np.abs(u) - length / 2 - 0.1, np.abs(v) - width / 2 - 0.1)
    keep = outside <= rim
    # Garnish patches: a coarse random field (0.4 m cells) thresholded to the coverage.
    cell = max(1, round(0.4 / vs))
    coarse = rng.random(((nx + cell - 1) // cell + 1, (ny + cell - 1) // cell + 1))
    keep &= coarse[cols[:, 0] // cell, cols[:, 1] // cell] < p.net_coverage
    cols, outside = cols[keep], outside[keep]
    lift = roof * np.clip(1 - np.maximum(outside, 0) / rim, 0, 1)
    floor = ground[cols[:, 0], cols[:, 1]]
    top = np.maximum(vehicle.base + np.floor(lift / vs).astype(np.int64), floor)
    # Steep drape: fill down by the slope so rays cannot slip between layers.
    drop = np.where(outside > 0, np.ceil(roof / rim), 0).astype(np.int64)
    bottom = np.maximum(top - drop, floor)
    counts = top - bottom + 1
    column = np.repeat(np.arange(len(cols)), counts)
    starts = np.cumsum(counts) - counts
    z = bottom[column] + (np.arange(column.size) - starts[column])
    return np.stack([cols[column, 0], cols[column, 1], z], axis=1).astype(np.int32)


# ---- trees --------------------------------------------------------------------


@dataclass
class _Trees:
    """Per-tree arrays, grid units (x, y centre; base layer; heights in voxels)."""

    x: np.ndarray
    y: np.ndarray
    base: np.ndarray
    height: np.ndarray
    crown_base: np.ndarray
    crown_radius: np.ndarray
    trunk_radius: np.ndarray
    conifer: np.ndarray

    def __len__(self):
        return len(self.x)


def _place_trees(p: SceneParams, nx, ny, ground, vehicles, rng) -> _Trees:
    vs = p.voxel_size
    # Up to three of the trees stand round the first vehicle; the rest anywhere.
    n_cover = min(3, p.trees) if vehicles else 0
    # A jittered grid keeps trunks apart without a rejection loop.
    spacing = math.sqrt(nx * ny / max(p.trees, 1))
    gx = np.arange(spacing / 2, nx, spacing)
    gy = np.arange(spacing / 2, ny, spacing)
    x, y = (a.ravel() for a in np.meshgrid(gx, gy, indexing="ij"))
    x = x + rng.uniform(-0.35, 0.35, x.size) * spacing
    y = y + rng.uniform(-0.35, 0.35, y.size) * spacing
    pick = rng.permutation(x.size)[: p.trees - n_cover]
    x, y = x[pick], y[pick]
    cover_x, cover_y = [], []
    if vehicles:
        length, width, height = p.vehicle_size
        keep = np.ones(x.size, dtype=bool)
        for v in vehicles:
            keep &= np.hypot(x - v.cx, y - v.cy) * vs > length / 2 + 1.5
        x, y = x[keep], y[keep]
        # Trees standing round the first vehicle so that their crowns close over it.
        first = vehicles[0]
        start = rng.uniform(0, 2 * np.pi)
        for k in range(n_cover):
            angle = start + k * 2 * np.pi / 3 + rng.uniform(-0.3, 0.3)
            distance = (length / 2 + rng.uniform(1.0, 2.0)) / vs
            cover_x.append(first.cx + distance * np.cos(angle))
            cover_y.append(first.cy + distance * np.sin(angle))
    count = x.size + len(cover_x)
    x = np.clip(np.concatenate([x, cover_x]), 0, nx - 1)
    y = np.clip(np.concatenate([y, cover_y]), 0, ny - 1)
    height = rng.uniform(*p.tree_height, count) / vs
    crown_radius = rng.uniform(*p.crown_radius, count) / vs
    conifer = rng.random(count) < p.conifer_share
    crown_share = np.where(conifer, rng.uniform(0.7, 0.85, count), rng.uniform(0.5, 0.7, count))
    crown_base = height * (1 - crown_share)
    trunk_radius = rng.uniform(*p.trunk_radius, count) / vs
    if n_cover:
        # Cover trees: broadleaf, wide crowns reaching over the vehicle, high enough to clear it.
        reach = (p.vehicle_size[0] / 2 + 2.5) / vs
        crown_radius[-n_cover:] = np.maximum(crown_radius[-n_cover:], reach)
        conifer[-n_cover:] = False
        low = (p.vehicle_size[2] + 1.5) / vs
        crown_base[-n_cover:] = np.clip(crown_base[-n_cover:], low, None)
        height[-n_cover:] = np.maximum(height[-n_cover:], crown_base[-n_cover:] + 2 * reach * 0.8)
    base = ground[x.astype(np.int64), y.astype(np.int64)]
    return _Trees(
        x,
        y,
        base.astype(np.float64),
        height,
        crown_base,
        crown_radius,
        np.maximum(trunk_radius, 0.5),
        conifer,
    )


def _trunk_voxels(trees: _Trees, vs) -> np.ndarray:
    """Hollow tapering tubes (only the skin can be seen), 1.5 voxels thick."""
    pieces = []
    for i in range(len(trees)):
        radius = trees.trunk_radius[i]
        top = trees.height[i] if trees.conifer[i] else 0.8 * trees.height[i]
        layers = np.arange(int(top))
        reach = int(math.ceil(radius)) + 1
        offsets = np.arange(-reach, reach + 1)
        ox, oy = (a.ravel() for a in np.meshgrid(offsets, offsets, indexing="ij"))
        cx, cy = int(round(trees.x[i])), int(round(trees.y[i]))
        distance = np.hypot(ox + cx - trees.x[i], oy + cy - trees.y[i])
        taper = radius * (1 - 0.6 * layers / max(top, 1))
        skin = (distance[None, :] <= taper[:, None] + 0.5) & (distance[None, :] > taper[:, None] - 1)
        layer, cell = np.nonzero(skin)
        z = trees.base[i] + layers[layer]
        pieces.append(np.stack([cx + ox[cell], cy + oy[cell], z], axis=1))
    return _concat(pieces)


def _crown_centre(trees: _Trees):
    """Centre (grid) and half-height of each crown's envelope."""
    half = (trees.height - trees.crown_base) / 2
    return trees.base + trees.crown_base + half, half


def _branch_voxels(trees: _Trees, p: SceneParams, rng) -> np.ndarray:
    """Straight limbs from the trunk out to the crown's skin (broadleaf trees)."""
    broad = np.nonzero(~trees.conifer)[0]
    if not len(broad) or not p.branches:
        return np.zeros((0, 3), dtype=np.int32)
    tree = np.repeat(broad, p.branches)
    centre_z, half = _crown_centre(trees)
    start_z = trees.base[tree] + trees.crown_base[tree] + rng.uniform(0, 0.6, tree.size) * 2 * half[tree]
    azimuth = rng.uniform(0, 2 * np.pi, tree.size)
    rise = rng.uniform(0.2, 0.9, tree.size)  # end height inside the crown, share of half-height
    reach = 0.85 * trees.crown_radius[tree] * np.sqrt(1 - np.minimum(rise, 0.95) ** 2)
    start = np.stack([trees.x[tree], trees.y[tree], start_z], axis=1)
    end = np.stack(
        [
            trees.x[tree] + reach * np.cos(azimuth),
            trees.y[tree] + reach * np.sin(azimuth),
            centre_z[tree] + rise * half[tree],
        ],
        axis=1,
    )
    return _segments(start, end)


def _segments(start, end) -> np.ndarray:
    """Voxels along straight segments, sampled every half voxel."""
    steps = np.maximum(np.ceil(np.linalg.norm(end - start, axis=1) * 2).astype(np.int64), 1) + 1
    seg = np.repeat(np.arange(len(start)), steps)
    first = np.cumsum(steps) - steps
    t = (np.arange(seg.size) - first[seg]) / (steps[seg] - 1)
    points = start[seg] + (end - start)[seg] * t[:, None]
    return np.floor(points + 0.5).astype(np.int32)


def _foliage_voxels(trees: _Trees, p: SceneParams, rng) -> np.ndarray:
    """Leaf clumps scattered through the outer shell of every crown."""
    vs = p.voxel_size
    centre_z, half = _crown_centre(trees)
    radius = trees.crown_radius
    conifer = trees.conifer
    # Envelope surface areas (grid units squared): ellipsoid (Thomsen) or cone side.
    a, c = radius, half
    ellipsoid = 4 * np.pi * (((a * a) ** 1.6 + 2 * (a * c) ** 1.6) / 3) ** (1 / 1.6)
    cone = np.pi * radius * np.hypot(radius, 2 * half)
    area = np.where(conifer, cone, ellipsoid)
    clump_area = np.pi * (np.mean(p.clump_radius) / vs) ** 2
    per_tree = np.ceil(-math.log(1 - p.density) * area / clump_area).astype(np.int64)
    tree = np.repeat(np.arange(len(trees)), per_tree)
    n = tree.size
    depth = 1 - p.shell_depth * rng.random(n)  # share of the envelope radius
    # Ellipsoid: a uniform direction, scaled to the envelope.
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    # Lumpy envelopes: each crown bulges along a few random low-order waves.
    amplitude = rng.uniform(0.0, 0.15, (len(trees), 3))
    phase = rng.uniform(0, 2 * np.pi, (len(trees), 3))

    def lumps(azimuth, elevation):
        a, ph = amplitude[tree], phase[tree]
        return (
            1
            + a[:, 0] * np.cos(2 * azimuth + ph[:, 0])
            + a[:, 1] * np.cos(3 * azimuth + ph[:, 1])
            + a[:, 2] * np.cos(2 * elevation + ph[:, 2])
        )

    bulge = lumps(np.arctan2(direction[:, 1], direction[:, 0]), np.arcsin(direction[:, 2]))
    ex = direction[:, 0] * radius[tree] * depth * bulge
    ey = direction[:, 1] * radius[tree] * depth * bulge
    ez = centre_z[tree] + direction[:, 2] * half[tree] * depth * bulge
    # Cone: area-uniform over the side (apex at the top of the tree).
    s = np.sqrt(rng.random(n))
    angle = rng.uniform(0, 2 * np.pi, n)
    ring = radius[tree] * s * depth * lumps(angle, s * np.pi)
    top = trees.base[tree] + trees.height[tree]
    is_cone = conifer[tree]
    cx = trees.x[tree] + np.where(is_cone, ring * np.cos(angle), ex)
    cy = trees.y[tree] + np.where(is_cone, ring * np.sin(angle), ey)
    cz = np.where(is_cone, top - s * 2 * half[tree], ez)
    centres = np.floor(np.stack([cx, cy, cz], axis=1) + 0.5).astype(np.int32)
    clump = rng.uniform(*p.clump_radius, n) / vs
    return _stamp_clumps(centres, clump, rng)


def _stamp_clumps(centres, radii, rng, variants=6) -> np.ndarray:
    """Place a ragged flattened blob at every centre; blobs grouped by size class."""
    classes = np.maximum(np.round(radii * 2) / 2, 0.5)  # half-voxel size classes
    variant = rng.integers(0, variants, len(centres))
    pieces = []
    for size in np.unique(classes):
        templates = [_clump_template(size, rng) for _ in range(variants)]
        in_class = classes == size
        for k, template in enumerate(templates):
            chosen = centres[in_class & (variant == k)]
            if len(chosen):
                pieces.append((chosen[:, None, :] + template[None, :, :]).reshape(-1, 3))
    return _concat(pieces)


def _clump_template(radius, rng, flatness=0.35) -> np.ndarray:
    """Offsets of one leaf clump: an oblate blob whose rim is thinned at random."""
    reach = int(math.ceil(radius))
    o = np.arange(-reach, reach + 1)
    ox, oy, oz = (a.ravel() for a in np.meshgrid(o, o, o, indexing="ij"))
    vertical = max(radius * flatness, 0.5)
    r = np.sqrt((ox**2 + oy**2) / radius**2 + oz**2 / vertical**2)
    keep = (r <= 1.0) & ((r <= 0.6) | (rng.random(r.size) < 0.6))
    keep[(ox == 0) & (oy == 0) & (oz == 0)] = True
    return np.stack([ox[keep], oy[keep], oz[keep]], axis=1).astype(np.int32)


# ---- assembly -----------------------------------------------------------------


def _concat(pieces) -> np.ndarray:
    pieces = [np.asarray(p, dtype=np.int32).reshape(-1, 3) for p in pieces if len(p)]
    return np.concatenate(pieces) if pieces else np.zeros((0, 3), dtype=np.int32)


def _clip(voxels, nx, ny) -> np.ndarray:
    voxels = np.asarray(voxels, dtype=np.int32).reshape(-1, 3)
    inside = (
        (voxels[:, 0] >= 0)
        & (voxels[:, 0] < nx)
        & (voxels[:, 1] >= 0)
        & (voxels[:, 1] < ny)
        & (voxels[:, 2] >= 0)
    )
    return voxels[inside]


def _merge_labelled(lists) -> tuple[np.ndarray, np.ndarray]:
    """Union of voxel lists (sorted like ``_merge``) and the 1-based index of the list
    each voxel came from; a voxel in several lists keeps the first."""
    voxels = _concat(lists)
    labels = np.repeat(np.arange(1, len(lists) + 1, dtype=np.int32), [len(v) for v in lists])
    if not len(voxels):
        return voxels, labels
    top = voxels.max(axis=0).astype(np.int64) + 1
    keys = (voxels[:, 0].astype(np.int64) * top[1] + voxels[:, 1]) * top[2] + voxels[:, 2]
    order = np.argsort(keys, kind="stable")
    keys = keys[order]
    first = np.concatenate(([True], keys[1:] != keys[:-1]))
    return voxels[order[first]], labels[order[first]]


def _merge(lists) -> np.ndarray:
    """Union of voxel lists, sorted by x, then y, then z."""
    voxels = _concat(lists)
    if not len(voxels):
        return voxels
    top = voxels.max(axis=0).astype(np.int64) + 1
    keys = (voxels[:, 0].astype(np.int64) * top[1] + voxels[:, 1]) * top[2] + voxels[:, 2]
    keys.sort()  # np.unique's hashing is many times slower on millions of keys
    keys = keys[np.concatenate(([True], keys[1:] != keys[:-1]))]
    z = keys % top[2]
    y = (keys // top[2]) % top[1]
    x = keys // (top[1] * top[2])
    return np.stack([x, y, z], axis=1).astype(np.int32)
