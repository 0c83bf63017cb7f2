"""The rig interfaces of `rig.py` over ROS: the wrapper layer between the workflow and the nodes.

Arm and gripper go through rascal_control's Python client (the `/rascal/arm/move` and
`/rascal/gripper` actions); perception, scale and archival camera through their services and
topics. Every wait is sliced and gives up with a RigError naming the topic or service.
"""

import math
import threading
import time

import rospy
from rascal_control import Arm as ControlArm
from rascal_control import Gripper as ControlGripper
from rascal_control.results import ControlError, Timeout
from std_srvs.srv import Trigger

from rascal_msgs.msg import GripperState
from rascal_msgs.msg import ScaleReading as ScaleReadingMsg
from rascal_msgs.srv import CalibrateBackground, CaptureArchival, Detect
from rascal_tasks import rig

SERVICE_WAIT = 30.0  # s (wall clock): how long a node may take to come up
# The arm controller publishes the gripper's opening and whether it holds something (its one
# holding rule, the same its close result uses) with every /joint_states message.
GRIPPER_STATE = "/rascal/gripper/state"
GRIPPER_STATE_WAIT = 2.0  # s (wall clock) without a fresh gripper state: the controller is silent
CODE_NAMES = {1: "UNREACHABLE", 2: "COLLISION", 3: "TIMEOUT", 4: "PREEMPTED", 5: "INVALID_GOAL"}


def _yaw(q) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def _gripper_yaw(q) -> float:
    """Yaw of a gripper-pointing-down orientation R = Rz(yaw) Ry(pi/2), from its closing axis
    R y = (-sin yaw, cos yaw, 0). (The usual Euler formula is degenerate at pitch pi/2.)"""
    return math.atan2(2.0 * (q.w * q.z - q.x * q.y), 1.0 - 2.0 * (q.x * q.x + q.z * q.z))


def observation_from_msg(s) -> rig.Observation:
    """rascal_msgs/Sherd -> Observation (both in base_link)."""
    return rig.Observation(
        x=s.pose.position.x,
        y=s.pose.position.y,
        yaw=_yaw(s.pose.orientation),
        length=s.length,
        width=s.width,
        height=s.height,
        grasp_x=s.grasp_pose.position.x,
        grasp_y=s.grasp_pose.position.y,
        grasp_z=s.grasp_pose.position.z,
        grasp_yaw=_gripper_yaw(s.grasp_pose.orientation),
        grasp_width=s.grasp_width,
        colour=(s.color.r, s.color.g, s.color.b),
        score=s.score,
    )


def _proxy(name, srv_type):
    try:
        rospy.wait_for_service(name, timeout=SERVICE_WAIT)
    except rospy.ROSException:
        raise rig.RigError(
            name, "MISSING", "service %s is not offered; is its node running?" % name
        ) from None
    return rospy.ServiceProxy(name, srv_type)


def _rig_error(device: str, e: ControlError) -> rig.RigError:
    return rig.RigError(device, CODE_NAMES.get(e.code, "FAILED"), e.message)


class RosArm(rig.Arm):
    """rascal_control.Arm with the gripper pointing down."""

    def __init__(self, speed_scale: float = 1.0):
        try:
            self._arm = ControlArm(wait=SERVICE_WAIT)
        except ControlError as e:
            raise _rig_error("/rascal/arm/move", e) from None
        self.speed_scale = speed_scale

    def move_down(self, x, y, z, yaw, linear=False):
        pose = ControlArm.top_down(x, y, z, yaw)
        for attempt in range(2):
            try:
                return self._arm.move_to(
                    pose, motion="linear" if linear else "joint", speed_scale=self.speed_scale
                ).duration
            except Timeout as e:
                # The arm did not arrive (a stalled or lost trajectory): send the goal once more
                # from where it is; a second timeout is a fault for a person to look at.
                if attempt:
                    raise _rig_error("arm", e) from None
                rospy.logwarn("arm: %s; trying the move once more", e.message)
            except ControlError as e:
                raise _rig_error("arm", e) from None

    def go(self, named):
        try:
            return self._arm.go(named, speed_scale=self.speed_scale).duration
        except ControlError as e:
            raise _rig_error("arm", e) from None

    def stop(self):
        self._arm.stop()


