"""The rig interfaces of `rig.py` over ROS: the wrapper layer between the workflow and the nodes.

Arm and gripper go through rascal_control's Python client (the `/rascal/arm/move` and
`/rascal/gripper` actions); perception, scale and archival camera through their services and
topics. Every wait has a deadline derived from the configuration's timings (rascal_control's
`deadline.py`: ROS and wall time, wall time alone while ROS time stands still), gives up with a
RigError naming the node, topic or service, and ends within 0.05 s when the run's `stop` event
is set during it (Ctrl-C), with code PREEMPTED.
"""

import collections
import math
import threading
import time

import rospy
from rascal_control import Arm as ControlArm
from rascal_control import Gripper as ControlGripper
from rascal_control import deadline as dl
from rascal_control.results import ControlError, Timeout
from std_msgs.msg import Header
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
CODE_NAMES = {
    1: "UNREACHABLE",
    2: "COLLISION",
    3: "TIMEOUT",
    4: "PREEMPTED",
    5: "INVALID_GOAL",
    6: "DRIVER_RESTARTED",
    7: "TRACKING_ERROR",
}
# the archival camera's shutter has closed (RosArchivalCamera)
EXPOSED = "/archival_camera/exposed"
TF_WAIT = 0.5  # [s] the detector's TF lookup after its frame (rascal_perception's README)
CLOCK_STALL = 2.0  # [s] wall time without ROS time moving: the clock (simulator) is gone


def _yaw(q) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def gripper_yaw(q) -> float:
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
        support=s.support,
        thickness=s.thickness,
        covered=s.covered,
        grasp_clear=s.grasp_clear,
        vessel_diameter=s.vessel_diameter,
        vessel_diameter_sigma=s.vessel_diameter_sigma,
        grasp_x=s.grasp_pose.position.x,
        grasp_y=s.grasp_pose.position.y,
        grasp_z=s.grasp_pose.position.z,
        grasp_yaw=gripper_yaw(s.grasp_pose.orientation),
        grasp_width=s.grasp_width,
        colour=(s.color.r, s.color.g, s.color.b),
        score=s.score,
    )


