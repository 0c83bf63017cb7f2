"""Typed results and exceptions of the arm and gripper clients (no ROS needed)."""

from dataclasses import dataclass, field
from typing import List

# Codes shared by rascal_msgs/MoveArm, rascal_msgs/Gripper and rascal_msgs/ComputeIK.
OK = 0
UNREACHABLE = 1
COLLISION = 2
TIMEOUT = 3
PREEMPTED = 4
INVALID_GOAL = 5
DRIVER_RESTARTED = 6  # MoveArm and Gripper: refused until the restart is acknowledged
TRACKING_ERROR = 7  # MoveArm: the arm left its planned path; it was stopped
IK_JOINT_LIMIT = 2
IK_SINGULAR = 3
IK_INVALID = 4


class ControlError(RuntimeError):
    """A move, gripper command or IK request that did not succeed; `code` is the controller's."""

    def __init__(self, code: int, message: str, result=None):
        super().__init__(message)
        self.code = code
        self.message = message
        self.result = result


class Unreachable(ControlError):
    """The goal is out of reach, beyond a joint limit, or the line to it is not continuous."""


class Collision(ControlError):
    """The planned motion would hit the table or a station fixture; the arm did not move."""


class Timeout(ControlError):
    """The arm or gripper did not arrive in time, or the controller did not answer."""


class Preempted(ControlError):
    """The command was cancelled (by the caller or a newer goal); the arm stopped."""


class InvalidGoal(ControlError):
    """The request itself is malformed (frame, quaternion, unknown named pose, width range)."""


class DriverRestarted(ControlError):
    """The arm driver (or simulator) restarted: the controller refuses every goal until the task
    acknowledges it (`Arm.acknowledge_restart()`, which `rascal run` calls when it starts)."""


class TrackingError(ControlError):
    """The arm left its planned path by more than arm.tracking_tolerance; it was stopped."""


_MOVE_ERRORS = {
    UNREACHABLE: Unreachable,
    COLLISION: Collision,
    TIMEOUT: Timeout,
    PREEMPTED: Preempted,
    INVALID_GOAL: InvalidGoal,
    DRIVER_RESTARTED: DriverRestarted,
    TRACKING_ERROR: TrackingError,
}
_IK_ERRORS = {
    UNREACHABLE: Unreachable,
    IK_JOINT_LIMIT: Unreachable,
    IK_SINGULAR: Unreachable,
    IK_INVALID: InvalidGoal,
}


GOAL_SUCCEEDED = 3  # actionlib_msgs/GoalStatus.SUCCEEDED
GOAL_STATUS_NAMES = {
    0: "PENDING",
    1: "ACTIVE",
    2: "PREEMPTED",
    3: "SUCCEEDED",
    4: "ABORTED",
    5: "REJECTED",
    6: "PREEMPTING",
    7: "RECALLING",
    8: "RECALLED",
    9: "LOST",
}


def unrun_goal(action: str, status: int, text: str) -> "Timeout":
    """A goal the server ended without running it (an empty result says code 0, OK, in 0.0 s:
    never taken as success)."""
    return Timeout(
        TIMEOUT,
        "arm_controller ended the goal on %s without running it (%s: %s); is another client "
        "sending goals to it?" % (action, GOAL_STATUS_NAMES.get(status, str(status)), text),
    )


def move_error(code: int, message: str, result=None) -> ControlError:
    """The exception for a MoveArm or Gripper result code."""
    return _MOVE_ERRORS.get(code, ControlError)(code, message, result)


def ik_error(code: int, message: str) -> ControlError:
    """The exception for a ComputeIK code (JOINT_LIMIT and SINGULAR count as unreachable)."""
    return _IK_ERRORS.get(code, ControlError)(code, message)


@dataclass
class MoveResult:
    """A finished arm move."""

    code: int
    message: str
    duration: float  # [s] executed (sim time under use_sim_time)
    joints: List[float] = field(default_factory=list)  # [rad] at the end

    @property
    def ok(self) -> bool:
        return self.code == OK


@dataclass
class GripperResult:
    """A finished gripper command; truthy when an object is held."""

    code: int
    message: str
    width: float  # [m] opening between the fingertips at the end
    holding: bool  # fingers stopped short of closed
    duration: float  # [s]

    def __bool__(self) -> bool:
        return self.holding
