"""Ctrl-C during a long call, as the module's tests check it."""

import _thread
import threading
import time

import pytest


def _timed(call, n):
    start = time.monotonic()
    call(n)
    return time.monotonic() - start


def assert_ctrl_c_stops(call, n, most):
    """call(n) made long enough to interrupt, whatever the machine's speed (n doubled
    up to `most`), then interrupted at a sixth of its time: it must raise
    KeyboardInterrupt well before it would have ended.

    The time is the faster of two calls (a first one may pay for caches), and a call
    that ends before Ctrl-C reaches it (a machine that sped up when the other tests
    beside this one ended) is timed again and tried again, up to three times; the
    interrupt never outlives the attempt, so it cannot strike a later test."""
    while True:
        full = min(_timed(call, n) for _ in range(2))
        if full > 0.8 or n >= most:
            break
        n *= 2
    for _ in range(3):
        timer = threading.Timer(full / 6, _thread.interrupt_main)
        returned = False
        start = time.monotonic()
        timer.start()
        try:
            try:
                call(n)
                returned = True
            finally:
                timer.cancel()
                timer.join()
        except KeyboardInterrupt:
            if returned:  # Ctrl-C came after the call had ended: too fast to test this time
                full = time.monotonic() - start
                continue
            took = time.monotonic() - start
            assert took < full / 2, f"stopped after {took:.2f} s of a {full:.2f} s call"
            return
        full = time.monotonic() - start  # ended before Ctrl-C: time it again
    pytest.fail("three calls ended before Ctrl-C reached them")
