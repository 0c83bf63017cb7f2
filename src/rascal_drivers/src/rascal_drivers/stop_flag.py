"""Ctrl-C and SIGTERM as a flag a driver's loop reads, not an exception thrown into whatever its
main thread was doing at that instant. No ROS in here.

A KeyboardInterrupt can land between a lock's acquire and the `with` block that releases it
(or inside pyserial, or a rospy publish): the lock stays held, and the torque-off or the port's
close after the loop then waits for ever. In CI a driver that had not exited 10 s after Ctrl-C
was killed (exit -9) with no torque-off line. The handler here only sets an attribute: it takes
no lock, so it cannot deadlock with the code it interrupts; every loop it ends sleeps or waits
at most a fraction of a second between reads of it. Installed explicitly, it also works where
the driver was started with SIGINT ignored (a shell's background job, a CI run): Python then
installs no KeyboardInterrupt of its own, and Ctrl-C did nothing at all (the likelier cause of
the CI kills above: the drivers had relied on that default).
"""

import signal


class StopFlag:
    """`requested` turns True on SIGINT or SIGTERM once `install()`ed (the loop's condition)."""

    def __init__(self):
        self.requested = False

    def _set(self, _signum, _frame):
        self.requested = True

    def install(self) -> "StopFlag":
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self._set)
        return self
