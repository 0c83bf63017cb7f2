"""rascal_control.Arm: move the arm by pose, named pose or joints through /rascal/arm/move."""

import math
import threading
from typing import Optional, Sequence

from rascal_control import deadline as dl
from rascal_control.results import (
    GOAL_SUCCEEDED,
    OK,
    PREEMPTED,
    TIMEOUT,
    MoveResult,
    Preempted,
    Timeout,
    ik_error,
    move_error,
    unrun_goal,
)

ARM_JOINTS = ("waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate")
MOTIONS = {"joint": 0, "linear": 1}


def quaternion_from_rpy(roll: float, pitch: float, yaw: float):
    """(x, y, z, w) of R = Rz(yaw) Ry(pitch) Rx(roll) (static XYZ, as Interbotix uses)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def to_pose_stamped(pose):
    """PoseStamped in base_link from a PoseStamped, a Pose, (x, y, z, roll, pitch, yaw) or
    (x, y, z, qx, qy, qz, qw)."""
    from geometry_msgs.msg import Pose, PoseStamped

    if isinstance(pose, PoseStamped):
        if not pose.header.frame_id:
            pose.header.frame_id = "base_link"
        return pose
    out = PoseStamped()
    out.header.frame_id = "base_link"
    if isinstance(pose, Pose):
        out.pose = pose
        return out
    values = [float(v) for v in pose]
    if len(values) == 6:
        quat = quaternion_from_rpy(*values[3:])
    elif len(values) == 7:
        quat = values[3:]
    else:
        raise ValueError(
            "a pose is a PoseStamped, a Pose, (x, y, z, roll, pitch, yaw) or "
            "(x, y, z, qx, qy, qz, qw); got %d numbers" % len(values)
        )
    out.pose.position.x, out.pose.position.y, out.pose.position.z = values[:3]
    (
        out.pose.orientation.x,
        out.pose.orientation.y,
        out.pose.orientation.z,
        out.pose.orientation.w,
    ) = quat
    return out


class Arm:
    """PyRobot-like arm client. Needs rospy.init_node() first (unless clients are injected).

    Every move returns a MoveResult or raises Unreachable, Collision, Timeout, Preempted,
    InvalidGoal, DriverRestarted or TrackingError with the controller's one-line reason. Every
    wait has a deadline from `timings` (deadline.ControllerTimings; default: the schema's
    defaults): a controller that does not answer in time, or whose node is gone, raises Timeout
    naming arm_controller. `stop` (a threading.Event, e.g. the task's Ctrl-C) set during a wait
    cancels the goal and raises Preempted within deadline.SLICE seconds.
    """

    def __init__(
        self,
        move_client=None,
        ik_service=None,
        fk_service=None,
        wait: float = 10.0,
        timings: Optional[dl.ControllerTimings] = None,
        stop: Optional[threading.Event] = None,
        acknowledge_service=None,
        ros_now=None,
    ):
        self.timings = timings or dl.ControllerTimings.defaults()
        self.stop_event = stop
        self._ros_now = ros_now or dl.ros_time
        if move_client is None:
            import rospy
            from rascal_msgs.msg import MoveArmAction
            from rascal_msgs.srv import ComputeFK, ComputeIK
            from std_srvs.srv import Trigger

            from rascal_control.goal_runner import GoalRunner

            move_client = GoalRunner("/rascal/arm/move", MoveArmAction)
            if not move_client.wait_for_server(rospy.Duration(wait), stop):
                raise Timeout(
                    TIMEOUT,
                    "no /rascal/arm/move action server within %.0f s (not connected: %s); is "
                    "arm_controller running?" % (wait, ", ".join(move_client.missing())),
                )
            try:
                rospy.wait_for_service("/rascal/arm/compute_ik", wait)
            except rospy.ROSException as e:
                raise Timeout(
                    TIMEOUT,
                    "no /rascal/arm/compute_ik service within %.0f s; is arm_controller running?"
                    % wait,
                ) from e
            ik_service = rospy.ServiceProxy("/rascal/arm/compute_ik", ComputeIK)
            fk_service = rospy.ServiceProxy("/rascal/arm/compute_fk", ComputeFK)
            acknowledge_service = rospy.ServiceProxy("/rascal/arm/acknowledge_restart", Trigger)
        self._move = move_client
        self._ik = ik_service
        self._fk = fk_service
        self._acknowledge = acknowledge_service
        self.last_result: Optional[MoveResult] = None

    # -- goals ------------------------------------------------------------------------------
    @staticmethod
    def top_down(x: float, y: float, z: float, yaw: float = 0.0):
        """ee_gripper_link pointing straight down at (x, y, z), turned by `yaw` about z."""
        return to_pose_stamped((x, y, z, 0.0, math.pi / 2, yaw))

    def move_to(
        self, pose, motion: str = "joint", speed_scale: float = 1.0, timeout: Optional[float] = None
    ) -> MoveResult:
        """Move ee_gripper_link to `pose` (see to_pose_stamped) by a joint or linear motion."""
        goal = self._goal(motion, speed_scale)
        goal.target_type = goal.TARGET_POSE
        goal.pose = to_pose_stamped(pose)
        return self._run(goal, timeout)

    def move_through(
        self,
        poses: Sequence,
        motions: Sequence[str],
        blend_above: float = 0.0,
        speed_scale: float = 1.0,
        timeout: Optional[float] = None,
    ) -> MoveResult:
        """Move ee_gripper_link to each of `poses` in turn ("joint" or "linear" for each), as one
        goal: with `blend_above` > 0 [m], the next move starts before the one before has stopped
        wherever the gripper stays above that height (MoveArm.action). Done when the last pose is
        reached."""
        if len(poses) != len(motions) or not poses:
            raise ValueError("move_through: one motion per pose, at least one pose")
        goal = self._goal(motions[0], speed_scale)
        goal.target_type = goal.TARGET_POSE
        goal.pose = to_pose_stamped(poses[0])
        goal.then_poses = [to_pose_stamped(p).pose for p in poses[1:]]
        goal.then_motions = [self._goal(m, speed_scale).motion for m in motions[1:]]  # checked
        goal.blend_above = float(blend_above)
        return self._run(goal, timeout)

    def go(
        self,
        name: str,
        motion: str = "joint",
        speed_scale: float = 1.0,
        timeout: Optional[float] = None,
    ) -> MoveResult:
        """Move to a named pose of the config (arm/named_poses), e.g. "home", "sleep"."""
        goal = self._goal(motion, speed_scale)
        goal.target_type = goal.TARGET_NAMED
        goal.named_pose = name
        return self._run(goal, timeout)

    def move_joints(
        self,
        joints: Sequence[float],
        motion: str = "joint",
        speed_scale: float = 1.0,
        timeout: Optional[float] = None,
    ) -> MoveResult:
        """Move to a joint vector [rad]: waist, shoulder, elbow, forearm_roll, wrist_angle,
        wrist_rotate."""
        goal = self._goal(motion, speed_scale)
        goal.target_type = goal.TARGET_JOINTS
        goal.joints = [float(j) for j in joints]
        return self._run(goal, timeout)

    def stop(self):
        """Cancel the current move; the controller stops the arm."""
        self._move.cancel_all_goals()

    # -- kinematics -------------------------------------------------------------------------
    def compute_ik(self, pose, seed: Optional[Sequence[float]] = None):
        """Joint vector for `pose`, closest to `seed` (default: the current joints)."""
        response = self._call(
            self._ik, "/rascal/arm/compute_ik", to_pose_stamped(pose), list(seed or [])
        )
        if response.code != OK:
            raise ik_error(response.code, response.message)
        return list(response.joints)

    def compute_fk(self, joints: Optional[Sequence[float]] = None, link: str = ""):
        """PoseStamped of `link` (default ee_gripper_link) in base_link; joints default to the
        current ones."""
        response = self._call(self._fk, "/rascal/arm/compute_fk", list(joints or []), link)
        if not response.success:
            raise move_error(5, response.message)
        return response.pose

    def acknowledge_restart(self) -> str:
        """Tell the controller the task knows the driver restarted (it re-calibrates now): goals
        are accepted again. Returns the controller's one line ("no driver restart to
        acknowledge" when there was none). A no-op without the service (injected clients)."""
        if self._acknowledge is None:
            return "no acknowledge service"
        response = self._call(self._acknowledge, "/rascal/arm/acknowledge_restart")
        return response.message

    def get_ee_pose(self):
        """Current PoseStamped of ee_gripper_link."""
        return self.compute_fk()

    # -- internals --------------------------------------------------------------------------
    @staticmethod
    def _goal(motion: str, speed_scale: float):
        from rascal_msgs.msg import MoveArmGoal

        if motion not in MOTIONS:
            raise ValueError("motion must be 'joint' or 'linear', not %r" % (motion,))
        if not 0.0 < speed_scale <= 1.0:
            raise ValueError("speed_scale must be in (0, 1], not %r" % (speed_scale,))
        goal = MoveArmGoal()
        goal.motion = MOTIONS[motion]
        goal.speed_scale = float(speed_scale)
        return goal

    def _call(self, service, name: str, *args):
        """A service of the controller, with the deadline timings.service()."""
        import rospy

        deadline = dl.Deadline(self.timings.service(), self._ros_now)
        try:
            return dl.call(service, *args, deadline=deadline, stop=self.stop_event)
        except dl.Unfinished as e:
            if e.outcome == dl.STOPPED:
                raise Preempted(PREEMPTED, "stop requested while waiting for %s" % name) from None
            raise Timeout(
                TIMEOUT,
                "arm_controller not answering on %s within %.1f s; is it running?"
                % (name, deadline.seconds),
            ) from None
        except rospy.ServiceException as e:  # the node is gone, or failed on this request
            raise Timeout(
                TIMEOUT,
                "arm_controller not answering on %s (%s); is it running?"
                % (name, str(e).splitlines()[0] if str(e) else type(e).__name__),
            ) from None

    def _run(self, goal, timeout: Optional[float]) -> MoveResult:
        """Send `goal` and wait: `timeout` seconds (ROS and wall time), or by default the
        controller's own deadline (the planned duration + arm.settle_timeout, from the goal's
        feedback) plus rig.answer_margin."""
        self._move.send_goal(goal)
        deadline = dl.Deadline(
            timeout if timeout is not None else self.timings.move(), self._ros_now
        )
        budget = None if timeout is not None else (lambda fb: self.timings.move(fb.duration))
        outcome = self._move.wait_for_result(deadline, self.stop_event, budget)
        if outcome != dl.DONE:
            self._move.cancel_goal()
            if outcome == dl.STOPPED:
                raise Preempted(PREEMPTED, "stop requested: move cancelled")
            if outcome == dl.GONE:
                raise Timeout(
                    TIMEOUT,
                    "arm_controller not answering on /rascal/arm/move (its node does not "
                    "respond); is it running? (rosrun rascal_control arm_controller)",
                )
            raise Timeout(
                TIMEOUT,
                "arm_controller not answering on /rascal/arm/move: no result %.1f s after the "
                "goal; is it running?" % deadline.seconds,
            )
        msg = self._move.get_result()
        status, text = self._move.terminal()
        if msg is not None and msg.code == OK and status != GOAL_SUCCEEDED:
            raise unrun_goal("/rascal/arm/move", status, text)
        if msg is None:
            raise Timeout(
                TIMEOUT,
                "/rascal/arm/move ended without a result (arm_controller restarted or gone?)",
            )
        result = MoveResult(msg.code, msg.message, msg.duration, list(msg.joints))
        self.last_result = result
        if msg.code != OK:
            raise move_error(msg.code, msg.message, result)
        return result
