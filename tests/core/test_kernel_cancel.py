"""Cancel and Ctrl-C reach the kernel within one long 5-axis move, through the binding: the progress callback's
False raises Cancelled within a second (measured from the False to the exception), and a KeyboardInterrupt
without any callback arrives within a second too. The move is long enough (about 400 000 tool instances,
tens of seconds) that a kernel checking only between moves cannot pass; the bounds allow 3x for a loaded
machine and do not depend on its speed otherwise."""
from __future__ import annotations

import _thread
import signal
import threading
import time

import numpy as np
import pytest

from tmm_workbench.core.kernel import native

SLACK = 3.0  # s: the one-second target, three times over


def long_move(progress=None):
    stock = native.ZMap(-205.0, -5.0, 0.05, 8200, 200, 1.0)
    tips = np.array([[-200.0, 0.0, 0.0], [200.0, 0.0, 0.0]])
    axes = np.array([[0.0, 0.0, 1.0], [0.3, 0.0, 1.0]])
    return native.cut_5axis(stock, 2.0, 1.0, "round_insert", tips, axes, np.array([0]), max_step=0.001,
                            threads=2, progress=progress)


def test_cancel_within_one_long_five_axis_move():
    start = time.monotonic()
    seen = []
    said_no = []

    def progress(fraction):
        seen.append(fraction)
        if time.monotonic() - start < 0.5:
            return True
        said_no.append(time.monotonic())
        return False

    with pytest.raises(native.Cancelled):
        long_move(progress)
    assert said_no, "the callback was never asked after the first half second"
    assert time.monotonic() - said_no[0] < SLACK
    assert any(0.02 < f < 1.0 for f in seen), seen[-5:]  # progress from within the move


def test_ctrl_c_without_a_callback_stops_a_long_move():
    interrupted = []

    def interrupt():
        interrupted.append((time.monotonic(), signal.getsignal(signal.SIGINT)))
        _thread.interrupt_main()  # as Ctrl-C: the signal flag Python checks in the main thread

    timer = threading.Timer(0.5, interrupt)
    start = time.monotonic()
    timer.start()
    kernel_returned = []
    try:
        with pytest.raises(KeyboardInterrupt):
            long_move()
            kernel_returned.append(time.monotonic())
            time.sleep(5)  # not reached when the kernel honours it; else the interrupt lands here
    except pytest.fail.Exception as e:
        # seen twice on a loaded machine, among many passes: what the next occurrence should tell
        told = [(round(t - start, 3), handler) for t, handler in interrupted]
        raise AssertionError(f"{e}; interrupt at (s, SIGINT handler) {told}, kernel returned at "
                             f"{[round(t - start, 3) for t in kernel_returned]} s, main thread: "
                             f"{threading.current_thread() is threading.main_thread()}") from None
    finally:
        timer.cancel()
    assert interrupted and time.monotonic() - interrupted[0][0] < SLACK
