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


def dispatch_encoder(device, limits: dict[str, int], pipeline, group, rays: int, copies=()):
    """A command encoder holding one dispatch of ``pipeline`` with bind group 0
    ``group`` over ``rays`` rays (BUNDLE a workgroup), to be finished by the caller;
    ``copies``: (source, offset, target, bytes) copies to the start of ``target``
    made before the dispatch."""
    groups = dispatch_grid(-(-rays // BUNDLE), limits["max-compute-workgroups-per-dimension"])
    encoder = device.create_command_encoder()
    for source, offset, target, size in copies:
        encoder.copy_buffer_to_buffer(source, offset, target, 0, size)
    compute = encoder.begin_compute_pass()
    compute.set_pipeline(pipeline)
    compute.set_bind_group(0, group)
    compute.dispatch_workgroups(groups[0], groups[1], 1)
    compute.end()
    return encoder


# Bindings of shaders/object_order.wgsl, in order ("tile_starts": tile_bounds_source's).
SCAN_BINDINGS = ("params", "origins", "directions", "order", "ray_tiles", "tile_starts", "entries", "found")
# Its uniform block, struct TileParams: two u32 (padded to 16 bytes), three vec4 of
# 32-bit integers, then the origin (vec4 of f64).
TILE_PARAMS_BYTES = 4 * 16 + 4 * 8
# Tiles whose bounds a uniform buffer holds: its 64 KiB (WebGPU's least
# maxUniformBufferBindingSize) as array<vec4<u32>, 4096>, one end a tile.
UNIFORM_TILES = 16384


def tile_bounds_source(uniform: bool) -> str:
    """WGSL of binding 5 and ``tile_bounds(tile)``, tile k's entries as (first, end).
    ``uniform``: from the ends of the tiles' lists in a uniform buffer (``tile_ends``;
    at most UNIFORM_TILES tiles), else from the lists' starts in storage."""
    if not uniform:
        return (
            "@group(0) @binding(5) var<storage, read> tile_starts: array<u32>;  // tile k: [k] .. [k + 1]\n"
            "fn tile_bounds(tile: u32) -> vec2<u32> {\n"
            "    return vec2<u32>(tile_starts[tile], tile_starts[tile + 1u]);\n"
            "}\n"
        )
    return (
        f"@group(0) @binding(5) var<uniform> tile_ends: array<vec4<u32>, {UNIFORM_TILES // 4}>;\n"
        "fn tile_end(tile: u32) -> u32 {\n"
        "    return tile_ends[tile >> 2u][tile & 3u];\n"
        "}\n"
        "fn tile_bounds(tile: u32) -> vec2<u32> {\n"
        "    return vec2<u32>(select(tile_end(max(tile, 1u) - 1u), 0u, tile == 0u), tile_end(tile));\n"
        "}\n"
    )


def tile_ends(tile_starts) -> np.ndarray:
    """The uniform buffer's words: the end of each tile's list (``tile_starts[1:]``),
    zeros after the last tile up to UNIFORM_TILES."""
    words = np.zeros(UNIFORM_TILES, np.uint32)
    words[: len(tile_starts) - 1] = tile_starts[1:]
    return words


def pack_tile_params(rays, scan, origin=(0.0, 0.0, 0.0)) -> bytes:
    """The uniform block of one object-order dispatch, laid out as ``struct TileParams``
    (``origin``: where every ray starts, read when the pipeline's ONE_ORIGIN is set)."""
    offset, shifts, masks = scan.packing
    ints = np.zeros((4, 4), dtype=np.int64)
    ints[0, :2] = (rays, scan.tile_shift)
    ints[1, :3], ints[2, :3], ints[3, :3] = shifts, masks, offset
    reals = np.zeros(4, np.float64)
    reals[:3] = origin
    # (the i32 fields as their two's complement)
    return ints.astype(np.uint32).tobytes() + reals.tobytes()


def write_mapped(buffer, array) -> None:
    """``array`` into the start of ``buffer``, mapped for writing (``write_pieces``)."""
    write_pieces(buffer, [(0, array)])


# Pieces this large are copied on numba's threads; smaller ones cost less than waking them.
PARALLEL_COPY_BYTES = 1 << 16


def write_pieces(buffer, pieces) -> None:
    """Each ``(offset, array)`` of ``pieces`` into ``buffer``, mapped for writing:
    copied into the mapped range where wgpu-py hands it out (its experimental
    ``_experimental_get_mapped_range``, asked for once; the view is dropped before
    the caller unmaps), large pieces on numba's threads; else by the buffer's own
    ``write_mapped``, on one thread (a scan's 6 MB of directions took 0.65 ms
    there)."""
    mapped_range = getattr(buffer, "_experimental_get_mapped_range", None)
    whole_words = all(offset % 4 == 0 and np.asarray(array).nbytes % 4 == 0 for offset, array in pieces)
    if mapped_range is None or not whole_words:
        for offset, array in pieces:
            buffer.write_mapped(array, offset)
        return
    end = max(offset + np.asarray(array).nbytes for offset, array in pieces)
    view = mapped_range(0, end)
    try:
        words = np.frombuffer(view, np.uint32)
        for offset, array in pieces:
            source = np.ascontiguousarray(array).reshape(-1).view(np.uint32)
            target = words[offset // 4 : offset // 4 + len(source)]
            if source.nbytes >= PARALLEL_COPY_BYTES:
                copy_in_parts(target, source)
            else:
                target[:] = source
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

    def __init__(
        self,
        device,
        limits: dict[str, int],
        shader_file: Callable[[str], str],
        maps_storage: bool,
        uniform_tile_bounds: bool = False,
    ):
        """``limits`` as the device was opened with (and capped); ``shader_file(name)``
        gives a shader's source; ``maps_storage``: the device maps storage buffers
        (``mappable-primary-buffers``, asked for on a CPU adapter);
        ``uniform_tile_bounds``: scans of up to UNIFORM_TILES tiles read their tiles'
        bounds from a uniform buffer (``tile_bounds_source``; lavapipe's way)."""
        self._device = device
        self._limits = limits
        self._shader_file = shader_file
        self.maps_storage = maps_storage
        self.uniform_tile_bounds = uniform_tile_bounds
        self._compiled: dict[tuple[bool, bool, bool], Any] = {}  # pipelines by ``_pipeline``'s arguments
        # By uniform tile bounds: shader modules; bind group and pipeline layouts.
        self._modules: dict[bool, Any] = {}
        self._layouts: dict[bool, tuple[Any, Any]] = {}
        self._buffers: dict[str, Any] = {}  # by name
        self._groups: dict[bool, tuple[tuple[int, ...], Any]] = {}  # as _layouts: buffer ids, bind group
        self._mapping: dict[str, Any] = {}  # buffers being mapped for the next scan

    def _pipeline(self, uniform: bool, one_per_bin: bool, one_origin: bool):
        """The object-order pipeline (f64 only): its tile bounds from a uniform buffer
        or from storage, its constants ONE_PER_BIN and ONE_ORIGIN set as given."""
        key = (uniform, one_per_bin, one_origin)
        if key not in self._compiled:
            if uniform not in self._modules:
                code = "\n".join(
                    (
                        wgsl_constants("f64"),
                        self._shader_file("axis.wgsl"),
                        tile_bounds_source(uniform),
                        self._shader_file("object_order.wgsl"),
                    )
                )
                self._modules[uniform] = self._device.create_shader_module(label="tiles", code=code)
            module = self._modules[uniform]
            constants = {"ONE_PER_BIN": float(one_per_bin), "ONE_ORIGIN": float(one_origin)}
            # Pipelines of one tile bounds share a layout, so one bind group serves them.
            self._compiled[key] = self._device.create_compute_pipeline(
                label="tiles",
                layout=self._layout(uniform)[1],
                compute={"module": module, "entry_point": "test_tiles", "constants": constants},
            )
        return self._compiled[key]

    def _layout(self, uniform: bool):
        """The bind group and pipeline layouts of SCAN_BINDINGS (binding 5 a uniform
        buffer or storage)."""
        import wgpu

        if uniform not in self._layouts:
            kinds = {"params": wgpu.BufferBindingType.uniform, "found": wgpu.BufferBindingType.storage}
            if uniform:
                kinds["tile_starts"] = wgpu.BufferBindingType.uniform
            entries = [
                {
                    "binding": b,
                    "visibility": wgpu.ShaderStage.COMPUTE,
                    "buffer": {"type": kinds.get(name, wgpu.BufferBindingType.read_only_storage)},
                }
                for b, name in enumerate(SCAN_BINDINGS)
            ]
            group = self._device.create_bind_group_layout(entries=entries)
            self._layouts[uniform] = (group, self._device.create_pipeline_layout(bind_group_layouts=[group]))
        return self._layouts[uniform]

    def test_tiles(self, origins, directions, scan, shared_origin=False) -> np.ndarray | None:
        """Each ray's hit as its packed cell (``scan.packing``; NO_CELL none), from
        shaders/object_order.wgsl; None when an array exceeds a storage binding.
        ``shared_origin``: every ray starts at ``origins[0]``, the one row sent."""
        import wgpu

        n = len(directions)
        uniform = self.uniform_tile_bounds and len(scan.tile_starts) - 1 <= UNIFORM_TILES
        inputs = {
            "origins": origin_rows(origins, shared_origin),  # as given when already so
            "directions": directions,
            "order": scan.order,
            "ray_tiles": scan.ray_tiles,
            "entries": scan.entries,
        }
        if not uniform:
            inputs["tile_starts"] = scan.tile_starts
        sizes = {name: array.nbytes for name, array in inputs.items()}
        sizes["found"] = 4 * n
        if max(sizes.values()) > self._buffer_limit():
            return None
        buffers = {name: self._buffer(name, size) for name, size in sizes.items()}
        buffers["params"] = self._buffer("params", TILE_PARAMS_BYTES, uniform=True)
        queue = self._device.queue
        origin = origins[0] if shared_origin else (0.0, 0.0, 0.0)
        queue.write_buffer(buffers["params"], 0, pack_tile_params(n, scan, origin))
        if uniform:
            buffers["tile_starts"] = self._buffer("tile_ends", 4 * UNIFORM_TILES, uniform=True)
            queue.write_buffer(buffers["tile_starts"], 0, tile_ends(scan.tile_starts))
        for name, array in inputs.items():
            self._fill(name, buffers[name], np.ascontiguousarray(array))
        pipeline = self._pipeline(uniform, not len(scan.ray_tiles), shared_origin)
        key = tuple(id(buffers[name]) for name in SCAN_BINDINGS)
        made = self._groups.get(uniform)
        if made is None or made[0] != key:  # made again only when a buffer has grown
            made = self._groups[uniform] = (
                key,
                self._device.create_bind_group(
                    layout=self._layout(uniform)[0],
                    entries=[
                        {"binding": b, "resource": {"buffer": buffers[name]}}
                        for b, name in enumerate(SCAN_BINDINGS)
                    ],
                ),
            )
        queue.submit([dispatch_encoder(self._device, self._limits, pipeline, made[1], n).finish()])
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
            if uniform:  # fixed sizes, bound whole: the uniform block, the tile ends
                size = max(16, size)
            else:  # room to grow, within the limits (which need not be powers of two)
                size = max(16, min(1 << (max(size, 1) - 1).bit_length(), self._buffer_limit() // 4 * 4))
            buffer = self._device.create_buffer(label=f"scan-{name}", size=size, usage=usage)
            self._buffers[name] = buffer
        return buffer
