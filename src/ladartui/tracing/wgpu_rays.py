"""The wgpu backend's rays through trace.wgsl's ``trace_rays``, one invocation a ray:
f32, the march, and exact f64 rays in a box too large for ``first_hits``' offsets
(tracing/wgpu_hits.py).

Rays go packed six reals a ray, in batches that fit the buffers, with a bundle
start per workgroup in exact f64 (in f32 each origin is moved to its start on
the host instead, tracing/f32_rays.py); kind, cell and ``t`` come back. The
march runs in passes of MARCH_SAMPLES_PER_PASS samples a ray (lavapipe ends
an invocation's loops after 65,535 iterations): rays without an answer go again
from the next sample on. An exact ray that meets no voxel comes back a miss,
and the host applies the ground rule to it in float64 (``answers.ground_answers``).

``wgpu`` is imported only inside the methods, as in tracing/wgpu_backend.py.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ladartui.errors import check_cancelled
from ladartui.tracing.answers import ground_answers
from ladartui.tracing.backend import GROUND, MISS, VOXEL
from ladartui.tracing.bundle import bundle_start_array, halo_arrays
from ladartui.tracing.config import BUNDLE, CUT, MARCH_SAMPLES_PER_PASS, SHADER_INF, UNFINISHED
from ladartui.tracing.f32_rays import f32_shift, f32_start_offsets, floor_preserving_f32
from ladartui.tracing.prepare import origin_rows
from ladartui.tracing.wgpu_occupancy import PARAMS_BYTES, pack_params
from ladartui.tracing.wgpu_scans import dispatch_encoder, rays_per_dispatch

RAY_BINDINGS = ("params", "rays", "cells", "ranges", "starts")  # trace_rays' bindings 0-4


class RayPasses:
    """trace_rays on one device: its ray buffers per precision, kept across calls."""

    def __init__(self, device: Any, limits: dict[str, int], ray_batch: int):
        self._device = device
        self._limits = limits
        self._ray_batch = ray_batch
        self._buffers: dict[str, dict[str, Any]] = {}

    def buffers(self, precision: str) -> dict[str, Any]:
        """Ray input and hit output buffers for one batch, reused across calls."""
        import wgpu

        buffers = self._buffers.get(precision)
        if buffers is None:
            device = self._device
            real_bytes = 8 if precision == "f64" else 4
            rays = rays_per_dispatch(self._limits, self._ray_batch, 6 * real_bytes)
            usage_in = wgpu.BufferUsage.STORAGE | wgpu.BufferUsage.COPY_DST
            usage_out = wgpu.BufferUsage.STORAGE | wgpu.BufferUsage.COPY_SRC
            buffers = {
                "capacity": rays,
                "params": device.create_buffer(
                    size=PARAMS_BYTES, usage=wgpu.BufferUsage.UNIFORM | wgpu.BufferUsage.COPY_DST
                ),
                "rays": device.create_buffer(size=rays * 6 * real_bytes, usage=usage_in),
                "cells": device.create_buffer(size=rays * 16, usage=usage_out),
                "ranges": device.create_buffer(size=rays * real_bytes, usage=usage_out),
                "starts": device.create_buffer(size=max(1, -(-rays // BUNDLE)) * real_bytes, usage=usage_in),
            }
            self._buffers[precision] = buffers
        return buffers

    def trace(
        self,
        occupancy,
        upload,
        pipeline,
        rays,
        method: str,
        step: float,
        precision: str,
        cancel,
        into,
    ) -> int:
        """The answers of ``rays`` (origins, directions, shared_origin: every ray starts
        at ``origins[0]``) into ``into`` (kind, index, t); returns how many rays the
        adapter cut short (then the answers are not to be used). ``upload``: the
        occupancy on the device (wgpu_occupancy.Upload); ``pipeline``: trace_rays for
        its layout and ``precision``."""
        origins, directions, shared_origin = rays
        kind, index, t = into
        n = len(directions)
        buffers = self.buffers(precision)
        bound = {b: buffers[name] for b, name in enumerate(RAY_BINDINGS)}
        bind_group = upload.bind_group(
            self._device, pipeline, (precision, id(pipeline), id(buffers["rays"])), bound
        )
        real = np.float64 if precision == "f64" else np.float32
        halo = halo_arrays(occupancy)
        offsets = None
        shift = np.zeros(3, dtype=np.int64)
        if precision == "f32":
            # f32 moves each origin to its start on the host (the shader sees no starts).
            top = float(max(int(occupancy.zmax) + 1, 0))
            ray_starts = None
            if method == "exact":
                ray_starts = np.repeat(bundle_start_array(origins, directions, halo), BUNDLE)[:n]
            offsets = f32_start_offsets(origins, directions, occupancy.shape, top, method, ray_starts)
            shift = f32_shift(occupancy)  # the cells found come back less it
        capacity = buffers["capacity"]
        pending = None  # None: every ray (the first pass), taken in slices, not copies
        first_sample = 0
        while True:
            total = n if pending is None else len(pending)
            for start in range(0, total, capacity):
                check_cancelled(cancel, "trace cancelled")
                rows: slice | np.ndarray
                if pending is None:
                    rows = slice(start, min(total, start + capacity))
                    count = rows.stop - rows.start
                else:
                    rows = pending[start : start + capacity]
                    count = len(rows)
                batch_origins, batch_directions = origins[rows], directions[rows]
                packed = np.empty((count, 6), dtype=real)
                if offsets is None:
                    packed[:, :3] = batch_origins
                else:
                    packed[:, :3] = floor_preserving_f32(
                        batch_origins + offsets[rows, None] * batch_directions - shift
                    )
                packed[:, 3:] = batch_directions
                if offsets is None and method == "exact":
                    # The shader has no infinity (its INF is 1e30): cap "never" there.
                    starts = np.minimum(
                        bundle_start_array(batch_origins, batch_directions, halo), SHADER_INF
                    ).astype(real)
                else:
                    starts = np.zeros(-(-count // BUNDLE), dtype=real)
                params = pack_params(
                    occupancy,
                    upload,
                    method,
                    step,
                    count,
                    precision,
                    first_sample,
                    MARCH_SAMPLES_PER_PASS,
                    shift=shift[:2],
                )
                cells, ranges = self._dispatch(pipeline, bind_group, buffers, params, packed, starts)
                batch_kind = cells[:, 0]
                kind[rows] = batch_kind
                index[rows] = cells[:, 1:]
                if shift.any():  # f32: back from the shifted cell space
                    found = (batch_kind == VOXEL) | (batch_kind == GROUND)
                    index[rows] += np.where(found[:, None], shift, 0).astype(np.int32)
                batch_t = ranges.astype(np.float64)
                if offsets is not None:
                    batch_t += offsets[rows]
                batch_t[(batch_kind != VOXEL) & (batch_kind != GROUND)] = np.inf
                t[rows] = batch_t
            done = kind if pending is None else kind[pending]
            if np.any(done == CUT):
                return int(np.sum(kind == CUT))
            pending = np.flatnonzero(done == UNFINISHED) if pending is None else pending[done == UNFINISHED]
            if len(pending) == 0:
                break
            first_sample += MARCH_SAMPLES_PER_PASS
        if method == "exact":
            nx, ny = float(occupancy.shape[0]), float(occupancy.shape[1])
            no_voxel = np.flatnonzero(kind == MISS)
            rows_read = origin_rows(origins, shared_origin)
            ground_answers(no_voxel, rows_read, shared_origin, directions, nx, ny, kind, index, t)
        index[kind == MISS] = -1
        return 0

    def _dispatch(self, pipeline, bind_group, buffers, params, rays, starts):
        """One dispatch over ``rays`` (count, 6) with their bundle ``starts`` (one per
        workgroup): their hit cells (count, 4) and ranges."""
        device = self._device
        count = len(rays)
        device.queue.write_buffer(buffers["params"], 0, params)
        device.queue.write_buffer(buffers["rays"], 0, rays)
        device.queue.write_buffer(buffers["starts"], 0, starts)
        device.queue.submit([dispatch_encoder(device, self._limits, pipeline, bind_group, count).finish()])
        cells = np.frombuffer(
            device.queue.read_buffer(buffers["cells"], 0, count * 16), dtype=np.int32
        ).reshape(count, 4)
        ranges = np.frombuffer(
            device.queue.read_buffer(buffers["ranges"], 0, count * rays.itemsize), dtype=rays.dtype
        )
        return cells, ranges
