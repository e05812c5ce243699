"""The wgpu backend's exact rays in ray order: shaders/trace.wgsl's ``first_hits``.

The shader reads the host's (N, 3) float64 origins and directions as they are
(no packing into one array of six) and writes one i32 a ray, the hit voxel's
offset in the occupied box; ``answers.box_offset_answers`` then makes the
answers on the host, ``t`` recomputed by the slab test object order uses too,
and the ground rule where no voxel was hit. Per ray that moves 48 bytes in and
4 out, against trace_rays' 48 and 24 (24 in when the rays share one origin,
as a scan's do), and the host makes no numpy pass over
the rays besides the bundle starts (on a CPU adapter only) and the answers.
On a GPU a batch's inputs go through one staging buffer of the backend's own
(``FirstHits``' ``staged``), and the read-back is mapped without wgpu-py's
extra submit (``map_for_reading``): one submit a batch. Batches are as large
as the buffers allow (on an H200, four dispatches of
65,536 rays one after the other took twice as long as one of 262,144), and
overlap: the host writes one batch and answers another while the device traces.
trace_rays stays for the march, f32, and boxes whose offsets do not fit an i32.

``wgpu`` is imported only inside the methods, as in tracing/wgpu_backend.py.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from typing import Any

import numpy as np

from ladartui.errors import check_cancelled
from ladartui.tracing.answers import box_offset_answers
from ladartui.tracing.bundle import Halos, bundle_start_array
from ladartui.tracing.config import BUNDLE, SHADER_INF
from ladartui.tracing.wgpu_scans import dispatch_encoder, rays_per_dispatch, write_pieces

# Bindings of first_hits besides the occupancy chunks (trace.wgsl).
HIT_BINDINGS = {"params": 0, "starts": 4, "origins": 5, "directions": 6, "found": 7}
OFFSET_LIMIT = 1 << 31  # the box offsets are i32


def box_sides(occupancy) -> tuple[int, int, int] | None:
    """The occupied box's sides when every offset in it fits an i32, else None."""
    sides = tuple(int(hi) - int(lo) for lo, hi in zip(occupancy.bbox_lo, occupancy.bbox_hi))
    if min(sides) <= 0 or sides[0] * sides[1] * sides[2] > OFFSET_LIMIT:
        return None
    return sides[0], sides[1], sides[2]


# wgpu-py submits an empty command buffer before each map for reading (a buffer
# written by queue.write_buffer with no submit after it could read as zeros); its
# own mode "READ_NOSYNC" skips that. Ours are written by copies we submitted, so
# it is used where the installed wgpu-py knows it: one submit a call, not two.
_READ_WITHOUT_SUBMIT = ["READ_NOSYNC"]


def map_for_reading(buffer, size: int) -> None:
    """Map the first ``size`` bytes of ``buffer`` for reading, once the device has
    written them (a wait for all submitted work)."""
    import wgpu

    if _READ_WITHOUT_SUBMIT:
        try:
            buffer.map_sync(_READ_WITHOUT_SUBMIT[0], 0, size)
            return
        except (AttributeError, KeyError, TypeError, ValueError):  # (checked before anything is mapped)
            _READ_WITHOUT_SUBMIT.clear()
    buffer.map_sync(wgpu.MapMode.READ, 0, size)


def regions_may_overlap() -> bool:
    """Whether two of numba's parallel regions may run at once on two threads: under
    TBB and OpenMP, not under the workqueue layer (it ends the process)."""
    import numba

    try:
        return numba.threading_layer() != "workqueue"
    except ValueError:  # no parallel region has run yet: the layer is not chosen
        return False


@contextmanager
def mapped_words(back, count: int):
    """The first ``count`` i32 words of read-back buffer ``back``, mapped once the
    device has written them (``map_for_reading``), read in place and unmapped after
    the block."""
    map_for_reading(back, 4 * count)
    try:
        view = back.read_mapped(0, 4 * count, copy=False)
        try:
            yield np.frombuffer(view, np.int32)
        finally:
            del view  # the view must go before the unmap
    finally:
        back.unmap()


