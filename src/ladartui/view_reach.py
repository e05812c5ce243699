"""Whether a scenario's scans can see its scene and its target at all, told without tracing.

A scan's rays start on the focal plane, a square ``grid * pixel_pitch`` wide
about the aircraft, and spread at most ``fov / 2`` from the boresight on each
axis. In the sensor's frame (boresight -z) every ray point at depth ``t`` below
the focal plane lies within ``|u|, |v| <= grid * pitch / 2 + t tan(fov / 2)``:
the scan's view is that frustum, and no point of it is nearer the aircraft than
its depth. Cut at the distance of a box's farthest corner it is a convex solid
of eight corners, and it meets the box unless one of 26 axes (the box's faces,
the frustum's faces, and the crossings of their edges) parts them: the
separating axis test, exact for two convex solids. The frustum holds the
outermost rays half a ray's cell inside its edges, so a scan said to miss a box
has no ray that reaches it.
"""

from __future__ import annotations

import math

import numpy as np

from ladartui.number_text import plural, trimmed

# targets x scans tested one target at a time; past it only all the targets together
MAX_TARGET_TESTS = 2_000_000
FAR_FOR_MAP = 10_000.0  # metres off the scene from which a log's x, y look like map coordinates


class ScanViews:
    """The views of scans at ``poses`` (with ``attitudes``: (roll, pitch) per scan for a
    body-fixed sensor, None for a stabilised one), to test against boxes."""

    def __init__(self, sensor, poses, attitudes):
        from ladartui.sensor import scan_rotation

        count = len(poses)
        rotations = np.array([scan_rotation(p, a) for p, a in zip(poses, attitudes)]).reshape(count, 3, 3)
        self.positions = np.array([p.position for p in poses], dtype=np.float64).reshape(count, 3)
        half = sensor.grid * sensor.pixel_pitch / 2
        spread = math.tan(math.radians(sensor.fov / 2))
        square = np.array([[-1.0, 1.0], [1.0, 1.0], [1.0, -1.0], [-1.0, -1.0]])
        starts = np.column_stack([square * half, np.zeros(4)])  # the focal plane's corners
        steps = np.column_stack([square * spread, -np.ones(4)])  # per metre of depth
        faces = [[0, 0, 1], [1, 0, spread], [-1, 0, spread], [0, 1, spread], [0, -1, spread]]
        edges = [[1, 0, 0], [0, 1, 0], *steps]
        frame = np.einsum("sij,aj->sai", rotations, np.array([*faces, *edges], dtype=np.float64))
        crossed = np.cross(frame[:, 5:, None, :], np.eye(3)[None, None]).reshape(count, 18, 3)
        axes = np.concatenate([np.broadcast_to(np.eye(3), (count, 3, 3)), frame[:, :5], crossed], axis=1)
        lengths = np.linalg.norm(axes, axis=2, keepdims=True)
        # an edge along a box axis crosses it to nothing: that axis parts nothing
        self.axes = np.divide(axes, lengths, out=np.zeros_like(axes), where=lengths > 1e-12)
        corners = self.positions[:, None, :] + np.einsum("sij,vj->svi", rotations, starts)
        self._near = np.einsum("sak,svk->sav", self.axes, corners)
        self._step = np.einsum("sak,svk->sav", self.axes, np.einsum("sij,vj->svi", rotations, steps))

    def meet(self, lo, hi) -> np.ndarray:
        """Per scan, whether its view meets the box from ``lo`` to ``hi`` (metres)."""
        lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        box = np.array([[(lo, hi)[i >> k & 1][k] for k in range(3)] for i in range(8)])
        # deeper than the farthest corner, the view is farther from the aircraft than the box
        depth = np.linalg.norm(box[None] - self.positions[:, None], axis=2).max(axis=1)
        far = self._near + depth[:, None, None] * self._step
        low = np.minimum(self._near.min(axis=2), far.min(axis=2))
        high = np.maximum(self._near.max(axis=2), far.max(axis=2))
        centre, half = (lo + hi) / 2, (hi - lo) / 2
        middle, reach = self.axes @ centre, np.abs(self.axes) @ half
        slack = 1e-9 * (np.abs(self.positions).max(axis=1) + depth + np.abs(box).max() + 1.0)[:, None]
        apart = (high < middle - reach - slack) | (low > middle + reach + slack)
        return ~apart.any(axis=1)


def voxel_box(bounds, voxel_size: float) -> tuple[np.ndarray, np.ndarray]:
    """The box (metres) the voxels with indices from ``bounds`` (least, greatest) fill:
    voxel (i, j, k) is the cube of side ``voxel_size`` centred on (i, j, k) times it."""
    lo, hi = bounds
    return (np.asarray(lo) - 0.5) * voxel_size, (np.asarray(hi) + 0.5) * voxel_size


def reach_notes(scenario, scene, partial: bool = True) -> list[str]:
    """Sentences for a path whose scans never look at ``scene`` (the scenario's, loaded),
    or at its target or one of its targets: a run of it would cover nothing there. With
    ``partial`` also one for some of its scans that do not look at the scene."""
    from ladartui.attitude import plan_attitudes

    poses = scenario.poses()
    if not (len(scene.voxels) and poses):
        return []
    views = ScanViews(
        scenario.sensor, poses, plan_attitudes(scenario.flight, scenario.speed, scenario.sensor)
    )
    many = len(poses) > 1
    none = f"none of the {plural(len(poses), 'scan')} looks" if many else "the one scan does not look"
    lo, hi = voxel_box(scene.bounds(), scene.voxel_size)
    seen = views.meet(lo, hi)
    if not seen.any():
        said = f"{none} at the scene: {_where(views.positions, lo, hi)}"
        return [said + _map_hint(scenario, views.positions, lo, hi)]
    notes = [] if seen.all() or not partial else [_missed(scenario, seen)]
    return notes + _target_notes(scenario, scene, views, none)


