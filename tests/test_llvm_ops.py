"""LLVM instructions the tracers use through numba intrinsics (tracing/llvm_ops.py)."""

import numpy as np
import pytest
from numba import njit

from ladartui.tracing.llvm_ops import prefetch_row, prefetch_row_for_write, trailing_zeros


def test_trailing_zeros_numbers_the_lowest_set_bit():
    # The tile tests walk a row's live bins by their lowest set bit.
    count = njit(lambda x: trailing_zeros(x))
    rng = np.random.default_rng(5)
    values = [np.int64(1) << n for n in range(63)] + [np.int64(-(2**63))]
    values += [np.int64(x) for x in rng.integers(1, 2**62, 200)] + [np.int64(-1), np.int64(-6)]
    for x in values:
        lowest = int(x) & -int(x)
        assert count(x) == lowest.bit_length() - 1, x


@pytest.mark.parametrize("shape", [(50,), (50, 3)])
def test_prefetches_are_emitted_and_change_nothing(shape):
    # A prefetch is a hint: the function reads and writes what it would without it,
    # including rows past the end (no fault), and its code asks for the lines.
    @njit
    def gather(values, order, out):
        total = 0.0
        for k in range(order.shape[0]):
            prefetch_row(values, order[(k + 8) % order.shape[0]])
            prefetch_row_for_write(out, order[k] + 1000)
            total += values[order[k]].sum() if values.ndim > 1 else values[order[k]]
            out[order[k]] = k
        return total

    rng = np.random.default_rng(2)
    values = rng.random(shape)
    order = rng.permutation(shape[0])
    out = np.zeros(shape[0])
    assert gather(values, order, out) == pytest.approx(values.sum())
    assert np.array_equal(out[order], np.arange(shape[0]))
    code = gather.inspect_llvm(gather.signatures[0])
    assert code.count("call void @llvm.prefetch") >= 2
