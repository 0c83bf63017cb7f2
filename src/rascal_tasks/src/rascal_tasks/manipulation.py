"""Grasping: how wide to open, and a grasp with its retries. Used by every state that picks a
sherd up (pickup, repick, recovery, resume). No ROS in here.
"""

import contextlib
import dataclasses
import math
from typing import Optional, Tuple

from rascal_workcell import urdf_model

from rascal_tasks.failures import SherdFailure, about_this_sherd
from rascal_tasks.rig import Observation, RigError
from rascal_tasks.selection import STACKED, THICK_WALL, apart_from_left, covered
from rascal_tasks.survey import survey_at, taken_off_the_mat
from rascal_tasks.wrist import route_yaw

# Opening between the stock fingertips, from the URDF's finger limits (facts §1.4: 30..74 mm);
# pads fitted inside the fingers take two pads off both (openings).
MIN_OPENING, MAX_OPENING = urdf_model.opening_limits()
# [m] how far the fingertips reach below ee_gripper_link pointing down (the URDF's finger box)
FINGERTIP_OFFSET = urdf_model.fingertip_offset()
# [m] the thinnest sherd wall (fine ware, facts/sherds_and_colour.md): a sherd lying on a
# station is at least this high where the fingers close
MIN_WALL = 0.003
# [m] fingers this much short of the opening they were sent to stopped on something: the
# controller calls a finger within 0.5 mm of its target there (GripperMonitor::kFingerReached)
RELEASE_SLACK = 0.002


def openings(config) -> Tuple[float, float]:
    """(closed, fully open) opening between the fingers of this rig [m]: the stock limits less
    two arm.gripper.fingertip_pads."""
    return urdf_model.opening_limits(pads=config["arm"]["gripper"]["fingertip_pads"])


def holdable(config, chord: float) -> bool:
    """Whether the fingers hold a sherd across a chord of `chord` [m]: closed on it, they stop
    more than arm.gripper.held_margin wider than closed, what the controller calls holding (the
    detector's grasp planner keeps 1 mm more in hand when it chooses a chord)."""
    closed = openings(config)[0]
    return chord > closed + config["arm"]["gripper"]["held_margin"]


def opening_for(width: float, margin: float, limits=(MIN_OPENING, MAX_OPENING)) -> float:
    """`width` + `margin` within `limits` (openings(config); the stock fingers' by default)."""
    lo, hi = limits
    return min(hi, max(lo, width + margin))


def release(b, width: float) -> float:
    """Let go of what the fingers hold: open to `width` (the sherd's, seen from above) plus the
    grasp margin, and never less than the margin wider than the fingers hold it now. A grasp
    across a longer chord than the width seen (turned to clear neighbours, or a sherd partly
    hidden in a heap) holds it wider, and an open narrower than that presses the fingers
    inwards and lets nothing go. Checked: fingers that stopped short open fully; if they stop
    short again, RigError (the sherd is not where the batch would record it). Returns the
    width to pick it up by again: `width`, or the opening the fingers held it at when wider
    (fingers that had closed on nothing say nothing of the sherd)."""
    margin = b.config["arm"]["grasp_margin"]
    lo, hi = limits = openings(b.config)
    held = b.rig.gripper.width()
    target = opening_for(max(width, held), margin, limits)
    again = max(width, held) if held > lo + RELEASE_SLACK else width
    b.rig.gripper.open(target)
    if b.rig.gripper.width() >= target - RELEASE_SLACK:
        return again
    b.rig.gripper.open()
    got = b.rig.gripper.width()
    if got < hi - RELEASE_SLACK:
        raise RigError(
            "gripper",
            "NOT_RELEASED",
            "the fingers stopped at %.1f mm opening fully to let go of the sherd (sent to "
            "%.1f mm): something holds them; free the fingers, then re-run"
            % (got * 1000, hi * 1000),
        )
    return again


@contextlib.contextmanager
def _aiming_at(o: Observation, station):
    """Moves to a target computed from the detection `o`: a refusal is the sherd's failure."""
    try:
        yield
    except RigError as e:
        if about_this_sherd(e, sherd_target=True):
            raise SherdFailure(
                "the arm refused its grasp at (%.3f, %.3f) m on the %s: %s"
                % (o.grasp_x, o.grasp_y, station.name, e),
                station,
                o,
            ) from e
        raise


def approach(b, o: Observation) -> None:
    """To the pose above `o` where a grasp's descent starts, the fingers opening to the planned
    width (it includes the grasp margin) on the way: the stroke is done long before the arm
    is low, and the controller's collision check takes them fully open anyway."""
    above = o.grasp_z + b.config["arm"]["approach_offset"]
    b.rig.gripper.open_while(
        opening_for(o.grasp_width, 0.0, openings(b.config)),
        lambda: b.move_down(o.grasp_x, o.grasp_y, above, o.grasp_yaw),
    )


