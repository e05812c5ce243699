"""The tracing backend protocol and registry.

A backend traces rays in *cell space* (voxel (i, j, k) spans [i, i+1) on each
axis, see docs/architecture.md) against an ``Occupancy``. ``ladartui.trace``
converts metres to cells and back, so backends never see the voxel size.
Backends are probed lazily: an unavailable one explains why only when asked.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal, Protocol

import numpy as np

from ladartui.errors import BackendUnavailable, FieldError
from ladartui.tracing.config import GROUND, MIN_STEP, MISS, VOXEL  # noqa: F401  (the kinds of CellHits)

METHODS = ("exact", "march")  # the exact traversal; the report's fixed-step march
PRECISIONS = ("f64", "f32")  # float64 everywhere; float32 on adapters without shader-f64
# Which order exact scans go in: "auto" lets each block go the way that has been
# faster on this occupancy (object_order.OrderChoice), "object" takes object order
# wherever it applies whatever it costs, "ray" never. The march and f32 always go
# in ray order.
TraceOrder = Literal["auto", "object", "ray"]
ORDERS: tuple[TraceOrder, ...] = ("auto", "object", "ray")


def check_order(order: str) -> TraceOrder:
    """``order`` if it is one of ORDERS, else FieldError."""
    if order not in ORDERS:
        raise FieldError("order", order, "one of " + ", ".join(ORDERS))
    return order


def check_step(step) -> None:
    """FieldError unless ``step`` is a number of voxels of at least MIN_STEP (the march's
    floor: finer never ended, or overflowed its count of samples)."""
    # bool is an int, but True is no step of one voxel
    number = isinstance(step, (int, float, np.floating, np.integer)) and not isinstance(step, bool)
    if not (number and np.isfinite(step) and step >= MIN_STEP):
        raise FieldError("step", step, f"a number of voxels from {MIN_STEP:g}")


@dataclass
class CellHits:
    """Per-ray answers in cell space: kind (u8), index (N, 3) i32, t in cell units."""

    kind: np.ndarray
    index: np.ndarray
    t: np.ndarray
    info: dict = field(default_factory=dict)


class Backend(Protocol):
    name: str
    summary: str

    def probe(self) -> str | None:
        """None when usable here, else one line: why not and what to install."""

    def describe(self) -> dict:
        """What runs the work (threads, adapter name/type/backend), for reports."""

    def trace_cells(
        self,
        occupancy,
        origins,
        directions,
        *,
        method="exact",
        step=0.5,
        precision="f64",
        cancel: threading.Event | None = None,
        order: TraceOrder = "auto",
        block_bounds=None,
    ) -> CellHits:
        """Trace (N, 3) float64 cell-space origins and unit directions (``order``: ORDERS).
        The origins may be one row broadcast to every ray (``prepare.rays_to_cells``
        gives them so when all are one point; ``prepare.float_rows``).

        ``block_bounds``, when given, is ``prepare.rays_to_cells``'s third answer for these
        rays: per block of SCAN_BLOCK rays the origins' least and greatest cells and the
        directions' sum, which a scan's frame is made of (object order)."""


_FACTORIES: dict[str, Callable[[], Backend]] = {}
_INSTANCES: dict[str, Backend] = {}
_BUILTIN_MODULES = ("ladartui.tracing.numba_backend", "ladartui.tracing.wgpu_backend")
_lock = threading.Lock()
_builtin_loaded = False


def register_backend(name: str, factory: Callable[[], Backend]) -> None:
    _FACTORIES[name] = factory


def backend_names() -> list[str]:
    _load_builtin()
    return list(_FACTORIES)


def get_backend(name: str) -> Backend:
    """The usable backend ``name``; raises BackendUnavailable with the reason."""
    _load_builtin()
    if not isinstance(name, str) or name not in _FACTORIES:  # (a list is unhashable)
        raise FieldError("backend", name, "one of " + ", ".join(["auto", *_FACTORIES]))
    with _lock:
        if name not in _INSTANCES:
            _INSTANCES[name] = _FACTORIES[name]()
    backend = _INSTANCES[name]
    reason = backend.probe()
    if reason:
        raise BackendUnavailable(f"backend {name!r} is unavailable: {reason}")
    return backend


def backend_status() -> dict[str, str | None]:
    """Each registered backend's probe answer (None = available)."""
    status: dict[str, str | None] = {}
    for name in backend_names():
        try:
            get_backend(name)
            status[name] = None
        except BackendUnavailable as error:
            status[name] = str(error)
    return status


def _load_builtin() -> None:
    # Importing a backend module registers it; the modules themselves import
    # their heavy dependencies lazily so this stays cheap. A flag, not the
    # registry's size, says whether this ran: one backend module may have been
    # imported directly before.
    global _builtin_loaded
    if _builtin_loaded:
        return
    import importlib

    for module in _BUILTIN_MODULES:
        try:
            importlib.import_module(module)
        except ModuleNotFoundError as error:
            if error.name != module:
                raise
    _builtin_loaded = True
