"""The wrist's turns along a sherd's way through the stations. No ROS in here.

For a top-down pose the arm's IK gives wrist_rotate = waist - yaw, with the waist pointing at
(x, y); a joint move takes as long as its slowest joint's trapezoid (pi rad/s, 5 rad/s^2), so a
turn of the wrist costs nothing while the waist turns as far, and up to 1.3 s where the arm
barely moves (the archival camera's standby beside its spot). Measured with bench/throughput
(seed 10): a sherd's moves took 11.0 s, of which the turn to the standby and back 2.6 s and a
4.4 rad turn from one sherd's yaw to the next's 0.8 s more than the waist's own move.

Two choices remove most of it:
- the fingers are alike, so a grasp at yaw g is the grasp at g + pi: the pickup's grasp yaw is
  the one of the two whose turns along the sherd's way take the least time (`route_yaw`);
- the sherd is set down under the archival camera turned as the standby needs (`standby_yaw`:
  the wrist camera facing away from the camera's view), so the trip to the standby and back
  needs no turn; the turn is made on the way from the scale, where the waist turns too.
"""

import math
from typing import Sequence, Tuple

from rascal_tasks.joint_motion import trapezoid


def wrist_angle(x: float, y: float, yaw: float) -> float:
    """wrist_rotate [rad] of a top-down pose at (x, y) turned to `yaw`, in [-pi, pi)."""
    return math.remainder(math.atan2(y, x) - yaw, 2.0 * math.pi)


def same_grasp_yaws(yaw: float) -> Tuple[float, float]:
    """`yaw` and the same grasp turned by pi (the fingers are alike), in [-pi, pi)."""
    return yaw, math.remainder(yaw + math.pi, 2.0 * math.pi)


def leg_time(a: Tuple[float, float, float], b: Tuple[float, float, float]) -> float:
    """Rough seconds of a move between two top-down poses (x, y, yaw): the slower of the
    waist's and the wrist's trapezoids (the shoulder and elbow move about alike on every
    route, so they do not decide between yaws)."""
    waist = math.atan2(b[1], b[0]) - math.atan2(a[1], a[0])
    wrist = wrist_angle(*b) - wrist_angle(*a)
    return max(trapezoid(waist), trapezoid(wrist))


def standby_yaw(config, station) -> float:
    """The yaw at the archival camera's standby: the wrist camera (mounted ahead of the
    gripper) faces away from the camera's view, like the rest of the arm."""
    sx, sy = config["arm"]["standby"]
    cx, cy = station.area.center
    return math.atan2(sy - cy, sx - cx)


def station_yaw(config, station, held_yaw: float) -> float:
    """The gripper's yaw at a station: the taught one (`rascal teach`); under the archival
    camera (also on a scale under it, `over_scale`) the standby's; elsewhere as the sherd is
    held (no wrist turn on the way)."""
    if station.place_yaw is not None:
        return station.place_yaw
    if station.type == "archival_camera":
        return standby_yaw(config, station)
    if station.type == "scale":
        camera = next(s for s in config.stations.values() if s.type == "archival_camera")
        if camera.over_scale:
            return standby_yaw(config, camera)
    return held_yaw


def route_yaw(config, start, grasp_xy, grasp_yaw: float, stations: Sequence) -> float:
    """Of `grasp_yaw` and the same grasp turned by pi, the one whose moves from `start` (the
    arm's last pose (x, y, yaw), None if unknown) through `stations` (config Stations, in the
    order the sherd visits them) take the least time. The wrist cannot pass its +-pi stop, so
    a turn across it goes the long way round: that is counted."""
    best, best_time = grasp_yaw, math.inf
    for g in same_grasp_yaws(grasp_yaw):
        here = (grasp_xy[0], grasp_xy[1], g)
        total = leg_time(start, here) if start is not None else 0.0
        for st in stations:
            there = (st.place_at[0], st.place_at[1], station_yaw(config, st, here[2]))
            total += leg_time(here, there)
            here = there
        if total < best_time - 1e-9:
            best, best_time = g, total
    return best