class FirstHits:
    """Exact f64 rays through ``first_hits`` on one device, up to ``batch`` rays a
    dispatch."""

    def __init__(
        self, device, limits: dict[str, int], ray_batch: int, bundle_starts: bool, staged: bool = False
    ):
        """``bundle_starts``: compute them on the host. On lavapipe they save a fifth
        of the shader's time; on an H200 the shader ran as fast without them and
        they cost the host 0.6 ms a 262,144-ray scan, so a scan took 3.8 ms with
        them and 3.1 ms without. Without, the starts buffer stays zero: every ray
        starts at its entry into the occupied box.

        ``staged``: a batch's inputs (uniform block, origins, directions) go to the
        device through one staging buffer of our own, mapped for writing and filled
        on numba's threads (``write_pieces``), then copied on the device ahead of
        the dispatch; else ``queue.write_buffer`` copies each into staging memory
        of its own on one thread, and the submit carries its copies in a command
        buffer of their own."""
        self._device = device
        self._limits = limits
        self.batch = rays_per_dispatch(limits, ray_batch, 24)  # the directions' binding
        self.bundle_starts = bundle_starts
        self.staged = staged
        self._mapping: dict[int, Any] = {}  # staging buffer number -> its pending map for writing
        self._stale_starts = False  # the starts buffer holds starts (else zeros)
        self._origins_at = self._directions_at = 0  # where they start in a staging buffer
        self._buffers: dict[str, Any] = {}
        self._answer_thread: ThreadPoolExecutor | None = None

    def trace(
        self,
        occupancy,
        sides: tuple[int, int, int],
        pipeline,
        group,
        params_for: Callable[[int], bytes],
        origins,
        directions,
        halo: Halos,
        cancel,
        kind,
        index,
        t,
        shared_origin: bool = False,
    ) -> int:
        """Answers of contiguous (N, 3) float64 rays into kind/index/t (``origins`` one
        row when ``shared_origin``); returns how many rays the adapter cut short
        (their answers are then not to be used).
        ``sides``: the occupied box's (``box_sides``, not None);
        ``group`` binds ``buffers()`` and the occupancy at HIT_BINDINGS;
        ``params_for(count)`` gives the uniform block of a batch (saying whether
        the rays share one origin); ``shared_origin``: every ray starts at
        ``origins[0]`` (``one_origin``), so only that origin is written.

        Batches overlap: the device traces batch k + 1 while batch k is answered
        (on a thread of its own where there are no bundle starts to compute) and
        batch k + 2 written; words come back through two mapped buffers in turn,
        read in place. A wait waits for all submitted work, so k + 1 is submitted
        only once k's words are there.
        """
        import wgpu

        buffers = self._buffers
        queue = self._device.queue
        lo = np.asarray(occupancy.bbox_lo, np.int64)
        nx, ny = float(occupancy.shape[0]), float(occupancy.shape[1])
        n = len(directions)
        firsts = range(0, n, self.batch)

        def rows(k: int) -> slice:
            return slice(firsts[k], min(n, firsts[k] + self.batch))

        def origins_of(k: int):
            return origins[:1] if shared_origin else origins[rows(k)]

        def count(k: int) -> int:
            return rows(k).stop - rows(k).start

        def write(k: int) -> None:
            o, d = origins_of(k), directions[rows(k)]
            if self.staged:
                params = np.frombuffer(params_for(len(d)), np.uint8)
                self._stage(k % 2, [(0, params), (self._origins_at, o), (self._directions_at, d)])
            else:
                queue.write_buffer(buffers["params"], 0, params_for(len(d)))
                queue.write_buffer(buffers["origins"], 0, o)
                queue.write_buffer(buffers["directions"], 0, d)
            if self.bundle_starts:
                every = np.broadcast_to(o, d.shape) if shared_origin else o
                # SHADER_INF is the shader's "never".
                queue.write_buffer(
                    buffers["starts"], 0, np.minimum(bundle_start_array(every, d, halo), SHADER_INF)
                )
                self._stale_starts = True
            elif self._stale_starts:  # another call's starts, not these rays'
                queue.write_buffer(buffers["starts"], 0, np.zeros(-(-self.batch // BUNDLE)))
                self._stale_starts = False

        def submit(k: int) -> None:
            copies = []
            if self.staged:
                stage = buffers["staging"][k % 2]
                copies = [
                    (stage, 0, buffers["params"], buffers["params"].size),
                    (stage, self._origins_at, buffers["origins"], 24 * len(origins_of(k))),
                    (stage, self._directions_at, buffers["directions"], 24 * count(k)),
                ]
            encoder = dispatch_encoder(self._device, self._limits, pipeline, group, count(k), copies)
            encoder.copy_buffer_to_buffer(buffers["found"], 0, buffers["back"][k % 2], 0, 4 * count(k))
            queue.submit([encoder.finish()])
            if self.staged:  # mapped again for batch k + 2 (or the next call) once copied
                self._mapping[k % 2] = buffers["staging"][k % 2].map_async(wgpu.MapMode.WRITE)

        def answer(k: int, words) -> int:
            here = rows(k)
            return box_offset_answers(
                words,
                lo,
                sides[0],
                sides[1],
                origins_of(k),
                shared_origin,
                directions[here],
                nx,
                ny,
                kind[here],
                index[here],
                t[here],
            )

        check_cancelled(cancel, "trace cancelled")
        # Writing runs numba where it computes bundle starts or stages the rays: then
        # not beside the answers (two parallel regions at once end the process under
        # numba's workqueue layer; the others take them).
        overlap = not self.bundle_starts and (not self.staged or regions_may_overlap())
        write(0)
        submit(0)
        if len(firsts) > 1:
            write(1)  # while the device traces batch 0
        cut = 0
        for k in range(len(firsts)):
            later = k + 2 < len(firsts)
            with mapped_words(buffers["back"][k % 2], count(k)) as words:
                if k + 1 < len(firsts):
                    submit(k + 1)  # traced while batch k's answers are made
                if later and overlap:
                    # Batch k answered on the thread while this one writes batch k + 2.
                    answering = self._answerer().submit(answer, k, words)
                    try:
                        check_cancelled(cancel, "trace cancelled")
                        write(k + 2)
                    finally:
                        cut += answering.result()  # before the words are unmapped
                    continue
                cut += answer(k, words)
            if later:
                check_cancelled(cancel, "trace cancelled")
                write(k + 2)
        return cut

    def _stage(self, number: int, pieces) -> None:
        """``pieces`` ((offset, array) pairs) into staging buffer ``number`` through its
        mapping, left unmapped for the device's copies."""
        import wgpu

        buffer = self._buffers["staging"][number]
        mapping = self._mapping.get(number)
        if mapping is not None:
            mapping.sync_wait()  # (a wait cut short leaves it here for the next call)
            del self._mapping[number]
        else:
            buffer.map_sync(wgpu.MapMode.WRITE)
        try:
            write_pieces(buffer, pieces)
        finally:
            buffer.unmap()

    def _answerer(self) -> ThreadPoolExecutor:
        """The thread that makes one batch's answers while this one writes the next."""
        if self._answer_thread is None:
            self._answer_thread = ThreadPoolExecutor(1, thread_name_prefix="ladartui-answers")
        return self._answer_thread

    def buffers(self, params_bytes: int) -> dict[str, Any]:
        """The batch's buffers by HIT_BINDINGS name (and "back", the two read-back
        buffers that batches take in turn), made on first use and kept."""
        import wgpu

        if not self._buffers:
            rays = self.batch
            into = wgpu.BufferUsage.STORAGE | wgpu.BufferUsage.COPY_DST
            create = self._device.create_buffer
            back = wgpu.BufferUsage.MAP_READ | wgpu.BufferUsage.COPY_DST
            self._buffers = {
                "params": create(
                    label="hits-params",
                    size=params_bytes,
                    usage=wgpu.BufferUsage.UNIFORM | wgpu.BufferUsage.COPY_DST,
                ),
                "origins": create(label="hits-origins", size=rays * 24, usage=into),
                "directions": create(label="hits-directions", size=rays * 24, usage=into),
                "starts": create(
                    label="hits-starts", size=-(-rays // BUNDLE) * 8, usage=into
                ),  # zeros until written
                "found": create(
                    label="hits-found",
                    size=rays * 4,
                    usage=wgpu.BufferUsage.STORAGE | wgpu.BufferUsage.COPY_SRC,
                ),
                "back": [create(label=f"hits-back-{k}", size=rays * 4, usage=back) for k in (0, 1)],
            }
            if self.staged:  # the uniform block, origins, directions; batches take them in turn
                self._origins_at = -(-params_bytes // 8) * 8
                self._directions_at = self._origins_at + rays * 24
                up = wgpu.BufferUsage.MAP_WRITE | wgpu.BufferUsage.COPY_SRC
                size = self._directions_at + rays * 24
                self._buffers["staging"] = [create(label=f"hits-up-{k}", size=size, usage=up) for k in (0, 1)]
        return self._buffers
