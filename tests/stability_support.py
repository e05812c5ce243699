"""Cases, tracers and checks of tests/test_stability.py: a case is a scene and rays in
cell space; ``check_all`` traces it with every tracer and checks each answer (valid,
within a time bound, equal to the float64 reference for exact methods, never earlier
than it for the march)."""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

from ladartui.scene.occupancy import Occupancy
from ladartui.tracing import GROUND, MISS, VOXEL, backend_status, trace
from ladartui.tracing.reference import reference_trace_cells

CALL_SECONDS = 60.0  # a call that takes longer is taken for an endless loop
F32_RELATIVE = 2e-6  # float32 rounding allowance, relative to the scene size (about 16 ulp)
MARCH_STEPS = (1.0, 0.5, 0.25, 0.1)
EXAMPLES = settings(
    max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)


def _tracers():
    status = backend_status()
    out = []
    if status.get("numba") is None:
        out += [("numba", "exact", "f64"), ("numba", "march", "f64")]
    if "wgpu" in status and status["wgpu"] is None:
        out += [("wgpu", "exact", "f64"), ("wgpu", "exact", "f32"), ("wgpu", "march", "f32")]
    return out


TRACERS = _tracers()
EXACT = [t for t in TRACERS if t[1] == "exact"]
MARCH = [t for t in TRACERS if t[1] == "march"]
ids = ["-".join(t) for t in TRACERS]


_WARM: set = set()


def warm(tracer):
    """Compile a tracer's kernels or shaders once, outside the per-call time bound."""
    if tracer in _WARM:
        return
    backend, method, precision = tracer
    trace(
        Occupancy.build(np.array([[0, 0, 0]]), (2, 2, 2)),
        [[0.0, 0.0, 3.0]],
        [[0.0, 0.0, -1.0]],
        backend=backend,
        method=method,
        precision=precision,
    )
    _WARM.add(tracer)


def tracer_param(tracers):
    return pytest.mark.parametrize("tracer", tracers, ids=["-".join(t) for t in tracers])


# --------------------------------------------------------------------------- cases and checks


class Case:
    """A scene (voxel list and shape) and rays, all in cell space."""

    def __init__(self, voxels, shape, origins, directions, voxel_size=1.0):
        self.voxels = np.asarray(voxels, np.int64).reshape(-1, 3)
        self.shape = tuple(int(s) for s in shape)
        self.occupancy = Occupancy.build(self.voxels, self.shape)
        self.origins = np.asarray(origins, np.float64).reshape(-1, 3)
        d = np.asarray(directions, np.float64).reshape(-1, 3)
        self.directions = d / np.linalg.norm(d, axis=1, keepdims=True)
        self.voxel_size = float(voxel_size)
        # What ``trace`` receives, and the cell-space rays it derives from that (it
        # converts and normalises again), so the reference sees the very same bits.
        self.metres = (self.origins - 0.5) * self.voxel_size
        self.origins = self.metres / self.voxel_size + 0.5
        self.directions = self.directions / np.linalg.norm(self.directions, axis=1)[:, None]
        self.sent_directions = d / np.linalg.norm(d, axis=1, keepdims=True)

    def run(self, tracer, step=0.5):
        """(kind, index, t in cells) from ``tracer``, on a watchdog thread."""
        backend, method, precision = tracer
        warm(tracer)
        metres = self.metres
        box = {}

        def call():
            try:
                box["result"] = trace(
                    self.occupancy,
                    metres,
                    self.sent_directions,
                    backend=backend,
                    method=method,
                    step=step,
                    precision=precision,
                    voxel_size=self.voxel_size,
                )
            except BaseException as error:  # handed to the test thread
                box["error"] = error

        worker = threading.Thread(target=call, daemon=True)
        worker.start()
        worker.join(CALL_SECONDS)
        assert not worker.is_alive(), f"{tracer} did not return within {CALL_SECONDS} s"
        if "error" in box:
            raise box["error"]
        r = box["result"]
        return r.kind, r.index, r.range / self.voxel_size

    def reference(self):
        ref = reference_trace_cells(self.voxels, self.shape, self.origins, self.directions)
        return ref.kind, ref.index, ref.t


