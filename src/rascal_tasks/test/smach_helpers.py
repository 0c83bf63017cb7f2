"""States and fixtures shared by the test_smach_* files (no ROS, no master)."""

import threading
import time

from rascal_tasks import smach


class Setter(smach.State):
    """Writes `value` under output key `key` and returns `outcome`."""

    def __init__(self, key="x", value=1, outcome="done", outcomes=("done",)):
        smach.State.__init__(self, outcomes=list(outcomes), output_keys=[key])
        self.key, self.value, self.outcome = key, value, outcome

    def execute(self, ud):
        ud[self.key] = self.value
        return self.outcome


class Getter(smach.State):
    """Reads input key `key` into `self.seen` and returns 'done'."""

    def __init__(self, key="x"):
        smach.State.__init__(self, outcomes=["done"], input_keys=[key])
        self.key = key
        self.seen = []

    def execute(self, ud):
        self.seen.append(ud[self.key])
        return "done"


class Returns(smach.State):
    """Returns a fixed outcome and counts its executions (records order in `log`)."""

    def __init__(self, outcome="done", outcomes=("done",), log=None, name=None):
        smach.State.__init__(self, outcomes=list(outcomes))
        self.outcome, self.runs, self.log, self.name = outcome, 0, log, name

    def execute(self, ud):
        self.runs += 1
        if self.log is not None:
            self.log.append(self.name)
        return self.outcome


class Raises(smach.State):
    def __init__(self, exc=None):
        smach.State.__init__(self, outcomes=["done"])
        self.exc = exc if exc is not None else RuntimeError("boom")

    def execute(self, ud):
        raise self.exc


class Waiter(smach.State):
    """Blocks until preempted (services it if `service`) or `timeout` passes."""

    def __init__(self, service=True, timeout=5.0, started=None):
        smach.State.__init__(self, outcomes=["done", "preempted"])
        self.service, self.timeout = service, timeout
        self.started = started or threading.Event()
        self.saw_preempt = False

    def execute(self, ud):
        self.started.set()
        deadline = time.monotonic() + self.timeout
        while time.monotonic() < deadline:
            if self.preempt_requested():
                self.saw_preempt = True
                if self.service:
                    self.service_preempt()
                    return "preempted"
                return "done"
            time.sleep(0.005)
        return "done"
