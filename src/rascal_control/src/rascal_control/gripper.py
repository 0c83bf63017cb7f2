"""rascal_control.Gripper: open, close or set the gripper through /rascal/gripper."""

import threading
from typing import Optional

from rascal_control import deadline as dl
from rascal_control.gripper_limits import opening_limits
from rascal_control.results import (
    GOAL_SUCCEEDED,
    OK,
    PREEMPTED,
    TIMEOUT,
    GripperResult,
    Preempted,
    Timeout,
    move_error,
    unrun_goal,
)


class Gripper:
    """PyRobot-like gripper client. `close()` returns a GripperResult that is truthy when an
    object is held; failures raise Timeout, Preempted, InvalidGoal or DriverRestarted. Every
    wait has a deadline (timings.gripper(): arm.gripper.timeout + margin); a controller that
    does not answer, or whose node is gone, raises Timeout naming arm_controller; `stop` set
    during a wait cancels the command and raises Preempted."""

    def __init__(
        self,
        client=None,
        wait: float = 10.0,
        timings: Optional[dl.ControllerTimings] = None,
        stop: Optional[threading.Event] = None,
        ros_now=None,
    ):
        self.timings = timings or dl.ControllerTimings.defaults()
        self.stop_event = stop
        self._ros_now = ros_now or dl.ros_time
        if client is None:
            import rospy
            from rascal_msgs.msg import GripperAction

            from rascal_control.goal_runner import GoalRunner

            client = GoalRunner("/rascal/gripper", GripperAction)
            if not client.wait_for_server(rospy.Duration(wait), stop):
                raise Timeout(
                    TIMEOUT,
                    "no /rascal/gripper action server within %.0f s (not connected: %s); is "
                    "arm_controller running?" % (wait, ", ".join(client.missing())),
                )
        self._client = client
        self.last_result: Optional[GripperResult] = None
        # [m] opening between the fingertips, closed and fully open (the URDF's finger limits)
        self.min_width, self.max_width = opening_limits()

    @property
    def width(self) -> Optional[float]:
        """[m] opening at the end of the last command (None before the first)."""
        return self.last_result.width if self.last_result is not None else None

    def open(self, width: Optional[float] = None, timeout: Optional[float] = None) -> GripperResult:
        """Open fully, or to `width` [m]."""
        return self._run(0, width or 0.0, timeout)

    def close(self, timeout: Optional[float] = None) -> GripperResult:
        """Close until the fingers stop; truthy result = an object is held."""
        return self._run(1, 0.0, timeout)

    def set_width(self, width: float, timeout: Optional[float] = None) -> GripperResult:
        """Move the fingers to an opening of `width` [m], min_width..max_width (0.030..0.074)."""
        if not self.min_width <= width <= self.max_width:
            raise ValueError(
                "width %.4f m is outside [%.3f, %.3f]" % (width, self.min_width, self.max_width)
            )
        return self._run(2, width, timeout)

    def open_while(self, width: Optional[float], during, timeout: Optional[float] = None):
        """Open fully, or to `width` [m], while `during()` runs (an arm move the fingers' stroke
        may overlap: the caller knows it is safe); returns what `during()` returned, once the
        gripper has opened too. Should `during()` raise, the opening is still waited for (its
        own failure then left to the next command) and `during()`'s error raised."""
        self._send(0, width or 0.0)
        try:
            value = during()
        except BaseException:
            try:
                self._wait(timeout)
            except Exception:  # the move's failure is the one to report
                pass
            raise
        self._wait(timeout)
        return value

    def _run(self, command: int, width: float, timeout: Optional[float]) -> GripperResult:
        self._send(command, width)
        return self._wait(timeout)

    def _send(self, command: int, width: float) -> None:
        from rascal_msgs.msg import GripperGoal

        self._client.send_goal(GripperGoal(command=command, width=float(width)))

    def _wait(self, timeout: Optional[float]) -> GripperResult:
        """The result of the goal sent last; the deadline counts from now (a goal sent before
        an arm move has had that move's time as well)."""
        deadline = dl.Deadline(
            timeout if timeout is not None else self.timings.gripper(), self._ros_now
        )
        outcome = self._client.wait_for_result(deadline, self.stop_event)
        if outcome != dl.DONE:
            self._client.cancel_goal()
            if outcome == dl.STOPPED:
                raise Preempted(PREEMPTED, "stop requested: gripper command cancelled")
            if outcome == dl.GONE:
                raise Timeout(
                    TIMEOUT,
                    "arm_controller not answering on /rascal/gripper (its node does not "
                    "respond); is it running? (rosrun rascal_control arm_controller)",
                )
            raise Timeout(
                TIMEOUT,
                "arm_controller not answering on /rascal/gripper: no result %.1f s after the "
                "command; is it running?" % deadline.seconds,
            )
        msg = self._client.get_result()
        status, text = self._client.terminal()
        if msg is not None and msg.code == OK and status != GOAL_SUCCEEDED:
            raise unrun_goal("/rascal/gripper", status, text)
        if msg is None:
            raise Timeout(
                TIMEOUT,
                "/rascal/gripper ended without a result (arm_controller restarted or gone?)",
            )
        result = GripperResult(msg.code, msg.message, msg.width, msg.holding, msg.duration)
        self.last_result = result
        if msg.code != OK:
            raise move_error(msg.code, msg.message, result)
        return result
