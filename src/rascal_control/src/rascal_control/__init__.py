"""PyRobot-like Python client of RASCAL's arm controller.

    import rospy
    from rascal_control import Arm, Gripper
    rospy.init_node("my_task")
    arm, gripper = Arm(), Gripper()
    arm.go("home")
    arm.move_to(Arm.top_down(0.30, 0.10, 0.15, yaw=0.3))
    arm.move_to(Arm.top_down(0.30, 0.10, 0.02, yaw=0.3), motion="linear")
    held = gripper.close()          # GripperResult; truthy when an object is held
    print(held.width)

Failures raise a subclass of ControlError carrying the controller's code and one-line reason.
Every wait has a deadline (`deadline.py`): a controller that does not answer, or whose node is
gone, raises Timeout naming arm_controller; a `stop` event set during a wait cancels the goal and
raises Preempted.
"""

from rascal_control.arm import Arm
from rascal_control.gripper import Gripper
from rascal_control.results import (
    Collision,
    ControlError,
    DriverRestarted,
    GripperResult,
    InvalidGoal,
    MoveResult,
    Preempted,
    Timeout,
    TrackingError,
    Unreachable,
)

__all__ = [
    "Arm",
    "Gripper",
    "MoveResult",
    "GripperResult",
    "ControlError",
    "Unreachable",
    "Collision",
    "Timeout",
    "Preempted",
    "InvalidGoal",
    "DriverRestarted",
    "TrackingError",
]
