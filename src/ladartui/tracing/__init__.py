"""Ray tracing against a voxel scene: ``trace()`` and its result.

``trace`` takes rays in metres (scene frame), converts them to cell space
(``c = p / voxel_size + 0.5``: voxel i spans [i, i+1)), runs a backend and
converts ranges back to metres. See docs/architecture.md, "Trace contract".
"""

from __future__ import annotations

import functools
import threading
import time
from dataclasses import dataclass, field

import numpy as np

from ladartui.errors import BackendUnavailable, Described, FieldError, check_callbacks, described
from ladartui.scene.voxel_arrays import voxel_size_field
from ladartui.tracing.backend import (
    GROUND,
    METHODS,
    MISS,
    PRECISIONS,
    VOXEL,
    backend_names,
    backend_status,
    check_step,
    get_backend,
)
from ladartui.tracing.backend_choice import CHOICES, learns
from ladartui.tracing.config import DEFAULT_STEP
from ladartui.tracing.passes import recording, timed

__all__ = [
    "trace",
    "TraceResult",
    "choose_backend",
    "auto_summary",
    "to_cells",
    "MISS",
    "VOXEL",
    "GROUND",
    "METHODS",
    "backend_names",
    "backend_status",
    "get_backend",
]

TINY = 1e-200


@dataclass
class TraceResult:
    """Per-ray answers: kind (MISS/VOXEL/GROUND), voxel index, range in metres."""

    kind: np.ndarray
    index: np.ndarray
    range: np.ndarray
    backend: str
    method: str
    info: dict = field(default_factory=dict)

    def __len__(self):
        return len(self.kind)

    def as_array(self) -> np.ndarray:
        """(N, 5) float64: kind, i, j, k, range."""
        return np.column_stack([self.kind.astype(np.float64), self.index.astype(np.float64), self.range])


@functools.cache
def choose_backend() -> str:
    """wgpu on a real GPU adapter, else numba (probed once): auto's backend, except that
    exact float64 calls then go to whichever of wgpu and numba has traced calls of
    their size faster (tracing/backend_choice.py)."""
    try:
        gpu = get_backend("wgpu")
        if str(gpu.describe().get("adapter_type", "")).lower() in (
            "discretegpu",
            "integratedgpu",
            "discrete",
            "integrated",
        ):
            return "wgpu"
    except (BackendUnavailable, FieldError):
        pass
    return "numba"


def auto_summary() -> str:
    """One line: what ``backend="auto"`` traces with on this machine."""
    best = choose_backend()
    if learns(best, "exact", "f64"):
        return f"{best} (a GPU) or numba, whichever has traced calls of that size faster"
    return f"{best}, the fastest here (no GPU adapter)"


def to_cells(origins_m, voxel_size):
    """Metres to cell space: voxel (i, j, k) spans [i, i+1) x [j, j+1) x [k, k+1)."""
    return np.asarray(origins_m, dtype=np.float64) / voxel_size + 0.5


