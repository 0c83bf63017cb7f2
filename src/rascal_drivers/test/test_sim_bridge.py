"""Core tests of the emulated rig's bridge (no master): the simulator's joint state becomes the
servos' Present Position as arm_driver's bus reads it through dynamixel_sdk, the goals the
driver writes become commands for the simulated arm and gripper, and the simulator's scale
reading becomes the emulated scale's load as scale_driver's link reads it."""

import math
import time

import pytest
import serial

from rascal_drivers import arm_bus, finger_linkage, sim_bridge, workspace_venv
from rascal_drivers import control_table as ct
from rascal_drivers.parameters import read_section
from rascal_drivers.scale_emulator import ScaleEmulator
from rascal_drivers.scale_link import ScaleLink
from rascal_drivers.scale_protocols import PROTOCOLS
from rascal_drivers.servo_bus_emulator import ServoBusEmulator, wx250s_servos
from rascal_drivers.sim_bridge import SimBridge

workspace_venv.add()
sdk = pytest.importorskip("dynamixel_sdk")

NAMES = list(arm_bus.ARM_JOINTS) + ["left_finger", "right_finger"]
SLEEP = [0.0, -1.80, 1.55, 0.0, 0.8, 0.0, 0.037, -0.037]
TICK = 2 * math.pi / 4096


def arm_config(link, offsets=None):
    section = read_section({"device": link}, "drivers.arm")
    if offsets:
        section["offsets"] = offsets
    return arm_bus.config_from_section(section)


def start_bus(tmp_path, offsets=None, mirror_arm=False):
    config = arm_config(str(tmp_path / "ttyDXL"), offsets)
    ticks = SimBridge.initial_ticks(NAMES, SLEEP, config.ids, config.offsets)
    bus = ServoBusEmulator(wx250s_servos(ticks=ticks), link=config.device)
    bridge = SimBridge(bus, ScaleEmulator("mt_sics"), config.ids, config.offsets, mirror_arm)
    bridge.on_sim_joints(NAMES, SLEEP, [0.0] * 8)
    bus.start()
    driver_bus = arm_bus.ArmBus(config, sdk)
    driver_bus.open()
    for attempt in range(3):  # a machine loaded by other work can starve the emulator's thread
        try:
            driver_bus.configure()  # torque on, goals = present positions
            break
        except arm_bus.BusError:
            if attempt == 2:
                raise
    return bus, bridge, driver_bus


def read(driver_bus):
    time.sleep(0.05)
    sample, deadline = None, time.monotonic() + 2.0
    while sample is None and time.monotonic() < deadline:  # a late reply skips one read
        sample = driver_bus.read_state()
    assert sample is not None
    return dict(zip(sample.names, sample.position, strict=True))


