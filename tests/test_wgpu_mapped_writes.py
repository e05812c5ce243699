"""A scan's arrays into buffers mapped for writing (tracing/wgpu_scans.write_mapped):
on numba's threads where wgpu-py hands out the mapped range, else by its write_mapped."""

import numpy as np

from ladartui.tracing import wgpu_scans


class WriteOnlyBuffer:
    """A mapped buffer that only has wgpu-py's public ``write_mapped``."""

    def __init__(self):
        self.writes = []

    def write_mapped(self, data, offset):
        self.writes.append((bytes(memoryview(data).cast("B")), offset))


class RangedBuffer(WriteOnlyBuffer):
    """One that also hands out its mapped range (as wgpu-py's experimental method does)."""

    def __init__(self, size):
        super().__init__()
        self.memory = bytearray(size)

    def _experimental_get_mapped_range(self, offset, size):
        return memoryview(self.memory)[offset : offset + size]


def test_without_the_mapped_range_the_public_write_takes_the_array():
    buffer, array = WriteOnlyBuffer(), np.arange(10, dtype=np.float64)
    wgpu_scans.write_mapped(buffer, array)
    assert buffer.writes == [(array.tobytes(), 0)]


def test_the_mapped_range_gets_every_byte_and_nothing_past_them():
    for array in (
        np.random.default_rng(3).normal(size=(1001, 3)),  # a scan's directions
        np.arange(4097, dtype=np.uint32),
        np.arange(6, dtype=np.uint64).reshape(3, 2)[:, :1],  # not contiguous: copied first
    ):
        buffer = RangedBuffer(array.nbytes + 16)
        wgpu_scans.write_mapped(buffer, array)
        assert buffer.writes == []
        assert bytes(buffer.memory[: array.nbytes]) == np.ascontiguousarray(array).tobytes()
        assert bytes(buffer.memory[array.nbytes :]) == bytes(16)


def test_a_size_not_in_whole_words_goes_the_public_way():
    buffer, array = RangedBuffer(8), np.arange(3, dtype=np.uint8)
    wgpu_scans.write_mapped(buffer, array)
    assert buffer.writes == [(array.tobytes(), 0)] and bytes(buffer.memory) == bytes(8)


def test_a_device_buffer_reads_back_what_was_written(wgpu_backend):
    """On the adapter here (the locked wgpu-py hands out the mapped range)."""
    import wgpu

    device = wgpu_backend._open_device()
    array = np.random.default_rng(5).normal(size=(4096, 3))
    source = device.create_buffer(
        size=array.nbytes, usage=wgpu.BufferUsage.MAP_WRITE | wgpu.BufferUsage.COPY_SRC
    )
    target = device.create_buffer(
        size=array.nbytes, usage=wgpu.BufferUsage.COPY_DST | wgpu.BufferUsage.MAP_READ
    )
    assert hasattr(source, "_experimental_get_mapped_range")
    source.map_sync(wgpu.MapMode.WRITE)
    try:
        wgpu_scans.write_mapped(source, array)
    finally:
        source.unmap()
    encoder = device.create_command_encoder()
    encoder.copy_buffer_to_buffer(source, 0, target, 0, array.nbytes)
    device.queue.submit([encoder.finish()])
    target.map_sync(wgpu.MapMode.READ)
    try:
        back = np.frombuffer(target.read_mapped(), dtype=np.float64).reshape(array.shape)
    finally:
        target.unmap()
    np.testing.assert_array_equal(back, array)
