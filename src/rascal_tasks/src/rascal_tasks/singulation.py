"""Singulation: a sherd the gripper failed on twice at the same spot of a heap is pushed once,
away from its neighbours and never off the mat, and the area surveyed again; only a sherd that
still cannot be picked after that is left for a person. No ROS here.

A push: fingers closed, the gripper turned so both fingers meet the sherd, down beside it at
the height its grasp closes at (its own mid-height above what it rests on: a sherd lying on
another is pushed off it), then along the line through its centre.
"""

import math
from typing import List, Optional, Tuple

from rascal_tasks.failures import about_this_sherd
from rascal_tasks.rig import Observation, RigError

PUSH = 0.04  # [m] how far the sherd's centre is pushed: most of a neighbour's width
LEAD = 0.015  # [m] the fingers start this far outside its outline
EDGE = 0.01  # [m] a pushed sherd keeps its outline this far inside the mat
DIRECTIONS = 16
MAX_PUSHES = 20  # per batch: a heap that needs more is a person's job


def push_direction(
    o: Observation, others: List[Observation], area
) -> Optional[Tuple[float, float]]:
    """The unit direction (dx, dy) to push `o` in: where it ends farthest from its neighbours'
    outlines, its own outline still `EDGE` inside `area` (a config.Rect); None if no push
    keeps it on the mat."""
    best, best_room = None, -math.inf
    half = o.length / 2 + EDGE
    for k in range(DIRECTIONS):
        a = 2 * math.pi * k / DIRECTIONS
        d = (math.cos(a), math.sin(a))
        end = (o.x + PUSH * d[0], o.y + PUSH * d[1])
        if any(
            abs(end[i] - area.center[i]) > area.size[i] / 2 - half for i in (0, 1)
        ):  # would leave the mat
            continue
        room = min(
            (math.hypot(end[0] - p.x, end[1] - p.y) - p.length / 2 for p in others if p is not o),
            default=1.0,
        )
        if room > best_room + 1e-9:
            best, best_room = d, room
    return best


def push(b, o: Observation, d: Tuple[float, float]) -> bool:
    """Push `o` along `d` (see the module). False when the arm refuses a move of it (the
    sherd is then left for a person); other rig errors stop the batch as anywhere."""
    yaw = math.atan2(d[1], d[0])  # the fingers close across the push: both touch the sherd
    back = o.length / 2 + LEAD
    start = (o.x - back * d[0], o.y - back * d[1])
    end = (o.x + PUSH * d[0], o.y + PUSH * d[1])
    z = o.grasp_z
    with b.phase("grasping"):
        b.rig.gripper.close()
    at = None  # where the fingers went down (lifted from there, whatever happens)
    try:
        b.move_down(*start, z + b.config["arm"]["approach_offset"], yaw)
        at = start
        b.move_down(*start, z, yaw, linear=True)
        b.move_down(*end, z, yaw, linear=True)
        at = end
    except RigError as e:
        if not about_this_sherd(e, sherd_target=True):
            raise
        b.event(None, "push_refused", "sherd at (%.3f, %.3f) m: %s" % (o.x, o.y, e))
        return False
    finally:
        if at is not None:
            b.move_down(*at, b.travel_z(), yaw, linear=True)
    return True
