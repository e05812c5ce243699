"""The settings a speed-against-accuracy study compares.

A setting is one way to trace a scan: a backend, a method (exact traversal or
the report's fixed-step march), a float precision, a march step, and the ray
grid m (m x m rays per detector). The exact float64 numba trace at the same m
is the per-ray reference; exact float64 numba at the largest m (8 in the full
study) is the converged reference for coverage.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from ladartui.tracing.backend import PRECISIONS

MARCH_STEPS = (1.0, 0.5, 0.25, 0.1)
RAY_GRIDS = (1, 2, 4, 8)
QUICK_RAY_GRIDS = (1, 2)
QUICK_MARCH_STEPS = (1.0, 0.25)


@dataclass(frozen=True)
class Setting:
    """One traced configuration: backend, method, precision, march step, ray grid."""

    backend: str
    method: str
    precision: str = "f64"
    step: float | None = None
    ray_grid: int = 1

    @property
    def tracer(self) -> tuple:
        """The setting without its ray grid: what a tracer call needs."""
        return (self.backend, self.method, self.precision, self.step)

    @property
    def tracer_label(self) -> str:
        if self.method == "march":
            return f"{self.backend} march {self.step:g} {self.precision}"
        return f"{self.backend} exact {self.precision}"

    @property
    def label(self) -> str:
        return f"{self.tracer_label} m={self.ray_grid}"

    @property
    def is_reference(self) -> bool:
        """True for the per-ray reference: exact float64 numba."""
        return (self.backend, self.method, self.precision) == ("numba", "exact", "f64")

    def to_dict(self) -> dict:
        return asdict(self)


def reference_setting(ray_grid: int) -> Setting:
    """Exact float64 numba at ray grid ``ray_grid``: the answer every setting is measured against."""
    return Setting("numba", "exact", "f64", None, ray_grid)


def tracer_settings(steps=MARCH_STEPS, exact_wgpu=PRECISIONS, march_backends=("numba", "wgpu")):
    """Tracer configurations (ray grid 1): exact numba, exact wgpu per precision, march per step.

    The numba backend computes in float64 only. The wgpu march runs in float32,
    the precision a GPU would use for a fast approximate method.
    """
    out = [reference_setting(1)]
    out += [Setting("wgpu", "exact", precision) for precision in exact_wgpu]
    for backend in march_backends:
        precision = "f32" if backend == "wgpu" else "f64"
        out += [Setting(backend, "march", precision, float(step)) for step in steps]
    return out


def study_settings(ray_grids=RAY_GRIDS, steps=MARCH_STEPS, **tracer_options) -> list[Setting]:
    """Every tracer configuration at every ray grid, reference first at each grid."""
    out = []
    for m in ray_grids:
        for tracer in tracer_settings(steps, **tracer_options):
            out.append(Setting(tracer.backend, tracer.method, tracer.precision, tracer.step, int(m)))
    return out


def full_settings() -> list[Setting]:
    """The full study: 3 exact tracers and march at 4 steps on 2 backends, ray grids 1, 2, 4, 8."""
    return study_settings(RAY_GRIDS, MARCH_STEPS)


def quick_settings() -> list[Setting]:
    """A fast check: exact numba and wgpu f32, march at steps 1.0 and 0.25, ray grids 1 and 2."""
    return study_settings(QUICK_RAY_GRIDS, QUICK_MARCH_STEPS, exact_wgpu=("f32",))
