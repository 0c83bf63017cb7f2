"""Control-table fields of the two servo models of the wx250s, and their units.

Addresses, sizes and units: ROBOTIS e-manual, XM430-W350 and XL430-W250 control tables
(Protocol 2.0; emanual.robotis.com/docs/en/dxl/x/xm430-w350/ and .../xl430-w250/). Only the
fields the driver and the emulator use are listed. The XL430-W250 has no current sensing: no
Current Limit (38) or Goal Current (102), Present Load (126, 0.1 % units) instead of Present
Current, and no current-based position mode (its operating modes are velocity, position,
extended position and PWM). No ROS here.
"""

import math
from dataclasses import dataclass
from typing import Dict, Tuple

XM430_W350 = 1020  # Model Number (address 0) of the XM430-W350
XL430_W250 = 1060  # Model Number of the XL430-W250

# name: (address, size in bytes, writable, EEPROM)
FIELDS: Dict[str, Tuple[int, int, bool, bool]] = {
    "model_number": (0, 2, False, True),
    "firmware_version": (6, 1, False, True),
    "id": (7, 1, True, True),
    "baud_rate": (8, 1, True, True),
    "drive_mode": (10, 1, True, True),
    "operating_mode": (11, 1, True, True),
    "secondary_id": (12, 1, True, True),
    "pwm_limit": (36, 2, True, True),
    "current_limit": (38, 2, True, True),  # XM only
    "velocity_limit": (44, 4, True, True),
    "max_position_limit": (48, 4, True, True),
    "min_position_limit": (52, 4, True, True),
    "shutdown": (63, 1, True, True),
    "torque_enable": (64, 1, True, False),
    "hardware_error_status": (70, 1, False, False),
    "goal_pwm": (100, 2, True, False),
    "goal_current": (102, 2, True, False),  # XM only
    "profile_acceleration": (108, 4, True, False),
    "profile_velocity": (112, 4, True, False),
    "goal_position": (116, 4, True, False),
    "moving": (122, 1, False, False),
    "present_current": (126, 2, False, False),  # XL430: Present Load
    "present_velocity": (128, 4, False, False),
    "present_position": (132, 4, False, False),
    "present_temperature": (146, 1, False, False),
}
XM_ONLY = ("current_limit", "goal_current")

# Operating Mode values
POSITION_MODE = 3
CURRENT_BASED_POSITION_MODE = 5  # XM430 only

# Hardware Error Status bits (address 70)
HARDWARE_ERRORS = {
    0: "input voltage error",
    2: "overheating",
    3: "motor encoder error",
    4: "electrical shock",
    5: "overload",
}

# Units (e-manual)
TICKS_PER_REV = 4096  # 0.088 deg per tick; 2048 = 0 rad (facts §1.3)
CENTRE_TICK = 2048
VELOCITY_UNIT = 0.229 * 2.0 * math.pi / 60.0  # rad/s per unit (0.229 rpm)
ACCELERATION_UNIT = 214.577 * 2.0 * math.pi / 3600.0  # rad/s^2 per unit (214.577 rev/min^2)
XM430_CURRENT_UNIT = 2.69e-3  # A per unit
XM430_CURRENT_LIMIT_MAX = 1193  # units (3.21 A)
XL430_PWM_LIMIT_MAX = 885  # units (100 %)
XL430_LOAD_UNIT = 0.001  # fraction of the maximum torque per unit (0.1 %)

_PRESENT_SIGNED = ("present_current", "present_velocity", "present_position")


@dataclass(frozen=True)
class Field:
    address: int
    size: int


def field(name: str) -> Field:
    a, s, _, _ = FIELDS[name]
    return Field(a, s)


def has_field(model: int, name: str) -> bool:
    return not (model == XL430_W250 and name in XM_ONLY)


def ticks_to_rad(ticks: int) -> float:
    return (ticks - CENTRE_TICK) * 2.0 * math.pi / TICKS_PER_REV


def rad_to_ticks(rad: float) -> int:
    return int(round(rad * TICKS_PER_REV / (2.0 * math.pi))) + CENTRE_TICK


def signed(value: int, size: int) -> int:
    bits = 8 * size
    return value - (1 << bits) if value & (1 << (bits - 1)) else value


def is_signed(name: str) -> bool:
    return name in _PRESENT_SIGNED or name in ("goal_current", "goal_pwm")


def describe_hardware_error(status: int) -> str:
    names = [text for bit, text in sorted(HARDWARE_ERRORS.items()) if status & (1 << bit)]
    return ", ".join(names) if names else "unknown hardware error 0x%02x" % status
