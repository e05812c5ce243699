"""The CLI's cancellable runner: a Ctrl-C is a cancel wherever the main thread is when it lands."""

from __future__ import annotations

import _thread
import sys
import threading

import pytest

from ladartui.cli.progress import run_cancellable
from ladartui.errors import Cancelled


def test_a_ctrl_c_that_lands_while_the_worker_starts_is_a_cancel():
    # A long switch interval keeps the GIL with the worker until it blocks, so the
    # interrupt is always pending when the main thread resumes inside Thread.start().
    previous = sys.getswitchinterval()
    sys.setswitchinterval(30.0)
    cancel = threading.Event()
    stopped_by_cancel = []

    def work():
        _thread.interrupt_main()  # as Ctrl-C would, on the main thread
        stopped_by_cancel.append(cancel.wait(10))
        raise Cancelled("stopped")

    try:
        with pytest.raises(Cancelled, match="nothing written"):
            run_cancellable(work, cancel, "test-worker", Cancelled("nothing written"))
    finally:
        sys.setswitchinterval(previous)
    assert stopped_by_cancel == [True]


def test_a_result_that_arrives_before_the_cancel_is_kept():
    cancel = threading.Event()
    assert run_cancellable(lambda: 42, cancel, "test-worker", Cancelled("no")) == 42
    assert not cancel.is_set()
