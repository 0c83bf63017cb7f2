"""The arm on its own, for the verbs that move it outside a batch (`rascal calibrate`,
`rascal teach`): the same checks as `rascal run` before anything moves, each with a deadline and
one line (a master, the site file matching the layout the nodes run with, this rig not in use,
the nodes answering), then the arm, the clock and TF; the arm parked at the end, whatever
happened.
"""

import signal
import sys
import threading
import time

import rospy

from rascal_tasks import exit_codes
from rascal_tasks.config import ConfigError
from rascal_tasks.ros_config import load_from_param_server
from rascal_tasks.ros_graph import GraphError, Need, check_master, wait_for_nodes
from rascal_tasks.run_lock import Busy, RigLock

MASTER_TIMEOUT = 3.0  # [s]
# [s] of wall time for a frame's pose at a given stamp: TF's publisher is another process, and a
# loaded machine can leave it that far behind (a wait counted in simulated time can be over in
# a few wall-clock milliseconds on a simulator running faster than real time)
TF_WAIT = 2.0
TF_POLL = 0.01  # [s]
ARM = ("arm_controller", "start it with rosrun rascal_control arm_controller")
ARM_NEEDS = [Need("action", "/rascal/arm/move", *ARM)]


class SessionError(Exception):
    """One line and the exit code it ends with."""

    def __init__(self, message: str, code: int):
        super().__init__(message)
        self.code = code


def wait_for_transform(tf, frame: str, stamp, wait=TF_WAIT, clock=time.monotonic):
    """`tf.lookup_transform("base_link", frame, stamp)`, tried every TF_POLL s until it answers
    or `wait` seconds of `clock` have passed; then SessionError with tf2's reason."""
    deadline = clock() + wait
    while True:
        try:
            return tf.lookup_transform("base_link", frame, stamp)
        except Exception as e:  # tf2's lookup, connectivity and extrapolation errors alike
            if clock() >= deadline:
                raise SessionError(
                    "TF base_link -> %s: %s" % (frame, str(e).splitlines()[0]), exit_codes.FAULT
                ) from None
        time.sleep(TF_POLL)


def rotation(q):
    """3 x 3 rotation matrix (nested lists) of a geometry_msgs Quaternion."""
    x, y, z, w = q.x, q.y, q.z, q.w
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]


class ArmSession:
    """`with ArmSession(cfg, path, "teach", needs) as s:` ... `s.arm`, `s.clock`, `s.tf`."""

    def __init__(self, cfg, config_path: str, verb: str, needs=()):
        self.cfg, self.config_path, self.verb = cfg, config_path, verb
        self.needs = ARM_NEEDS + list(needs)
        self.stop = threading.Event()
        self.arm = self.clock = self.tf = None
        self._lock = None

    def __enter__(self):
        try:
            uri = check_master(timeout=MASTER_TIMEOUT)
        except GraphError as e:
            raise SessionError(str(e), exit_codes.FAULT) from None
        rospy.init_node("rascal_" + self.verb, anonymous=True, disable_signals=True)
        signal.signal(signal.SIGINT, lambda *_: self.stop.set())
        signal.signal(signal.SIGTERM, lambda *_: self.stop.set())
        try:
            running = load_from_param_server()
        except ConfigError as e:
            raise SessionError(str(e), exit_codes.BAD_INPUT) from None
        for name, st in self.cfg["stations"].items():
            if running["stations"].get(name, {}).get("position") != st["position"]:
                raise SessionError(
                    "stations.%s: the running nodes use another layout than %s; `rosparam load "
                    "%s` and restart them" % (name, self.config_path, self.config_path),
                    exit_codes.BAD_INPUT,
                )
        try:
            self._lock = RigLock(self.cfg["rig"]["name"], uri, self.verb).acquire()
        except Busy as e:
            raise SessionError(str(e), exit_codes.BUSY) from None
        try:
            waited = wait_for_nodes(
                self.needs, self.cfg["rig"]["node_wait"], uri, stopped=self.stop.is_set
            )
            if not waited:
                raise SessionError("interrupted before anything moved", exit_codes.INTERRUPTED)
            import tf2_ros

            from rascal_tasks.rig import RigError
            from rascal_tasks.ros_rig import RosArm, RosClock

            try:
                self.arm = RosArm(config=self.cfg, stop=self.stop)
            except RigError as e:
                raise SessionError(str(e), exit_codes.FAULT) from None
            self.clock = RosClock(stop=self.stop)
            self.tf = tf2_ros.Buffer()
            self._listener = tf2_ros.TransformListener(self.tf)
        except GraphError as e:
            self._lock.release()
            raise SessionError(str(e), exit_codes.FAULT) from None
        except BaseException:
            self._lock.release()
            raise
        return self

    def __exit__(self, *exc):
        try:
            self.park()
        finally:
            self._lock.release()

    def park(self):
        if self.arm is None:
            return
        try:
            self.arm.go("sleep")
        except Exception as e:  # parking is the last thing tried; say why it did not happen
            print("error: the arm could not be parked: %s" % e, file=sys.stderr)

    def transform(self, frame: str, stamp=None):
        """`frame`'s pose in base_link (geometry_msgs TransformStamped) at `stamp` (latest),
        waited for up to TF_WAIT seconds of wall time."""
        return wait_for_transform(self.tf, frame, stamp or rospy.Time(0))

    def gripper_pose(self):
        """(x, y, z, yaw) of ee_gripper_link now (the gripper pointing down)."""
        from rascal_tasks.ros_rig import gripper_yaw

        # the pose now, not TF's latest cached one (which may predate the move's end)
        t = self.transform("ee_gripper_link", rospy.Time.now()).transform
        return t.translation.x, t.translation.y, t.translation.z, gripper_yaw(t.rotation)
