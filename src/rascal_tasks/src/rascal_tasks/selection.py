"""Which sherd is picked next: the one selection policy, over the merged survey of the pickup
area (`perception.selection_policy`); and whether two looks may be one sherd. No ROS in here.
"""

import math
from typing import List

from rascal_tasks.rig import Observation

# A sherd with more of its outline than this under another one lying on it is not picked while
# a free one is left: lifting it would drag or lift the one on top (a tipped-out bag). Its
# measurement is of the part that shows; it is picked from a later survey, once uncovered.
COVERED = 0.05
# A grasp turned further than this off closing across the sherd's minor axis (perception turns
# it where a neighbour blocks a finger) closes on a longer chord nearer the narrow ends, and
# slips more: such a sherd is taken after the others of its kind, by when its neighbours may be
# gone (perception's candidates: 0, 15, 30, 45 and 90 degrees).
TURNED = math.radians(20.0)
# A grasp moved further than this (a fraction of the half-length) along the sherd off its centre
# holds it by a lever as long: taken after the others of its kind as one turned is (perception's
# offers: moved 0.25 and 0.45; held 0.45 off, the simulator's slip model gives it the chance of
# one turned 25 degrees on an elongated sherd).
MOVED = 0.35
# [m] a sherd seen this near where one slipped out of the fingers as often as the recovery
# allows is that one (a drop scatters it by a centimetre or two: recovery.unlikeness)
SLIPPED_HERE = 0.03
# Two measurements of one sherd agree this well in length and width (one that fell may lie
# tilted now).
SAME_SIZE = 0.25
# [m] Two detections closer than this are the same sherd seen from two views.
SAME_SHERD = 0.02
# [m] a sherd whose support (what it lies on, above the station surface) is higher lies on
# another sherd (the detector's StackSplitter steps by at least a wall, 2.5 mm)
STACKED = 0.002
# [m] thicker than a body sherd's wall usually is (body 5-10 mm, typical 6-8 mm: facts/
# sherds_and_colour.md §2, [S15]): seen from above, such a wall may be two sherds lying one
# wholly on the other, so the sherd is looked at on a station and taken up there high on its
# edge (manipulation.rider_z)
THICK_WALL = 0.010
# Two mean colours of one sherd differ by less than this in CIELAB a*, b* (its chromaticity:
# shading, a shadow, a neighbour's reflection change L* more than hue and chroma; wares of the
# generator's and the field's chips, facts sherds_and_colour.md §2d, 2.5YR 5/6 against
# 10YR 7/3, differ by ~25).
UNLIKE_COLOUR = 15.0


def same_size(a, b) -> bool:
    """Whether observations `a` and `b` may be one sherd by their length and width."""
    return abs(a.length - b.length) <= SAME_SIZE * b.length and abs(
        a.width - b.width
    ) <= SAME_SIZE * max(b.width, 0.5 * b.length)


def chromaticity(rgb):
    """CIELAB (a*, b*) of an sRGB colour in [0, 1] (OpenCV's conversion, D65); None when not
    told (black, the Observation's default; or none)."""
    if not any(rgb):
        return None
    import cv2  # a task-layer test without OpenCV never compares colours
    import numpy as np

    lab = cv2.cvtColor(np.array([[rgb]], dtype=np.float32), cv2.COLOR_RGB2Lab)[0, 0]
    return float(lab[1]), float(lab[2])


def colour_difference(a, b) -> float:
    """[CIELAB a*, b*] between the mean colours of `a` and `b` (Observations); 0 when either
    was not told or is not to be trusted: partly under another sherd (`covered`), its mean
    takes in the shadow and the edge of the one on it (heap_25_offcentre seed 70: one sherd
    partly under two, 46 x 27 mm of it seen, measured another colour once uncovered)."""
    # a Leftover (rig.py) carries no colour
    ca, cb = chromaticity(getattr(a, "colour", ())), chromaticity(getattr(b, "colour", ()))
    if ca is None or cb is None or covered(a) or covered(b):
        return 0.0
    return math.dist(ca, cb)


def unlike_in_colour(a, b) -> bool:
    """Whether `a` and `b` (Observations) are surely two sherds by their mean colours: apart by
    more than UNLIKE_COLOUR (colour_difference). Alike, or not trusted: not surely."""
    return colour_difference(a, b) > UNLIKE_COLOUR


def surely_another(c, o: Observation) -> bool:
    """Whether `c`, seen now, is surely not `o` (of an earlier survey) moved or uncovered since:
    unlike in colour, however near and alike in size. A sherd nudged, slid off the one it lay
    on or uncovered shows more or less of itself, in shade or shadow, but not another hue and
    chroma; the one it hid is the sherd most often found where it lay, often of its size
    (heap_25_offcentre seed 70 and heap_20 seed 62: a sherd lying on another was flung off the
    mat by a grasp beside it, the one under it, of its size and at its spot, counted as it seen
    again, and nothing was said)."""
    return c is not o and unlike_in_colour(c, o)


def itself(p, o: Observation) -> bool:
    """Whether `p`, of a survey, is `o` (often a fresh look's detection) seen again: as near as
    SAME_SHERD and of its size."""
    return p is o or (o.distance_to(p.x, p.y) <= SAME_SHERD and same_size(p, o))


