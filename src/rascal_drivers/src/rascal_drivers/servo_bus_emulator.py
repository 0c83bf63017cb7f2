"""A Dynamixel Protocol 2.0 bus of emulated servos on a pseudo-terminal.

The arm driver opens the pty's slave side with dynamixel_sdk exactly as it opens a U2D2, so its
whole wire path (framing, CRC, sync read/write, status packets, error bytes) is exercised. Each
servo keeps a control table (control_table.FIELDS), answers PING, READ, WRITE, SYNC_READ,
SYNC_WRITE and REBOOT, refuses what a real one refuses (CRC error, unknown instruction, EEPROM
writes with torque on, read-only or out-of-table addresses), follows a Secondary (shadow) ID, and
moves toward its goal as a first-order lag limited by its profile velocity. Tests inject
hardware errors, a rigid object between the fingers, garbage bytes and unplugging. No ROS here.
"""

import os
import select
import struct
import time
from typing import Dict, List, Optional

from rascal_drivers import control_table as ct
from rascal_drivers import protocol2 as p2
from rascal_drivers.pty_device import PtyDevice

TIME_CONSTANT = 0.05  # [s] first-order lag of the emulated position loop
MAX_STEP = 0.01  # [s] a starved emulator thread moves its servos late, never in a jump
LOAD_PER_TICK = 0.004  # emulated load (fraction of max torque) per tick of position error
OVERLOAD_AFTER = 1.0  # [s] at full output before the overload error (a real servo: a few s)


