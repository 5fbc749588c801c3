"""Ctrl-C during a long call, as the module's tests check it."""

import _thread
import threading
import time

import pytest


def assert_ctrl_c_stops(call, n, most):
    """call(n) made long enough to interrupt, whatever the machine's speed (n doubled
    up to `most`), then interrupted at a sixth of its time: it must raise
    KeyboardInterrupt well before it would have ended."""
    while True:
        start = time.monotonic()
        call(n)
        full = time.monotonic() - start
        if full > 0.8 or n >= most:
            break
        n *= 2
    timer = threading.Timer(full / 6, _thread.interrupt_main)
    timer.start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        call(n)
    took = time.monotonic() - start
    timer.join()
    assert took < full / 2, f"stopped after {took:.2f} s of a {full:.2f} s call"
