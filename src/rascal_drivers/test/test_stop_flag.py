"""StopFlag: Ctrl-C and SIGTERM end a driver's loop through a flag, with no exception raised
into the code the signal interrupts (a KeyboardInterrupt between a lock's acquire and its `with`
left the lock held and the torque-off after the loop waiting for ever)."""

import os
import signal
import threading

import pytest

from rascal_drivers.stop_flag import StopFlag


@pytest.fixture
def handlers():
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    yield
    for s, h in saved.items():
        signal.signal(s, h)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_sets_the_flag_and_raises_nothing_inside_a_held_lock(handlers, sig):
    stop = StopFlag().install()
    lock = threading.Lock()
    assert not stop.requested
    with lock:
        os.kill(os.getpid(), sig)  # handled at the next bytecode, inside the with block
        for _ in range(1000):
            if stop.requested:
                break
    assert stop.requested
    assert lock.acquire(timeout=0.1)  # released by its with block: nothing was thrown there