class EmulatedServo:
    def __init__(self, dxl_id: int, model: int, position: int = ct.CENTRE_TICK):
        self.model = model
        self.table = bytearray(256)
        self.position = float(position)
        self.velocity = 0.0
        self.obstacle: Optional[float] = None  # ticks below which the horn cannot turn (a sherd)
        self.saturated_for = 0.0
        self.load = 0.0  # fraction of the maximum torque
        # [ticks] where a simulator says the horn is (the emulated rig): replaces the motion model
        self.external_position: Optional[float] = None
        self.external_velocity = 0.0  # [ticks/s] its rate, from the same source
        self.set("model_number", model)
        self.set("firmware_version", 46)
        self.set("id", dxl_id)
        self.set("baud_rate", 3)  # 1 Mbps
        self.set("operating_mode", ct.POSITION_MODE)
        self.set("secondary_id", 255)
        self.set("pwm_limit", ct.XL430_PWM_LIMIT_MAX)
        if model == ct.XM430_W350:
            self.set("current_limit", ct.XM430_CURRENT_LIMIT_MAX)
        self.set("velocity_limit", 131)
        self.set("max_position_limit", 4095)
        self.set("shutdown", 0x34)  # e-manual default: overheating, electrical shock, overload
        self.set("goal_position", position)
        self.publish_state()

    @property
    def dxl_id(self) -> int:
        return self.get("id")

    def get(self, name: str) -> int:
        f = ct.field(name)
        value = int.from_bytes(self.table[f.address : f.address + f.size], "little")
        return ct.signed(value, f.size) if ct.is_signed(name) else value

    def set(self, name: str, value: int) -> None:
        f = ct.field(name)
        self.table[f.address : f.address + f.size] = (
            int(value) & ((1 << 8 * f.size) - 1)
        ).to_bytes(f.size, "little")

    def alert(self) -> int:
        return p2.ERR_ALERT if self.get("hardware_error_status") else 0

    def check_write(self, address: int, data: bytes) -> int:
        """0 when a real servo would accept this write, else its status error code."""
        for name, (a, size, writable, eeprom) in ct.FIELDS.items():
            if address < a + size and a < address + len(data):
                if not writable or not ct.has_field(self.model, name):
                    return p2.ERR_ACCESS
                if eeprom and self.get("torque_enable"):
                    return p2.ERR_ACCESS  # EEPROM is locked while torque is on
                if name == "operating_mode" and self.model == ct.XL430_W250:
                    mode = data[a - address] if a >= address else None
                    if mode not in (1, 3, 4, 16):
                        return p2.ERR_DATA_RANGE
        if address + len(data) > ct.FIELDS["present_temperature"][0] + 1:
            return p2.ERR_ACCESS
        return 0

    def write(self, address: int, data: bytes) -> None:
        if self.get("hardware_error_status") and address == ct.field("torque_enable").address:
            if data and data[0]:
                return  # a servo in shutdown keeps torque off until rebooted
        self.table[address : address + len(data)] = data

    def step(self, dt: float) -> None:
        torque = self.get("torque_enable") and not self.get("hardware_error_status")
        if not torque:
            self.velocity = 0.0
            if self.external_position is not None:
                self.position = self.external_position
        else:
            goal = float(self.get("goal_position"))
            vmax = (self.get("profile_velocity") or self.get("velocity_limit")) * ct.VELOCITY_UNIT
            vmax_ticks = vmax * ct.TICKS_PER_REV / (2.0 * 3.141592653589793)
            v = max(-vmax_ticks, min(vmax_ticks, (goal - self.position) / TIME_CONSTANT))
            new = self.position + v * dt
            if self.external_position is not None:  # the simulated arm moves this servo
                new = self.external_position
            elif self.obstacle is not None and new < self.obstacle:
                new = (
                    max(min(self.position, new), self.obstacle)
                    if self.position >= self.obstacle
                    else new
                )
            self.velocity = (new - self.position) / dt if dt > 0 else 0.0
            if self.external_position is not None:
                self.velocity = self.external_velocity
            self.position = new
            load = abs(goal - self.position) * LOAD_PER_TICK
            limit = self.get("pwm_limit") / ct.XL430_PWM_LIMIT_MAX
            self.load = min(load, limit)
            # at the full output the motor can give, held against something: overload
            self.saturated_for = self.saturated_for + dt if load >= 1.0 and limit >= 0.99 else 0.0
            if self.saturated_for > OVERLOAD_AFTER:
                self.inject_hardware_error(5)
        self.publish_state()

    def publish_state(self) -> None:
        self.set("present_position", int(round(self.position)))
        self.set("present_velocity", int(round(self.velocity * 60.0 / ct.TICKS_PER_REV / 0.229)))
        load = self.load if self.get("torque_enable") else 0.0
        if self.model == ct.XL430_W250:
            self.set("present_current", int(round(load / ct.XL430_LOAD_UNIT)))
        else:
            self.set("present_current", int(round(load * 1.0 / ct.XM430_CURRENT_UNIT)))
        goal = self.get("goal_position")
        self.set("moving", int(abs(goal - self.position) > 10 and self.get("torque_enable")))

    def inject_hardware_error(self, bit: int) -> None:
        self.set("hardware_error_status", self.get("hardware_error_status") | (1 << bit))
        if self.get("shutdown") & (1 << bit):
            self.set("torque_enable", 0)

    def reboot(self) -> None:
        self.set("hardware_error_status", 0)
        self.set("torque_enable", 0)
        self.saturated_for = 0.0