def regrasp_z(b, station) -> float:
    """ee_gripper_link height that picks up again a sherd set down on `station` when the height
    it was picked up at closed on nothing (grasp_where_set_down): the fingertips
    perception.grasp_tip_clearance above it, as low as any grasp closes. Set down, a sherd lies
    on the station itself, at least as high as the thinnest wall (3 mm,
    facts/sherds_and_colour.md) where the fingers close."""
    tip = b.config["perception"]["grasp_tip_clearance"]
    return station.surface_z + tip + FINGERTIP_OFFSET


def rider_z(station, o: Observation) -> float:
    """ee_gripper_link height that closes the fingertips MIN_WALL below the lowest point of the
    top of `o` lying on `station` (its measured wall): on the edge of whatever lies on top,
    which is at least that thick, and above anything under it (two seen as one outline: heap_20
    seeds 59, 64); a single sherd is held by its upper edge. What stays on a scale's pan is
    weighed out of the row by difference (stations.ScaleStation._left_on_pan)."""
    return station.surface_z + o.thickness - MIN_WALL + FINGERTIP_OFFSET


def maybe_two(s, o: Observation) -> bool:
    """Whether `o`, the sherd in progress `s` as it lies on a station (seen there, or as picked
    from the mat's surface), may be two sherds seen as one: its mass doubted the wall picked
    (SherdRecord.wall_doubted), or its wall is thicker than THICK_WALL."""
    return o.thickness > 0.0 and (s.wall_doubted or o.thickness > THICK_WALL)


def placed_observation(b, s, station) -> Observation:
    """Where the sherd in progress `s` was set down on `station`, as it was held: the blind
    grasp that picks it up again (`station_states.repick`). At the height it was picked up at
    (grasp_where_set_down); but one taken off another sherd with nothing on it or stacked
    within reach of it (not SherdRecord.among_others: nothing can have come up with it) lies
    lower on the station than it was grasped by what it lay on, and is taken up low at once
    (regrasp_z): that first close met nothing in 7 of 8 misses of a heap of 20 (heap_20 seed
    60), a close and a reopen each. One seen alone there (the scale's look,
    SherdRecord.measured_alone) is taken up by that detection's grasp, as it lies (its wrist
    turned as the gripper is: the fingers are alike), not where and as it was set down (heap_20
    seed 60: 7 of the 8 blind closes on the pan that met nothing came after a look that saw
    the sherd alone there). High on its edge where it may be two seen as one (maybe_two,
    rider_z)."""
    high = taken_up_high(s)
    if s.seen_set_down is not None:
        o = s.seen_set_down
        back = (o.grasp_yaw, o.grasp_yaw + math.pi)
        yaw = min(back, key=lambda g: abs(math.remainder(g - s.grasp_yaw, 2.0 * math.pi)))
        o = dataclasses.replace(o, grasp_yaw=math.remainder(yaw, 2.0 * math.pi))
        if high is not None:
            o = dataclasses.replace(o, grasp_z=max(o.grasp_z, rider_z(station, high)))
        return o
    x, y = s.last_xy
    z = station.surface_z + s.grasp_height
    if lifted_off_another(s):
        z = min(z, regrasp_z(b, station))
    elif high is not None:
        z = max(z, rider_z(station, high))
    return Observation(
        x,
        y,
        s.grasp_yaw,
        s.observation.length,
        s.width,
        0.0,
        x,
        y,
        z,
        s.grasp_yaw,
        opening_for(s.width, b.config["arm"]["grasp_margin"], openings(b.config)),
    )


def taken_up_high(s) -> Optional[Observation]:
    """The detection of the sherd in progress `s` as it lies on a station (the look's there, or
    the pickup's where it lay on the mat itself: its wall the same) when that says it may be
    two seen as one (maybe_two), to be taken up high on its edge (rider_z); else None."""
    if s.seen_set_down is not None:
        o = s.seen_set_down
    elif s.observation is not None and not lifted_off_another(s):
        o = s.observation if s.observation.support <= STACKED else None
    else:
        o = None
    return o if o is not None and maybe_two(s, o) else None


def lifted_off_another(s) -> bool:
    """Whether the sherd in progress `s` was picked from atop another one, alone (its pickup's
    detection lay on a support, and nothing could have come up with it: among_others)."""
    o = s.observation
    return o is not None and o.support > STACKED and not s.among_others


def grasp_where_set_down(b, s, station) -> bool:
    """The grasp that picks up again the sherd in progress `s` where it was set down on
    `station` (placed_observation: by the look's grasp where one saw it alone there, low at
    once for one lifted_off_another, else blind): at the height it was picked up at, so that
    a sherd that rode on it from a heap is taken off it and the one under it, left on the pan,
    is weighed out of the row by difference. Closing on nothing there (it lay tilted on the
    heap and lies lower now: 18-24 mm seen there, 6-11 mm on the pan, heap seed 36), the
    fingers go down and close again low over the station (regrasp_z), with no look between;
    later stations then grasp it there at once. A look and a second grasp after the miss cost
    ~5 s a station."""
    o = placed_observation(b, s, station)
    if grasp(b, o, station, lift_on_miss=False):
        s.taken_up_at(o.grasp_z, station)  # (low already, for one lifted_off_another)
        if taken_up_high(s) is not None:  # what it lay on may stay (ScaleStation.while_away)
            s.parted_on = station.name
        return True
    low = regrasp_z(b, station)
    if low > o.grasp_z - MIN_WALL / 2:  # as low already: a miss there is a miss
        b.move_down(o.grasp_x, o.grasp_y, b.travel_z(), o.grasp_yaw, linear=True)
        return False
    # the fingers opened again where they closed: straight down from there, not up to travel
    # height and down again (~1 s a miss; 12 in a heap of 20, seed 39)
    o = dataclasses.replace(o, grasp_z=low)
    b.move_down(o.grasp_x, o.grasp_y, low, o.grasp_yaw, linear=True)
    b.poised = o
    if not grasp(b, o, station):
        return False
    s.taken_up_at(low, station)
    return True


