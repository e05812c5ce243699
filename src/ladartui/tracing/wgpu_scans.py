"""The wgpu backend's object order on the device: the buffers, dispatch and
read-back of shaders/object_order.wgsl (the host's half is tracing/shader_scan.py).

A scan's arrays go into storage buffers kept from scan to scan (grown when a
larger scan needs more). On a CPU adapter (lavapipe: the device's memory is the
host's) the buffers are mapped by the host, which writes and reads them without
the staging copy each way that ``queue.write_buffer`` and ``read_buffer`` make
(``write_mapped`` copies on numba's threads); the inputs are mapped again for
the next scan as soon as one ends. Elsewhere (a GPU) the queue's copies.

``wgpu`` is imported only inside the methods, as in tracing/wgpu_backend.py.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit, prange

from ladartui.tracing.config import BUNDLE, PARTS, wgsl_constants
from ladartui.tracing.prepare import origin_rows


def dispatch_grid(workgroups: int, max_per_dimension: int) -> tuple[int, int]:
    """(x, y) workgroup counts covering ``workgroups`` within the per-dimension limit."""
    if workgroups <= 0:
        return (0, 0)
    x = min(workgroups, max_per_dimension)
    y = -(-workgroups // x)
    if y > max_per_dimension:
        raise ValueError(f"{workgroups} workgroups exceed a {max_per_dimension}^2 grid")
    return (x, y)


def rays_per_dispatch(limits: dict[str, int], ray_batch: int, binding_bytes_per_ray: int) -> int:
    """Rays in one dispatch: at most ``ray_batch``, as many as the largest binding
    holds at ``binding_bytes_per_ray``, and as many as ``dispatch_grid`` can cover."""
    groups = limits["max-compute-workgroups-per-dimension"]
    by_binding = limits["max-storage-buffer-binding-size"] // binding_bytes_per_ray
    return max(1, min(ray_batch, by_binding, groups * groups * BUNDLE))


def dispatch_encoder(device, limits: dict[str, int], pipeline, group, rays: int):
    """A command encoder holding one dispatch of ``pipeline`` with bind group 0
    ``group`` over ``rays`` rays (BUNDLE a workgroup), to be finished by the caller."""
    groups = dispatch_grid(-(-rays // BUNDLE), limits["max-compute-workgroups-per-dimension"])
    encoder = device.create_command_encoder()
    compute = encoder.begin_compute_pass()
    compute.set_pipeline(pipeline)
    compute.set_bind_group(0, group)
    compute.dispatch_workgroups(groups[0], groups[1], 1)
    compute.end()
    return encoder


# Bindings of shaders/object_order.wgsl, in order.
SCAN_BINDINGS = ("params", "origins", "directions", "order", "ray_tiles", "tile_starts", "entries", "found")
# Its uniform block, struct TileParams: four vec4 of 32-bit integers.
TILE_PARAMS_BYTES = 4 * 16


def pack_tile_params(rays, scan, shared_origin=False) -> bytes:
    """The uniform block of one object-order dispatch, laid out as ``struct TileParams``
    (``shared_origin``: every ray starts at the one origin sent)."""
    offset, shifts, masks = scan.packing
    ints = np.zeros((4, 4), dtype=np.int64)
    ints[0] = (rays, scan.tile_shift, 0 if len(scan.ray_tiles) else 1, 1 if shared_origin else 0)
    ints[1, :3], ints[2, :3], ints[3, :3] = shifts, masks, offset
    return ints.astype(np.uint32).tobytes()  # the i32 fields as their two's complement


def write_mapped(buffer, array) -> None:
    """``array`` into the start of ``buffer``, mapped for writing: copied on numba's
    threads into the mapped range where wgpu-py hands it out (its experimental
    ``_experimental_get_mapped_range``; the view is dropped before the caller
    unmaps), else by ``write_mapped``, on one thread (a scan's 6 MB of directions
    took 0.65 ms there)."""
    mapped_range = getattr(buffer, "_experimental_get_mapped_range", None)
    if mapped_range is None or array.nbytes % 4:
        buffer.write_mapped(array, 0)
        return
    view = mapped_range(0, array.nbytes)
    try:
        copy_in_parts(np.frombuffer(view, np.uint32), np.ascontiguousarray(array).reshape(-1).view(np.uint32))
    finally:
        view.release()


@njit(parallel=True, nogil=True, cache=True)
def copy_in_parts(target, source):
    """target[:] = source, in PARTS slices on numba's threads."""
    n = source.shape[0]
    for part in prange(PARTS):
        lo, hi = part * n // PARTS, (part + 1) * n // PARTS
        target[lo:hi] = source[lo:hi]


