"""The rig interfaces of `rig.py` over ROS: the wrapper layer between the workflow and the nodes.

Arm and gripper go through rascal_control's Python client (the `/rascal/arm/move` and
`/rascal/gripper` actions); perception, scale and archival camera through their services and
topics. Every wait is sliced and gives up with a RigError naming the topic or service.
"""
import math
import threading

import rospy
from std_srvs.srv import Trigger

from rascal_msgs.msg import ScaleReading as ScaleReadingMsg
from rascal_msgs.srv import CalibrateBackground, CaptureArchival, Detect
from rascal_tasks import rig

SERVICE_WAIT = 10.0  # s (wall clock): how long a node may take to come up


def _yaw(q) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def observation_from_msg(s) -> rig.Observation:
    """rascal_msgs/Sherd -> Observation (both in base_link)."""
    return rig.Observation(
        x=s.pose.position.x, y=s.pose.position.y, yaw=_yaw(s.pose.orientation),
        length=s.length, width=s.width, height=s.height,
        grasp_x=s.grasp_pose.position.x, grasp_y=s.grasp_pose.position.y,
        grasp_z=s.grasp_pose.position.z, grasp_yaw=_yaw(s.grasp_pose.orientation),
        grasp_width=s.grasp_width, colour=(s.color.r, s.color.g, s.color.b), score=s.score)


def _proxy(name, srv_type):
    try:
        rospy.wait_for_service(name, timeout=SERVICE_WAIT)
    except rospy.ROSException:
        raise rig.RigError(name, "MISSING", "service %s is not offered; is its node running?"
                           % name) from None
    return rospy.ServiceProxy(name, srv_type)


class RosPerception(rig.Perception):
    def __init__(self):
        self._detect = _proxy("/rascal/perception/detect", Detect)
        self._calibrate = _proxy("/rascal/perception/calibrate_background", CalibrateBackground)

    def calibrate(self, station):
        res = self._calibrate(station)
        if not res.success:
            raise rig.RigError("perception", "CALIBRATION", res.message)

    def detect(self, station):
        res = self._detect(station)
        if not res.success:
            raise rig.RigError("perception", "DETECT", res.message)
        return [observation_from_msg(s) for s in res.detections.sherds]


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
