"""The trees of a generated forest (scene.generate): where they stand, and their
trunks, branches and crowns of leaf clumps as voxels.

A trunk is a hollow tapering tube (only its skin can be seen); a crown is a
shell of small flattened leaf clumps with real gaps between them, broadleaf
ellipsoids and conifer cones, ``density`` of its surface covered. Grid units
throughout; the parameters are scene.generate's ``SceneParams``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ladartui.scene.generate import SceneParams


def concat_voxels(pieces) -> np.ndarray:
    """(N, 3) int32 voxels of the non-empty pieces, in order."""
    pieces = [np.asarray(p, dtype=np.int32).reshape(-1, 3) for p in pieces if len(p)]
    return np.concatenate(pieces) if pieces else np.zeros((0, 3), dtype=np.int32)


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


def place_trees(p: SceneParams, nx, ny, ground, vehicles, rng) -> _Trees:
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


def trunk_voxels(trees: _Trees, vs) -> np.ndarray:
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
    return concat_voxels(pieces)


def _crown_centre(trees: _Trees):
    """Centre (grid) and half-height of each crown's envelope."""
    half = (trees.height - trees.crown_base) / 2
    return trees.base + trees.crown_base + half, half


def branch_voxels(trees: _Trees, p: SceneParams, rng) -> np.ndarray:
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


def clumps_per_tree(trees: _Trees, p: SceneParams) -> np.ndarray:
    """How many leaf clumps each crown gets: ``density`` of its envelope's surface covered."""
    _, half = _crown_centre(trees)
    radius = trees.crown_radius
    # Envelope surface areas (grid units squared): ellipsoid (Thomsen) or cone side.
    a, c = radius, half
    ellipsoid = 4 * np.pi * (((a * a) ** 1.6 + 2 * (a * c) ** 1.6) / 3) ** (1 / 1.6)
    cone = np.pi * radius * np.hypot(radius, 2 * half)
    area = np.where(trees.conifer, cone, ellipsoid)
    clump_area = np.pi * (np.mean(p.clump_radius) / p.voxel_size) ** 2
    return np.ceil(-math.log(1 - p.density) * area / clump_area).astype(np.int64)


# The trunks' and branches' voxels beside the crowns' (1.2x: small preset, 2,000 and
# 8,000 trees; the estimate came within 0.97-1.17x of the count there, 0.8x on the
# reference preset).
WOOD_SHARE = 1.2


def expected_tree_voxels(trees: _Trees, p: SceneParams) -> float:
    """About how many voxels the trees' parts make before merging (for a memory estimate
    ahead of the work): the clumps times a clump template's expected size."""
    # over the radii as _stamp_clumps rounds them (the volume goes as the cube: the
    # mean radius alone undercounted large clumps by a fifth)
    classes = _size_classes(np.linspace(*p.clump_radius, 9) / p.voxel_size)
    template = max(float(np.mean([expected_clump_voxels(size) for size in classes])), 1.0)
    return float(clumps_per_tree(trees, p).sum()) * template * WOOD_SHARE


def foliage_voxels(trees: _Trees, p: SceneParams, rng, checkpoint=None) -> np.ndarray:
    """Leaf clumps scattered through the outer shell of every crown. ``checkpoint()``,
    if given, is called between chunks of the work (a cancel can stop it there: the
    stage took 68 s for 100,000 trees)."""
    vs = p.voxel_size
    per_tree = clumps_per_tree(trees, p)
    tree = np.repeat(np.arange(len(trees)), per_tree)
    n = tree.size
    # Every random number is drawn first, in the order the scene's seed has always
    # given them; the arithmetic then runs a chunk of clumps at a time (the same
    # values: each clump's own), which a whole-array pass did in 44 s.
    depth = 1 - p.shell_depth * rng.random(n)  # share of the envelope radius
    direction = rng.normal(size=(n, 3))  # a uniform direction, scaled to the envelope
    # Lumpy envelopes: each crown bulges along a few random low-order waves.
    amplitude = rng.uniform(0.0, 0.15, (len(trees), 3))
    phase = rng.uniform(0, 2 * np.pi, (len(trees), 3))
    s = np.sqrt(rng.random(n))
    angle = rng.uniform(0, 2 * np.pi, n)
    centres = np.empty((n, 3), np.int32)
    shape = _CrownShape(trees, amplitude, phase)
    for first in range(0, n, FOLIAGE_CHUNK):
        if checkpoint is not None:
            checkpoint()
        run = slice(first, min(n, first + FOLIAGE_CHUNK))
        centres[run] = shape.clump_centres(tree[run], depth[run], direction[run], s[run], angle[run])
    clump = rng.uniform(*p.clump_radius, n) / vs
    return _stamp_clumps(centres, clump, rng, checkpoint=checkpoint)


# Clumps whose centres are computed at a time (``foliage_voxels``).
FOLIAGE_CHUNK = 1 << 20


