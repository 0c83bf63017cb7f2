"""Singulation: a sherd the gripper failed on twice at the same spot of a heap is pushed once,
away from its neighbours and never off the mat, and the area surveyed again; only a sherd that
still cannot be picked after that is left for a person. A sherd the tipped-out bag left standing
on its edge (perception's leftover `on_edge`) is pushed over once, so that it lies flat. No ROS
here.

A push: fingers closed, the gripper turned so both fingers meet the sherd, down beside it at
the height its grasp closes at (its own mid-height above what it rests on: a sherd lying on
another is pushed off it), then along the line through its centre.
A topple: fingers closed and in line with the push (the leading finger's 20 mm face meets the
middle of the sherd's face, however short it is), down behind it at three quarters of its
height (above its centre of mass: it tips rather than slides), then across until the finger
has passed where it stood by half its height.
"""

import math
from typing import List, Optional, Tuple

from rascal_workcell import urdf_model

from rascal_tasks.failures import about_this_sherd
from rascal_tasks.rig import Leftover, Observation, RigError
from rascal_tasks.selection import STACKED, same_size

PUSH = 0.04  # [m] how far the sherd's centre is pushed: most of a neighbour's width
# [m] how far where no full push has a clear path: a finger's thickness and the grasp margin
# (8 + 6 mm) freed beside it, and a few millimetres over (in a heap a full push's 40 mm strip
# met a neighbour 12 of 14 times in session 45's runs; each refused one was grasped turned)
SHORT_PUSH = 0.02
LEAD = 0.015  # [m] the fingers start this far outside its outline
EDGE = 0.01  # [m] a pushed sherd keeps its outline this far inside the mat
DIRECTIONS = 16
MAX_PUSHES = 20  # per batch (pushes and topples): a heap that needs more is a person's job
PUSHED_NEAR = 0.025  # [m] a pushed sherd lies about this near where the push sent it
TOPPLE_AT = 0.75  # of a standing sherd's height: where the finger pushes it
FINGERTIP = urdf_model.fingertip_offset()  # [m] fingertips below ee_gripper_link
# [m] ee_gripper_link to the leading finger's outer face, fingers closed and in line with a push
# (half the closed opening, then the finger's thickness: the URDF's finger box)
FINGER_REACH = urdf_model.opening_limits()[0] / 2 + urdf_model.finger_thickness()
FINGER_HALF_WIDTH = urdf_model.finger_width() / 2  # [m] the fingers' half-width along a push
# [m] the closed fingers come down to push no nearer than this to a neighbour's outline box (the
# arm's repeatability and the outline's few millimetres: in heaps the fingers met neighbours at
# the edges of their footprint)
PUSHER_CLEARANCE = 0.003
# [m] a neighbour whose outline box reaches this little into the strip a pushed sherd sweeps is
# slid past, not shoved (sherds touching side by side in a heap)
SLID_PAST = 0.001


def push_direction(
    o: Observation, others: List[Observation], area, travel: float = PUSH
) -> Optional[Tuple[float, float]]:
    """The unit direction (dx, dy) to push `o` in by `travel`: where it ends farthest from its
    neighbours' outlines, its own outline still `EDGE` inside `area` (a config.Rect), the
    fingers and its path clear of them; None if there is none."""
    clear = [
        d for d in _directions() if pusher_clear(o, d, others) and path_clear(o, d, others, travel)
    ]
    return _roomiest(o, clear, travel, o.length / 2 + EDGE, others, area)


def _directions() -> List[Tuple[float, float]]:
    """The DIRECTIONS unit directions a push is tried along, evenly round."""
    return [
        (math.cos(2 * math.pi * k / DIRECTIONS), math.sin(2 * math.pi * k / DIRECTIONS))
        for k in range(DIRECTIONS)
    ]


def push_plan(
    o: Observation, others: List[Observation], area
) -> Optional[Tuple[Tuple[float, float], float]]:
    """How to push `o` apart from `others`: (direction, travel), a full PUSH where one has a
    clear path, else a SHORT_PUSH; None if neither has."""
    for travel in (PUSH, SHORT_PUSH):
        d = push_direction(o, others, area, travel)
        if d is not None:
            return d, travel
    return None


