"""numba's threading layer, chosen when ``ladartui`` is imported (before numba starts
its threads on the first parallel kernel).

TBB where its runtime is installed (the ``tbb`` wheel, x86-64 Linux): its threads
steal work and sleep when idle. Under OpenMP (libgomp, numba's next choice) every
parallel pass ends at a barrier that waits for each thread's fixed share, and
waiting threads spin, so a trace beside another busy process slowed far more
(figures: docs/architecture.md, "Threads"). TBB is also the layer numba calls
safe under both threads and fork (Dask's workers).

numba finds the runtime by its name, ``libtbb.so.12``, which the wheel puts in the
environment's ``lib`` folder, off the loader's path; loading it there first lets
numba's own lookup find it. A user's ``NUMBA_THREADING_LAYER`` still decides.
"""

from __future__ import annotations

import ctypes
import os
import sys
from pathlib import Path

TBB_RUNTIME = "libtbb.so.12"


def tbb_runtime() -> Path | None:
    """The TBB runtime in this Python environment's ``lib`` folder, if there is one."""
    for prefix in dict.fromkeys((sys.prefix, sys.base_prefix)):
        path = Path(prefix) / "lib" / TBB_RUNTIME
        if path.is_file():
            return path
    return None


def load_tbb() -> bool:
    """Load the environment's TBB runtime so numba can pick its TBB layer; False when
    there is none or it does not load (numba then uses OpenMP)."""
    path = tbb_runtime()
    if path is None:
        return False
    try:
        ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)
    except OSError:
        return False
    return True


# The layers numba's NUMBA_THREADING_LAYER names (any case); another ends a parallel run.
NUMBA_LAYERS = ("default", "safe", "threadsafe", "forksafe", "tbb", "omp", "workqueue")


def environment_problem() -> str | None:
    """What is wrong with numba's NUMBA_THREADING_LAYER or NUMBA_NUM_THREADS, in one line:
    numba raises on the first parallel kernel (an unknown layer, a count under 1) or
    drops a count it cannot read without a word. None when both are fine or unset."""
    layer = os.environ.get("NUMBA_THREADING_LAYER", "")
    if layer.strip() and layer.lower() not in NUMBA_LAYERS:
        return f"NUMBA_THREADING_LAYER = {layer!r}: expected one of {', '.join(NUMBA_LAYERS)}"
    count = os.environ.get("NUMBA_NUM_THREADS", "")
    whole = count.strip()
    if whole and not (whole.isascii() and whole.isdigit() and int(whole) >= 1):
        return f"NUMBA_NUM_THREADS = {count!r}: expected a whole number of threads, 1 or more"
    return None


def configure() -> None:
    """Prefer TBB; shorten OpenMP's spin for where numba falls back to it.

    libgomp's default spin (300,000) kept numba's threads on the cores for
    milliseconds after each parallel pass, which starved lavapipe (the wgpu backend
    up to 30 % slower), Dask's workers and the terminal UI; 30,000 still bridges
    the gaps between a trace's passes. A user's own spin count or wait policy stands.
    """
    load_tbb()
    if "OMP_WAIT_POLICY" not in os.environ:
        os.environ.setdefault("GOMP_SPINCOUNT", "30000")