def _missed(scenario, seen) -> str:
    """Which of the scans, some but not all, do not look at the scene, by segment."""
    missed = int(np.count_nonzero(~seen))
    parts, first = [], 0
    for number, (segment, poses) in enumerate(
        zip(scenario.flight.segments, scenario.flight.segment_poses()), 1
    ):
        count, made = int(np.count_nonzero(~seen[first : first + len(poses)])), len(poses)
        first += made
        if count:
            parts.append(
                f"{'all ' if count == made > 1 else ''}{count:,} of segment {number} ({segment.kind})"
            )
    shown = ", ".join(parts[:3]) + (f" and {len(parts) - 3} more segments" if len(parts) > 3 else "")
    verb = "does" if missed == 1 else "do"
    return f"{missed:,} of the {plural(len(seen), 'scan')} {verb} not look at the scene: {shown}"


def _target_notes(scenario, scene, views, none: str) -> list[str]:
    """The target, or the targets, none of the scans looks at (the scene seen)."""
    if not len(scene.target):
        return []
    many = len(views.positions) > 1
    lo, hi = voxel_box(scene.bounds(target=True), scene.voxel_size)
    if not views.meet(lo, hi).any():
        reach = "their views reach" if many else "its view reaches"
        return [f"{none} at the target: {reach} the scene but not the target's box ({_box(lo, hi)})"]
    ids = scene.target_id_list
    if len(ids) < 2 or len(ids) * len(views.positions) > MAX_TARGET_TESTS:
        return []
    boxes = {i: voxel_box(box, scene.voxel_size) for i, box in _target_boxes(scene).items()}
    unseen = [i for i in ids if not views.meet(*boxes[i]).any()]
    if not unseen:
        return []
    named = [
        f"target {i}" + (f" {name!r}" if (name := dict(scenario.target_names).get(i)) else "") for i in unseen
    ]
    if len(unseen) == 1:
        return [f"{none} at {named[0]} ({_box(*boxes[unseen[0]])})"]
    shown = ", ".join(named[:3]) + (f" and {len(named) - 3} more" if len(named) > 3 else "")
    return [f"{none} at {len(unseen)} of the {len(ids)} targets: {shown}"]


def _target_boxes(scene) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """The least and greatest voxel index of each target, by id."""
    order = np.argsort(scene.target_ids, kind="stable")
    ids = scene.target_ids[order]
    voxels = scene.target[order]
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    low = np.minimum.reduceat(voxels, starts, axis=0)
    high = np.maximum.reduceat(voxels, starts, axis=0)
    return {int(ids[s]): (low[n], high[n]) for n, s in enumerate(starts)}


def _span(low: float, high: float) -> str:
    return trimmed(low) if trimmed(low) == trimmed(high) else f"{trimmed(low)}..{trimmed(high)}"


def _box(lo, hi) -> str:
    return ", ".join(f"{axis} {_span(a, b)}" for axis, a, b in zip("xyz", lo, hi))


def _distance(metres: float) -> str:
    if metres < 1000:
        return f"{trimmed(round(metres, 1))} m"
    return f"{metres / 1000:.1f} km" if metres < 100_000 else f"{metres / 1000:.0f} km"


def _where(positions, lo, hi) -> str:
    """Where the scans are against the scene's box ``lo``..``hi``, across the ground."""
    low, high = positions[:, :2].min(axis=0), positions[:, :2].max(axis=0)
    gaps = _gaps(positions, lo, hi)
    if not any(gaps):
        return (
            f"the path comes over it (x {_span(low[0], high[0])}, y {_span(low[1], high[1])} against "
            f"the scene's x {_span(lo[0], hi[0])}, y {_span(lo[1], hi[1])}), but its views point away"
        )
    sides = [
        ("east" if low[k] > hi[k] else "west") if k == 0 else ("north" if low[k] > hi[k] else "south")
        for k in range(2)
        if gaps[k]
    ]
    apart = [k for k in range(2) if gaps[k]]
    ours = ", ".join(f"{'xy'[k]} {_span(low[k], high[k])}" for k in apart)
    scene = ", ".join(f"{'xy'[k] + ' ' if len(apart) > 1 else ''}{_span(lo[k], hi[k])}" for k in apart)
    direction = "-".join(reversed(sides))  # north-east, not east-north
    return (
        f"the path lies {_distance(math.hypot(*gaps))} {direction} of it ({ours} against the scene's {scene})"
    )


def _gaps(positions, lo, hi) -> list[float]:
    """How far the scans lie outside the scene's box ``lo``..``hi`` in x and in y (0 where
    they overlap it)."""
    low, high = positions[:, :2].min(axis=0), positions[:, :2].max(axis=0)
    return [max(lo[k] - high[k], low[k] - hi[k], 0.0) for k in range(2)]


def _map_hint(scenario, positions, lo, hi) -> str:
    """For a path of flight logs far off the scene: how a log's positions are read."""
    logs = [seg for seg in scenario.flight.segments if seg.kind == "log"]
    gaps = _gaps(positions, lo, hi)
    if not logs or math.hypot(*gaps) < FAR_FOR_MAP:
        return ""
    from pathlib import Path

    name = Path(logs[0].file).name
    if logs[0].origin is not None:
        return f"; the segment's origin places {name} in the scene: is it the scene frame's origin?"
    return (
        f"; {name} gives x and y in metres from the scene's origin: map coordinates (UTM) "
        "are to be shifted to it"
    )