def leftover_from_msg(m) -> rig.Leftover:
    """rascal_msgs/Leftover -> Leftover (both in base_link)."""
    return rig.Leftover(
        m.position.x,
        m.position.y,
        m.length,
        m.width,
        m.why,
        m.position.z,
        m.yaw,
        m.height,
        m.on_edge,
        m.cut_by_border,
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


_CONFIG = []  # the parameter server's checked configuration, read once


def _config(config):
    """`config`, or the parameter server's checked configuration (what the nodes read)."""
    if config is not None:
        return config
    if not _CONFIG:
        from rascal_tasks.config import ConfigError
        from rascal_tasks.ros_config import load_from_param_server

        try:
            _CONFIG.append(load_from_param_server())
        except ConfigError as e:
            raise rig.RigError("config", "INVALID", str(e)) from None
    return _CONFIG[0]


def _call(fn, *args, seconds, stop, device, code, node, name):
    """A service call with a deadline of `seconds` (ROS and wall time) that `stop` interrupts;
    RigError(device, TIMEOUT | PREEMPTED | code) naming `node` and the service `name`."""
    deadline = dl.Deadline(seconds, dl.ros_time)
    return _answer(dl.Background(fn, *args), deadline, stop, device, code, node, name)


def _answer(pending, deadline, stop, device, code, node, name):
    """The answer of a service call running in the background (dl.Background), or _call's
    RigError."""
    try:
        return pending.result(deadline, stop)
    except dl.Unfinished as e:
        if e.outcome == dl.STOPPED:
            raise rig.RigError(device, "PREEMPTED", "stop requested") from None
        raise rig.RigError(
            device,
            "TIMEOUT",
            "%s not answering on %s within %.1f s; is it running?" % (node, name, deadline.seconds),
        ) from None
    except rospy.ServiceException as e:
        first = (str(e).splitlines() or [type(e).__name__])[0]
        raise rig.RigError(
            device, code, "%s not answering on %s (%s); is it running?" % (node, name, first)
        ) from None


def ros_sleep(seconds: float, stop=None):
    """Sleep `seconds` of ROS time. RigError when ROS time runs backwards (the simulator or the
    driver restarted), stands still for CLOCK_STALL seconds of wall time (no /clock), or `stop`
    is set during the sleep."""
    watch_stop = stop is not None and not stop.is_set()
    start = last = rospy.get_time()
    moved = time.monotonic()
    while True:
        now = rospy.get_time()
        if now - start >= seconds:
            return
        if now < last:
            raise rig.RigError(
                "/clock",
                "DRIVER_RESTARTED",
                "ROS time went backwards (%.3f s -> %.3f s): the simulator (arm driver) "
                "restarted; re-run `rascal run` to re-calibrate" % (last, now),
            )
        if now != last:
            last, moved = now, time.monotonic()
        elif time.monotonic() - moved > CLOCK_STALL:
            raise rig.RigError(
                "/clock",
                "TIMEOUT",
                "ROS time stood still for %.0f s (no /clock); is the simulator (or the "
                "driver) running?" % CLOCK_STALL,
            )
        if watch_stop and stop.is_set():
            raise rig.RigError("batch", "PREEMPTED", "stop requested")
        time.sleep(0.005)


class RosArm(rig.Arm):
    """rascal_control.Arm with the gripper pointing down. `config`: the checked configuration
    (default: the parameter server's), for the deadlines; `stop`: the run's stop event."""

    def __init__(self, speed_scale: float = 1.0, config=None, stop=None):
        timings = dl.ControllerTimings.from_config(_config(config))
        try:
            self._arm = ControlArm(wait=SERVICE_WAIT, timings=timings, stop=stop)
        except ControlError as e:
            raise _rig_error("/rascal/arm/move", e) from None
        self.speed_scale = speed_scale

    def move_down(self, x, y, z, yaw, linear=False):
        pose = ControlArm.top_down(x, y, z, yaw)
        motion = "linear" if linear else "joint"
        return self._once_more(lambda: self._arm.move_to(pose, motion, self.speed_scale))

    def move_through(self, steps, blend_above):
        # once more (_once_more), every move of the chain: a lost trajectory left the arm at
        # its start; after a stall part-way it goes back through the moves' own targets, each
        # move collision-checked
        poses = [ControlArm.top_down(x, y, z, yaw) for x, y, z, yaw, _linear in steps]
        motions = ["linear" if step[4] else "joint" for step in steps]
        return self._once_more(
            lambda: self._arm.move_through(poses, motions, blend_above, self.speed_scale)
        )

    @staticmethod
    def _once_more(send) -> float:
        """`send()` a goal; the seconds it took. When the controller says the arm did not arrive
        (a stalled or lost trajectory) the goal is sent once more from where the arm is; a
        second timeout is a fault for a person to look at. A controller that did not answer at
        all (no result) is one now."""
        for attempt in range(2):
            try:
                return send().duration
            except Timeout as e:
                if attempt or e.result is None:
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

    def acknowledge_restart(self):
        try:
            return self._arm.acknowledge_restart()
        except ControlError as e:
            raise _rig_error("arm", e) from None


class RosGripper(rig.Gripper):
    """rascal_control.Gripper, plus the controller's gripper state (GRIPPER_STATE) to notice a
    drop: whether a sherd is held is the controller's decision, not a threshold applied here."""

    def __init__(self, held_margin=None, config=None, stop=None):
        del held_margin  # unused: the controller applies arm.gripper.held_margin (kept for callers)
        timings = dl.ControllerTimings.from_config(_config(config))
        self._stop = stop
        try:
            self._gripper = ControlGripper(wait=SERVICE_WAIT, timings=timings, stop=stop)
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
        within GRIPPER_STATE_WAIT seconds of wall time, when ROS time went back before the last
        command (a restarted simulator: its states are stamped earlier), or on `stop`."""
        deadline = time.monotonic() + GRIPPER_STATE_WAIT
        watch_stop = self._stop is not None and not self._stop.is_set()
        while not rospy.is_shutdown():
            state = self._state
            if state is not None and state.header.stamp >= self._after:
                return state
            if rospy.Time.now() < self._after:
                raise rig.RigError(
                    GRIPPER_STATE,
                    "DRIVER_RESTARTED",
                    "ROS time went back before the last gripper command: the simulator (arm "
                    "driver) restarted; re-run `rascal run` to re-calibrate",
                )
            if watch_stop and self._stop.is_set():
                raise rig.RigError("gripper", "PREEMPTED", "stop requested")
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

    def open_while(self, width, during):
        # the controller runs gripper and arm goals side by side; a move's own RigError passes
        return self._run(self._gripper.open_while, width, during)

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

    def __init__(self, config=None, stop=None):
        cfg = _config(config)
        # each call: the detector's frame wait and TF lookup, and the margin
        self.timeout = cfg["perception"]["frame_wait"] + TF_WAIT + cfg["rig"]["answer_margin"]
        self._stop = stop
        self._detect = _proxy("/rascal/perception/detect", Detect)
        self._calibrate = _proxy("/rascal/perception/calibrate_background", CalibrateBackground)
        self._leftovers = {}  # station -> what its last detect saw but did not offer

    def _call(self, proxy, station, what, none_if=None):
        """The successful response; None as soon as a failure's message holds `none_if`."""
        for attempt in range(self.ATTEMPTS):
            res = _call(
                proxy,
                station,
                seconds=self.timeout,
                stop=self._stop,
                device="perception",
                code=what,
                node="sherd_detector",
                name=proxy.resolved_name,
            )
            if res.success:
                return res
            if none_if and none_if in res.message:
                return None
            rospy.logwarn(
                "perception %s at %s failed (attempt %d): %s",
                what.lower(),
                station,
                attempt + 1,
                res.message,
            )
            ros_sleep(self.RETRY_WAIT, self._stop)
        raise rig.RigError("perception", what, res.message)

    def calibrate(self, station):
        self._call(self._calibrate, station, "CALIBRATION")

    def _answer(self, station, res):
        """A successful Detect answer -> its observations; its leftovers kept for `leftovers`."""
        self._leftovers[station] = [leftover_from_msg(m) for m in res.leftovers]
        return [observation_from_msg(s) for s in res.detections.sherds]

    def detect(self, station):
        return self._answer(station, self._call(self._detect, station, "DETECT"))

    def leftovers(self, station):
        return list(self._leftovers.get(station, []))

    def detect_if_calibrated(self, station):
        # Any attempt may be the one that says 'no background model': the detector waits for a
        # frame and its transform before it looks for the model, so an attempt that failed on
        # those (at start-up with the simulator at full speed, TF lags the images) says it on
        # the retry. (Retrying through detect() turned that answer into an error.)
        res = self._call(self._detect, station, "DETECT", none_if="no background model")
        return None if res is None else self._answer(station, res)


class RosScale(rig.Scale):
    """/scale/mass readings, kept with their stamps (the last KEEP); /scale/tare answered within
    rig.answer_margin. How long and how steady a reading must be is the station's rule
    (`stations.ScaleStation`), not this adapter's."""

    KEEP = 600  # readings: a minute at the scale's 10 Hz

    def __init__(self, clock=None, config=None, stop=None):
        self.clock = clock  # unused: readings carry their own stamps (kept for callers)
        self._timeout = _config(config)["rig"]["answer_margin"]
        self._stop = stop
        self._lock = threading.Lock()
        self._kept = collections.deque(maxlen=self.KEEP)
        self._sub = rospy.Subscriber("/scale/mass", ScaleReadingMsg, self._on_reading, queue_size=5)
        self._tare = _proxy("/scale/tare", Trigger)

    @staticmethod
    def reading_from_msg(msg, received: float) -> rig.ScaleReading:
        """rascal_msgs/ScaleReading -> ScaleReading; an unstamped reading takes `received`."""
        stamp = msg.header.stamp.to_sec() or received
        return rig.ScaleReading(msg.mass, bool(msg.stable), stamp)

    def _on_reading(self, msg):
        r = self.reading_from_msg(msg, rospy.get_time())
        with self._lock:
            if self._kept and r.stamp < self._kept[-1].stamp:
                self._kept.clear()  # time ran backwards: the simulator or the driver restarted
            self._kept.append(r)

    def tare(self):
        res = _call(
            self._tare,
            seconds=self._timeout,
            stop=self._stop,
            device="/scale/tare",
            code="TARE",
            node="the scale (its driver, or the simulator)",
            name="/scale/tare",
        )
        if not res.success:
            raise rig.RigError("/scale/tare", "TARE", res.message)

    def readings(self, since):
        with self._lock:
            return [r for r in self._kept if r.stamp > since]


class RosArchivalCamera(rig.ArchivalCamera):
    """/archival_camera/capture, answered within rig.capture_timeout. The camera (the
    simulator, or archival_camera_driver) says on /archival_camera/exposed (std_msgs/Header,
    stamped with the capture's shutter time) when the shutter has closed: the arm may then
    move over the sherd while the image is transferred (`capture_while`)."""

    SERVICE = "/archival_camera/capture"
    NODE = "the archival camera (its driver, or the simulator)"

    def __init__(self, config=None, stop=None):
        self.timeout = _config(config)["rig"]["capture_timeout"]
        self._stop = stop
        self._capture = _proxy(self.SERVICE, CaptureArchival)
        self._exposed = threading.Event()
        self._since = None
        self._exposed_sub = rospy.Subscriber(EXPOSED, Header, self._on_exposed, queue_size=4)

    def _on_exposed(self, msg):
        since = self._since
        if since is not None and msg.stamp.to_sec() >= since:
            self._exposed.set()

    def capture(self, path, exposure_ev=0.0):
        return self.capture_while(path, exposure_ev, None)

    def capture_while(self, path, exposure_ev, during):
        deadline = dl.Deadline(self.timeout, dl.ros_time)
        answer = (deadline, self._stop, self.SERVICE, "FAILED", self.NODE, self.SERVICE)
        self._exposed.clear()
        self._since = dl.ros_time()  # a shutter from before this call is not this one's
        pending = dl.Background(self._capture, path, exposure_ev)
        moved = during is None
        if not moved:
            # the arm stays out of view until the shutter has closed, or the capture ended
            outcome = dl.wait_for(
                lambda: self._exposed.is_set() or pending.finished.is_set(),
                deadline,
                self._stop,
            )
            # a refusal (arm in view, another capture running) runs no move
            if outcome == dl.DONE and self._exposed_or_answered(pending, deadline):
                moved = True
                try:
                    during()
                except BaseException:
                    try:  # a move's failure is the one to report; the capture still ends
                        _answer(pending, *answer)
                    except Exception:
                        pass
                    raise
        res = _answer(pending, *answer)
        if not res.success:
            raise rig.RigError(self.SERVICE, "REFUSED", res.message)
        if not moved:
            during()  # the answer came before the word that the shutter closed
        return rig.Capture(res.path, res.stamp.to_sec(), res.width, res.height)

    def _exposed_or_answered(self, pending, deadline) -> bool:
        """The shutter of this capture has closed, or the camera answered with a photo."""
        if self._exposed.is_set():
            return True
        return not pending.failed() and bool(pending.result(deadline).success)


class RosClock(rig.Clock):
    """ROS time: simulated time under use_sim_time. Sleeps end with a RigError when the clock
    stops or runs backwards, or on `stop` (see ros_sleep)."""

    def __init__(self, stop=None):
        self._stop = stop

    def now(self):
        return rospy.get_time()

    def sleep(self, seconds):
        if seconds > 0:
            ros_sleep(seconds, self._stop)
