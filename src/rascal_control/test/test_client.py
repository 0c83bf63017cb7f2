"""Core tests of the Python client (no master): goal building, pose conversion, and the mapping of
controller results to typed results and exceptions. The action clients are injected fakes."""

import math

import pytest

pytest.importorskip("rascal_msgs.msg", reason="rascal_msgs not built (source devel/setup.bash)")

from rascal_msgs.msg import GripperResult as GripperResultMsg  # noqa: E402
from rascal_msgs.msg import MoveArmResult  # noqa: E402

from rascal_control import (  # noqa: E402
    Arm,
    Collision,
    Gripper,
    InvalidGoal,
    Preempted,
    Timeout,
    Unreachable,
)
from rascal_control.arm import quaternion_from_rpy, to_pose_stamped  # noqa: E402


class FakeActionClient:
    """Records goals and answers with a fixed result."""

    def __init__(self, result, finishes=True):
        self.result = result
        self.finishes = finishes
        self.goals = []
        self.cancelled = 0

    def send_goal(self, goal):
        self.goals.append(goal)

    def wait_for_result(self, timeout):
        return self.finishes

    def get_result(self):
        return self.result

    def cancel_goal(self):
        self.cancelled += 1

    def cancel_all_goals(self):
        self.cancelled += 1


def move_result(code, message="msg"):
    return MoveArmResult(code=code, message=message, duration=1.5, joints=[0.1] * 6)


def test_top_down_pose_points_the_gripper_down():
    pose = Arm.top_down(0.3, -0.1, 0.05, yaw=0.0)
    assert pose.header.frame_id == "base_link"
    q = pose.pose.orientation
    # Ry(pi/2): quaternion (0, sin(pi/4), 0, cos(pi/4)).
    assert q.y == pytest.approx(math.sqrt(0.5)) and q.w == pytest.approx(math.sqrt(0.5))
    assert pose.pose.position.z == pytest.approx(0.05)


def test_pose_forms():
    assert to_pose_stamped((0.1, 0.2, 0.3, 0, 0, 0, 1)).pose.orientation.w == 1.0
    x, y, z, w = quaternion_from_rpy(0.0, 0.0, math.pi / 2)
    assert (x, y) == (0.0, 0.0) and z == pytest.approx(w)
    with pytest.raises(ValueError):
        to_pose_stamped((0.1, 0.2))


def test_move_to_sends_a_linear_pose_goal():
    client = FakeActionClient(move_result(0, "arrived"))
    arm = Arm(move_client=client)
    result = arm.move_to(Arm.top_down(0.3, 0.0, 0.1), motion="linear", speed_scale=0.5)
    goal = client.goals[0]
    assert goal.target_type == goal.TARGET_POSE and goal.motion == goal.MOTION_LINEAR
    assert goal.speed_scale == 0.5
    assert result.ok and result.duration == 1.5 and result.joints == [0.1] * 6


def test_go_and_move_joints_goals():
    client = FakeActionClient(move_result(0))
    arm = Arm(move_client=client)
    arm.go("home")
    arm.move_joints([0, 0, 0, 0, 0, 0])
    assert client.goals[0].target_type == client.goals[0].TARGET_NAMED
    assert client.goals[0].named_pose == "home"
    assert client.goals[1].target_type == client.goals[1].TARGET_JOINTS
    with pytest.raises(ValueError):
        arm.go("home", motion="teleport")
    with pytest.raises(ValueError):
        arm.go("home", speed_scale=0.0)


@pytest.mark.parametrize(
    "code,error", [(1, Unreachable), (2, Collision), (3, Timeout), (4, Preempted), (5, InvalidGoal)]
)
def test_failures_raise_typed_errors_with_the_reason(code, error):
    arm = Arm(move_client=FakeActionClient(move_result(code, "the reason")))
    with pytest.raises(error) as info:
        arm.go("home")
    assert info.value.code == code and str(info.value) == "the reason"
    assert info.value.result.duration == 1.5


def test_client_side_timeout_cancels():
    client = FakeActionClient(None, finishes=False)
    with pytest.raises(Timeout):
        Arm(move_client=client).go("home", timeout=0.1)
    assert client.cancelled == 1


def test_gripper_close_is_truthy_when_holding():
    held = GripperResultMsg(
        code=0, message="opening 41 mm", width=0.041, holding=True, duration=0.4
    )
    gripper = Gripper(client=FakeActionClient(held))
    result = gripper.close()
    assert result and result.holding and gripper.width == 0.041
    empty = GripperResultMsg(
        code=0, message="opening 30 mm", width=0.030, holding=False, duration=0.5
    )
    assert not Gripper(client=FakeActionClient(empty)).close()


def test_gripper_goals_and_errors():
    client = FakeActionClient(GripperResultMsg(code=0, width=0.074))
    gripper = Gripper(client=client)
    gripper.open()
    gripper.set_width(0.05)
    assert [g.command for g in client.goals] == [0, 2]
    assert client.goals[1].width == 0.05
    with pytest.raises(ValueError):
        gripper.set_width(0.1)
    failing = Gripper(client=FakeActionClient(GripperResultMsg(code=3, message="slow")))
    with pytest.raises(Timeout):
        failing.close()
