"""Wiring tests of arm_driver (master on a free port): the node, started with rosrun, talks
through dynamixel_sdk to the Protocol 2.0 servo-bus emulator on a pseudo-terminal."""

import json
import os
import subprocess
import time

import pytest

from rascal_drivers import control_table as ct
from rascal_drivers import finger_linkage
from rascal_drivers.servo_bus_emulator import ServoBusEmulator, wx250s_servos
from rascal_tasks.sim_rig import stop

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
CONFIG = os.path.join(WORKSPACE, "config", "rascal.yaml")
CLIENT = os.path.join(HERE, "arm_client.py")
CONTROLLER_CLIENT = os.path.join(HERE, "controller_client.py")
URDF = os.path.join(WORKSPACE, "src", "rascal_description", "urdf", "wx250s.urdf")


@pytest.fixture
def bus(tmp_path):
    emu = ServoBusEmulator(wx250s_servos(), link=str(tmp_path / "ttyDXL")).start()
    yield emu
    emu.stop()


def load(master, device):
    master.run(["rosparam", "load", CONFIG])
    master.run(["rosparam", "set", "/drivers/arm/device", device])
    # the emulator shares this test's CPU with everything else: no false "bus lost" under load
    master.run(["rosparam", "set", "/drivers/arm/bus_timeout", "1.0"])


def client(master, scenario):
    res = master.run(["/usr/bin/python3", CLIENT, scenario], timeout=40)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout.strip().splitlines()[-1])


def wait_for_torque(bus, on, timeout=20.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        with bus.lock:
            if all(bool(s.get("torque_enable")) == on for s in bus.servos.values()):
                return True
        time.sleep(0.05)
    return False


def output(proc):
    stop(proc)
    return proc.stdout.read()


def test_a_hardware_error_stops_the_arm_with_one_line(ros_master, rosrun, bus):
    load(ros_master, bus.link)
    node = rosrun("rascal_drivers", "arm_driver")
    assert wait_for_torque(bus, True), output(node)
    with bus.lock:
        bus.servos[4].inject_hardware_error(5)  # the elbow overloads
    result = client(ros_master, "hold")
    if "after" not in result:
        pytest.fail("%s; arm_driver said: %s" % (result, output(node)))
    for joint in ("waist", "shoulder", "wrist_angle"):
        assert abs(result["after"][joint] - result["before"][joint]) < 0.01, result
    text = output(node)
    lines = [ln for ln in text.splitlines() if "hardware error" in ln]
    assert lines, text
    assert "servo 4 (elbow): overload" in lines[0]
    assert "the arm is stopped" in lines[0]
    assert any("/arm/joint_trajectory refused" in ln for ln in text.splitlines()), text


def test_an_unplugged_bus_gives_one_line_and_exit_1(ros_master, rosrun, bus):
    load(ros_master, bus.link)
    node = rosrun("rascal_drivers", "arm_driver")
    assert wait_for_torque(bus, True), output(node)
    bus.unplug()
    node.wait(timeout=20)
    text = node.stdout.read()
    assert node.returncode == 1, text
    lines = [ln for ln in text.splitlines() if "arm_driver:" in ln and "lost" in ln]
    assert len(lines) == 1, text


@pytest.mark.parametrize(
    "key,value,message",
    [
        (
            "/drivers/arm/device",
            "/dev/no_such_u2d2",
            "drivers.arm.device: /dev/no_such_u2d2 does not exist",
        ),
        (
            "/drivers/arm/loop_rate",
            "50.0",
            "drivers.arm.loop_rate: expected a number in Hz in [100, 500]",
        ),
    ],
)
def test_a_bad_parameter_is_named_in_one_line_and_exit_1(ros_master, key, value, message):
    ros_master.run(["rosparam", "load", CONFIG])
    ros_master.run(["rosparam", "set", key, value])
    res = subprocess.run(
        ["rosrun", "rascal_drivers", "arm_driver"],
        env=ros_master.env,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert res.returncode == 1
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], res.stderr


def test_arm_controller_runs_unchanged_on_the_driver(ros_master, rosrun, bus):
    """The seam: arm_controller and the task layer's client (rascal_control.Arm, Gripper), with
    arm_driver in place of sim: named pose, pose goal, open, close on a rigid 50 mm sherd (held,
    no overload); then torque off on every servo when the driver stops."""
    with bus.lock:
        gripper = bus.servos[9]
        gripper.position = ct.rad_to_ticks(finger_linkage.angle_from_finger(0.037))  # open
        gripper.obstacle = ct.rad_to_ticks(finger_linkage.angle_from_finger(0.025))  # 50 mm sherd
    load(ros_master, bus.link)
    ros_master.run(["rosparam", "set", "/robot_description", "-t", URDF])
    driver = rosrun("rascal_drivers", "arm_driver")
    rosrun("rascal_control", "arm_controller")
    assert wait_for_torque(bus, True), output(driver)
    with bus.lock:  # the set-up the facts ask for: reversed shadows, shadows follow primaries
        assert bus.servos[3].get("drive_mode") == 1 and bus.servos[3].get("secondary_id") == 2
        assert bus.servos[5].get("secondary_id") == 4 and bus.servos[7].get("drive_mode") == 1
        assert bus.servos[9].get("pwm_limit") == round(0.3 * 885)
    res = ros_master.run(["/usr/bin/python3", CONTROLLER_CLIENT], timeout=60)
    assert res.returncode == 0, res.stdout + res.stderr
    got = json.loads(res.stdout.strip().splitlines()[-1])
    for q, want in zip(got["sleep"], (0.0, -1.80, 1.55, 0.0, 0.8, 0.0), strict=True):
        assert abs(q - want) < 0.005, got
    assert all(abs(a - b) < 0.005 for a, b in zip(got["pose"], (0.30, 0.0, 0.12), strict=True))
    assert abs(got["opened"] - 0.074) < 0.001, got
    assert got["closed"]["holding"] and abs(got["closed"]["width"] - 0.050) < 0.001, got
    with bus.lock:
        assert not gripper.get("hardware_error_status")
        assert abs(bus.servos[3].position - bus.servos[2].position) < 3  # the shadows went along
        assert abs(bus.servos[5].position - bus.servos[4].position) < 3
    text = output(driver)
    assert driver.returncode == 0, text
    assert "torque off on every servo" in text
    with bus.lock:
        assert not any(s.get("torque_enable") for s in bus.servos.values())


def test_the_arm_goes_limp_for_teaching_by_hand_and_holds_where_it_is_left(ros_master, rosrun, bus):
    load(ros_master, bus.link)
    node = rosrun("rascal_drivers", "arm_driver")
    assert wait_for_torque(bus, True), output(node)

    def limp(on):
        res = ros_master.run(
            ["rosservice", "call", "/arm/limp", "data: %s" % ("true" if on else "false")],
            timeout=30,
        )
        assert "success: True" in res.stdout, res.stdout + res.stderr

    limp(True)
    with bus.lock:
        assert [bus.servos[i].get("torque_enable") for i in range(1, 10)] == [0] * 8 + [1]
        bus.servos[1].position += 300  # the waist turned by hand
        left = bus.servos[1].position
    time.sleep(0.3)
    limp(False)
    assert wait_for_torque(bus, True), output(node)
    time.sleep(0.5)
    with bus.lock:  # holding where the hands left it: the goal is there, not the old one
        assert abs(bus.servos[1].get("goal_position") - left) <= 2
        assert abs(bus.servos[1].position - left) <= 2
    stop(node)
