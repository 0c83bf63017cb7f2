"""The wx250s's servo bus through ROBOTIS's dynamixel_sdk: set-up, one control cycle, shutdown.

Roles, IDs and models: facts widowx250_d435.md §1.3 (DOCS servos_wx250s.csv): XM430-W350 on
waist, shoulder (+ shadow), elbow (+ shadow), forearm_roll, wrist_angle; XL430-W250 on
wrist_rotate and gripper; 1 Mbps. Drive_Mode 1 (reversed) on the shadows and wrist_angle
(MANIP wx250s.yaml), so every primary servo reads in the URDF's sign; 2048 ticks = 0 rad. A
shadow gets its primary's ID as Secondary ID (e-manual, address 12): it executes the writes to
its primary and never answers them, so the pair is commanded with one goal and reads back its
own position. Position limits in ticks: MANIP wx250s.yaml (the URDF's limits, facts §1.3).

The gripper's XL430-W250 has no current sensing or current-based position mode (e-manual), so
its force is bounded with PWM Limit (address 36) in position mode, the same lever the vendor's
PWM gripper uses (facts §1.4): closed on a rigid sherd the horn stalls at that output and does
not overload. No ROS here: the node wrapper passes the configuration and calls `cycle()`.
"""

import math
import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional

from rascal_drivers import control_table as ct
from rascal_drivers import finger_linkage

ROLES = (
    "waist",
    "shoulder",
    "shoulder_shadow",
    "elbow",
    "elbow_shadow",
    "forearm_roll",
    "wrist_angle",
    "wrist_rotate",
    "gripper",
)
ARM_JOINTS = ("waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate")
PRIMARIES = ARM_JOINTS + ("gripper",)
SHADOW_OF = {"shoulder_shadow": "shoulder", "elbow_shadow": "elbow"}
MODEL = {r: ct.XL430_W250 if r in ("wrist_rotate", "gripper") else ct.XM430_W350 for r in ROLES}
REVERSED = ("shoulder_shadow", "elbow_shadow", "wrist_angle")  # Drive_Mode 1, MANIP wx250s.yaml
POSITION_LIMITS = {  # ticks, MANIP wx250s.yaml (= the URDF limits)
    "shoulder": (819, 3345),
    "shoulder_shadow": (819, 3345),
    "elbow": (648, 3094),
    "elbow_shadow": (648, 3094),
    "wrist_angle": (910, 3447),
}
VELOCITY_LIMIT = math.pi  # [rad/s] URDF velocity of every arm joint (facts §1.1)
SUPPORTED_BAUDS = (9600, 57600, 115200, 1000000, 2000000, 3000000, 4000000, 4500000)
STATE_FIELDS = ("present_current", "present_velocity", "present_position")  # 126..135
STATE_START, STATE_LENGTH = 126, 10
ERROR_CHECK_EVERY = 5  # cycles between reads of Hardware Error Status
RETRIES = 3  # attempts of a single read or write whose answer does not come


class BusError(RuntimeError):
    """One line: what failed on the bus, and what to do."""


@dataclass
class ArmBusConfig:
    device: str
    baud: int
    ids: Dict[str, int]
    connect_timeout: float
    bus_timeout: float
    acceleration: float
    offsets: Dict[str, float]
    gripper_pwm_limit: float


@dataclass
class JointSample:
    names: List[str] = field(default_factory=list)
    position: List[float] = field(default_factory=list)
    velocity: List[float] = field(default_factory=list)
    current: Dict[str, float] = field(default_factory=dict)  # [A] XM, [fraction of max] XL


def config_from_section(section: dict) -> ArmBusConfig:
    """The validated drivers.arm section as a config; raises ValueError naming the key."""
    ids = section["ids"]
    if any(float(i) != int(i) for i in ids):
        raise ValueError("drivers.arm.ids: servo IDs are whole numbers, got %r" % (ids,))
    ids = [int(i) for i in ids]
    if len(set(ids)) != len(ids):
        raise ValueError("drivers.arm.ids: every servo needs its own ID, got %r" % (ids,))
    if section["baud"] not in SUPPORTED_BAUDS:
        raise ValueError(
            "drivers.arm.baud: expected one of %s (the Dynamixel X rates), got %r"
            % (", ".join(str(b) for b in SUPPORTED_BAUDS), section["baud"])
        )
    return ArmBusConfig(
        device=section["device"],
        baud=int(section["baud"]),
        ids=dict(zip(ROLES, ids, strict=True)),
        connect_timeout=section["connect_timeout"],
        bus_timeout=section["bus_timeout"],
        acceleration=section["acceleration"],
        offsets=dict(zip(PRIMARIES, section["offsets"], strict=True)),
        gripper_pwm_limit=section["gripper_pwm_limit"],
    )


