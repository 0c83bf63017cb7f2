"""Core tests (no master): Protocol 2.0 framing, the servo-bus emulator answering ROBOTIS's
dynamixel_sdk like a real bus (errors included), the finger linkage and the trajectory sampling."""

import math
import os
import time

import pytest

from rascal_drivers import control_table as ct
from rascal_drivers import finger_linkage, protocol2, workspace_venv
from rascal_drivers.arm_bus import ArmBus, BusError, config_from_section, latency_warning
from rascal_drivers.arm_driver import ArmDriver
from rascal_drivers.parameters import read_section
from rascal_drivers.servo_bus_emulator import ServoBusEmulator, wx250s_servos
from rascal_drivers.trajectory_follower import TrajectoryFollower

workspace_venv.add()
dxl = pytest.importorskip("dynamixel_sdk")


def test_a_ping_packet_matches_the_e_manual_example():
    # e-manual, Protocol 2.0, "Ping" example: ID 1 -> FF FF FD 00 01 03 00 01 19 4E
    assert protocol2.encode(1, protocol2.PING) == bytes.fromhex("FFFFFD0001030001194E")


def test_byte_stuffing_round_trips_and_garbage_before_a_packet_is_skipped():
    params = bytes([0x74, 0x00, 0xFF, 0xFF, 0xFD, 0x00])
    frame = protocol2.encode(1, protocol2.WRITE, params)
    assert b"\xff\xff\xfd\xfd" in frame[7:]
    buffer = bytearray(b"\x00\xff\x12" + frame)
    packet, _ = protocol2.take_packet(buffer)
    assert packet.crc_ok and packet.params == params and not buffer
    broken = bytearray(frame[:-1] + bytes([frame[-1] ^ 1]))
    assert protocol2.take_packet(broken)[0].crc_ok is False


@pytest.fixture
def emulator():
    emu = ServoBusEmulator(wx250s_servos()).start()
    yield emu
    emu.stop()


def open_sdk(device):
    port = dxl.PortHandler(device)
    assert port.openPort() and port.setBaudRate(1000000)
    return port, dxl.PacketHandler(2.0)


def test_the_emulator_answers_the_sdk_and_refuses_what_a_servo_refuses(emulator):
    port, ph = open_sdk(emulator.device)
    model, result, error = ph.ping(port, 8)
    assert (result, error, model) == (dxl.COMM_SUCCESS, 0, ct.XL430_W250)
    assert ph.ping(port, 42)[1] == dxl.COMM_RX_TIMEOUT  # nobody has ID 42
    assert ph.write1ByteTxRx(port, 1, 64, 1) == (dxl.COMM_SUCCESS, 0)  # torque on
    # EEPROM (Operating Mode) is locked while the torque is on: Access error
    assert ph.write1ByteTxRx(port, 1, 11, 5)[1] == protocol2.ERR_ACCESS
    # the XL430 has no Goal Current and no current-based position mode
    assert ph.write2ByteTxRx(port, 9, 102, 100)[1] == protocol2.ERR_ACCESS
    assert ph.write1ByteTxRx(port, 9, 11, 5)[1] == protocol2.ERR_DATA_RANGE
    # a packet with a broken CRC is answered with the CRC error
    bad = bytearray(protocol2.encode(1, protocol2.READ, bytes([132, 0, 4, 0])))
    bad[-1] ^= 0xFF
    port.writePort(bad)
    time.sleep(0.05)
    reply = bytes(port.readPort(64))
    assert reply[7] == protocol2.STATUS and reply[8] == protocol2.ERR_CRC
    # an unknown instruction: Instruction error
    port.writePort(protocol2.encode(1, 0x77))
    time.sleep(0.05)
    assert bytes(port.readPort(64))[8] == protocol2.ERR_INSTRUCTION
    # a hardware error raises the alert bit in every status packet, and drops the torque
    emulator.servos[1].inject_hardware_error(5)
    value, result, error = ph.read1ByteTxRx(port, 1, 70)
    assert value == 1 << 5 and error & protocol2.ERR_ALERT
    assert ph.read1ByteTxRx(port, 1, 64)[0] == 0
    port.closePort()