def precision_eps(case: Case, precision) -> float:
    """How far (cells) a float32 trace may be off: a few ulps of the scene's coordinates.

    The float32 shader sees coordinates no larger than the scene (the host moves
    each origin to the scene box in float64 first), so its rounding grows with
    the scene's size, not with the aircraft's distance.
    """
    if precision == "f64":
        return 1e-9
    return F32_RELATIVE * max(1.0, float(max(case.shape)))


def assert_valid(case: Case, answer, method, precision="f64"):
    """Kinds, cells and ranges that make sense, checked against the ray itself."""
    kind, index, t = answer
    n = len(case.origins)
    assert kind.shape == (n,) and index.shape == (n, 3) and t.shape == (n,)
    assert set(np.unique(kind).tolist()) <= {MISS, VOXEL, GROUND}
    assert not np.isnan(t).any()
    miss, voxel, ground = kind == MISS, kind == VOXEL, kind == GROUND
    assert np.all(index[miss] == -1) and np.all(np.isinf(t[miss]))
    assert np.all(np.isfinite(t[~miss])) and np.all(t[~miss] >= 0)
    assert case.occupancy.contains(index[voxel]).all(), "a voxel answer that is not occupied"
    nx, ny = case.shape[0], case.shape[1]
    g = index[ground]
    assert np.all(g[:, 2] == 0) and np.all((g[:, 0] >= 0) & (g[:, 0] < nx))
    assert np.all((g[:, 1] >= 0) & (g[:, 1] < ny))
    # The point at the range lies in the answer's cell (march: its sample; exact: the entry).
    finite_t = np.where(np.isfinite(t), t, 0.0)
    point = case.origins + finite_t[:, None] * case.directions
    eps = precision_eps(case, precision)
    tol = (
        1e-9 * np.maximum(1.0, np.abs(point))
        + eps
        + 1e-12 * np.maximum(1.0, finite_t)[:, None] * np.ones((1, 3))
    )
    cell = index[voxel]
    p = point[voxel]
    assert np.all((p >= cell - tol[voxel]) & (p <= cell + 1 + tol[voxel])), "range off its voxel"
    pg = point[ground]
    tg = tol[ground]
    assert np.all((pg[:, :2] >= g[:, :2] - tg[:, :2]) & (pg[:, :2] <= g[:, :2] + 1 + tg[:, :2]))
    if method == "exact":
        assert np.all(np.abs(pg[:, 2]) <= tg[:, 2]), "ground return off the ground plane"
    else:
        assert np.all(pg[:, 2] <= tg[:, 2]), "march ground sample above the ground"