def why_not_pushed(o: Observation, others: List[Observation], area) -> str:
    """Why no push of `o` is tried (push_plan None), counted over its DIRECTIONS directions:
    how many the closed fingers would come down on a neighbour (pusher_clear), how many more
    drive it into one even by SHORT_PUSH (path_clear), and how many of the rest leave it less
    than EDGE inside the mat. For tracing a run."""
    fingers = path = 0
    for d in _directions():
        if not pusher_clear(o, d, others):
            fingers += 1
        elif not path_clear(o, d, others, SHORT_PUSH):
            path += 1
    return (
        "of %d directions, %d with the fingers on a neighbour, %d with one in its path, %d "
        "ending off the mat" % (DIRECTIONS, fingers, path, DIRECTIONS - fingers - path)
    )


def push_start(o: Observation, d: Tuple[float, float]) -> Tuple[float, float]:
    """Where the closed fingers come down to push `o` along `d`: LEAD outside its outline."""
    back = o.length / 2 + LEAD
    return (o.x - back * d[0], o.y - back * d[1])


def pusher_clear(o: Observation, d: Tuple[float, float], others: List[Observation]) -> bool:
    """Whether the closed fingers, come down at push_start to push `o` along `d` (their
    footprint: FINGER_HALF_WIDTH along `d`, FINGER_REACH across it), lie PUSHER_CLEARANCE clear
    of every neighbour's outline box (`others`' length x width about their yaw). heap_25_offcentre
    seed 111: a push before a grasp came down on two neighbours, and one went off the mat."""
    sx, sy = push_start(o, d)
    pusher = ((sx, sy), math.atan2(d[1], d[0]), FINGER_HALF_WIDTH, FINGER_REACH)
    return not any(_boxes_overlap(pusher, _box(c, PUSHER_CLEARANCE)) for c in others if c is not o)


def path_clear(
    o: Observation, d: Tuple[float, float], others: List[Observation], travel: float = PUSH
) -> bool:
    """Whether `o`, pushed `travel` along `d`, sweeps into no neighbour: the strip its outline box
    covers ahead of it (from its leading edge `travel` on, as wide across `d` as the box, less
    SLID_PAST each side) meets no neighbour's outline box but those it lies on (their tops no
    higher than what it rests on: it is pushed at its own mid-height and slides off them).
    heap_20 seed 116: a push drove a sherd into a stack of three lying near the mat's edge; they
    slid 25 mm, half off the mat, and a grasp beside them later pushed the top one off it, said
    nowhere."""
    theta = math.atan2(d[1], d[0])
    rel = o.yaw - theta
    ahead = abs(o.length / 2 * math.cos(rel)) + abs(o.width / 2 * math.sin(rel))
    across = abs(o.length / 2 * math.sin(rel)) + abs(o.width / 2 * math.cos(rel))
    mid = ahead + travel / 2
    strip = ((o.x + mid * d[0], o.y + mid * d[1]), theta, travel / 2, across - SLID_PAST)
    own = _box(o, 0.0)
    return not any(
        _boxes_overlap(strip, _box(c, 0.0))
        for c in others
        if c is not o
        and not (c.height <= o.support + STACKED and _boxes_overlap(own, _box(c, 0.0)))
    )


def _box(c, grown: float):
    """The outline box of `c` (an Observation) grown by `grown` all round, as _boxes_overlap
    reads it."""
    return ((c.x, c.y), c.yaw, c.length / 2 + grown, c.width / 2 + grown)


def _boxes_overlap(a, b) -> bool:
    """Whether two oriented rectangles ((cx, cy), yaw, half-length, half-width) overlap: no
    axis of either separates them."""

    def axes(box):
        (_, yaw, hl, hw) = box
        return [((math.cos(yaw), math.sin(yaw)), hl), ((-math.sin(yaw), math.cos(yaw)), hw)]

    dx, dy = b[0][0] - a[0][0], b[0][1] - a[0][1]
    both = axes(a) + axes(b)
    for n, _ in both:
        reach = sum(h * abs(n[0] * u[0] + n[1] * u[1]) for u, h in both)
        if abs(dx * n[0] + dy * n[1]) > reach:
            return False
    return True