def latency_warning(device: str) -> str:
    """'' or one line when the USB-serial adapter behind `device` keeps the FTDI default latency
    timer (16 ms): every status packet then waits for it and the loop cannot reach 100 Hz."""
    name = os.path.basename(os.path.realpath(device))
    path = os.path.join("/sys/bus/usb-serial/devices", name, "latency_timer")
    try:
        with open(path, encoding="ascii") as f:
            ms = int(f.read().strip())
    except (OSError, ValueError):
        return ""  # not an FTDI adapter (or no sysfs): nothing to say
    if ms <= 1:
        return ""
    return (
        "%s: USB latency timer is %d ms, the loop will miss 100 Hz; install "
        "src/rascal_drivers/udev/99-rascal.rules (sets 1 ms) and replug the U2D2" % (device, ms)
    )


class ArmBus:
    def __init__(self, config: ArmBusConfig, sdk):
        """`sdk` is the dynamixel_sdk module (injected so the core imports nothing it need not)."""
        self.config = config
        self.sdk = sdk
        self.port = None
        self.packet = None
        self.cycles = 0
        self.last_answer = time.monotonic()
        self.fault: Optional[str] = None
        self._reader = None
        self._error_reader = None
        self._writer = None

    # ------------------------------------------------------------------ helpers
    def _id(self, role: str) -> int:
        return self.config.ids[role]

    def _where(self, role: str) -> str:
        return "servo %d (%s)" % (self._id(role), role)

    def _write(self, role: str, name: str, value: int) -> None:
        f = ct.field(name)
        writer = {1: "write1ByteTxRx", 2: "write2ByteTxRx", 4: "write4ByteTxRx"}[f.size]
        for _ in range(RETRIES):  # a lost answer is asked again; a refusal is not
            try:
                self.port.ser.reset_input_buffer()
                result, error = getattr(self.packet, writer)(
                    self.port, self._id(role), f.address, int(value) & ((1 << 8 * f.size) - 1)
                )
            except Exception as e:  # pyserial: the adapter is gone
                raise BusError("servo bus %s lost (%s)" % (self.config.device, e)) from e
            if result == self.sdk.COMM_SUCCESS:
                break
        if result != self.sdk.COMM_SUCCESS:
            raise BusError(
                "%s did not answer writing %s on %s (%s); check its cable and power"
                % (self._where(role), name, self.config.device, self.packet.getTxRxResult(result))
            )
        if error & 0x7F:
            raise BusError(
                "%s refused writing %s = %d: %s"
                % (self._where(role), name, value, self.packet.getRxPacketError(error))
            )

    def _read(self, role: str, name: str) -> int:
        f = ct.field(name)
        reader = {1: "read1ByteTxRx", 2: "read2ByteTxRx", 4: "read4ByteTxRx"}[f.size]
        for _ in range(RETRIES):
            try:
                self.port.ser.reset_input_buffer()
                value, result, _ = getattr(self.packet, reader)(
                    self.port, self._id(role), f.address
                )
            except Exception as e:
                raise BusError("servo bus %s lost (%s)" % (self.config.device, e)) from e
            if result == self.sdk.COMM_SUCCESS:
                break
        if result != self.sdk.COMM_SUCCESS:
            raise BusError(
                "%s did not answer reading %s on %s; check its cable and power"
                % (self._where(role), name, self.config.device)
            )
        return ct.signed(value, f.size) if ct.is_signed(name) else value

    # ------------------------------------------------------------------ start
    def open(self) -> None:
        c = self.config
        if not os.path.exists(c.device):
            raise BusError(
                "drivers.arm.device: %s does not exist; plug in the U2D2 (or set the path in "
                "config/rascal.yaml)" % c.device
            )
        self.port = self.sdk.PortHandler(c.device)
        self.packet = self.sdk.PacketHandler(2.0)
        try:
            opened = self.port.openPort() and self.port.setBaudRate(c.baud)
        except Exception as e:  # pyserial's SerialException and OSError
            raise BusError("drivers.arm.device: cannot open %s: %s" % (c.device, e)) from e
        if not opened:
            raise BusError("drivers.arm.device: cannot open %s at %d baud" % (c.device, c.baud))
        # the SDK polls the port with a zero timeout, spinning a core while it waits for a status
        # packet; a 1 ms read timeout lets the read sleep until the bytes arrive instead
        self.port.ser.timeout = 0.001
        deadline = time.monotonic() + c.connect_timeout
        for role in ROLES:
            while True:
                model, result, _ = self.packet.ping(self.port, self._id(role))
                if result == self.sdk.COMM_SUCCESS:
                    break
                if time.monotonic() > deadline:
                    raise BusError(
                        "%s does not answer a ping on %s at %d baud within %.1f s; check power, "
                        "the cable and drivers.arm.ids/baud"
                        % (self._where(role), c.device, c.baud, c.connect_timeout)
                    )
                time.sleep(0.01)
            if model != MODEL[role]:
                raise BusError(
                    "%s is model %d, expected %d (%s); check drivers.arm.ids"
                    % (
                        self._where(role),
                        model,
                        MODEL[role],
                        "XM430-W350" if MODEL[role] == ct.XM430_W350 else "XL430-W250",
                    )
                )

    def configure(self) -> None:
        """Torque off, EEPROM set-up, goals at the present positions, profiles, torque on."""
        for role in ROLES:
            self._write(role, "torque_enable", 0)
        errors = self.hardware_errors(all_roles=True)
        if errors:
            raise BusError(errors + "; power-cycle the arm, then start arm_driver again")
        for role in ROLES:
            self._write(role, "drive_mode", 1 if role in REVERSED else 0)
            self._write(role, "operating_mode", ct.POSITION_MODE)
            self._write(
                role, "secondary_id", self._id(SHADOW_OF[role]) if role in SHADOW_OF else 255
            )
            lo, hi = POSITION_LIMITS.get(role, (0, 4095))
            self._write(role, "min_position_limit", lo)
            self._write(role, "max_position_limit", hi)
        self._write(
            "gripper",
            "pwm_limit",
            round(self.config.gripper_pwm_limit * ct.XL430_PWM_LIMIT_MAX),
        )
        profile_velocity = max(1, round(VELOCITY_LIMIT / ct.VELOCITY_UNIT))
        profile_acceleration = max(1, round(self.config.acceleration / ct.ACCELERATION_UNIT))
        for role in ROLES:
            self._write(role, "profile_velocity", profile_velocity)
            self._write(role, "profile_acceleration", profile_acceleration)
            self._write(role, "goal_position", self._read(role, "present_position"))
        for role in ROLES:
            self._write(role, "torque_enable", 1)
        self._reader = self.sdk.GroupSyncRead(self.port, self.packet, STATE_START, STATE_LENGTH)
        for role in PRIMARIES:
            self._reader.addParam(self._id(role))
        hw = ct.field("hardware_error_status")
        self._error_reader = self.sdk.GroupSyncRead(self.port, self.packet, hw.address, hw.size)
        for role in ROLES:
            self._error_reader.addParam(self._id(role))
        gp = ct.field("goal_position")
        self._writer = self.sdk.GroupSyncWrite(self.port, self.packet, gp.address, gp.size)
        self.last_answer = time.monotonic()

    # ------------------------------------------------------------------ each cycle
    def read_state(self) -> Optional[JointSample]:
        """Present position/velocity/current of the primaries; None when the bus did not answer
        this cycle (BusError once it has been silent for drivers.arm.bus_timeout)."""
        try:
            self.port.ser.reset_input_buffer()  # a late answer to a timed-out request is stale
            result = self._reader.txRxPacket()
        except Exception as e:  # the adapter unplugged: pyserial raises out of the SDK
            raise BusError(
                "servo bus %s lost (%s); the arm is unpowered or unplugged, check the U2D2 "
                "cable, then start arm_driver again" % (self.config.device, e)
            ) from e
        if result != self.sdk.COMM_SUCCESS:
            self._check_silence()
            return None
        raw = {}
        try:
            for role in PRIMARIES:
                i = self._id(role)
                raw[role] = (
                    ct.signed(self._reader.getData(i, 132, 4), 4),
                    ct.signed(self._reader.getData(i, 128, 4), 4),
                    ct.signed(self._reader.getData(i, 126, 2), 2),
                )
        except (IndexError, TypeError):  # a short status packet (a stale reply) taken for data
            self._check_silence()
            return None
        self.last_answer = time.monotonic()
        sample = JointSample()
        for role in ARM_JOINTS:
            ticks, vel, cur = raw[role]
            sample.names.append(role)
            sample.position.append(ct.ticks_to_rad(ticks) - self.config.offsets[role])
            sample.velocity.append(vel * ct.VELOCITY_UNIT)
            sample.current[role] = (
                cur * ct.XM430_CURRENT_UNIT
                if MODEL[role] == ct.XM430_W350
                else cur * ct.XL430_LOAD_UNIT
            )
        ticks, vel, cur = raw["gripper"]
        theta = ct.ticks_to_rad(ticks) - self.config.offsets["gripper"]
        finger = finger_linkage.finger_from_angle(theta)
        rate = finger_linkage.finger_rate(theta, vel * ct.VELOCITY_UNIT)
        sample.names += ["left_finger", "right_finger"]
        sample.position += [finger, -finger]
        sample.velocity += [rate, -rate]
        sample.current["gripper"] = cur * ct.XL430_LOAD_UNIT
        return sample

    def _check_silence(self) -> None:
        silent = time.monotonic() - self.last_answer
        if silent > self.config.bus_timeout:
            raise BusError(
                "no answer from the servos on %s for %.2f s (drivers.arm.bus_timeout); check "
                "power and the cable, then start arm_driver again" % (self.config.device, silent)
            )

    def hardware_errors(self, all_roles: bool = False) -> str:
        """'' or one line naming every servo whose Hardware Error Status is set."""
        found = []
        if all_roles or self._error_reader is None:
            for role in ROLES:
                status = self._read(role, "hardware_error_status")
                if status:
                    found.append("%s: %s" % (self._where(role), ct.describe_hardware_error(status)))
        else:
            try:
                self.port.ser.reset_input_buffer()
                result = self._error_reader.txRxPacket()
            except Exception as e:
                raise BusError("servo bus %s lost (%s)" % (self.config.device, e)) from e
            if result != self.sdk.COMM_SUCCESS:
                self._check_silence()
                return ""
            try:
                statuses = {r: self._error_reader.getData(self._id(r), 70, 1) for r in ROLES}
            except (IndexError, TypeError):  # a stale short reply: read again next time
                return ""
            for role, status in statuses.items():
                if status:
                    # dynamixel_sdk takes any status packet of the right ID as the answer, so a
                    # late reply to the last state read (10 bytes) can pass for this 1-byte one:
                    # a fault stops the arm, so it is read once more, alone, before it counts
                    status = self._read(role, "hardware_error_status")
                if status:
                    found.append("%s: %s" % (self._where(role), ct.describe_hardware_error(status)))
        return "hardware error on " + "; ".join(found) if found else ""

    def set_arm_torque(self, on: bool) -> None:
        """Torque of the arm's servos (not the gripper's) off, so a person can move the arm by
        hand, or on again holding where the arm now is: each goal is set to its servo's present
        position first, or the arm would spring back to where it was before."""
        arm_roles = [r for r in ROLES if r != "gripper"]
        if on:
            for role in arm_roles:
                self._write(role, "goal_position", self._read(role, "present_position"))
        for role in arm_roles:
            self._write(role, "torque_enable", 1 if on else 0)

    def write_goals(self, arm: Optional[List[float]], finger: Optional[float]) -> None:
        """Goal positions of the six arm joints [rad] (None: none, the arm is limp) and the left
        finger [m], in one sync write (the shadows follow their primaries through the Secondary
        ID)."""
        self._writer.clearParam()
        goals = dict(zip(ARM_JOINTS, arm, strict=True)) if arm is not None else {}
        if finger is not None:
            goals["gripper"] = finger_linkage.angle_from_finger(finger)
        for role, rad in goals.items():
            ticks = ct.rad_to_ticks(rad + self.config.offsets[role])
            lo, hi = POSITION_LIMITS.get(role, (0, 4095))
            ticks = min(max(ticks, lo), hi)
            self._writer.addParam(self._id(role), list(int(ticks).to_bytes(4, "little")))
        try:
            self._writer.txPacket()
        except Exception as e:
            raise BusError("servo bus %s lost (%s)" % (self.config.device, e)) from e

    def cycle_errors(self) -> str:
        """Every ERROR_CHECK_EVERY-th cycle: the hardware errors ('' when none)."""
        self.cycles += 1
        if self.cycles % ERROR_CHECK_EVERY:
            return ""
        return self.hardware_errors()

    # ------------------------------------------------------------------ stop
    def torque_off(self) -> List[str]:
        """Torque off on every servo; returns the roles that did not confirm."""
        failed = []
        if self.packet is None:
            return failed
        # a signal may have cut a transaction short: the SDK would call the port busy forever
        self.port.is_using = False
        try:
            self.port.clearPort()
        except Exception:
            pass
        for role in ROLES:
            try:
                self._write(role, "torque_enable", 0)  # (asked again if unanswered)
            except Exception:
                failed.append(role)
        return failed

    def close(self) -> None:
        if self.port is not None:
            try:
                self.port.closePort()
            except Exception:
                pass
