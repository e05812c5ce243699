"""numba kernels compiled on their first call, so that small files never import numba.

A module marks its kernels with its own ``LazyKernels(globals())``. The first
call of any of them imports numba and rebinds every kernel of the module at
once (nogil, cached), so kernels calling kernels see compiled callees.
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable

# Up to this many bytes of data, array passes in numpy beat loading the compiled
# kernels (about 45 ms a megabyte): such work stays in numpy.
NUMPY_BYTES = 4_000_000


class LazyKernels:
    """A decorator marking the kernels of the module whose globals it is given."""

    def __init__(self, namespace: dict):
        self._namespace = namespace
        self._kernels: dict[str, Callable] = {}  # (Python functions, callees first)
        self._lock = threading.Lock()
        self._compiled = False

    def __call__(self, func):
        self._kernels[func.__name__] = func

        @functools.wraps(func)
        def first_call(*args):
            self._compile()
            return self._namespace[func.__name__](*args)

        return first_call

    def _compile(self) -> None:
        with self._lock:
            if self._compiled:
                return  # another thread got here first
            import numba

            for name, py_func in self._kernels.items():
                self._namespace[name] = numba.njit(nogil=True, cache=True)(py_func)
            self._compiled = True
