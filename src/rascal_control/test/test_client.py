"""Core tests of the Python client (no master): goal building, pose conversion, and the mapping of
controller results to typed results and exceptions. The action clients are injected fakes."""

import math
import threading
import time

import pytest

pytest.importorskip("rascal_msgs.msg", reason="rascal_msgs not built (source devel/setup.bash)")

from rascal_msgs.msg import GripperResult as GripperResultMsg  # noqa: E402
from rascal_msgs.msg import MoveArmFeedback, MoveArmResult  # noqa: E402
from std_srvs.srv import TriggerResponse  # noqa: E402

from rascal_control import (  # noqa: E402
    Arm,
    Collision,
    DriverRestarted,
    Gripper,
    InvalidGoal,
    Preempted,
    Timeout,
    TrackingError,
    Unreachable,
)
from rascal_control import deadline as dl  # noqa: E402
from rascal_control.arm import quaternion_from_rpy, to_pose_stamped  # noqa: E402


class FakeActionClient:
    """Records goals and answers with a fixed result (or never, with `finishes=False`: then it
    waits as GoalRunner does, until the deadline, the stop event or `alive()` ends it)."""

    def __init__(self, result, finishes=True, alive=None, feedback=None, status=3, text=""):
        self.result = result
        self.status, self.text = status, text  # actionlib's terminal status (3 SUCCEEDED)
        self.finishes = finishes
        self.alive = alive
        self.feedback = feedback
        self.goals = []
        self.cancelled = 0
        self.deadlines = []

    def send_goal(self, goal):
        self.goals.append(goal)

    def wait_for_result(self, deadline, stop=None, budget=None):
        if budget is not None and self.feedback is not None:
            deadline.seconds = max(deadline.seconds, budget(self.feedback))
        self.deadlines.append(deadline.seconds)
        if self.finishes:
            return dl.DONE
        return dl.wait_for(lambda: False, deadline, stop, self.alive)

    def get_result(self):
        return self.result

    def terminal(self):
        return self.status, self.text

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
    "code,error",
    [
        (1, Unreachable),
        (2, Collision),
        (3, Timeout),
        (4, Preempted),
        (5, InvalidGoal),
        (6, DriverRestarted),
        (7, TrackingError),
    ],
)
def test_failures_raise_typed_errors_with_the_reason(code, error):
    arm = Arm(move_client=FakeActionClient(move_result(code, "the reason")))
    with pytest.raises(error) as info:
        arm.go("home")
    assert info.value.code == code and str(info.value) == "the reason"
    assert info.value.result.duration == 1.5


def test_a_goal_the_server_cancelled_unrun_is_never_success():
    """actionlib's SimpleActionServer cancels a goal stamped before its last one (ROS time went
    backwards: a restarted simulator) with an empty result: code 0, OK, 0.0 s, no joints."""
    text = "This goal was canceled because another goal was recieved by the simple action server"
    empty = MoveArmResult()
    for status in (2, 8):  # PREEMPTED, RECALLED
        with pytest.raises(Timeout) as info:
            Arm(move_client=FakeActionClient(empty, status=status, text=text)).go("home")
        assert "ended the goal on /rascal/arm/move without running it" in info.value.message
        assert text in info.value.message
    with pytest.raises(Timeout):
        Gripper(client=FakeActionClient(GripperResultMsg(), status=8, text=text)).close()


def test_client_side_timeout_cancels():
    client = FakeActionClient(None, finishes=False)
    with pytest.raises(Timeout) as info:
        Arm(move_client=client).go("home", timeout=0.1)
    assert client.cancelled == 1
    assert "arm_controller not answering on /rascal/arm/move" in info.value.message
    assert info.value.result is None  # the controller never answered


TIMINGS = dl.ControllerTimings(
    settle_timeout=2.0, state_timeout=1.0, gripper_timeout=3.0, margin=5.0
)


def test_the_move_deadline_is_the_planned_duration_plus_settle_timeout_plus_margin():
    client = FakeActionClient(move_result(0), feedback=MoveArmFeedback(duration=4.0))
    Arm(move_client=client, timings=TIMINGS).go("home")
    assert client.deadlines == [pytest.approx(3 * 1.0 + 4.0 + 2.0 + 5.0)]
    client = FakeActionClient(move_result(0))  # no feedback yet: the controller's waits only
    Arm(move_client=client, timings=TIMINGS).go("home")
    assert client.deadlines == [pytest.approx(3 * 1.0 + 2.0 + 5.0)]


