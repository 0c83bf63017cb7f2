"""Wiring tests of `rosrun rascal_perception sherd_detector` against a master on a free port.

Parameter checks and service answers without a camera need only the node; the detection test
runs the simulator (`rosrun rascal_sim sim`) and robot_state_publisher with sim time, moves the
arm over the pickup mat, calibrates the empty mat, spawns the demo scenario and compares the
detections with /sim/ground_truth. The command-line tools keep this process free of rospy.
"""

import math
import os
import subprocess
import time

import pytest
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
CONFIG = os.path.join(WORKSPACE, "config", "rascal.yaml")
URDF = os.path.join(WORKSPACE, "src", "rascal_description", "urdf", "wx250s.urdf")
ARM = ["waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate"]
# camera over the pickup mat's centre, image rows along the mat: pointDown() and the camera-offset
# correction of test/SimScenes.cpp (surveyJoints), printed by the Print.SurveyJoints gtest
SURVEY = [0.8340, -0.1250, -0.0507, 0.0, 1.7465, -0.8340]


def built(package, executable):
    try:
        out = subprocess.run(
            ["catkin_find", "--first-only", package, executable],
            capture_output=True,
            text=True,
            timeout=30,
        )
    except (OSError, subprocess.TimeoutExpired):
        return False
    return out.returncode == 0 and bool(out.stdout.strip())


requires_sim = pytest.mark.skipif(
    not built("rascal_sim", "sim"),
    reason="rascal_sim is not built; the detection test runs against `rosrun rascal_sim sim`",
)


