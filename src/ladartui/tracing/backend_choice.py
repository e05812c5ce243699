"""Which backend traces a call for ``backend="auto"`` where a GPU is there too.

A GPU does not always win. On an H200 machine, a 262,144-ray scan of the
reference scene ran at 116 M rays/s on numba's 16 host threads, and at
33-88 M rays/s on the GPU (its clock idles until kept busy, and the host's
share of a call, uploading rays and making answers, was three quarters of
it); with 4.2 M rays a call, wgpu's tracer was 2.3-2.9x as fast as numba's.
So where ``choose_backend`` finds a GPU, exact float64 calls (whose answers
the backends give bit for bit alike) are left to a ``TwoWayChoice`` between
the GPU's backend and numba, learned per occupancy and size of call (classes
a factor of four wide: a GPU's cost per call is much of a small call's), from
the calls' wall time less any compiling of numba kernels. Other calls, and
every call where there is no GPU, go to ``choose_backend``'s pick.
"""

from __future__ import annotations

import threading
import weakref
from typing import Any

from ladartui.tracing.learned_choice import TwoWayChoice

HOST = "numba"  # the backend on the host's cores


def size_class(rays: int) -> int:
    """Calls of rays within a factor of four share a class."""
    return max(0, rays).bit_length() // 2


def learns(gpu_backend: str, method: str, precision: str) -> bool:
    """Whether auto's calls are left to a learned choice: a GPU is there (its
    backend is not the host's) and the call is exact float64."""
    return gpu_backend != HOST and method == "exact" and precision == "f64"


class BackendChoices:
    """The learned choices, per occupancy (kept while it lives), GPU backend and size class."""

    def __init__(self):
        self._choices: weakref.WeakKeyDictionary[Any, dict[tuple[str, int], TwoWayChoice]] = (
            weakref.WeakKeyDictionary()
        )
        self._lock = threading.Lock()

    def choice(self, occupancy, gpu_backend: str, rays: int) -> TwoWayChoice:
        # The GPU first (as before there was a choice); no gap settles the turns
        # early, as its first call also opens the device and builds pipelines.
        with self._lock:
            per_key = self._choices.setdefault(occupancy, {})
            key = (gpu_backend, size_class(rays))
            if key not in per_key:
                per_key[key] = TwoWayChoice((gpu_backend, HOST), settled_gap=float("inf"))
            return per_key[key]


CHOICES = BackendChoices()