def driver_on(emulator, **overrides):
    # a long bus_timeout: the emulator thread shares this process with the test under load
    settings = dict({"device": emulator.device, "bus_timeout": 2.0}, **overrides)
    section = read_section(settings, "drivers.arm")
    bus = ArmBus(config_from_section(section), dxl)
    bus.open()
    bus.configure()
    return ArmDriver(bus)


def test_garbage_on_the_line_is_skipped_and_the_loop_carries_on(emulator):
    driver = driver_on(emulator)
    driver.cycle(time.monotonic())
    for _ in range(20):  # a header, a length, then noise: neither side may lose its footing
        emulator.send_garbage(b"\xff\xff\xfd\x00\x07\x01\x00\x13\x37")
        driver.cycle(time.monotonic())
    samples = [driver.cycle(time.monotonic())[0] for _ in range(30)]
    assert any(s is not None for s in samples[-10:]) and not driver.fault
    assert driver.bus.torque_off() == []
    driver.bus.close()


def test_a_servo_missing_at_start_is_named(emulator):
    del emulator.servos[7]
    section = read_section({"device": emulator.device, "connect_timeout": 0.2}, "drivers.arm")
    bus = ArmBus(config_from_section(section), dxl)
    with pytest.raises(BusError, match=r"servo 7 \(wrist_angle\) does not answer a ping"):
        bus.open()
    bus.close()


def test_a_rigid_sherd_does_not_overload_the_pwm_limited_gripper(emulator):
    gripper = emulator.servos[9]
    gripper.position = ct.rad_to_ticks(finger_linkage.angle_from_finger(0.037))  # open
    gripper.obstacle = ct.rad_to_ticks(finger_linkage.angle_from_finger(0.025))
    driver = driver_on(emulator)
    driver.cycle(time.monotonic())
    driver.on_gripper(["left_finger"], [0.015])  # close hard on a 50 mm sherd
    end = time.monotonic() + 1.5  # longer than the emulator's overload time at full output
    while time.monotonic() < end:
        sample, fault = driver.cycle(time.monotonic())
        time.sleep(0.005)
    assert not driver.fault
    assert abs(driver.last.position[6] - 0.025) < 0.0005  # held at the sherd's width
    assert emulator.servos[9].get("torque_enable") == 1
    driver.bus.torque_off()
    driver.bus.close()


def test_without_the_pwm_limit_the_same_grip_overloads_and_stops_the_arm(emulator):
    gripper = emulator.servos[9]
    gripper.position = ct.rad_to_ticks(finger_linkage.angle_from_finger(0.037))  # open
    gripper.obstacle = ct.rad_to_ticks(finger_linkage.angle_from_finger(0.025))
    driver = driver_on(emulator, gripper_pwm_limit=1.0)
    driver.cycle(time.monotonic())
    driver.on_gripper(["left_finger"], [0.015])
    end = time.monotonic() + 3.0
    while time.monotonic() < end and not driver.fault:
        driver.cycle(time.monotonic())
        time.sleep(0.005)
    assert "servo 9 (gripper): overload" in driver.fault
    assert driver.on_trajectory(["waist"], [(0.0, [0.3])], time.monotonic()).startswith("refused")
    driver.bus.torque_off()
    driver.bus.close()


def test_the_finger_linkage_inverts_and_matches_the_facts():
    assert finger_linkage.finger_from_angle(0.0) == pytest.approx(0.01949, abs=1e-5)  # facts §1.4
    assert finger_linkage.angle_from_finger(0.015) == pytest.approx(-0.378, abs=2e-3)
    assert finger_linkage.angle_from_finger(0.037) == pytest.approx(1.268, abs=2e-3)
    for f in (0.016, 0.025, 0.036):
        assert finger_linkage.finger_from_angle(
            finger_linkage.angle_from_finger(f)
        ) == pytest.approx(f, abs=1e-9)
    h = 1e-6
    numeric = (
        finger_linkage.finger_from_angle(0.3 + h) - finger_linkage.finger_from_angle(0.3)
    ) / h
    assert finger_linkage.finger_rate(0.3, 1.0) == pytest.approx(numeric, rel=1e-4)


