"""Deadlines for every wait on another node, and waits that a stop request interrupts.

No ROS in here: the clocks, the stop event and the liveness check are injected, so the rules are
tested without a master (test_deadline.py). `goal_runner.py` and the task's rig adapters use them.

The rule of a `Deadline` is arm_controller's own (MoveMonitor): it expires when its seconds are
over in ROS time *and* in wall time, so a simulator running many times faster than real time,
or one running slower, is given the same time a move needs. While ROS time stands still or runs
backwards (no /clock: the simulator or the driver is gone or restarted), wall time alone counts.
"""

import threading
import time
from dataclasses import dataclass
from typing import Callable, Optional

DONE = "done"
STOPPED = "stopped"  # the stop event was set during the wait
GONE = "gone"  # the node that should answer is not running
EXPIRED = "expired"  # the deadline passed

SLICE = 0.05  # [s] wall time between checks of the stop event (Ctrl-C interrupts within this)
ALIVE_PERIOD = 0.5  # [s] wall time between liveness checks
CLOCK_STALL = 1.0  # [s] wall time without ROS time moving: ROS time counts as stopped


def ros_time() -> float:
    """ROS time [s] (simulated under use_sim_time); before rospy.init_node, wall time."""
    import rospy

    try:
        return rospy.get_time()
    except rospy.exceptions.ROSInitException:
        return time.monotonic()


def _schema_default(key: str) -> float:
    from rascal_workcell import schema

    return float(schema.builtin().find(key).default)


@dataclass
class ControllerTimings:
    """The schema's timings a client derives its deadlines from: arm_controller answers a move
    within its planned duration + arm.settle_timeout after up to 3 x arm.state_timeout of
    waiting (for a fresh /joint_states, for the arm to come to rest, for the driver's
    subscription), a gripper command within arm.gripper.timeout after up to 2 x
    arm.state_timeout; the client gives it rig.answer_margin more before naming it as not
    answering."""

    settle_timeout: float  # [s] arm.settle_timeout
    state_timeout: float  # [s] arm.state_timeout
    gripper_timeout: float  # [s] arm.gripper.timeout
    margin: float  # [s] rig.answer_margin

    @classmethod
    def from_config(cls, config) -> "ControllerTimings":
        """From the task's checked configuration (rascal_tasks.config.Config or its dict)."""
        arm = config["arm"]
        return cls(
            settle_timeout=arm["settle_timeout"],
            state_timeout=arm["state_timeout"],
            gripper_timeout=arm["gripper"]["timeout"],
            margin=config["rig"]["answer_margin"],
        )

    @classmethod
    def defaults(cls) -> "ControllerTimings":
        """The schema's defaults (rascal_workcell/schema/parameters.yaml)."""
        return cls(
            settle_timeout=_schema_default("arm.settle_timeout"),
            state_timeout=_schema_default("arm.state_timeout"),
            gripper_timeout=_schema_default("arm.gripper.timeout"),
            margin=_schema_default("rig.answer_margin"),
        )

    def move(self, planned: float = 0.0) -> float:
        """[s] for a move whose trajectory takes `planned` seconds (0 until it is known)."""
        return 3.0 * self.state_timeout + planned + self.settle_timeout + self.margin

    def gripper(self) -> float:
        return 2.0 * self.state_timeout + self.gripper_timeout + self.margin

    def service(self) -> float:
        """[s] for the controller's services (IK, FK, acknowledge), which answer at once."""
        return self.state_timeout + self.margin


class Deadline:
    """`seconds` from now, in ROS time and in wall time (see the module's rule); `seconds` may be
    raised later (a move's planned duration becomes known with its first feedback)."""

    def __init__(
        self,
        seconds: float,
        ros_now: Callable[[], float],
        wall_now: Callable[[], float] = time.monotonic,
    ):
        self.seconds = seconds
        self._ros_now = ros_now
        self._wall_now = wall_now
        self.ros0 = ros_now()
        self.wall0 = wall_now()
        self._last_ros = self.ros0
        self._ros_moved = self.wall0

    def wall_elapsed(self) -> float:
        return self._wall_now() - self.wall0

    def expired(self) -> bool:
        wall, ros = self._wall_now(), self._ros_now()
        if ros != self._last_ros:
            self._last_ros, self._ros_moved = ros, wall
        if wall - self.wall0 <= self.seconds:
            return False
        ros_elapsed = ros - self.ros0
        return (
            ros_elapsed > self.seconds or ros_elapsed < 0.0 or wall - self._ros_moved > CLOCK_STALL
        )


class Unfinished(Exception):
    """A wait ended without its answer; `outcome` is STOPPED, GONE or EXPIRED."""

    def __init__(self, outcome: str):
        super().__init__(outcome)
        self.outcome = outcome


def wait_for(
    done: Callable[[], bool],
    deadline: Deadline,
    stop: Optional[threading.Event] = None,
    alive: Optional[Callable[[], bool]] = None,
    sleep: Callable[[float], None] = time.sleep,
    wall_now: Callable[[], float] = time.monotonic,
) -> str:
    """Wait until `done()`; DONE, or why not: STOPPED (`stop` was set during the wait: a stop
    already set when the wait began does not interrupt it, so parking after Ctrl-C still
    waits for the arm), GONE (`alive()` said no; asked every ALIVE_PERIOD) or EXPIRED."""
    watch_stop = stop is not None and not stop.is_set()
    next_alive = wall_now() + ALIVE_PERIOD
    while True:
        if done():
            return DONE
        if watch_stop and stop.is_set():
            return STOPPED
        if alive is not None and wall_now() >= next_alive:
            next_alive = wall_now() + ALIVE_PERIOD
            if not alive():
                return DONE if done() else GONE
        if deadline.expired():
            return DONE if done() else EXPIRED
        sleep(SLICE)


class Background:
    """fn(*args) (a blocking service call) running in a worker thread from construction on, so
    the caller can do other work meanwhile (`Gripper.open_while`'s pattern for service calls)."""

    def __init__(self, fn: Callable, *args):
        self._box = {}
        self.finished = threading.Event()
        threading.Thread(target=self._work, args=(fn, args), daemon=True).start()

    def _work(self, fn, args):
        try:
            self._box["value"] = fn(*args)
        except BaseException as e:  # handed to the caller
            self._box["error"] = e
        finally:
            self.finished.set()

    def failed(self) -> bool:
        """Finished, with an exception."""
        return self.finished.is_set() and "error" in self._box

    def result(self, deadline: Deadline, stop: Optional[threading.Event] = None):
        """Its value or its exception once it finishes, or Unfinished(STOPPED or EXPIRED) when
        the wait ends first (the worker is left to finish)."""
        outcome = wait_for(self.finished.is_set, deadline, stop, sleep=self.finished.wait)
        if outcome != DONE:
            raise Unfinished(outcome)
        if "error" in self._box:
            raise self._box["error"]
        return self._box["value"]


def call(fn: Callable, *args, deadline: Deadline, stop: Optional[threading.Event] = None):
    """fn(*args) (a blocking service call) in a worker thread: its value or its exception, or
    Unfinished(STOPPED or EXPIRED) when the wait ends first (the worker is left to finish)."""
    return Background(fn, *args).result(deadline, stop)