def wait_for(master, what, name, timeout=30.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        out = master.run(["ros" + what, "list"], check=False)
        if name in out.stdout.split():
            return
        time.sleep(0.2)
    raise AssertionError("%s %s did not appear" % (what, name))


def call(master, service, request, timeout=60.0):
    out = master.run(["rosservice", "call", service, request], timeout=timeout)
    return yaml.safe_load(out.stdout)


def start_detector(master, rosrun):
    proc = rosrun("rascal_perception", "sherd_detector")
    wait_for(master, "service", "/rascal/perception/detect")
    return proc


def exit_message(proc, timeout=30.0):
    out, _ = proc.communicate(timeout=timeout)
    return proc.returncode, out


def test_missing_config_says_how_to_load_it(ros_master, rosrun):
    proc = rosrun("rascal_perception", "sherd_detector")
    code, out = exit_message(proc)
    assert code != 0
    assert "rosparam load config/rascal.yaml" in out


@pytest.mark.parametrize(
    "key, value, named",
    [
        ("/perception/hue_tolerance", "2.0", "perception.hue_tolerance: expected"),
        ("/perception/border_margin", "0.5", "perception.border_margin: expected"),
        ("/arm/grasp_margin", "-1", "arm.grasp_margin: expected"),
        ("/stations/scale/surface_z", "abc", "stations.scale.surface_z: expected"),
        ("/robot_description", "<robot name='no_gripper'/>", "/robot_description: URDF"),
    ],
)
def test_bad_parameter_names_the_key(ros_master, rosrun, key, value, named):
    ros_master.run(["rosparam", "load", CONFIG])
    ros_master.run(["rosparam", "set", key, value])
    code, out = exit_message(rosrun("rascal_perception", "sherd_detector"))
    assert code != 0
    assert named in out


def test_answers_without_a_camera(ros_master, rosrun):
    ros_master.run(["rosparam", "load", CONFIG])
    ros_master.run(["rosparam", "set", "/perception/frame_wait", "0.3"])
    # the selection policy is the task layer's (schema reader rascal): the node does not read it
    ros_master.run(["rosparam", "set", "/perception/selection_policy", "random"])
    start_detector(ros_master, rosrun)
    r = call(ros_master, "/rascal/perception/detect", "{station: nowhere}")
    assert r["success"] is False and "nowhere" in r["message"]
    r = call(ros_master, "/rascal/perception/calibrate_background", "{station: pickup}")
    assert r["success"] is False and "/camera/color/image_raw" in r["message"]
    r = call(ros_master, "/rascal/perception/detect", "{station: scale}")
    assert r["success"] is False and "scale" in r["message"]


def move_arm(master, joints, seconds=2):
    msg = "{joint_names: [%s], points: [{positions: [%s], time_from_start: {secs: %d}}]}" % (
        ", ".join(ARM),
        ", ".join(str(j) for j in joints),
        seconds,
    )
    master.run(
        ["rostopic", "pub", "-1", "/arm/joint_trajectory", "trajectory_msgs/JointTrajectory", msg]
    )
    deadline = time.monotonic() + 60.0
    q = None
    while time.monotonic() < deadline:
        out = master.run(["rostopic", "echo", "-n", "1", "/joint_states"], timeout=30).stdout
        line = [s for s in out.splitlines() if s.startswith("position:")][0]
        q = [float(v) for v in line.split("[", 1)[1].rstrip("]").split(",")]
        if all(abs(a - b) < 0.002 for a, b in zip(q[:6], joints, strict=True)):
            return
        time.sleep(0.3)
    raise AssertionError("arm did not reach %s (at %s)" % (joints, q))


def truth_box(truth, yaw):
    """Centre of the true outline's box along `yaw` (what the detector measures), and extents."""
    p = truth["pose"]["position"]
    o = truth["pose"]["orientation"]
    t = math.atan2(2 * (o["w"] * o["z"] + o["x"] * o["y"]), 1 - 2 * (o["y"] ** 2 + o["z"] ** 2))
    pts = [
        (
            p["x"] + math.cos(t) * q["x"] - math.sin(t) * q["y"],
            p["y"] + math.sin(t) * q["x"] + math.cos(t) * q["y"],
        )
        for q in truth["outline"]
    ]
    a, b = (math.cos(yaw), math.sin(yaw)), (-math.sin(yaw), math.cos(yaw))
    u = [a[0] * x + a[1] * y for x, y in pts]
    v = [b[0] * x + b[1] * y for x, y in pts]
    cu, cv = (min(u) + max(u)) / 2, (min(v) + max(v)) / 2
    return (cu * a[0] + cv * b[0], cu * a[1] + cv * b[1]), max(u) - min(u), max(v) - min(v)


@requires_sim
def test_detects_the_demo_sherds_in_base_link(ros_master, rosrun):
    ros_master.run(["rosparam", "load", CONFIG])
    ros_master.run(["rosparam", "set", "/use_sim_time", "true"])
    ros_master.run(["rosparam", "set", "/simulator/real_time_factor", "1.0"])
    ros_master.run(["rosparam", "set", "--textfile", URDF, "/robot_description"])
    rosrun("rascal_sim", "sim")
    wait_for(ros_master, "topic", "/joint_states")
    rosrun("robot_state_publisher", "robot_state_publisher")
    start_detector(ros_master, rosrun)
    r = call(ros_master, "/sim/spawn", "{scenario_file: '', scenario_yaml: 'name: empty'}")
    assert r["success"], r["message"]
    move_arm(ros_master, SURVEY)

    calib = call(ros_master, "/rascal/perception/calibrate_background", "{station: pickup}")
    assert calib["success"], calib["message"]
    assert calib["clusters"] >= 1

    scenario = os.path.join(WORKSPACE, "config", "scenarios", "demo_10.yaml")
    r = call(ros_master, "/sim/spawn", "{scenario_file: '%s', scenario_yaml: ''}" % scenario)
    assert r["success"], r["message"]
    time.sleep(0.5)
    det = call(ros_master, "/rascal/perception/detect", "{station: pickup}")
    assert det["success"], det["message"]
    sherds = det["detections"]["sherds"]
    assert det["detections"]["header"]["frame_id"] == "base_link"
    assert len(sherds) >= 6
    truth = call(ros_master, "/sim/ground_truth", "{}")["sherds"]
    for s in sherds:
        p = s["pose"]["position"]
        o = s["pose"]["orientation"]
        yaw = 2 * math.atan2(o["z"], o["w"])
        best = min(
            truth,
            key=lambda t: math.hypot(
                t["pose"]["position"]["x"] - p["x"], t["pose"]["position"]["y"] - p["y"]
            ),
        )
        (cx, cy), length, width = truth_box(best, yaw)
        err = math.hypot(cx - p["x"], cy - p["y"])
        body = math.hypot(
            best["pose"]["position"]["x"] - p["x"], best["pose"]["position"]["y"] - p["y"]
        )
        print(
            "%s: centre %.2f mm from its outline's box (%.2f mm from the body origin), "
            "length %+.2f mm, width %+.2f mm"
            % (
                best["name"],
                1e3 * err,
                1e3 * body,
                1e3 * (s["length"] - length),
                1e3 * (s["width"] - width),
            )
        )
        assert err < 0.003
        assert abs(s["length"] - length) < 0.003 and abs(s["width"] - width) < 0.003
        assert 0.030 <= s["grasp_width"] <= 0.074
        assert len(s["outline"]) >= 3 and s["area"] > 0 and 0 < s["score"] <= 1
    markers = ros_master.run(
        ["rostopic", "echo", "-n", "1", "/rascal/detections"], timeout=30
    ).stdout
    assert 'ns: "sherds"' in markers and 'ns: "grasps"' in markers and 'ns: "labels"' in markers
    image = ros_master.run(
        ["rostopic", "echo", "-n", "1", "--noarr", "/rascal/perception/annotated"], timeout=30
    ).stdout
    assert 'encoding: "rgb8"' in image and "width: 640" in image