def reach(b, o: Observation) -> None:
    """Open on the way to the approach pose (`approach`), descend: the fingers stand open
    around the sherd, ready to close (`b.poised`)."""
    approach(b, o)
    b.move_down(o.grasp_x, o.grasp_y, o.grasp_z, o.grasp_yaw, linear=True)
    b.poised = o


def grasp(b, o: Observation, station, lift_on_miss=True, taken_for=None) -> bool:
    """Reach for `o` (unless the arm is poised there already: a station brought it while it
    waited), close, lift. The lift is a move of its own, checked at the top: a sherd that slips
    out on the way up falls back where it lay (blended into the carry, it would fall on the
    way, off any station: bench/throughput, session 21). Closed on nothing, the fingers open
    again, and (not `lift_on_miss`) stay where they are, for the caller's next grasp below.
    A sherd lifted off the pickup mat is noted as gone from where the last survey saw it
    (survey.taken_off_the_mat; `taken_for`: the survey's detection it was grasped for).
    Raises SherdFailure when the arm refuses the approach or the descent (failures.py)."""
    if b.poised != o:
        with _aiming_at(o, station):
            reach(b, o)
    b.poised = None
    with b.phase("grasping"):
        held = b.rig.gripper.close().holding
    if held or lift_on_miss:
        b.move_down(o.grasp_x, o.grasp_y, b.travel_z(), o.grasp_yaw, linear=True)
    if station is b.pickup and held:
        # it left the mat, for the edge check; one that slips out now is the slip check's
        taken_off_the_mat(b, o, taken_for)
    if held and not b.rig.gripper.holding():
        held = False  # slipped out while lifting (survey.account_for_slips looks for it)
        b.lift_slips.append(o)
    elif not held:  # said with what it was aimed at: a heap's misses are traced from these
        b.log(
            "grasp at (%.3f, %.3f) m on the %s: closed on nothing (ee_gripper_link %.1f mm above "
            "the surface; the sherd's top %.1f mm, what it lies on %.1f mm; turned %.0f deg, "
            "opened %.1f mm)"
            % (
                o.grasp_x,
                o.grasp_y,
                station.name,
                (o.grasp_z - station.surface_z) * 1000,
                o.height * 1000,
                o.support * 1000,
                math.degrees(o.grasp_turn),
                o.grasp_width * 1000,
            )
        )
        with b.phase("grasping"):
            b.rig.gripper.open(opening_for(o.grasp_width, 0.0, openings(b.config)))
    return held


def grasp_retrying(b, o: Observation, station, like=None, taken_for=None):
    """Grasp `o` at `station`; after a miss, detect again around it and grasp the detection
    nearest it (or least `like`), up to recovery.max_grasp_attempts in all (`taken_for`: as
    grasp's). On the pickup mat a retry takes what the pick order would: nothing covered by
    another (that waits for a survey, which offers the sherds lying on it first) and nothing
    left for a person (heap_25_offcentre seed 106: after a miss on a tilted sherd, the retry
    took a neighbour 34 % covered, its grasp along its length, and the fingers came down on
    two more, one of which pushed a third off the mat). Returns (the last observation tried,
    grasps made, whether it is held)."""
    rec = b.config["recovery"]
    like = like or (lambda c, last: c.distance_to(last.x, last.y))
    for attempt in range(rec["max_grasp_attempts"]):
        if station is b.pickup:  # the grasp turned by pi is the same grasp
            route = b.route()
            yaw = route_yaw(b.config, b.last_pose, (o.grasp_x, o.grasp_y), o.grasp_yaw, route)
            if yaw != o.grasp_yaw:
                o = dataclasses.replace(o, grasp_yaw=yaw)
        if grasp(b, o, station, taken_for=taken_for):
            return o, attempt + 1, True
        if attempt + 1 == rec["max_grasp_attempts"]:
            break
        seen = survey_at(b, station, o.x, o.y)
        if station is b.pickup:
            seen = [c for c in apart_from_left(seen, b.unpickable) if not covered(c)]
        near = [c for c in seen if c.distance_to(o.x, o.y) < rec["search_radius"]]
        if not near:
            break
        o = min(near, key=lambda c, last=o: like(c, last))
    return o, attempt + 1, False