def among_others(o: Observation, seen: list, put_back_at=()) -> bool:
    """Whether a second sherd may have come up with `o`, just picked, by what the survey saw
    (`seen`: Observations and Leftovers): one lying on it (its outline partly covered, or one
    resting on something, `support`, within reach of its outline), or no grasp whose fingers
    clear its neighbours; or it lay within its length of where two sherds were put back
    (`put_back_at`: set down together they may lie as one outline, and the next grasp took
    both again, heap_20 seed 46). A light one lying on it rides along within the mass bound
    (10 g on 29 g, heap_mixed_20 seed 51). A neighbour merely beside it is not: looking after
    every sherd within 10 mm of one took 17 looks in 20 sherds of heap_20 seed 45, none seeing
    two. A sherd's own survey detection is not its neighbour (lying on another, it counted as
    one resting on it: 16 looks in 20 sherds of heap_20 seed 58, none seeing two). But one
    lying on something whose wall reads thicker than a body sherd's (THICK_WALL) may be lying
    wholly on a sherd the grasp reaches: heap_22_corner seed 84, a 56 x 38 mm sherd seen with
    a 17.2 mm wall on 8.4 mm lay on a 46 x 34 mm one that the fingers closed on, and both were
    weighed as one row (34.9 g: within the mass bound of that wall)."""
    if o.covered > 0.0 or not o.grasp_clear:
        return True
    if o.support > STACKED and o.thickness > THICK_WALL:
        return True
    if any(o.distance_to(x, y) < o.length for x, y in put_back_at):
        return True
    return any(
        getattr(p, "support", 0.0) > STACKED and o.distance_to(p.x, p.y) < (o.length + p.length) / 2
        for p in seen
        if not itself(p, o)
    )


def covered(o: Observation) -> bool:
    return o.covered > COVERED


def taken_again(o: Observation, slipped: Observation) -> bool:
    """Whether `o`, held by the grasp after `slipped` slipped out of the fingers while lifted
    (it falls back where it lay), is that sherd: of its size, or, where either was seen partly
    under another (its size is of the part that shows, and changes as it falls back), where it
    lay (heap_22_corner seed 85: a sherd seen 55 x 23 mm slipped, was held again at once seen
    51 x 17 mm, and was recorded; the survey after it then said it slipped away, exit 1)."""
    if same_size(o, slipped):
        return True
    partly = covered(o) or covered(slipped)
    return partly and o.distance_to(slipped.x, slipped.y) <= SAME_SHERD


def turned(o: Observation) -> bool:
    """Whether its grasp is turned off its minor axis (TURNED)."""
    return abs(o.grasp_turn) > TURNED


def held_far_off(o: Observation) -> bool:
    """Whether its grasp is turned off its minor axis (`turned`) or moved along it far off its
    centre (MOVED)."""
    return turned(o) or o.grasp_shift > MOVED


def in_pick_order(found: List[Observation], policy: str, slipped_from=()) -> List[Observation]:
    """`found` in the order to pick it: sherds nothing lies on first (the top of a heap), the
    least covered of the rest after them; of alike covered ones, those that did not slip out of
    the fingers as often as the recovery allows (lying within SLIPPED_HERE of a spot of
    `slipped_from`: taken after the others, whose going may leave it a grasp that holds; heap_20
    seed 60 dropped one grasped along its length six times from amid its neighbours), then those
    whose fingers clear the neighbours (perception's grasp_clear), and of those the ones whose
    grasp closes across their minor axis near their middle (not `held_far_off`); then by
    `policy`:
    - nearest: nearest the arm's base first (the shortest reach, the least time; the default);
    - largest: largest length x width first;
    - most_isolated: largest edge-to-edge gap to its nearest neighbour first.
    Python's sort is stable: detection order breaks ties."""
    if policy == "largest":
        ordered = sorted(found, key=lambda o: -o.length * o.width)
    elif policy == "most_isolated":

        def gap(o):  # to the nearest neighbour, edge to edge along the line of centres
            return min(
                (o.distance_to(p.x, p.y) - (o.length + p.length) / 2 for p in found if p is not o),
                default=math.inf,
            )

        ordered = sorted(found, key=lambda o: -gap(o))
    else:
        ordered = sorted(found, key=lambda o: math.hypot(o.x, o.y))

    return sorted(
        ordered,
        key=lambda o: (
            o.covered if covered(o) else 0.0,
            slipped_here(o, slipped_from),
            not o.grasp_clear,
            held_far_off(o),
        ),
    )


def slipped_here(o: Observation, slipped_from) -> bool:
    """Whether `o` lies within SLIPPED_HERE of a spot of `slipped_from`: the sherd that slipped
    out there (recovery.Recover), put off for after the others."""
    return any(o.distance_to(x, y) < SLIPPED_HERE for x, y in slipped_from)


# [m] a sherd left for a person (Batch.unpickable) is the detection nearest its spot within
# this: a failed grasp, a push or a topple may have moved it by a few centimetres
LEFT_MOVED = 2 * SAME_SHERD


def apart_from_left(found: List[Observation], left) -> List[Observation]:
    """`found` less the sherds left for a person at the spots `left` (Batch.unpickable): each
    spot stands for one detection, the nearest to it within LEFT_MOVED (nearest pairs first,
    one to one). Its neighbours stay: every detection within LEFT_MOVED of a spot was dropped
    before, and in a tipped-out heap six sherds too small for the stock fingers hid six
    pickable ones lying among them, neither picked nor said (heap_mixed_20 seed 93)."""
    pairs = sorted(
        (o.distance_to(x, y), i, j)
        for i, o in enumerate(found)
        for j, (x, y) in enumerate(left)
        if o.distance_to(x, y) <= LEFT_MOVED
    )
    gone, used = set(), set()
    for _, i, j in pairs:
        if i not in gone and j not in used:
            gone.add(i)
            used.add(j)
    return [o for i, o in enumerate(found) if i not in gone]