class RosGripper(rig.Gripper):
    """rascal_control.Gripper, plus the controller's gripper state (GRIPPER_STATE) to notice a
    drop: whether a sherd is held is the controller's decision, not a threshold applied here."""

    def __init__(self, held_margin=None):
        del held_margin  # unused: the controller applies arm.gripper.held_margin (kept for callers)
        try:
            self._gripper = ControlGripper(wait=SERVICE_WAIT)
        except ControlError as e:
            raise _rig_error("/rascal/gripper", e) from None
        self._state = None  # the latest rascal_msgs/GripperState
        self._after = rospy.Time(0)  # a state stamped before the last command ended is stale
        self._sub = rospy.Subscriber(GRIPPER_STATE, GripperState, self._on_state, queue_size=2)

    def _on_state(self, msg):
        self._state = msg

    def _run(self, fn, *args):
        try:
            return fn(*args)
        except ControlError as e:
            raise _rig_error("gripper", e) from None
        finally:
            self._after = rospy.Time.now()

    def _fresh_state(self):
        """The first gripper state stamped after the last command ended; RigError when none comes
        within GRIPPER_STATE_WAIT seconds of wall time."""
        deadline = time.monotonic() + GRIPPER_STATE_WAIT
        while not rospy.is_shutdown():
            state = self._state
            if state is not None and state.header.stamp >= self._after:
                return state
            if time.monotonic() > deadline:
                break
            time.sleep(0.005)
        raise rig.RigError(
            GRIPPER_STATE,
            "TIMEOUT",
            "no gripper state for %.0f s; is arm_controller running?" % GRIPPER_STATE_WAIT,
        )

    def open(self, width=None):
        return self._run(self._gripper.open, width).duration

    def close(self):
        res = self._run(self._gripper.close)
        return rig.GraspResult(bool(res.holding), res.width)

    def holding(self):
        return bool(self._fresh_state().holding)

    def width(self):
        return self._fresh_state().width


class RosPerception(rig.Perception):
    """The detector's services. A failed call is retried a few times after a short wait: right
    after a move the newest image or transform may still be on its way."""

    ATTEMPTS = 4
    RETRY_WAIT = 0.3  # s (ROS time)

    def __init__(self):
        self._detect = _proxy("/rascal/perception/detect", Detect)
        self._calibrate = _proxy("/rascal/perception/calibrate_background", CalibrateBackground)

    def _call(self, proxy, station, what):
        for attempt in range(self.ATTEMPTS):
            try:
                res = proxy(station)
            except rospy.ServiceException as e:
                raise rig.RigError("perception", what, str(e)) from None
            if res.success:
                return res
            rospy.logwarn(
                "perception %s at %s failed (attempt %d): %s",
                what.lower(),
                station,
                attempt + 1,
                res.message,
            )
            rospy.sleep(self.RETRY_WAIT)
        raise rig.RigError("perception", what, res.message)

    def calibrate(self, station):
        self._call(self._calibrate, station, "CALIBRATION")

    def detect(self, station):
        res = self._call(self._detect, station, "DETECT")
        return [observation_from_msg(s) for s in res.detections.sherds]

    def detect_if_calibrated(self, station):
        """Detections, or None when the station has no background model yet. Any attempt may be
        the one that says so: one that failed first on a frame or transform still on its way (at
        start-up with the simulator at full speed) says it on the retry."""
        for attempt in range(self.ATTEMPTS):
            try:
                res = self._detect(station)
            except rospy.ServiceException as e:
                raise rig.RigError("perception", "DETECT", str(e)) from None
            if res.success:
                return [observation_from_msg(s) for s in res.detections.sherds]
            if "no background model" in res.message:
                return None
            rospy.logwarn(
                "perception detect at %s failed (attempt %d): %s", station, attempt + 1, res.message
            )
            rospy.sleep(self.RETRY_WAIT)
        raise rig.RigError("perception", "DETECT", res.message)


class RosScale(rig.Scale):
    """/scale/mass readings; a stable reading counts only if taken after the request."""

    def __init__(self, clock):
        self.clock = clock
        self._lock = threading.Condition()
        self._last = None
        self._sub = rospy.Subscriber("/scale/mass", ScaleReadingMsg, self._on_reading, queue_size=5)
        self._tare = _proxy("/scale/tare", Trigger)

    def _on_reading(self, msg):
        with self._lock:
            self._last = msg
            self._lock.notify_all()

    def tare(self):
        res = self._tare()
        if not res.success:
            raise rig.RigError("/scale/tare", "TARE", res.message)

    def read_stable(self, timeout):
        start = rospy.Time.now()
        deadline = self.clock.now() + timeout
        last = None
        while self.clock.now() < deadline and not rospy.is_shutdown():
            with self._lock:
                self._lock.wait(0.05)
                msg = self._last
            if msg is None or msg.header.stamp <= start:
                continue
            last = msg
            if msg.stable:
                return rig.ScaleReading(msg.mass, True)
        if last is None:
            raise rig.RigError("/scale/mass", "TIMEOUT", "no reading within %.1f s" % timeout)
        return rig.ScaleReading(last.mass, False)


class RosArchivalCamera(rig.ArchivalCamera):
    def __init__(self):
        self._capture = _proxy("/archival_camera/capture", CaptureArchival)

    def capture(self, path):
        try:
            res = self._capture(path)
        except rospy.ServiceException as e:
            raise rig.RigError("/archival_camera/capture", "FAILED", str(e)) from None
        if not res.success:
            raise rig.RigError("/archival_camera/capture", "REFUSED", res.message)
        return rig.Capture(res.path, res.stamp.to_sec(), res.width, res.height)


class RosClock(rig.Clock):
    """ROS time: simulated time under use_sim_time."""

    def now(self):
        return rospy.get_time()

    def sleep(self, seconds):
        if seconds > 0:
            rospy.sleep(seconds)