def _slab(o, d, lo, hi):
    """Entry and exit parameters of the ray through the box [lo, hi] (f64, per axis)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = (lo - o) / d
        t1 = (hi - o) / d
    inside = (o > lo) & (o < hi)
    near = np.where(d == 0, np.where(inside, -np.inf, np.inf), np.minimum(t0, t1))
    far = np.where(d == 0, np.where(inside, np.inf, -np.inf), np.maximum(t0, t1))
    return max(near.max(), 0.0), far.min()


def _fragile(case, i, kind, cell, eps) -> bool:
    """Whether this answer for ray ``i`` hangs on a tie within ``eps`` of the ray."""
    o, d = case.origins[i], case.directions[i]
    if kind == VOXEL:
        t_in, t_out = _slab(o, d, cell.astype(float), cell + 1.0)
        return t_out - t_in < eps  # the ray only clips or touches the voxel
    if d[2] < 0 and o[2] > 0:  # ground or miss: where the ray meets the ground
        g = o + (-o[2] / d[2]) * d
        edges = np.abs(g[:2] - np.round(g[:2]))
        # A height error of eps moves the ground point by eps / tan(depression).
        return bool(edges.min() < eps * (1.0 + math.hypot(d[0], d[1]) / abs(d[2])))
    return False


def _near(case, i, kind, cell, eps) -> bool:
    """A voxel answer must lie within ``eps`` of the ray (the ray meets its grown cube)."""
    if kind != VOXEL:
        return True
    o, d = case.origins[i], case.directions[i]
    t_in, t_out = _slab(o, d, cell - eps, cell + 1.0 + eps)
    return t_out > t_in


def assert_same(answer, reference, precision, what="", case=None, record=None):
    """Equal to the reference; float32 may differ only on ties within its rounding."""
    kind, index, t = answer
    r_kind, r_index, r_t = reference
    differ = (kind != r_kind) | np.any(index != r_index, axis=1)
    bad = np.flatnonzero(differ)
    if precision == "f32" and case is not None and bad.size:
        eps = precision_eps(case, precision)
        explained = [
            _near(case, i, kind[i], index[i], eps)
            and (_fragile(case, i, r_kind[i], r_index[i], eps) or _fragile(case, i, kind[i], index[i], eps))
            for i in bad
        ]
        if record is not None:
            record(f"{what}float32 ties within {eps:.1e} cells", int(np.sum(explained)))
        bad = bad[~np.array(explained, bool)]
    assert bad.size == 0, (
        f"{what}{bad.size} of {len(kind)} rays differ from the reference; "
        f"first ray {bad[0]}: {kind[bad[0]]} {index[bad[0]]} vs "
        f"{r_kind[bad[0]]} {r_index[bad[0]]}"
    )
    same = ~differ & (r_kind != MISS)
    if precision == "f64":
        np.testing.assert_allclose(t[same], r_t[same], rtol=1e-9, atol=1e-9)
    else:
        eps = precision_eps(case, precision) if case is not None else 1e-3
        np.testing.assert_allclose(t[same], r_t[same], rtol=F32_RELATIVE, atol=10 * eps)


def assert_never_earlier(case: Case, answer, reference) -> int:
    """March only ends earlier than the exact answer where a sample sits on a cell boundary.

    The report's march samples along the ray from the canopy top, so it normally
    ends later. A sample exactly on a boundary is given to the higher cell
    (floor), whose interior the ray may only touch: then it ends earlier. Returns
    how many rays ended earlier (all of them on a boundary).
    """
    t = answer[2]
    r_t = reference[2]
    scale = np.maximum(1.0, np.abs(np.where(np.isfinite(r_t), r_t, 0.0)))
    earlier = t < r_t - 1e-6 * scale
    point = case.origins[earlier] + t[earlier, None] * case.directions[earlier]
    on_boundary = np.any(np.abs(point - np.round(point)) <= 1e-9 * np.maximum(1, np.abs(point)), axis=1)
    assert on_boundary.all(), "march ended earlier than the exact answer off a cell boundary"
    return int(earlier.sum())


def differ_rate(answer, reference) -> float:
    kind, index, _ = answer
    r_kind, r_index, _ = reference
    return float(np.mean((kind != r_kind) | np.any(index != r_index, axis=1)))


def check_all(case: Case, tracers, record=None, label=""):
    """Every tracer: valid; exact ones equal the reference; march never earlier (rate recorded)."""
    reference = case.reference()
    for tracer in tracers:
        steps = MARCH_STEPS if tracer[1] == "march" else (0.5,)
        for step in steps:
            answer = case.run(tracer, step)
            assert_valid(case, answer, tracer[1], tracer[2])
            if tracer[1] == "exact":
                assert_same(answer, reference, tracer[2], f"{'-'.join(tracer)} {label}: ", case, record)
            else:
                earlier = assert_never_earlier(case, answer, reference)
                if record is not None:
                    name = f"{label} {'-'.join(tracer)} step {step}"
                    record(f"{name} differ rate", differ_rate(answer, reference))
                    record(f"{name} earlier on a boundary", earlier)
    return reference


def random_scene(rng, nx, ny, nz, density):
    mask = rng.random((nx, ny, nz)) < density
    return np.argwhere(mask)