class _CrownShape:
    """Where clumps sit on the crowns: ellipsoids (with lumps) or cones."""

    def __init__(self, trees: _Trees, amplitude, phase):
        self.trees, self.amplitude, self.phase = trees, amplitude, phase
        self.centre_z, self.half = _crown_centre(trees)

    def lumps(self, tree, azimuth, elevation):
        a, ph = self.amplitude[tree], self.phase[tree]
        return (
            1
            + a[:, 0] * np.cos(2 * azimuth + ph[:, 0])
            + a[:, 1] * np.cos(3 * azimuth + ph[:, 1])
            + a[:, 2] * np.cos(2 * elevation + ph[:, 2])
        )

    def clump_centres(self, tree, depth, direction, s, angle) -> np.ndarray:
        """The nearest voxels to the centres of clumps on crowns ``tree``."""
        trees, half = self.trees, self.half
        radius = trees.crown_radius
        direction = direction / np.linalg.norm(direction, axis=1, keepdims=True)
        # Ellipsoid: the direction scaled to the envelope.
        bulge = self.lumps(tree, np.arctan2(direction[:, 1], direction[:, 0]), np.arcsin(direction[:, 2]))
        ex = direction[:, 0] * radius[tree] * depth * bulge
        ey = direction[:, 1] * radius[tree] * depth * bulge
        ez = self.centre_z[tree] + direction[:, 2] * half[tree] * depth * bulge
        # Cone: area-uniform over the side (apex at the top of the tree).
        ring = radius[tree] * s * depth * self.lumps(tree, angle, s * np.pi)
        top = trees.base[tree] + trees.height[tree]
        is_cone = trees.conifer[tree]
        cx = trees.x[tree] + np.where(is_cone, ring * np.cos(angle), ex)
        cy = trees.y[tree] + np.where(is_cone, ring * np.sin(angle), ey)
        cz = np.where(is_cone, top - s * 2 * half[tree], ez)
        return np.floor(np.stack([cx, cy, cz], axis=1) + 0.5).astype(np.int32)


# Voxels stamped between two checkpoints (a 48 MB piece: a fraction of a second).
STAMP_VOXELS = 1 << 22


def _stamp_clumps(centres, radii, rng, variants=6, checkpoint=None) -> np.ndarray:
    """Place a ragged flattened blob at every centre; blobs grouped by size class
    (``checkpoint()`` called before each piece of up to STAMP_VOXELS voxels)."""
    classes = _size_classes(radii)
    variant = rng.integers(0, variants, len(centres))
    pieces = []
    for size in np.unique(classes):
        templates = [_clump_template(size, rng) for _ in range(variants)]
        in_class = classes == size
        for k, template in enumerate(templates):
            chosen = centres[in_class & (variant == k)]
            step = max(1, STAMP_VOXELS // max(len(template), 1))
            for first in range(0, len(chosen), step):  # in order: the same list as at once
                if checkpoint is not None:
                    checkpoint()
                run = chosen[first : first + step]
                pieces.append((run[:, None, :] + template[None, :, :]).reshape(-1, 3))
    return concat_voxels(pieces)


def _size_classes(radii) -> np.ndarray:
    """Clump radii (voxels) rounded to the half-voxel size classes clumps are stamped at."""
    return np.maximum(np.round(np.asarray(radii) * 2) / 2, 0.5)


# A leaf clump: an oblate blob (height over width CLUMP_FLATNESS), whole out to
# CLUMP_CORE of its radius, each voxel beyond it to the rim kept with CLUMP_RIM_KEPT.
CLUMP_FLATNESS = 0.35
CLUMP_CORE = 0.6
CLUMP_RIM_KEPT = 0.6


def _clump_chances(radius) -> tuple[np.ndarray, np.ndarray]:
    """(M, 3) int32 offsets around a leaf clump's centre and each one's chance of being in
    the clump. The one definition of its shape: templates draw from it, the estimate sums it."""
    reach = int(math.ceil(radius))
    o = np.arange(-reach, reach + 1)
    ox, oy, oz = (a.ravel() for a in np.meshgrid(o, o, o, indexing="ij"))
    vertical = max(radius * CLUMP_FLATNESS, 0.5)
    r = np.sqrt((ox**2 + oy**2) / radius**2 + oz**2 / vertical**2)
    chance = np.where(r <= CLUMP_CORE, 1.0, np.where(r <= 1.0, CLUMP_RIM_KEPT, 0.0))
    return np.stack([ox, oy, oz], axis=1).astype(np.int32), chance


def expected_clump_voxels(radius) -> float:
    """The expected voxels of a leaf clump of ``radius`` (a size class, voxels)."""
    return float(_clump_chances(radius)[1].sum())


def _clump_template(radius, rng) -> np.ndarray:
    """Offsets of one leaf clump: an oblate blob whose rim is thinned at random."""
    offsets, chance = _clump_chances(radius)
    return offsets[rng.random(len(chance)) < chance]  # a draw is below 1: the core is whole


# ---- assembly -----------------------------------------------------------------
