"""An occupancy on the wgpu device, and how trace.wgsl finds it.

The occupancy arrays (root, regions, tiles, bricks, columns, and the optional
empty-cube sides packed four octants to a word; all u32) are laid end to end
in one logical word array, split into power-of-two sized chunks, each its own
storage binding no larger than the adapter allows (``upload_occupancy``). The
shader reads them through ``fn occ(word)``, written per chunk count by
``occupancy_header``, and ``pack_params`` tells it where each array starts
(``struct Params``).

``wgpu`` is imported only inside the functions, as in tracing/wgpu_backend.py.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ladartui.errors import BackendUnavailable
from ladartui.scene.occupancy import BRICK_SHIFT, REGION_SHIFT
from ladartui.tracing.config import MARCH_SAMPLES_PER_PASS, METHOD_CODES, NO_COLUMNS, wgsl_constants

# trace.wgsl's bindings besides the occupancy chunks, which follow them: params,
# rays, hit cells, hit ranges, bundle starts (trace_rays); origins, directions,
# found (first_hits, tracing/wgpu_hits.py).
FIXED_BINDINGS = 8

# Params (uniform, see struct Params in trace.wgsl): 11 vec4 of 32-bit integers
# then a vec2<real> of float parameters (16 bytes in f64, 8 in f32).
PARAMS_BYTES = 11 * 16 + 16


class Upload:
    """An occupancy on the device: its chunk buffers, where each array starts,
    and the bind groups made with them (by the caller's key)."""

    def __init__(self, buffers, bases, total_words, chunk_shift):
        self.buffers = buffers
        self.bases = bases
        self.total_words = total_words
        self.chunk_shift = chunk_shift
        self.bind_groups: dict[Any, Any] = {}

    def bind_group(self, device, pipeline, key, bound):
        """The bind group of ``bound`` (binding -> buffer) and this occupancy's chunks
        for ``pipeline``, made once per ``key`` and kept here."""
        group = self.bind_groups.get(key)
        if group is None:
            entries = [{"binding": b, "resource": {"buffer": buffer}} for b, buffer in bound.items()]
            for chunk, buffer in enumerate(self.buffers):
                entries.append({"binding": FIXED_BINDINGS + chunk, "resource": {"buffer": buffer}})
            group = device.create_bind_group(layout=pipeline.get_bind_group_layout(0), entries=entries)
            self.bind_groups[key] = group
        return group


def chunk_words_for(max_binding_bytes: int) -> int:
    """Words per occupancy chunk: the largest power of two fitting one binding."""
    words = max(int(max_binding_bytes) // 4, 1)
    return 1 << (words.bit_length() - 1)


def upload_occupancy(device, occupancy, limits: dict[str, int], adapter_name: str, backend: str) -> Upload:
    """``occupancy``'s arrays copied into chunk buffers on ``device``; BackendUnavailable
    (naming ``backend`` and ``adapter_name``) when they cannot be addressed, need more
    bindings than ``limits`` allow, or cannot be allocated."""
    import wgpu

    arrays = [np.ascontiguousarray(part, dtype=np.uint32).ravel() for part in occupancy_arrays(occupancy)]
    bases, total = [], 0
    for array in arrays:
        bases.append(total)
        total += array.size
    if total >= 1 << 32:
        raise BackendUnavailable(
            f"backend {backend!r} cannot address this scene: its occupancy has {total} words (limit 2^32)"
        )
    max_binding = min(limits["max-storage-buffer-binding-size"], limits["max-buffer-size"])
    chunk_words = chunk_words_for(max_binding)
    chunks = max(-(-total // chunk_words), 1)
    allowed = limits["max-storage-buffers-per-shader-stage"] - FIXED_BINDINGS
    if chunks > allowed:
        raise BackendUnavailable(
            f"backend {backend!r} cannot hold this scene on {adapter_name!r}: "
            f"its occupancy needs {total * 4 / 2**20:.0f} MiB in {chunks} bindings of "
            f"{chunk_words * 4 / 2**20:.0f} MiB, the adapter allows {allowed}; use backend 'numba'"
        )
    buffers = []
    for chunk in range(chunks):
        start = chunk * chunk_words
        words = min(chunk_words, total - start)
        try:
            buffer = device.create_buffer(
                size=max(words, 4) * 4, usage=wgpu.BufferUsage.STORAGE | wgpu.BufferUsage.COPY_DST
            )
        except Exception as error:
            raise BackendUnavailable(
                f"backend {backend!r} could not allocate {words * 4 / 2**20:.0f} MiB "
                f"for the occupancy: {error}"
            ) from error
        # Copy the slices of each array that fall in this chunk.
        for base, array in zip(bases, arrays):
            lo, hi = max(base, start), min(base + array.size, start + words)
            if lo < hi:
                device.queue.write_buffer(buffer, (lo - start) * 4, array[lo - base : hi - base])
        buffers.append(buffer)
    return Upload(buffers, bases, total, chunk_words.bit_length() - 1)


def occupancy_header(real: str, chunks: int, chunk_shift: int) -> str:
    """The WGSL that trace.wgsl is assembled after: the shared constants, the
    occupancy's chunk bindings and ``fn occ(word)`` over them."""
    lines = [wgsl_constants(real)]
    for chunk in range(chunks):
        binding = FIXED_BINDINGS + chunk
        lines.append(f"@group(0) @binding({binding}) var<storage, read> occupancy{chunk}: array<u32>;")
    lines.append("// One logical word array over all chunks (see tracing/wgpu_occupancy.py).")
    lines.append("fn occ(word: u32) -> u32 {")
    if chunks == 1:
        lines.append("    return occupancy0[word];")
    else:
        mask = (1 << chunk_shift) - 1
        lines.append(f"    let offset = word & {mask}u;")
        lines.append(f"    switch (word >> {chunk_shift}u) {{")
        for chunk in range(chunks - 1):
            lines.append(f"        case {chunk}u: {{ return occupancy{chunk}[offset]; }}")
        lines.append(f"        default: {{ return occupancy{chunks - 1}[offset]; }}")
        lines.append("    }")
    lines.append("}")
    return "\n".join(lines)


def occupancy_arrays(occupancy):
    """The u32 arrays laid end to end on the device: root, regions, tiles, bricks, columns, cubes."""
    columns = getattr(occupancy, "columns", None)
    if columns is None:  # none: pack_params says NO_COLUMNS, and the column skip is off
        columns = np.zeros(0, np.uint32)
    return [
        occupancy.root,
        occupancy.regions,
        occupancy.tiles,
        occupancy.bricks,
        columns,
        cube_words(occupancy),
    ]


def cube_words(occupancy):
    """``Occupancy.cubes`` as u32 words, one per brick cell: byte ``octant`` of word
    ``cell`` is ``cubes[4 cell + octant]``. Empty when the occupancy has no cubes."""
    cubes = getattr(occupancy, "cubes", None)
    if cubes is None or getattr(occupancy, "cube_dims", None) is None or len(cubes) == 0:
        return np.zeros(0, dtype=np.uint32)
    return np.ascontiguousarray(cubes, dtype=np.uint8).view("<u4")


def cube_box(occupancy):
    """(cube_origin, cube_dims) as int64 (3,); zero dims (no jumps) without cubes."""
    if len(cube_words(occupancy)) == 0:
        return np.zeros(3, np.int64), np.zeros(3, np.int64)
    return (
        np.asarray(occupancy.cube_origin, dtype=np.int64),
        np.asarray(occupancy.cube_dims, dtype=np.int64),
    )


def pack_params(
    occupancy,
    upload,
    method,
    step,
    count,
    precision,
    first_sample=0,
    samples_per_pass=MARCH_SAMPLES_PER_PASS,
    shared_origin=False,
    shift=(0, 0),
) -> bytes:
    """The uniform block for one dispatch, laid out as ``struct Params``.

    ``first_sample`` and ``samples_per_pass`` bound the march's samples in this
    dispatch (see MARCH_SAMPLES_PER_PASS); ``shared_origin``: first_hits reads
    one origin for every ray. ``shift``: the (x, y) cell, a multiple of the root
    cell's 2**REGION_SHIFT = 512 (so every node's slots stay as they are), that the rays' cell
    space starts at: the occupancy's boxes and the scene's footprint are given
    less it (tracing/f32_rays.py, ``f32_shift``).
    """
    move = np.array([shift[0], shift[1], 0], dtype=np.int64)
    if np.any(move % (1 << REGION_SHIFT)):
        raise ValueError(f"shift {tuple(shift)} is not a multiple of {1 << REGION_SHIFT} cells")
    ints = np.zeros((11, 4), dtype=np.int32)
    ints[0, :3] = occupancy.shape
    ints[1, :3] = np.asarray(occupancy.bbox_lo, dtype=np.int64) - move
    ints[2, :3] = np.asarray(occupancy.bbox_hi, dtype=np.int64) - move
    ints[3, :3] = np.asarray(occupancy.root_origin, dtype=np.int64) - move
    ints[4, :3] = occupancy.root_dims
    ints[5, :] = np.array(upload.bases[:4], dtype=np.int64).astype(np.uint32).view(np.int32)
    ints[6, :] = (count, METHOD_CODES[method], int(occupancy.zmax), len(occupancy.root))
    columns_at = NO_COLUMNS if getattr(occupancy, "columns", None) is None else upload.bases[4]
    ints[7, 0] = np.array(columns_at, dtype=np.int64).astype(np.uint32).view(np.int32)
    ints[7, 1:4] = (first_sample, samples_per_pass, int(shared_origin))
    cube_origin, cube_dims = cube_box(occupancy)
    ints[8, :3] = cube_origin - (move >> BRICK_SHIFT)  # the cubes are in bricks
    ints[8, 3] = np.array(upload.bases[5], dtype=np.int64).astype(np.uint32).view(np.int32)
    ints[9, :3] = cube_dims
    # The scene's footprint [0, nx) x [0, ny) in the rays' cell space.
    ints[10, :] = (-move[0], -move[1], int(occupancy.shape[0]) - move[0], int(occupancy.shape[1]) - move[1])
    reals = np.array([step, 0], dtype=np.float64 if precision == "f64" else np.float32)
    return ints.tobytes() + reals.tobytes()