def _roomiest(
    it, directions, travel, half, others, area, hold_ground=False
) -> Optional[Tuple[float, float]]:
    """Of `directions`, the one that moves `it` by `travel` farthest from the outlines of
    `others` (their centres less half their length), `half` of it still inside `area`; or,
    `hold_ground`, along each side of the mat no nearer its edge than it is now (a standing
    sherd laid along an edge it stands near lands no farther out than it stands)."""
    start = area.to_local((it.x, it.y))
    best, best_room = None, -math.inf
    for d in directions:
        end = (it.x + travel * d[0], it.y + travel * d[1])
        local = area.to_local(end)
        if any(
            abs(local[i]) > area.size[i] / 2 - half
            and not (hold_ground and abs(local[i]) <= abs(start[i]) + 1e-9)
            for i in (0, 1)
        ):
            continue  # would leave the mat
        room = min(
            (math.hypot(end[0] - p.x, end[1] - p.y) - p.length / 2 for p in others if p is not it),
            default=1.0,
        )
        if room > best_room + 1e-9:
            best, best_room = d, room
    return best


def push(b, o: Observation, d: Tuple[float, float], travel: float = PUSH) -> bool:
    """Push `o` by `travel` along `d` (see the module). False when the arm refuses a move of it
    (the sherd is then left for a person); other rig errors stop the batch as anywhere."""
    start = push_start(o, d)
    end = (o.x + travel * d[0], o.y + travel * d[1])
    # the fingers close across the push: both touch the sherd
    return _sweep(b, (o.x, o.y), start, end, o.grasp_z, math.atan2(d[1], d[0]))


def part_from_neighbours(b, o: Observation, others: List[Observation], key, after: str) -> bool:
    """Push `o` apart from its neighbours (`others`), once per spot (`key`, rounded (x, y)) and
    once per sherd (was_pushed), if the batch has pushes left (MAX_PUSHES) and a push keeps it
    on the mat; said, `after` saying why. True when it was pushed."""
    if was_pushed(b, o):
        b.log("the sherd at (%.3f, %.3f) m is not pushed: pushed before" % (o.x, o.y))
        return False
    if not _spend_push(b, key):
        b.log(
            "the sherd at (%.3f, %.3f) m is not pushed: this spot pushed before, or the "
            "batch's %d pushes spent" % (o.x, o.y, MAX_PUSHES)
        )
        return False
    plan = push_plan(o, others, b.pickup.area)
    if plan is None:
        b.log(
            "the sherd at (%.3f, %.3f) m is not pushed: %s"
            % (o.x, o.y, why_not_pushed(o, others, b.pickup.area))
        )
        return False
    d, travel = plan
    if not push(b, o, d, travel):
        return False
    sent = ((o.x + travel * d[0], o.y + travel * d[1]), o)
    b.pushed_to.append(sent)
    b.pushed_since_survey.append(sent)  # looked for there by the next survey's edge check
    b.event(
        None,
        "pushed",
        "sherd at (%.3f, %.3f) m pushed %.0f mm towards (%.2f, %.2f) %s, to part it from its "
        "neighbours" % (o.x, o.y, travel * 1000, d[0], d[1], after),
    )
    return True


def _spend_push(b, key) -> bool:
    """Take one push from the batch's budget (MAX_PUSHES, pushes and topples together) for the
    spot `key` (rounded (x, y)): False when that spot was pushed before or the budget is spent.
    Spent before the push is tried, so a refused push is not tried again."""
    if key in b.pushed or len(b.pushed) >= MAX_PUSHES:
        return False
    b.pushed.add(key)
    return True


def was_pushed(b, o: Observation) -> bool:
    """Whether `o` is a sherd pushed before (one of its size lying about where a push sent it):
    pushed once and still not picked, it is a person's job (another push would chase it
    across the mat, six grasps at every spot)."""
    return any(
        math.hypot(o.x - x, o.y - y) < PUSHED_NEAR and same_size(o, p) for (x, y), p in b.pushed_to
    )