def test_the_servos_move_the_simulated_arm_and_the_simulated_fingers_stop_the_gripper(tmp_path):
    offsets = [0.0, 0.02, 0.0, 0.0, -0.01, 0.0, 0.0]
    bus, bridge, driver_bus = start_bus(tmp_path, offsets)
    try:
        got = read(driver_bus)  # the servos start where the simulated arm is, offsets removed
        for name, want in zip(NAMES, SLEEP, strict=True):
            assert abs(got[name] - want) <= (TICK if "finger" not in name else 5e-5), name
        first = bridge.arm_goal(0.0, 100.0)  # torque on: the simulator holds the arm there
        assert first is not None and first[1] == [0.0] * 6
        assert bridge.arm_goal(0.0, 100.001) is None  # nothing moved
        # the driver writes goals: the servos move (the emulator's model), the simulated arm is
        # sent where they are with their rate in ROS time, the gripper its goal once
        goal = [0.31, -1.6, 1.4, 0.1, 0.7, -0.2]
        driver_bus.write_goals(goal, 0.020)
        moving = None
        for k in range(200):  # within 2 s, however late the emulator's thread runs
            time.sleep(0.01)
            moving = bridge.arm_goal(0.001, 100.02 + 0.01 * k)
            if moving is not None:
                break
        q, v = moving
        assert abs(v[0]) > 0 and all(abs(x) <= 1.5 * math.pi for x in v)
        assert bridge.gripper_goal() == pytest.approx(0.020, abs=5e-5)
        assert bridge.gripper_goal() is None
        deadline = time.monotonic() + 3.0
        while time.monotonic() < deadline:  # until the servos have arrived at their goals
            with bus.lock:
                at = [bus.servos[i].get("present_position") for i in (1, 2, 4, 6, 7, 8)]
            want = [ct.rad_to_ticks(g + o) for g, o in zip(goal, offsets, strict=False)]
            if all(abs(a - w) <= 1 for a, w in zip(at, want, strict=True)):
                break
            time.sleep(0.02)
        bridge.arm_goal(0.002, 103.0)
        q, v = bridge.arm_goal(0.004, 103.0 + sim_bridge.STOPPED_AFTER + 0.01)
        assert v == [0.0] * 6  # stopped: one command holds the simulated arm there
        assert max(abs(a - b) for a, b in zip(q, goal, strict=True)) <= 2 * TICK
        # a sherd stops the simulated fingers at 25 mm: the gripper's horn stops there too
        bridge.on_sim_joints(NAMES, SLEEP[:6] + [0.025, -0.025], [0.0] * 8)
        got = read(driver_bus)
        assert abs(got["left_finger"] - 0.025) <= 5e-5
        assert abs(got["waist"] - 0.31) <= 2 * TICK  # the arm joints stay the servos' own
    finally:
        driver_bus.torque_off()
        driver_bus.close()
        bus.stop()


def test_mirrored_the_arm_servos_are_where_the_simulated_joints_are(tmp_path):
    bus, bridge, driver_bus = start_bus(tmp_path, mirror_arm=True)
    try:
        moved = [0.3, -1.2, 1.0, 0.1, 0.5, -0.2, 0.025, -0.025]
        bridge.on_sim_joints(NAMES, moved, [0.0] * 8)
        got = read(driver_bus)
        for name, want in zip(NAMES, moved, strict=True):
            assert abs(got[name] - want) <= (TICK if "finger" not in name else 5e-5), name
        driver_bus.write_goals([0.31, -1.19, 1.0, 0.1, 0.5, -0.2], None)
        time.sleep(0.02)
        q, _ = bridge.arm_goal(0.0, 100.0)  # the goals, not where the servos are
        assert abs(q[0] - 0.31) <= TICK and abs(q[1] + 1.19) <= TICK
    finally:
        driver_bus.torque_off()
        driver_bus.close()
        bus.stop()


def test_the_emulated_scale_follows_the_simulated_reading(tmp_path):
    scale = ScaleEmulator("a_and_d", link=str(tmp_path / "ttyScale")).start()
    bridge = SimBridge(None, scale, {}, {})
    port = serial.Serial(scale.link, 9600, timeout=0.5)
    link = ScaleLink(port, PROTOCOLS["a_and_d"](), scale.link, 2.0)
    try:
        bridge.on_sim_scale(0.0, True)
        bridge.on_sim_scale(0.012, False)  # the sherd being put down
        bridge.on_sim_scale(0.02518, False)
        bridge.on_sim_scale(0.02523, True)  # the simulator's scale has settled
        bridge.on_sim_scale(0.02524, True)  # noise below the readability: the load stays
        assert scale.load == pytest.approx(0.02523)
        deadline = time.monotonic() + 3.0
        reading = None
        while time.monotonic() < deadline:
            reading, _ = link.poll()
            if reading is not None and reading.stable:
                break
            time.sleep(0.05)
        assert reading is not None and reading.stable
        assert abs(reading.mass - 0.02523) <= 2e-4
    finally:
        port.close()
        scale.stop()


def test_finger_and_horn_agree_both_ways():
    for finger in (0.015, 0.020, 0.030, 0.037):
        theta = finger_linkage.angle_from_finger(finger)
        assert abs(finger_linkage.finger_from_angle(theta) - finger) < 1e-6