class ServoBusEmulator(PtyDevice):
    """Servos on one bus behind a pty; `device` is the path a driver opens."""

    def __init__(self, servos: List[EmulatedServo], link: Optional[str] = None):
        self.servos: Dict[int, EmulatedServo] = {s.dxl_id: s for s in servos}
        # the clock the servos move on: the wall clock, or the simulator's (the emulated rig,
        # so a servo moves exactly as far as the simulated time the driver stamps it with)
        self.clock = time.monotonic
        self.packets = 0
        self.crc_errors = 0
        super().__init__(link)

    def send_garbage(self, data: bytes) -> None:
        os.write(self.master, data)

    # ------------------------------------------------------------------ the bus
    def _run(self) -> None:
        buffer = bytearray()
        last = self.clock()
        while not self._stop.is_set():
            try:
                ready, _, _ = select.select([self.master], [], [], 0.002)
                if ready:
                    buffer += os.read(self.master, 4096)
            except OSError:
                return
            now = self.clock()
            with self.lock:
                for s in self.servos.values():
                    s.step(max(0.0, min(now - last, MAX_STEP)))
                last = now
                while True:
                    packet, need_more = p2.take_packet(buffer)
                    if packet is None:
                        if need_more:
                            break
                        continue
                    reply = self._handle(packet)
                    if reply:
                        try:
                            os.write(self.master, reply)
                        except OSError:
                            return

    def _handle(self, packet: p2.Packet) -> bytes:
        self.packets += 1
        target = self.servos.get(packet.dxl_id)
        if not packet.crc_ok:
            self.crc_errors += 1
            return p2.status(packet.dxl_id, p2.ERR_CRC) if target else b""
        inst, params = packet.instruction, packet.params
        if inst == p2.SYNC_WRITE:
            return self._sync_write(params)
        if inst == p2.SYNC_READ:
            return self._sync_read(params)
        if packet.dxl_id == p2.BROADCAST_ID and inst == p2.PING:
            return b"".join(self._ping(s) for s in self.servos.values())
        shadows = [s for s in self.servos.values() if s.get("secondary_id") == packet.dxl_id]
        if target is None:
            if inst == p2.WRITE:
                for s in shadows:  # a shadow acts on its primary's writes but never answers
                    if len(params) > 2 and not s.check_write(
                        params[0] | params[1] << 8, params[2:]
                    ):
                        s.write(params[0] | params[1] << 8, params[2:])
            return b""
        if inst == p2.PING:
            return self._ping(target)
        if inst == p2.READ:
            if len(params) != 4:
                return p2.status(target.dxl_id, p2.ERR_DATA_LENGTH | target.alert())
            address, length = struct.unpack("<HH", params)
            if address + length > len(target.table):
                return p2.status(target.dxl_id, p2.ERR_ACCESS | target.alert())
            data = bytes(target.table[address : address + length])
            return p2.status(target.dxl_id, target.alert(), data)
        if inst == p2.WRITE:
            if len(params) < 3:
                return p2.status(target.dxl_id, p2.ERR_DATA_LENGTH | target.alert())
            address, data = params[0] | params[1] << 8, params[2:]
            error = target.check_write(address, data)
            if not error:
                target.write(address, data)
                for s in shadows:
                    if not s.check_write(address, data):
                        s.write(address, data)
            return p2.status(target.dxl_id, error | target.alert())
        if inst == p2.REBOOT:
            target.reboot()
            return p2.status(target.dxl_id, 0)
        return p2.status(target.dxl_id, p2.ERR_INSTRUCTION | target.alert())

    @staticmethod
    def _ping(s: EmulatedServo) -> bytes:
        return p2.status(s.dxl_id, s.alert(), struct.pack("<HB", s.model, 46))

    def _sync_write(self, params: bytes) -> bytes:
        if len(params) < 4:
            return b""
        address, length = struct.unpack_from("<HH", params)
        body = params[4:]
        step = 1 + length
        for i in range(0, len(body) - step + 1, step):
            dxl_id, data = body[i], body[i + 1 : i + step]
            for s in self.servos.values():
                if s.dxl_id == dxl_id or s.get("secondary_id") == dxl_id:
                    if not s.check_write(address, data):
                        s.write(address, data)
        return b""

    def _sync_read(self, params: bytes) -> bytes:
        if len(params) < 5:
            return b""
        address, length = struct.unpack_from("<HH", params)
        out = b""
        for dxl_id in params[4:]:
            s = self.servos.get(dxl_id)
            if s is None:
                break  # a missing servo: the ones after it never get their turn
            data = bytes(s.table[address : address + length])
            out += p2.status(dxl_id, s.alert(), data)
        return out


def wx250s_servos(ids=(1, 2, 3, 4, 5, 6, 7, 8, 9), ticks=None) -> List[EmulatedServo]:
    """The wx250s's nine servos (facts §1.3): XM430-W350 on IDs 1-7, XL430-W250 on 8 and 9."""
    ticks = ticks or {}
    return [
        EmulatedServo(i, ct.XL430_W250 if n >= 7 else ct.XM430_W350, ticks.get(i, ct.CENTRE_TICK))
        for n, i in enumerate(ids)
    ]
