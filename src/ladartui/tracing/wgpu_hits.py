"""The wgpu backend's exact rays in ray order: shaders/trace.wgsl's ``first_hits``.

The shader reads the host's (N, 3) float64 origins and directions as they are
(no packing into one array of six) and writes one i32 a ray, the hit voxel's
offset in the occupied box; ``answers.box_offset_answers`` then makes the
answers on the host, ``t`` recomputed by the slab test object order uses too,
and the ground rule where no voxel was hit. Per ray that moves 48 bytes in and
4 out, against trace_rays' 48 and 24, and the host makes no numpy pass over
the rays besides the bundle starts (on a CPU adapter only) and the answers.
Batches are as large as the buffers allow: on an H200, four dispatches of
65,536 rays took twice as long as one of 262,144 (each wait for the device
waits for all it was given, so batches in flight would not overlap either).
trace_rays stays for the march, f32, and boxes whose offsets do not fit an i32.

``wgpu`` is imported only inside the methods, as in tracing/wgpu_backend.py.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ladartui.errors import check_cancelled
from ladartui.tracing.answers import box_offset_answers
from ladartui.tracing.bundle import Halos, bundle_start_array
from ladartui.tracing.config import BUNDLE, SHADER_INF
from ladartui.tracing.wgpu_scans import dispatch_encoder

# Bindings of first_hits besides the occupancy chunks (trace.wgsl).
HIT_BINDINGS = {"params": 0, "starts": 4, "origins": 5, "directions": 6, "found": 7}
OFFSET_LIMIT = 1 << 31  # the box offsets are i32


def box_sides(occupancy) -> tuple[int, int, int] | None:
    """The occupied box's sides when every offset in it fits an i32, else None."""
    sides = tuple(int(hi) - int(lo) for lo, hi in zip(occupancy.bbox_lo, occupancy.bbox_hi))
    if min(sides) <= 0 or sides[0] * sides[1] * sides[2] > OFFSET_LIMIT:
        return None
    return sides[0], sides[1], sides[2]


class FirstHits:
    """Exact f64 rays through ``first_hits`` on one device, up to ``batch`` rays a
    dispatch."""

    def __init__(self, device, limits: dict[str, int], ray_batch: int, bundle_starts: bool):
        """``bundle_starts``: compute them on the host. On lavapipe they save a fifth
        of the shader's time; on an H200 the shader ran as fast without them and
        they cost the host 0.6 ms a 262,144-ray scan, so a scan took 3.8 ms with
        them and 3.1 ms without. Without, the starts buffer stays zero: every ray
        starts at its entry into the occupied box."""
        self._device = device
        self._limits = limits
        groups = limits["max-compute-workgroups-per-dimension"]
        self.batch = max(
            1, min(ray_batch, limits["max-storage-buffer-binding-size"] // 24, groups * groups * BUNDLE)
        )
        self.bundle_starts = bundle_starts
        self._stale_starts = False  # the starts buffer holds starts (else zeros)
        self._buffers: dict[str, Any] = {}

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
    ) -> int:
        """Answers of contiguous (N, 3) float64 rays into kind/index/t; returns how many
        rays the adapter cut short (their answers are then not to be used).
        ``sides``: the occupied box's (``box_sides``, not None);
        ``group`` binds ``buffers()`` and the occupancy at HIT_BINDINGS;
        ``params_for(count)`` gives the uniform block of a batch. The words come
        back through a mapped buffer, read in place by the answers."""
        import wgpu

        buffers = self._buffers
        queue = self._device.queue
        lo = np.asarray(occupancy.bbox_lo, np.int64)
        nx, ny = float(occupancy.shape[0]), float(occupancy.shape[1])
        cut = 0
        for first in range(0, len(origins), self.batch):
            check_cancelled(cancel, "trace cancelled")
            end = min(len(origins), first + self.batch)
            o, d = origins[first:end], directions[first:end]
            count = end - first
            queue.write_buffer(buffers["params"], 0, params_for(count))
            queue.write_buffer(buffers["origins"], 0, o)
            queue.write_buffer(buffers["directions"], 0, d)
            if self.bundle_starts:
                # SHADER_INF is the shader's "never".
                queue.write_buffer(
                    buffers["starts"], 0, np.minimum(bundle_start_array(o, d, halo), SHADER_INF)
                )
                self._stale_starts = True
            elif self._stale_starts:  # another call's starts, not these rays'
                queue.write_buffer(buffers["starts"], 0, np.zeros(-(-self.batch // BUNDLE)))
                self._stale_starts = False
            encoder = dispatch_encoder(self._device, self._limits, pipeline, group, count)
            encoder.copy_buffer_to_buffer(buffers["found"], 0, buffers["back"], 0, 4 * count)
            queue.submit([encoder.finish()])
            back = buffers["back"]
            back.map_sync(wgpu.MapMode.READ, 0, 4 * count)
            words = back.read_mapped(0, 4 * count, copy=False)
            try:
                cut += box_offset_answers(
                    np.frombuffer(words, np.int32),
                    lo,
                    sides[0],
                    sides[1],
                    o,
                    d,
                    nx,
                    ny,
                    kind[first:end],
                    index[first:end],
                    t[first:end],
                )
            finally:
                del words  # the view must go before the unmap
                back.unmap()
        return cut

    def buffers(self, params_bytes: int) -> dict[str, Any]:
        """The batch's buffers by HIT_BINDINGS name (and the read-back buffer,
        "back"), made on first use and kept."""
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
                "back": create(label="hits-back", size=rays * 4, usage=back),
            }
        return self._buffers
