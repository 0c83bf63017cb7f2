"""The gripper's horn-and-arm linkage: servo angle <-> finger position.

Constants and the forward formula: facts widowx250_d435.md §1.4 (MANIP wx250s.yaml
`horn_radius: 0.014`, `arm_length: 0.024`; CORE robot_convert_angular_position_to_linear):
pos = r sin(theta) + sqrt(L^2 - (r cos(theta))^2). The inverse is solved numerically on the
monotonic branch, so command and feedback use one formula. No ROS here.
"""

import math

HORN_RADIUS = 0.014  # [m] facts §1.4
ARM_LENGTH = 0.024  # [m] facts §1.4
FINGER_MIN, FINGER_MAX = 0.015, 0.037  # [m] the URDF's left_finger limits (facts §1.1)


def finger_from_angle(theta: float) -> float:
    c = HORN_RADIUS * math.cos(theta)
    return HORN_RADIUS * math.sin(theta) + math.sqrt(ARM_LENGTH**2 - c * c)


def finger_rate(theta: float, theta_dot: float) -> float:
    """d(finger)/dt [m/s] for a horn turning at theta_dot [rad/s]."""
    c = HORN_RADIUS * math.cos(theta)
    d = HORN_RADIUS * math.cos(theta) + (HORN_RADIUS * c * math.sin(theta)) / math.sqrt(
        ARM_LENGTH**2 - c * c
    )
    return d * theta_dot


def angle_from_finger(finger: float) -> float:
    """The horn angle [rad] that puts the left finger at `finger` [m] (clamped to the limits)."""
    finger = min(max(finger, FINGER_MIN), FINGER_MAX)
    lo, hi = -math.pi / 2, math.pi / 2  # finger_from_angle rises monotonically here
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if finger_from_angle(mid) < finger:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
