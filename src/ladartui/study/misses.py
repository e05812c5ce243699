"""Where a tracing method's first hits differ from the exact answer, and why.

A ray *differs* when its kind (miss, voxel, ground) or its cell differs from
the exact float64 answer for the same ray. Each differing ray is classified by
the geometry of its *feature voxel*: the voxel the exact answer hit, or, when
the exact answer is ground or a miss, the voxel the method hit. Classes are not
exclusive (a ray can be thin and diagonal); each is also counted over all rays
that hit a voxel, so a class that explains misses shows up over-represented
(``class_share`` against ``base_share``: a class's share of the differing rays
that have a feature voxel, against its share of every voxel hit).

- thin: the ray's chord through the feature voxel is shorter than
  ``THIN_CHORD`` voxel and the voxel it leaves into is empty, so the occupied
  run along the ray is shorter than a march step of 1 (a corner clipped, a
  one-voxel branch crossed on the slant).
- diagonal: the ray is far from every grid axis: its second-largest direction
  component is at least ``DIAGONAL_RATIO`` of its largest (more than about
  27 degrees off the nearest axis in its main plane).
- grazing: the ray meets the face it enters by less than ``GRAZING_DEG``
  degrees (a near-horizontal ray entering a top face, a near-vertical ray
  entering a side face).
- edge: the entry point lies within ``EDGE_TOL`` voxel of an edge or corner
  of the feature voxel, where rounding decides between neighbours.

Outcome: *later* when the method's range exceeds the exact range (it passed
through something: the report's march almost only errs this way), *earlier*
when it is shorter. ``no_voxel`` counts differing rays with no voxel on either
side (a ground return in a neighbouring cell, or ground against a miss); they
have no feature voxel and no class.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ladartui.tracing.backend import MISS, VOXEL

CLASSES = ("thin", "diagonal", "grazing", "edge")
THIN_CHORD = 1.0
DIAGONAL_RATIO = 0.5
GRAZING_DEG = 10.0
EDGE_TOL = 0.02


def differing(exact_kind, exact_index, kind, index) -> np.ndarray:
    """Boolean mask: rays whose kind or cell differs from the exact answer."""
    exact_kind = np.asarray(exact_kind)
    kind = np.asarray(kind)
    same_cell = np.all(np.asarray(exact_index) == np.asarray(index), axis=1)
    return (exact_kind != kind) | ((exact_kind != MISS) & ~same_cell)


def voxel_geometry(origins, directions, voxels, occupancy=None) -> dict[str, np.ndarray]:
    """Class masks (see the module docstring) of rays against one voxel each.

    ``origins`` and ``directions`` are cell-space (N, 3) float64 (voxel i spans
    [i, i+1)); ``voxels`` are (N, 3) integer cells. ``occupancy`` decides
    whether the cell a ray leaves into is occupied (without it, never).
    """
    o = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    v = np.asarray(voxels, dtype=np.float64).reshape(-1, 3)
    n = len(o)
    if n == 0:
        return {name: np.zeros(0, bool) for name in CLASSES}
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    flat = d == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = (v - o) / d
        t1 = (v + 1.0 - o) / d
    near = np.minimum(t0, t1)
    far = np.maximum(t0, t1)
    # A ray parallel to an axis is inside that slab for all t, or never.
    inside_slab = (o > v) & (o < v + 1.0)
    near = np.where(flat, np.where(inside_slab, -np.inf, np.inf), near)
    far = np.where(flat, np.where(inside_slab, np.inf, -np.inf), far)
    entry_axis = np.argmax(near, axis=1)
    exit_axis = np.argmin(far, axis=1)
    rows = np.arange(n)
    t_in = np.maximum(near[rows, entry_axis], 0.0)
    t_out = far[rows, exit_axis]
    chord = np.clip(t_out - t_in, 0.0, None)

    exit_cell = v.astype(np.int64)
    exit_cell[rows, exit_axis] += np.where(d[rows, exit_axis] > 0, 1, -1)
    if occupancy is not None:
        continues = np.asarray(occupancy.contains(exit_cell), bool)
    else:
        continues = np.zeros(n, bool)
    thin = (chord < THIN_CHORD) & ~continues

    a = np.sort(np.abs(d), axis=1)
    diagonal = a[:, 1] >= DIAGONAL_RATIO * a[:, 2]

    grazing = np.abs(d[rows, entry_axis]) < np.sin(np.radians(GRAZING_DEG))

    entry = o + np.where(np.isfinite(t_in), t_in, 0.0)[:, None] * d
    margin = np.minimum(entry - v, v + 1.0 - entry)
    margin[rows, entry_axis] = np.inf
    edge = np.min(margin, axis=1) < EDGE_TOL
    return {"thin": thin, "diagonal": diagonal, "grazing": grazing, "edge": edge}


@dataclass
class MissSummary:
    """Counts of differing rays by class and outcome, summed over scans."""

    rays: int = 0
    voxel_rays: int = 0
    differing: int = 0
    later: int = 0
    earlier: int = 0
    no_voxel: int = 0
    classes: dict = field(default_factory=lambda: {name: 0 for name in CLASSES})
    base: dict = field(default_factory=lambda: {name: 0 for name in CLASSES})

    @property
    def share(self) -> float | None:
        """Share of rays whose first hit differs (0..1), None with no rays."""
        return self.differing / self.rays if self.rays else None

    def class_share(self, name: str) -> float | None:
        """Share of the differing rays with a feature voxel (those a class can describe)
        that fall in class ``name``; None when no differing ray has one."""
        classified = self.differing - self.no_voxel
        return self.classes[name] / classified if classified > 0 else None

    def base_share(self, name: str) -> float | None:
        """Share of all the rays whose exact answer is a voxel that fall in class ``name``:
        what ``class_share`` is set against; None when no ray hit a voxel."""
        return self.base[name] / self.voxel_rays if self.voxel_rays else None

    def add(self, other: MissSummary) -> None:
        self.rays += other.rays
        self.voxel_rays += other.voxel_rays
        self.differing += other.differing
        self.later += other.later
        self.earlier += other.earlier
        self.no_voxel += other.no_voxel
        for name in CLASSES:
            self.classes[name] += other.classes[name]
            self.base[name] += other.base[name]

    def to_dict(self) -> dict:
        return {
            "rays": self.rays,
            "voxel_rays": self.voxel_rays,
            "differing": self.differing,
            "share": self.share,
            "later": self.later,
            "earlier": self.earlier,
            "no_voxel": self.no_voxel,
            "classes": dict(self.classes),
            "base": dict(self.base),
        }

    def describe(self) -> str:
        """One line: how many differ, which way, and which classes they fall in."""
        if not self.differing:
            return "no differing rays"
        parts = []
        for name in CLASSES:
            own, base = self.class_share(name), self.base_share(name)
            if own is not None:
                parts.append(f"{name} {own:.0%} (all rays {base or 0.0:.0%})")
        said = (
            f"{self.differing} differ ({self.later} later, {self.earlier} earlier, "
            f"{self.no_voxel} ground or miss on both sides)"
        )
        return "; ".join([said, ", ".join(parts)]) if parts else said


def summarise(origins, directions, exact, other, occupancy=None, exact_voxel_classes=None) -> MissSummary:
    """Compare one scan's answers with the exact ones and classify the differing rays.

    ``exact`` and ``other`` are (kind, index, range) triples over the same rays;
    ``origins`` and ``directions`` are in cell space. ``exact_voxel_classes``
    may pass the class masks of the exact voxel hits, computed once per scan.
    """
    e_kind, e_index, e_range = (np.asarray(x) for x in exact)
    m_kind, m_index, m_range = (np.asarray(x) for x in other)
    out = MissSummary(rays=len(e_kind))
    e_voxel = e_kind == VOXEL
    out.voxel_rays = int(e_voxel.sum())
    if exact_voxel_classes is None:
        exact_voxel_classes = voxel_geometry(
            origins[e_voxel], directions[e_voxel], e_index[e_voxel], occupancy
        )
    for name in CLASSES:
        out.base[name] = int(exact_voxel_classes[name].sum())
    diff = differing(e_kind, e_index, m_kind, m_index)
    out.differing = int(diff.sum())
    if not out.differing:
        return out
    out.later = int((diff & (m_range > e_range)).sum())
    out.earlier = int((diff & (m_range < e_range)).sum())
    feature = np.where(e_voxel[:, None], e_index, m_index)
    has_feature = diff & ((e_kind == VOXEL) | (m_kind == VOXEL))
    out.no_voxel = int((diff & ~has_feature).sum())
    classes = voxel_geometry(origins[has_feature], directions[has_feature], feature[has_feature], occupancy)
    for name in CLASSES:
        out.classes[name] = int(classes[name].sum())
    return out