def trace(
    scene_or_occupancy,
    origins,
    directions,
    backend="auto",
    method="exact",
    step=None,
    precision="f64",
    voxel_size=None,
    cancel: threading.Event | None = None,
) -> TraceResult:
    """Trace rays (metres, scene frame) against a Scene or an Occupancy.

    ``method`` is "exact" (first voxel whose interior the ray enters) or "march"
    (the report's fixed-step sampling, ``step`` in voxels, default 0.5).
    ``backend`` is a registered name or "auto". Ranges come back in metres.
    A Scene gives its own voxel size; an Occupancy takes ``voxel_size`` (default
    1.0). ``precision`` is "f64" or "f32" (numba always computes in float64);
    ``cancel`` (a threading.Event) is checked between chunks of rays.
    """
    occupancy, voxel_size = _occupancy_and_size(scene_or_occupancy, voxel_size)
    check_callbacks(cancel=cancel)
    origins = _rays("origins", origins)
    directions = _rays("directions", directions)
    if origins.shape != directions.shape:
        raise FieldError("directions", described(directions), f"the same shape as origins {origins.shape}")
    if method not in METHODS:
        raise FieldError("method", method, "one of " + ", ".join(METHODS))
    if step is None:
        step = DEFAULT_STEP
    check_step(step)
    if precision not in PRECISIONS:
        raise FieldError("precision", precision, " or ".join(PRECISIONS))
    learned = None  # auto's learned choice between a GPU and the host's cores (backend_choice)
    if backend in (None, "auto"):
        name = choose_backend()
        if learns(name, method, precision):
            learned = CHOICES.choice(occupancy, name, len(origins))
            name = learned.pick()
    else:
        name = backend
    engine = get_backend(name)
    # Unit directions with components below TINY set to 0 (keeps 1 / d finite;
    # moves a ray by nothing measurable), origins in cell space.
    from ladartui.tracing.order_choice import compile_time  # numba: loaded on first trace
    from ladartui.tracing.prepare import rays_to_cells, scale_in_place

    with recording() as passes, _scratch().arrays(len(origins)) as scratch:
        with timed("rays to cells"):
            origin_cells, unit, block_bounds = rays_to_cells(origins, directions, voxel_size, TINY, scratch)
        with compile_time() as compiling:
            started = time.perf_counter()
            cells = engine.trace_cells(
                occupancy,
                origin_cells,
                unit,
                method=method,
                step=float(step),
                precision=precision,
                cancel=cancel,
                block_bounds=block_bounds,
            )
            seconds = time.perf_counter() - started
        if learned is not None:
            learned.record(name, seconds - compiling.seconds, len(unit))
        info = dict(cells.info)
        info["seconds_total"] = seconds
        with timed("to metres"):
            metres = cells.t
            if metres.base is None and metres.flags.writeable:  # the backend's own new array: scaled in place
                scale_in_place(metres, voxel_size)
            else:
                metres = metres * voxel_size
    info["passes"] = passes
    return TraceResult(cells.kind, cells.index, metres, name, method, info)


@functools.cache
def _scratch():
    """The cell-space rays' arrays kept between calls (``prepare.Scratch``): up to four
    scans' worth (48 MB), so a sweep's long calls do not hold more for good."""
    from ladartui.tracing.prepare import Scratch

    return Scratch(most=4 * 262_144)


def _occupancy_and_size(target, voxel_size):
    from ladartui.scene.occupancy import Occupancy

    if isinstance(target, Occupancy):
        occupancy = target
        size = 1.0 if voxel_size is None else voxel_size
    elif hasattr(target, "occupancy") and hasattr(target, "voxel_size"):
        occupancy = target.occupancy
        size = target.voxel_size
        if voxel_size is not None and voxel_size != size:  # would move its voxels in metres
            raise FieldError("voxel_size", voxel_size, f"the scene's voxel size ({size}) or None")
    else:
        raise FieldError("scene", described(target), "a Scene or an Occupancy")
    return occupancy, voxel_size_field(size)


def _rays(name, values):
    if np.iscomplexobj(values):  # (numpy would drop the imaginary parts with a warning)
        raise FieldError(name, Described("a complex array"), "an (N, 3) array of real numbers")
    try:
        given = np.asarray(values)
        array = None if given.dtype == np.bool_ else given.astype(np.float64, copy=False)
    except (TypeError, ValueError):
        raise FieldError(name, described(values), "an (N, 3) array of numbers") from None
    if array is None:  # a mask given for the rays: True read as 1
        shown = Described("an array of bool") if isinstance(values, np.ndarray) else described(values)
        raise FieldError(name, shown, "an (N, 3) array of numbers")
    if array.ndim == 1 and array.shape == (3,):
        array = array[None, :]
    if array.ndim != 2 or array.shape[1] != 3:
        raise FieldError(name, described(values), "an (N, 3) array")
    return array
