"""Where a trace's time goes: seconds per pass, for ``TraceResult.info["passes"]``.

``trace()`` opens a ``recording`` for its call; the passes inside it (the
conversion to cell space, a scan's binning, its voxels in view, its tile lists
and tile tests, ray order, a device's upload and shader, the answers) each run
under ``timed(name)`` (a block, or a decorator on the pass's function: the
scan's bins and voxels in view, timed where both backends call them), which
adds their wall time to the open recording of their thread (none open:
nothing). Either way it costs about a microsecond a pass, against milliseconds
a scan, so the backends call it unconditionally.
``ladartui bench --passes`` prints the medians: which pass limits a scan.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

_open = threading.local()  # .seconds: the recording of this thread's trace call, if any


@contextmanager
def recording() -> Iterator[dict[str, float]]:
    """Record the passes timed in this thread until the block ends, into the dict
    given (seconds by pass name, summed over a call's blocks). A recording
    opened inside another has a dict of its own, added to the outer one's when
    it ends."""
    outer = getattr(_open, "seconds", None)
    seconds: dict[str, float] = {}
    _open.seconds = seconds
    try:
        yield seconds
    finally:
        _open.seconds = outer
        if outer is not None:
            for name, spent in seconds.items():
                outer[name] = outer.get(name, 0.0) + spent


@contextmanager
def timed(name: str) -> Iterator[None]:
    """Add the block's wall time to pass ``name`` of this thread's recording, if one is open."""
    seconds = getattr(_open, "seconds", None)
    if seconds is None:
        yield
        return
    started = time.perf_counter()
    try:
        yield
    finally:
        seconds[name] = seconds.get(name, 0.0) + time.perf_counter() - started