def test_the_trajectory_follower_interpolates_holds_and_stops():
    f = TrajectoryFollower(["a", "b"])
    assert f.sample(0.0, [1.0, 2.0]) == [1.0, 2.0]
    f.replace(["b"], [(0.0, [2.0]), (1.0, [4.0])], start=10.0, current=[1.0, 2.0])
    assert f.sample(9.0, [1.0, 2.0]) == [1.0, 2.0]  # not started: hold
    assert f.sample(10.5, [1.0, 2.0]) == pytest.approx([1.0, 3.0])  # a keeps its goal
    assert f.sample(12.0, [1.0, 2.0]) == pytest.approx([1.0, 4.0])
    f.replace(["a", "b"], [], start=12.0, current=[1.5, 3.9])  # no points: stop where it is
    assert f.sample(13.0, [0.0, 0.0]) == [1.5, 3.9]


def test_ticks_and_radians():
    assert ct.ticks_to_rad(2048) == 0.0 and ct.rad_to_ticks(math.pi / 2) == 3072
    assert os.path.basename(ct.__file__) == "control_table.py"


@pytest.mark.parametrize(
    "overrides,message",
    [
        ({"ids": [1, 2, 3, 4, 5, 6, 7, 8, 8]}, "drivers.arm.ids: every servo needs its own ID"),
        ({"ids": [1, 2, 3, 4, 5, 6, 7, 8, 9.5]}, "drivers.arm.ids: servo IDs are whole numbers"),
        ({"baud": 12345}, "drivers.arm.baud: expected one of"),
        ({"offsets": [0.0] * 6}, "drivers.arm.offsets: expected"),
    ],
)
def test_bad_arm_parameters_are_named(overrides, message):
    with pytest.raises(ValueError, match=message):
        config_from_section(read_section(overrides, "drivers.arm"))


def test_no_latency_warning_for_a_pty_or_a_missing_device(emulator):
    # a pty has no USB latency timer; on the rig an FTDI adapter at 16 ms gets one line
    assert latency_warning(emulator.device) == "" and latency_warning("/dev/nothing") == ""


def test_a_limp_arm_is_moved_by_hand_and_holds_where_it_was_left(emulator):
    driver = driver_on(emulator)
    driver.cycle(time.monotonic())
    before = list(driver.last.position[:6])
    assert driver.set_limp(True) == ""
    assert all(emulator.servos[i].get("torque_enable") == 0 for i in range(1, 9))
    assert emulator.servos[9].get("torque_enable") == 1  # the gripper keeps its grip
    assert driver.on_trajectory(["waist"], [(0.0, [0.3])], time.monotonic()).startswith(
        "refused: the arm is limp"
    )
    waist = emulator.servos[1]
    waist.position += 300  # a person turns the waist by hand (about 26°)
    for _ in range(20):
        driver.cycle(time.monotonic())
        time.sleep(0.005)
    moved = driver.last.position[0]
    assert moved - before[0] == pytest.approx(300 * 2 * math.pi / 4096, abs=0.01)
    assert driver.set_limp(False) == ""
    assert all(emulator.servos[i].get("torque_enable") == 1 for i in range(1, 9))
    end = time.monotonic() + 0.5
    while time.monotonic() < end:  # held where it was left, not sprung back
        driver.cycle(time.monotonic())
        time.sleep(0.005)
    assert driver.last.position[0] == pytest.approx(moved, abs=0.005)
    assert driver.on_trajectory(["waist"], [(0.0, [moved])], time.monotonic()) == ""
    driver.bus.torque_off()
    driver.bus.close()
