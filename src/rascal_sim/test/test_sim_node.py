"""Wiring tests of `rosrun rascal_sim sim` against a master on a free port.

They use the command-line tools (rostopic, rosservice) so that this process needs no rospy node.
"""

import os
import struct
import time

import cv2
import numpy as np
import pytest

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
ARM = ["waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate"]
SLEEP = [0.0, -1.80, 1.55, 0.0, 0.8, 0.0]
# arm stretched out towards the archival camera station (0.31, -0.30): over the frame
OVER_CAMERA = [-0.77, 0.0, 0.0, 0.0, 0.0, 0.0]


def echo(master, topic, timeout=30.0, noarr=False):
    cmd = ["rostopic", "echo", "-n", "1"] + (["--noarr"] if noarr else []) + [topic]
    return master.run(cmd, timeout=timeout).stdout


def joint_positions(master):
    out = echo(master, "/joint_states", noarr=False)
    line = [s for s in out.splitlines() if s.startswith("position:")][0]
    return [float(v) for v in line.split("[", 1)[1].rstrip("]").split(",")]


def move_arm(master, joints, seconds=2.0):
    msg = "{joint_names: [%s], points: [{positions: [%s], time_from_start: {secs: %d}}]}" % (
        ", ".join(ARM),
        ", ".join(str(j) for j in joints),
        int(seconds),
    )
    master.run(
        ["rostopic", "pub", "-1", "/arm/joint_trajectory", "trajectory_msgs/JointTrajectory", msg]
    )
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline:
        q = joint_positions(master)
        if all(abs(a - b) < 0.01 for a, b in zip(q[:6], joints, strict=True)):
            return q
        time.sleep(0.2)
    raise AssertionError("arm did not reach %s (at %s)" % (joints, q))


def capture(master, path, exposure_ev=0.0):
    return master.run(
        [
            "rosservice",
            "call",
            "/archival_camera/capture",
            "{path: '%s', exposure_ev: %g}" % (path, exposure_ev),
        ]
    ).stdout


@pytest.fixture
def sim(ros_master, rosrun):
    ros_master.run(["rosparam", "load", "config/rascal.yaml"], cwd=WORKSPACE)
    ros_master.run(["rosparam", "set", "/simulator/scenario", "config/scenarios/small_3.yaml"])
    ros_master.run(["rosparam", "set", "/simulator/real_time_factor", "1.0"])
    proc = rosrun("rascal_sim", "sim")
    echo(ros_master, "/clock")
    assert proc.poll() is None
    return proc


def test_publishes_clock_joint_states_and_scale(ros_master, sim):
    q = joint_positions(ros_master)
    assert len(q) == 8
    assert q[:6] == pytest.approx(SLEEP, abs=1e-3)
    names = echo(ros_master, "/joint_states")
    for name in ARM + ["left_finger", "right_finger"]:
        assert "- " + name in names
    scale = echo(ros_master, "/scale/mass")
    assert "frame_id: \"scale_link\"" in scale
    assert "stable:" in scale


def test_publishes_images_and_point_clouds(ros_master, sim):
    colour = echo(ros_master, "/camera/color/image_raw", noarr=True)
    assert "encoding: \"rgb8\"" in colour and "width: 640" in colour and "height: 480" in colour
    assert "frame_id: \"camera_color_optical_frame\"" in colour
    depth = echo(ros_master, "/camera/aligned_depth_to_color/image_raw", noarr=True)
    assert "encoding: \"16UC1\"" in depth
    info = echo(ros_master, "/camera/color/camera_info")
    assert "K: [615.0, 0.0, 320.0, 0.0, 615.0, 240.0, 0.0, 0.0, 1.0]" in info
    cloud = echo(ros_master, "/camera/depth/color/points", noarr=True)
    width = [int(s.split(":")[1]) for s in cloud.splitlines() if s.startswith("width:")][0]
    assert width > 1000
    assert "point_step: 16" in cloud  # x, y, z, rgb as float32


def test_capture_refused_while_arm_in_view_then_stored(ros_master, sim, tmp_path):
    move_arm(ros_master, OVER_CAMERA)
    out = capture(ros_master, str(tmp_path / "refused.png"))
    assert "success: False" in out
    assert "arm in view" in out
    assert not (tmp_path / "refused.png").exists()

    move_arm(ros_master, SLEEP)
    path = tmp_path / "sherd.png"
    out = capture(ros_master, str(path))
    assert "success: True" in out, out
    with open(path, "rb") as f:
        header = f.read(24)
    width, height = struct.unpack(">II", header[16:24])
    assert (width, height) == (2000, 1500)

    # a stop darker: half the light on the sensor (compared in linear light, unclipped pixels)
    darker = tmp_path / "darker.png"
    assert "success: True" in capture(ros_master, str(darker), -1.0)
    a, b = (cv2.imread(str(p)).astype(float) / 255.0 for p in (path, darker))
    ok = (a < 0.95) & (a > 0.05)
    ratio = np.mean(b[ok] ** 2.2) / np.mean(a[ok] ** 2.2)
    assert 0.35 < ratio < 0.65, ratio
    out = capture(ros_master, str(tmp_path / "x.png"), -5.0)
    assert "success: False" in out and "exposure_ev" in out


def test_ground_truth_spawn_and_reset(ros_master, sim):
    truth = ros_master.run(["rosservice", "call", "/sim/ground_truth"]).stdout
    assert truth.count("name: \"sherd_0") == 3
    out = ros_master.run(
        [
            "rosservice",
            "call",
            "/sim/spawn",
            "{scenario_file: '', scenario_yaml: 'sherds: [{name: one, pose: [0.1, 0.25, 0]}]'}",
        ]
    ).stdout
    assert "success: True" in out and "count: 1" in out
    out = ros_master.run(
        [
            "rosservice",
            "call",
            "/sim/spawn",
            "{scenario_file: '', scenario_yaml: 'sherds: [{pose: [0, 0]}]'}",
        ]
    ).stdout
    assert "success: False" in out and "sherds[0].pose" in out
    out = ros_master.run(
        ["rosservice", "call", "/sim/inject_fault", "{fault: 1, duration: 1.0}"]
    ).stdout
    assert "success: True" in out
    assert "success: True" in ros_master.run(["rosservice", "call", "/sim/reset"]).stdout


def test_bad_parameter_is_named_and_exits_non_zero(ros_master, rosrun):
    ros_master.run(["rosparam", "load", "config/rascal.yaml"], cwd=WORKSPACE)
    ros_master.run(["rosparam", "set", "/stations/scale/position", "[0.3]"])
    proc = rosrun("rascal_sim", "sim")
    out, _ = proc.communicate(timeout=30)
    assert proc.returncode != 0
    named = [line for line in out.splitlines() if "stations.scale.position: expected" in line]
    assert len(named) == 1, out
