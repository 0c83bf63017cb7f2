"""Core tests of the ROS adapters' conversions (no master needed)."""

import math

import pytest

pytest.importorskip("rascal_msgs")

from rascal_control.arm import quaternion_from_rpy  # noqa: E402
from rascal_msgs.msg import Sherd  # noqa: E402

from rascal_tasks.ros_rig import observation_from_msg  # noqa: E402


@pytest.mark.parametrize("yaw", [-3.0, -1.2, -0.4, 0.0, 0.5, 1.21, 1.57, 2.9])
def test_grasp_yaw_survives_the_pitched_orientation(yaw):
    """The gripper points down (pitch pi/2), where Euler yaw extraction is degenerate."""
    s = Sherd()
    (
        s.grasp_pose.orientation.x,
        s.grasp_pose.orientation.y,
        s.grasp_pose.orientation.z,
        s.grasp_pose.orientation.w,
    ) = quaternion_from_rpy(0.0, math.pi / 2, yaw)
    s.pose.orientation.w = 1.0
    o = observation_from_msg(s)
    assert o.grasp_yaw == pytest.approx(yaw, abs=1e-9)


def test_sherd_fields_are_carried_over():
    s = Sherd()
    s.pose.position.x, s.pose.position.y = 0.12, 0.25
    s.pose.orientation.z, s.pose.orientation.w = math.sin(0.3), math.cos(0.3)
    s.length, s.width, s.height, s.grasp_width = 0.05, 0.03, 0.008, 0.042
    s.grasp_pose.position.z = 0.01
    s.grasp_pose.orientation.w = 1.0
    s.color.r, s.color.g, s.color.b = 0.6, 0.4, 0.3
    o = observation_from_msg(s)
    assert (o.x, o.y, o.length, o.width, o.height) == (0.12, 0.25, 0.05, 0.03, 0.008)
    assert o.yaw == pytest.approx(0.6)
    assert (o.grasp_z, o.grasp_width) == (0.01, 0.042)
    assert o.colour == pytest.approx((0.6, 0.4, 0.3))


def test_scale_readings_keep_their_stamp_and_flag():
    from rascal_msgs.msg import ScaleReading as ScaleReadingMsg

    from rascal_tasks.ros_rig import RosScale

    m = ScaleReadingMsg()
    m.mass, m.stable = 0.0139, True
    m.header.stamp.secs, m.header.stamp.nsecs = 12, 300000000
    r = RosScale.reading_from_msg(m, received=99.0)
    assert (r.mass, r.stable, r.stamp) == (0.0139, True, pytest.approx(12.3))
    m.header.stamp.secs = m.header.stamp.nsecs = 0  # a driver that does not stamp
    assert RosScale.reading_from_msg(m, received=99.0).stamp == 99.0


def test_a_transform_not_there_yet_is_waited_for_then_said_in_one_line():
    """TF's publisher is another process: a pose asked for at an image's stamp may come a
    little later (a loaded machine; CI once saw 0.28 s), so the lookup is tried again until
    a wall-clock deadline, and only then said, in one line."""
    from rascal_tasks.ros_session import SessionError, wait_for_transform

    class LateTf:
        calls = 0

        def lookup_transform(self, target, frame, stamp):
            self.calls += 1
            if self.calls < 3:
                raise RuntimeError("Lookup would require extrapolation into the future.\nmore")
            return (target, frame, stamp)

    tf = LateTf()
    assert wait_for_transform(tf, "camera_color_optical_frame", 83.5) == (
        "base_link",
        "camera_color_optical_frame",
        83.5,
    )
    assert tf.calls == 3

    class NeverTf:
        def lookup_transform(self, target, frame, stamp):
            raise RuntimeError("Lookup would require extrapolation into the future.\nmore")

    with pytest.raises(SessionError) as e:
        wait_for_transform(NeverTf(), "camera_color_optical_frame", 83.5, wait=0.05)
    assert str(e.value) == (
        "TF base_link -> camera_color_optical_frame: Lookup would require extrapolation into "
        "the future."
    )


def _camera(answer, exposed_after=None):
    """A RosArchivalCamera whose service answers `answer` (after saying its shutter closed,
    when `exposed_after` is a delay in s), no master needed."""
    import threading
    import time

    from rascal_tasks.ros_rig import RosArchivalCamera

    cam = RosArchivalCamera.__new__(RosArchivalCamera)
    cam.timeout, cam._stop, cam._exposed = 5.0, None, threading.Event()

    def service(path, ev):
        if exposed_after is not None:
            time.sleep(exposed_after)
            cam._exposed.set()
        time.sleep(0.05)  # the transfer
        return answer

    cam._capture = service
    return cam


def test_the_arm_moves_during_a_capture_only_once_its_shutter_closed_or_a_photo_came():
    from types import SimpleNamespace

    from rascal_tasks.rig import RigError

    photo = SimpleNamespace(
        success=True, path="/a.png", stamp=SimpleNamespace(to_sec=lambda: 1.0), width=4, height=3
    )
    moves = []
    assert _camera(photo, exposed_after=0.02).capture_while("/a.png", 0.0, lambda: moves.append(1))
    assert moves == [1]  # during the transfer
    assert _camera(photo).capture_while("/a.png", 0.0, lambda: moves.append(2)).path == "/a.png"
    assert moves == [1, 2]  # a camera that never says: once the photo came
    refused = SimpleNamespace(success=False, message="arm in view: move to standby")
    with pytest.raises(RigError) as e:
        _camera(refused).capture_while("/a.png", 0.0, lambda: moves.append(3))
    assert e.value.code == "REFUSED" and moves == [1, 2]  # a refusal moves nothing
