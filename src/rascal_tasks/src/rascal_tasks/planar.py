"""Rigid motions of the table's plane (base_link x, y; yaw about +z, counter-clockwise seen
from above): the one place the turn of a point is written, for stations, their markers, their
written places and the archival camera's support. No ROS in here."""

import math
from typing import Tuple

Point = Tuple[float, float]


def turned(v, yaw: float) -> Point:
    """The vector v = (x, y) turned by yaw [rad]."""
    c, s = math.cos(yaw), math.sin(yaw)
    return c * v[0] - s * v[1], s * v[0] + c * v[1]


def placed(origin, yaw: float, local) -> Point:
    """A point of the frame at `origin` turned by `yaw`, in the table's frame."""
    x, y = turned(local, yaw)
    return origin[0] + x, origin[1] + y


def local_of(origin, yaw: float, p) -> Point:
    """The table point p in the frame at `origin` turned by `yaw` (placed's inverse)."""
    return turned((p[0] - origin[0], p[1] - origin[1]), -yaw)