def topple_direction(lo: Leftover, others: List[Leftover], area) -> Optional[Tuple[float, float]]:
    """Which way to push a sherd standing on its edge over: of the two directions across its
    long side, the one where it lands farther from `others`, its far edge (a height beyond
    where it stands: it tips about its foot) still `EDGE` inside `area` (a config.Rect); None
    if neither. Its near side stays where it stood, so one standing at the mat's edge is laid
    inwards, never further off."""
    across = [(-sign * math.sin(lo.yaw), sign * math.cos(lo.yaw)) for sign in (1.0, -1.0)]
    return _roomiest(lo, across, lo.height, EDGE, others, area, hold_ground=True)


def topple(b, lo: Leftover, d: Tuple[float, float]) -> bool:
    """Push the standing sherd `lo` over along `d` (see the module). False when the arm
    refuses a move of it; other rig errors stop the batch as anywhere."""
    back = lo.width / 2 + LEAD + FINGER_REACH
    past = lo.width / 2 + lo.height / 2 - FINGER_REACH
    start = (lo.x - back * d[0], lo.y - back * d[1])
    end = (lo.x + past * d[0], lo.y + past * d[1])
    z = lo.surface_z + TOPPLE_AT * lo.height + FINGERTIP
    # fingers in line with the push: yaw a quarter turn from the direction
    return _sweep(b, (lo.x, lo.y), start, end, z, math.atan2(d[1], d[0]) + math.pi / 2)


def _sweep(b, at_xy, start, end, z, yaw) -> bool:
    """Fingers closed, down at `start` to ee height `z`, along to `end`, and up again."""
    yaw = math.remainder(yaw, math.pi)  # the fingers are alike: the turn the wrist has room for
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
        b.event(None, "push_refused", "sherd at (%.3f, %.3f) m: %s" % (*at_xy, e))
        return False
    finally:
        if at is not None:
            b.move_down(*at, b.travel_z(), yaw, linear=True)
    return True


def _push_over(b, lo, seen, area):
    """Push the standing sherd `lo` over, once per spot and within the push budget (MAX_PUSHES,
    shared with the heap's pushes): the direction it was pushed, or None (pushed there before,
    budget spent, no free side among `seen` in `area`, or the push failed)."""
    if not _spend_push(b, (round(lo.x, 2), round(lo.y, 2))):
        return None
    d = topple_direction(lo, seen, area)
    if d is None or not topple(b, lo, d):
        return None
    return d


def lay_flat(b) -> bool:
    """Push over every sherd of the last survey's leftovers that stands on its edge, once per
    spot (counted with the pushes); True when one was pushed (the area is to be surveyed again)."""
    pushed = False
    for lo in b.leftovers:
        d = _push_over(b, lo, b.leftovers, b.pickup.area) if lo.on_edge else None
        if d is None:
            continue
        pushed = True
        b.event(
            None,
            "laid_flat",
            "sherd standing on its edge at (%.3f, %.3f) m (%.0f mm tall) pushed over towards "
            "(%.2f, %.2f)" % (lo.x, lo.y, lo.height * 1000, d[0], d[1]),
        )
    return pushed


def lay_flat_at(b, station, x, y) -> bool:
    """Push over a sherd that the last look at `station` saw standing on its edge within
    recovery.search_radius of (x, y), where the sherd in progress was set down: one picked
    leaning steeply in a heap hangs from the fingers by its lower edge and can stand where it
    is set down, too thin across for the fingers to hold (heap seed 45: recorded lost, left on
    the pan, the next sherd weighed over it). Once per spot, counted with the pushes; True when
    pushed (look again)."""
    near = b.config["recovery"]["search_radius"]
    seen = b.rig.perception.leftovers(station.name)
    for lo in seen:
        if not lo.on_edge or math.hypot(lo.x - x, lo.y - y) > near:
            continue
        d = _push_over(b, lo, seen, station.area)
        if d is None:
            continue
        b.event(
            b.sherd,
            "laid_flat",
            "standing on its edge on the %s (%.0f mm tall): pushed over towards (%.2f, %.2f)"
            % (station.name, lo.height * 1000, d[0], d[1]),
        )
        return True
    return False