class ScanDispatcher:
    """Runs shaders/object_order.wgsl on one device (``test_tiles``)."""

    def __init__(self, device, limits: dict[str, int], shader_file: Callable[[str], str], maps_storage: bool):
        """``limits`` as the device was opened with (and capped); ``shader_file(name)``
        gives a shader's source; ``maps_storage``: the device maps storage buffers
        (``mappable-primary-buffers``, asked for on a CPU adapter)."""
        self._device = device
        self._limits = limits
        self._shader_file = shader_file
        self.maps_storage = maps_storage
        self._compiled: Any = None
        self._buffers: dict[str, Any] = {}  # by name
        self._group: tuple[tuple[int, ...] | None, Any] = (None, None)  # buffer ids, bind group
        self._mapping: dict[str, Any] = {}  # buffers being mapped for the next scan

    def _pipeline(self):
        """The object-order pipeline (f64 only)."""
        if self._compiled is None:
            code = (
                wgsl_constants("f64")
                + "\n"
                + self._shader_file("axis.wgsl")
                + "\n"
                + self._shader_file("object_order.wgsl")
            )
            module = self._device.create_shader_module(label="tiles", code=code)
            pipeline = self._device.create_compute_pipeline(
                label="tiles", layout="auto", compute={"module": module, "entry_point": "test_tiles"}
            )
            self._compiled = pipeline
        return self._compiled

    def test_tiles(self, origins, directions, scan, shared_origin=False) -> np.ndarray | None:
        """Each ray's hit as its packed cell (``scan.packing``; NO_CELL none), from
        shaders/object_order.wgsl; None when an array exceeds a storage binding.
        ``shared_origin``: every ray starts at ``origins[0]``, the one row sent."""
        import wgpu

        n = len(directions)
        inputs = {
            "origins": origin_rows(origins, shared_origin),  # as given when already so
            "directions": directions,
            "order": scan.order,
            "ray_tiles": scan.ray_tiles,
            "tile_starts": scan.tile_starts,
            "entries": scan.entries,
        }
        sizes = {name: array.nbytes for name, array in inputs.items()}
        sizes["found"] = 4 * n
        if max(sizes.values()) > self._buffer_limit():
            return None
        buffers = {name: self._buffer(name, size) for name, size in sizes.items()}
        buffers["params"] = self._buffer("params", TILE_PARAMS_BYTES, uniform=True)
        queue = self._device.queue
        queue.write_buffer(buffers["params"], 0, pack_tile_params(n, scan, shared_origin))
        for name, array in inputs.items():
            self._fill(name, buffers[name], np.ascontiguousarray(array))
        pipeline = self._pipeline()
        key = tuple(id(buffers[name]) for name in SCAN_BINDINGS)
        if self._group[0] != key:  # made again only when a buffer has grown
            self._group = (
                key,
                self._device.create_bind_group(
                    layout=pipeline.get_bind_group_layout(0),
                    entries=[
                        {"binding": b, "resource": {"buffer": buffers[name]}}
                        for b, name in enumerate(SCAN_BINDINGS)
                    ],
                ),
            )
        group = self._group[1]
        queue.submit([dispatch_encoder(self._device, self._limits, pipeline, group, n).finish()])
        found = np.frombuffer(self._read(buffers["found"], 4 * n), dtype=np.uint32)
        if self.maps_storage:
            # Map the inputs for the next scan now, so that the wait for it passes
            # while the host works (asked for right after the host's numba passes,
            # a map waited for their threads to stop spinning).
            for name in inputs:
                self._mapping[name] = buffers[name].map_async(wgpu.MapMode.WRITE)
        return found

    def _fill(self, name, buffer, array):
        """``array`` into the start of object-order buffer ``name``, which is left
        unmapped for the dispatch."""
        import wgpu

        mapping = self._mapping.pop(name, None)
        if not self.maps_storage:
            if array.nbytes:
                self._device.queue.write_buffer(buffer, 0, array)
            return
        if mapping is not None:
            mapping.sync_wait()
        elif array.nbytes:
            buffer.map_sync(wgpu.MapMode.WRITE)
        else:
            return
        try:
            if array.nbytes:
                write_mapped(buffer, array)
        finally:
            buffer.unmap()

    def _read(self, buffer, size):
        """A copy of the first ``size`` bytes of an object-order buffer, once the queue is done."""
        import wgpu

        if not self.maps_storage:
            return self._device.queue.read_buffer(buffer, 0, size)
        buffer.map_sync(wgpu.MapMode.READ, 0, size)
        try:
            return buffer.read_mapped(0, size)
        finally:
            buffer.unmap()

    def _buffer_limit(self):
        return min(self._limits["max-storage-buffer-binding-size"], self._limits["max-buffer-size"])

    def _buffer(self, name, size, uniform=False):
        """A buffer of at least ``size`` bytes for object order, kept for later scans."""
        import wgpu

        buffer = self._buffers.get(name)
        if buffer is None or buffer.size < size:
            mapping = self._mapping.pop(name, None)
            if buffer is not None and mapping is not None:  # the old buffer goes: end its mapping first
                mapping.sync_wait()
                buffer.unmap()
            usage = wgpu.BufferUsage.STORAGE
            if uniform:
                usage = wgpu.BufferUsage.UNIFORM | wgpu.BufferUsage.COPY_DST
            elif self.maps_storage:
                usage |= wgpu.BufferUsage.MAP_READ if name == "found" else wgpu.BufferUsage.MAP_WRITE
            else:
                usage |= wgpu.BufferUsage.COPY_SRC if name == "found" else wgpu.BufferUsage.COPY_DST
            # Room to grow, within the limits (which need not be powers of two).
            size = max(16, min(1 << (max(size, 1) - 1).bit_length(), self._buffer_limit() // 4 * 4))
            buffer = self._device.create_buffer(label=f"scan-{name}", size=size, usage=usage)
            self._buffers[name] = buffer
        return buffer
