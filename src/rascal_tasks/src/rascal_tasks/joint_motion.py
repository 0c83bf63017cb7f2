"""How long a joint move takes at the servos' limits (facts/timing.md: the simulator enforces
these; the servos' Velocity_Limit and the arm's MoveIt acceleration limit). No ROS in here."""

import math
from typing import Sequence

MAX_SPEED = math.pi  # [rad/s]
MAX_ACCELERATION = 5.0  # [rad/s^2]


def trapezoid(distance: float, speed: float = MAX_SPEED, acc: float = MAX_ACCELERATION) -> float:
    """Least time to travel `distance` [rad] from rest to rest within `speed` and `acc`."""
    d = abs(distance)
    if d <= speed * speed / acc:
        return 2.0 * math.sqrt(d / acc)
    return d / speed + speed / acc


def move_time(q0: Sequence[float], q1: Sequence[float]) -> float:
    """A joint move synchronised to its slowest joint."""
    return max(trapezoid(b - a) for a, b in zip(q0, q1, strict=True))
