"""rascal_control.Gripper: open, close or set the gripper through /rascal/gripper."""

from typing import Optional

from rascal_control.gripper_limits import opening_limits
from rascal_control.results import OK, GripperResult, Timeout, move_error


class Gripper:
    """PyRobot-like gripper client. `close()` returns a GripperResult that is truthy when an
    object is held; failures raise Timeout, Preempted or InvalidGoal."""

    def __init__(self, client=None, wait: float = 10.0):
        if client is None:
            import rospy
            from rascal_msgs.msg import GripperAction

            from rascal_control.goal_runner import GoalRunner

            client = GoalRunner("/rascal/gripper", GripperAction)
            if not client.wait_for_server(rospy.Duration(wait)):
                raise Timeout(
                    3,
                    "no /rascal/gripper action server within %.0f s; is "
                    "arm_controller running?" % wait,
                )
        self._client = client
        self.last_result: Optional[GripperResult] = None
        # [m] opening between the fingertips, closed and fully open (the URDF's finger limits)
        self.min_width, self.max_width = opening_limits()

    @property
    def width(self) -> Optional[float]:
        """[m] opening at the end of the last command (None before the first)."""
        return self.last_result.width if self.last_result else None

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

    def _run(self, command: int, width: float, timeout: Optional[float]) -> GripperResult:
        import rospy
        from rascal_msgs.msg import GripperGoal

        goal = GripperGoal(command=command, width=float(width))
        self._client.send_goal(goal)
        if not self._client.wait_for_result(rospy.Duration(timeout or 0.0)):
            self._client.cancel_goal()
            raise Timeout(3, "no result from /rascal/gripper within %.1f s; cancelled" % timeout)
        msg = self._client.get_result()
        if msg is None:
            raise Timeout(3, "/rascal/gripper ended without a result (controller gone?)")
        result = GripperResult(msg.code, msg.message, msg.width, msg.holding, msg.duration)
        self.last_result = result
        if msg.code != OK:
            raise move_error(msg.code, msg.message, result)
        return result