def test_a_controller_whose_node_is_gone_is_named_at_once():
    client = FakeActionClient(None, finishes=False, alive=lambda: False)
    t0 = time.monotonic()
    with pytest.raises(Timeout) as info:
        Arm(move_client=client, timings=TIMINGS).go("home")
    assert time.monotonic() - t0 < 1.5  # one liveness check, not the 10 s deadline
    assert info.value.message.startswith("arm_controller not answering on /rascal/arm/move")
    assert "is it running?" in info.value.message
    assert client.cancelled == 1


def test_stop_during_a_move_cancels_it_within_a_slice():
    stop = threading.Event()
    client = FakeActionClient(None, finishes=False)
    threading.Timer(0.2, stop.set).start()
    t0 = time.monotonic()
    with pytest.raises(Preempted):
        Arm(move_client=client, timings=TIMINGS, stop=stop).go("home")
    assert time.monotonic() - t0 < 0.2 + 0.3
    assert client.cancelled == 1


def test_a_stop_set_before_the_move_does_not_interrupt_it():
    """Parking after Ctrl-C: the stop event is already set, the park move must still run."""
    stop = threading.Event()
    stop.set()
    client = FakeActionClient(None, finishes=False)
    with pytest.raises(Timeout):  # it waited for its own deadline instead
        Arm(move_client=client, stop=stop).go("sleep", timeout=0.3)


def test_a_hanging_ik_service_times_out_naming_arm_controller():
    release = threading.Event()

    def hanging(*_args):
        release.wait(5.0)

    timings = dl.ControllerTimings(
        settle_timeout=2.0, state_timeout=0.1, gripper_timeout=3.0, margin=0.2
    )
    arm = Arm(move_client=FakeActionClient(None), ik_service=hanging, timings=timings)
    t0 = time.monotonic()
    with pytest.raises(Timeout) as info:
        arm.compute_ik(Arm.top_down(0.3, 0.0, 0.1))
    release.set()
    assert time.monotonic() - t0 < 1.0
    assert info.value.message == (
        "arm_controller not answering on /rascal/arm/compute_ik within 0.3 s; is it running?"
    )


def test_acknowledge_restart_calls_the_controller():
    calls = []

    def acknowledge():
        calls.append(1)
        return TriggerResponse(success=True, message="driver restart acknowledged (x)")

    arm = Arm(move_client=FakeActionClient(None), acknowledge_service=acknowledge)
    assert arm.acknowledge_restart() == "driver restart acknowledged (x)"
    assert calls == [1]
    assert Arm(move_client=FakeActionClient(None)).acknowledge_restart() == "no acknowledge service"


def test_gripper_deadline_and_a_gone_controller():
    client = FakeActionClient(None, finishes=False, alive=lambda: False)
    with pytest.raises(Timeout) as info:
        Gripper(client=client, timings=TIMINGS).close()
    assert info.value.message.startswith("arm_controller not answering on /rascal/gripper")
    assert client.deadlines == [pytest.approx(2 * 1.0 + 3.0 + 5.0)]


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


def test_open_while_sends_the_opening_before_the_move_and_waits_for_it_after():
    events = []

    class Ordered(FakeActionClient):
        def send_goal(self, goal):
            events.append("open sent")
            super().send_goal(goal)

        def wait_for_result(self, deadline, stop=None, budget=None):
            events.append("open waited")
            return super().wait_for_result(deadline, stop, budget)

    gripper = Gripper(client=Ordered(GripperResultMsg(code=0, width=0.05)))
    assert gripper.open_while(0.05, lambda: events.append("move") or "moved") == "moved"
    assert events == ["open sent", "move", "open waited"]
    assert gripper.width == 0.05

    # a move that fails: its error is raised, after the opening was waited for
    events.clear()
    failing_open = Gripper(client=Ordered(GripperResultMsg(code=3, message="slow")))

    def refused():
        events.append("move")
        raise Unreachable(1, "no IK")

    with pytest.raises(Unreachable):
        failing_open.open_while(0.05, refused)
    assert events == ["open sent", "move", "open waited"]
