"""Looking for sherds with the wrist camera: the lawnmower over the pickup area, its views merged,
and the states SURVEY and SURVEY_NEXT. No ROS in here.
"""

import math
from dataclasses import replace
from typing import List, Optional, Sequence, Tuple

from rascal_workcell import urdf_model

from rascal_tasks.batch import PUSHED_OFF, SLIPPED_AWAY, BatchState, NotSeenAgain
from rascal_tasks.rig import Leftover, Observation
from rascal_tasks.selection import (
    SAME_SHERD,
    apart_from_left,
    SAME_SIZE,
    colour_difference,
    covered,
    in_pick_order,
    surely_another,
    same_size,
)
from rascal_tasks.singulation import lay_flat

# Wrist camera offset from ee_gripper_link when the gripper points down, along the gripper's
# yaw direction (camera_link sits 0.055 m "above" gripper_link in the URDF).
CAMERA_OFFSET = urdf_model.camera_offset()
# Sherds seen within half a blob's length of its centre, together this much of its length x
# width: the blob was several sherds, seen apart now (seen_apart).
SEEN_APART = 0.75
# Looks of their own at sherds the image border cut in every survey view (one across the mat's
# edge): each costs a move there (about 1 s), and a batch meets a few such sherds at most.
MAX_EXTRA_LOOKS = 3
# How much nearer the base than a cut sherd the camera may look from when it cannot be over it
# at the survey height (the mat's far corners): the sherd then lies off the image's centre, by
# less than the view's half-height (~0.11 m) less half the longest sherd.
LOOK_BACK = 0.06


def lawnmower(
    center: Tuple[float, float], size: Tuple[float, float], step: float
) -> List[Tuple[float, float]]:
    """Camera positions [x, y] that cover the rectangle in cells no larger than `step`.

    Cells are spread evenly over the rectangle (the paper's grid started at a corner and
    overshot it); columns run along x, and y alternates direction from column to column so
    the arm never travels back across the area.
    """
    nx = max(1, math.ceil(size[0] / step - 1e-9))
    ny = max(1, math.ceil(size[1] / step - 1e-9))
    x0, y0 = center[0] - size[0] / 2, center[1] - size[1] / 2
    poses = []
    for i in range(nx):
        x = x0 + (i + 0.5) * size[0] / nx
        ys = [y0 + (j + 0.5) * size[1] / ny for j in range(ny)]
        poses.extend((x, y) for y in (ys if i % 2 == 0 else reversed(ys)))
    return poses


def gripper_for_camera_over(x: float, y: float, yaw=None) -> Tuple[float, float, float]:
    """(x, y, yaw) of ee_gripper_link, pointing down, that puts the wrist camera over (x, y):
    the camera faces away from the base, so the gripper stays clear of what it looks at
    (`yaw` [rad]: the gripper turned so instead, the camera still over (x, y))."""
    if yaw is None:
        yaw = math.atan2(y, x)
    return x - CAMERA_OFFSET * math.cos(yaw), y - CAMERA_OFFSET * math.sin(yaw), yaw


def reachable_look_yaws(x: float, y: float, z: float, yaws: Sequence) -> List:
    """Those of `yaws` (gripper yaws; None: facing away from the base) from which the wrist
    camera looks straight down at (x, y) from height `z` within the arm's reach, in order."""
    from rascal_tasks.config import top_down_reachable  # config imports this module

    return [a for a in yaws if top_down_reachable(*gripper_for_camera_over(x, y, a)[:2], z)]


def camera_over(b, station, x, y, yaw=None):
    """Put the wrist camera over (x, y) of a station, at the survey height."""
    ex, ey, yaw = gripper_for_camera_over(x, y, yaw)
    b.move_down(ex, ey, station.surface_z + b.config["survey"]["z"], yaw)


def survey_at(b, station, x, y, yaw=None) -> List[Observation]:
    """Put the wrist camera over (x, y) of a station (`yaw`: gripper_for_camera_over) and
    detect what is there."""
    camera_over(b, station, x, y, yaw)
    with b.phase("perception"):
        b.rig.clock.sleep(b.config["survey"]["settle_time"])
        return b.rig.perception.detect(station.name)


def on_the_mat(area, lo) -> bool:
    """Whether leftover `lo` reaches onto the pickup area (config.Rect): its centre within half
    its length of it (one at the mat's edge is the bag's; the table beyond is not)."""
    (lx, ly), (sx, sy) = area.to_local((lo.x, lo.y)), area.size
    return abs(lx) <= sx / 2 + lo.length / 2 and abs(ly) <= sy / 2 + lo.length / 2


def describe_leftover(lo) -> str:
    """One line for a person: what lies on the mat, where, and why it was not taken."""
    return "%.0f x %.0f mm at (%.3f, %.3f) m left on the pickup mat, not taken: %s" % (
        lo.length * 1000,
        lo.width * 1000,
        lo.x,
        lo.y,
        lo.why,
    )


def look_for(b, kind: str, expected, found: List[Observation], alike, say):
    """Each of `expected` ((x, y, Observation)) must be seen again by this survey: something
    `alike(c, o)` among `found` and the survey's leftovers within recovery.search_radius of
    (x, y), each thing seen standing for one of them (the nearest first), a leftover larger
    than several of it for any number. Each not seen is a batch event `kind` (`say(o,
    radius)`: its detail) and a NotSeenAgain in the batch's summary: it may lie beside the mat.
    One of those seen by a later survey is no longer said (in a heap a sherd that fell back may
    lie under another until that one is picked).
    (One for one: heap seed 36 at 106c498, a grasp flung one of two sherds lying at the mat's
    far edge 10 cm off it and stood the other on its edge; the one left, a leftover within the
    radius of both, stood for both, and the one flung off was said nowhere.)"""
    radius = b.config["recovery"]["search_radius"]
    seen = list(found) + list(b.leftovers)

    def near(x, y, o):
        return sorted(
            (i for i, c in enumerate(seen) if c.distance_to(x, y) < radius and alike(c, o)),
            key=lambda i: seen[i].distance_to(x, y),
        )

    for u in [u for u in b.not_seen_again if u.kind == kind and near(u.x, u.y, u.seen)]:
        b.not_seen_again.remove(u)
        b.event(
            None,
            "seen_again",
            "the sherd not seen again (%s) at (%.3f, %.3f) m is seen "
            "there now" % (kind, u.x, u.y),
        )
    candidates = [(x, y, o, near(x, y, o)) for x, y, o in expected]
    used = set()
    for x, y, o, near_it in sorted(
        candidates, key=lambda e: seen[e[3][0]].distance_to(e[0], e[1]) if e[3] else radius
    ):
        free = [i for i in near_it if i not in used or _several(seen[i], o)]
        if free:
            used.add(free[0])
            continue
        b.not_seen_again.append(NotSeenAgain(kind, x, y, o))
        b.event(None, kind, say(o, radius))


def _several(c, o: Observation) -> bool:
    """Whether `c`, seen, is large enough to be several sherds the size of `o` (a leftover longer
    than perception.max_sherd_size is one blob of a heap's sherds)."""
    return isinstance(c, Leftover) and c.length >= 2.0 * o.length


def account_for_slips(b, found: List[Observation]):
    """Sherds that slipped out of the fingers while lifted (pickup.py) have no number yet, so
    no row would miss one. Each must be seen again by the survey after it: a sherd of its size
    within recovery.search_radius of where it was held (others always lie near in a heap), not
    of another colour (selection.surely_another).
    One not seen may lie beside the mat: said, and the batch ends incomplete."""
    look_for(
        b,
        SLIPPED_AWAY,
        [(o.grasp_x, o.grasp_y, o) for o in b.unchecked_slips],
        found,
        lambda c, o: same_size(c, o) and not _surely_another(b, c, o),
        lambda o, radius: "a %.0f x %.0f mm sherd slipped out of the fingers while lifted at "
        "(%.3f, %.3f) m and the survey after it sees none of its size within %.0f mm of there: "
        "it may lie beside the mat"
        % (o.length * 1000, o.width * 1000, o.grasp_x, o.grasp_y, radius * 1000),
    )
    b.unchecked_slips = []


def near_the_edge(area, o: Observation) -> bool:
    """Whether `o` lies within its own length of the pickup area's edge (config.Rect): a shove
    of its own size could put it off the mat."""
    (lx, ly), (sx, sy) = area.to_local((o.x, o.y)), area.size
    return min(sx / 2 - abs(lx), sy / 2 - abs(ly)) <= o.length


def taken_off_the_mat(b, grasped: Observation, surveyed: Optional[Observation] = None):
    """Note for the edge check which sherd of the last survey (`b.seen`) has left the mat: the
    one the `grasped` detection (often a fresh look's) is. Its nearest within SAME_SHERD of
    its size first; else `surveyed`, the one it was taken for, when of its size (a grasp
    beside it may have nudged it further: heap_20 seed 65, 22 mm, and the nearest, a sherd of
    another size still lying there, was counted taken instead and this one said pushed off the
    mat); else its nearest within SAME_SHERD (one uncovered since shows more of itself, its
    centre shifted); else `surveyed`. A fresh look may grasp a neighbour instead of the sherd
    it looked for, which then still lies on the mat (heap seed 36: the sherd grasped was
    counted as still there)."""
    near = sorted(
        (c for c in b.seen if c.distance_to(grasped.x, grasped.y) <= SAME_SHERD),
        key=lambda c: c.distance_to(grasped.x, grasped.y),
    )
    alike = [c for c in near if same_size(grasped, c)]
    if alike:
        it = alike[0]
    elif surveyed is not None and same_size(grasped, surveyed):
        it = surveyed
    else:
        it = near[0] if near else surveyed
    if it is not None:
        b.taken_since_survey.append((it.x, it.y))


def taken_since(b, o: Observation) -> bool:
    """Whether `o`, of the last survey, was noted taken off the mat since (within SAME_SHERD of
    a spot of `b.taken_since_survey`)."""
    return any(math.hypot(o.x - x, o.y - y) <= SAME_SHERD for x, y in b.taken_since_survey)


def came_up_with(b, sherd, extra: int):
    """Note for the edge check (account_for_vanished) that `extra` sherds of the last survey
    (`b.seen`) came up with `sherd` (a SherdRecord) in one grasp, seen on the pan beside it or
    weighed heavier than it can be: the ones nearest where it was picked whose outlines reached
    it, not taken already. They are put back elsewhere on the mat (station_states.PutBack), and
    looked for where they lay they were said pushed off it (heap_20 seed 116: three sherds
    stacked near the mat's edge came up in one grasp and were put back apart; one was said not
    seen again, exit 1, a false alarm). A sherd not picked by this run (found on a station
    after a restart) has no spot to be near."""
    if sherd.picked_xy is None or sherd.size is None:
        return
    x, y = sherd.picked_xy
    length = sherd.size.length
    near = sorted(
        (
            c
            for c in b.seen
            if c.distance_to(x, y) < (length + c.length) / 2 and not taken_since(b, c)
        ),
        key=lambda c: c.distance_to(x, y),
    )
    b.taken_since_survey.extend((c.x, c.y) for c in near[:extra])


def seen_apart(o: Observation, found: List[Observation]) -> bool:
    """Whether `o`, of an earlier survey, was several of a heap's sherds seen as one that this
    survey (`found`) sees apart: longer than any sherd it sees, and two or more sherds lie
    within half its length of its centre, together at least SEEN_APART of its size (heap seed
    37: an "83 x 53 mm sherd" mid-mat, longer than the heap's largest, 70 mm, was asked back
    whole and said pushed off the mat)."""
    if not found or o.length <= max(c.length for c in found):
        return False
    pieces = [c for c in found if c.distance_to(o.x, o.y) < o.length / 2]
    return len(pieces) >= 2 and sum(c.length * c.width for c in pieces) >= (
        SEEN_APART * o.length * o.width
    )


def _surely_another(b, c, o: Observation) -> bool:
    """selection.surely_another, logged: which sherd seen was not taken for which (each pair
    once a batch: look_for asks each pair more than once)."""
    if not surely_another(c, o):
        return False
    if (id(c), id(o)) not in b.said_another:
        b.said_another.add((id(c), id(o)))
        b.log(
            "survey: the %.0f x %.0f mm sherd at (%.3f, %.3f) m is another colour (%.0f apart "
            "in a*, b*) than the %.0f x %.0f mm one seen at (%.3f, %.3f) m: not it seen again"
            % (
                c.length * 1e3,
                c.width * 1e3,
                c.x,
                c.y,
                colour_difference(c, o),
                o.length * 1e3,
                o.width * 1e3,
                o.x,
                o.y,
            )
        )
    return True


# [m] a sherd seen again uncovered is at most this much shorter than it was seen (or 10 % of
# its length, if more): two views' outlines of one sherd differ by a few millimetres
SHORTER_SEEN = 0.006


def may_stand_for(b, c, o: Observation) -> bool:
    """Whether `c`, seen now, may be `o`, seen near the mat's edge before, seen again: anything
    perception does not offer (a leftover), or a sherd at least about as long (uncovered since,
    it shows more of itself) that is not of another colour. Seen with nothing on it, it is
    shorter than `o` by SHORTER_SEEN at most; a quarter shorter only with something on it now
    (heap_25_offcentre seed 95 at 38461d2: a 68 mm sherd pushed off the mat, and a 53 mm
    neighbour nudged 2 cm by the same grasp, 17 mm from where it had lain, stood for it: exit
    0, said nowhere)."""
    if isinstance(c, Leftover):
        return True
    if c.covered > 0.0:
        shortest = (1.0 - SAME_SIZE) * o.length
    else:
        shortest = o.length - max(SHORTER_SEEN, 0.1 * o.length)
    return c.length >= shortest and not _surely_another(b, c, o)


def account_for_vanished(b, found: List[Observation]):
    """Each sherd of the survey before (`b.seen`) lying near the mat's edge that was not taken
    off the mat since (`b.taken_since_survey`: where the survey saw each sherd taken) must be
    seen again: a sherd at least about as long within recovery.search_radius of where it lay
    (a neighbour's grasp may nudge it; in a heap a sherd uncovered since shows more of itself,
    and smaller ones always lie near) but not one of another colour (selection.surely_another),
    or anything perception does not offer. One not seen
    may have been pushed off the mat by a grasp beside it: said, and the batch ends
    incomplete (a sherd recorded nowhere and said nowhere is the one failure a person would
    never notice)."""
    near = [
        (*expected_at(b, o), o)
        for o in b.seen
        if near_the_edge(b.pickup.area, o)  # elsewhere: moved, or under another, still on the mat
        # taken itself (a neighbour taken beside it does not count)
        and not taken_since(b, o)
        and not seen_apart(o, found)
    ]
    looked_for = [o for _, _, o in near]
    taken = [o for o in b.seen if any((o.x, o.y) == xy for xy in b.taken_since_survey)]
    kept = still_elsewhere(b.seen, looked_for + taken, found)
    said = len(b.not_seen_again)
    look_for(
        b,
        PUSHED_OFF,
        near,
        kept,
        lambda c, o: may_stand_for(b, c, o),
        lambda o, radius: "a %.0f x %.0f mm sherd seen at (%.3f, %.3f) m near the mat's edge "
        "was not picked up and is not seen within %.0f mm of there since: a grasp beside it may "
        "have pushed it off the mat" % (o.length * 1000, o.width * 1000, o.x, o.y, radius * 1000),
    )
    radius = b.config["recovery"]["search_radius"]
    for u in b.not_seen_again[said:]:  # what was seen there instead, for tracing a run
        for c in (c for c in found if c.distance_to(u.x, u.y) < radius):
            b.log(
                "  seen %.0f mm from there: %.0f x %.0f mm at (%.3f, %.3f) m, %s"
                % (
                    c.distance_to(u.x, u.y) * 1000,
                    c.length * 1000,
                    c.width * 1000,
                    c.x,
                    c.y,
                    "taken for a sherd of the survey before still lying there"
                    if all(c is not k for k in kept)
                    else "not alike"
                    if not may_stand_for(b, c, u.seen)
                    else "standing for another",
                )
            )
    b.taken_since_survey, b.pushed_since_survey = [], []


def expected_at(b, o: Observation) -> Tuple[float, float]:
    """Where `o`, of the survey before, should lie now: where a push since sent it (one pushed
    from within SAME_SHERD of it and of its size: often a fresh look's detection of it), else
    where it lay. heap_22_corner seed 118: a sherd pushed 40 mm from 2 cm inside the mat's
    edge slid 70 mm, beyond the search radius of where it had lain, and was said not seen
    again (exit 1, a false alarm)."""
    for (x, y), p in b.pushed_since_survey:
        if o.distance_to(p.x, p.y) <= SAME_SHERD and same_size(o, p):
            return x, y
    return o.x, o.y


def still_elsewhere(before: List[Observation], apart, found: List[Observation]):
    """`found` less what is, one for one, a sherd of the survey `before` still lying where it
    lay: within SAME_SHERD and of its size. That one is itself, and stands for no sherd gone
    from near it (heap_25_offcentre seed 73: a sherd dropped back 2 cm from the mat's far edge
    was flung off it by a grasp beside it, and a larger one that had lain 2 cm from it all
    along stood for it; the batch ended exit 0, 24 rows for 25 sherds, said nowhere). Those
    `apart` are not asked: the ones looked for, and the ones taken off the mat since, which lie
    nowhere on it (heap_25_offcentre seed 103: the first sherd picked, 66 mm, had lain 18 mm
    from a 52 mm one it half covered, and claimed that one seen whole since, so it was said
    not seen again: exit 1, a false alarm)."""
    kept = list(found)
    for o in before:
        if any(o is e for e in apart):
            continue
        here = [c for c in kept if c.distance_to(o.x, o.y) < SAME_SHERD and same_size(c, o)]
        if here:
            kept.remove(min(here, key=lambda c: c.distance_to(o.x, o.y)))
    return kept


def view_over(b, x: float, y: float) -> Optional[Tuple[float, float]]:
    """Where the wrist camera can look down from the survey height to see (x, y) near its
    image's centre: over it, else up to LOOK_BACK nearer the base (the mat's far corners are
    out of reach at that height), or None."""
    from rascal_tasks.config import top_down_reachable  # config imports this module

    z = b.pickup.surface_z + b.config["survey"]["z"]
    r = math.hypot(x, y)
    for k in range(7):
        shrink = max(0.0, r - LOOK_BACK * k / 6) / r
        ex, ey, _ = gripper_for_camera_over(x * shrink, y * shrink)
        if top_down_reachable(ex, ey, z):
            return x * shrink, y * shrink
    return None


def inside(part: Leftover, whole) -> bool:
    """Whether `part`'s centre lies within a sherd (or leftover) seen whole: within half its
    length of its centre."""
    return any(o.distance_to(part.x, part.y) <= o.length / 2 for o in whole)


def look_at_cut_sherds(b, look, found: List[Observation], parts: List[Leftover]):
    """Sherds the image border cut in every view so far (a sherd across the mat's edge lies
    partly beyond the lawnmower's views, and perception offers only what it sees whole): each is
    looked at from a view of its own (`look(x, y)`, which adds to `found`, `b.leftovers` and
    `parts`), at most MAX_EXTRA_LOOKS. One still cut after it, or out of the camera's reach, is
    left for a person as a leftover, said at the batch's end."""

    def unexplained():
        return [p for p in parts if not inside(p, found) and not inside(p, b.leftovers)]

    looked: List[Tuple[float, float]] = []
    while len(looked) < MAX_EXTRA_LOOKS:
        # a view not yet taken (one already taken saw it cut again: too long for a view)
        views = [
            (p, at)
            for p, at in ((p, view_over(b, p.x, p.y)) for p in unexplained())
            if at is not None
            and all(math.hypot(at[0] - x, at[1] - y) > SAME_SHERD for x, y in looked)
        ]
        if not views:
            break
        p, at = views[0]
        looked.append(at)
        b.log(
            "survey: a sherd at (%.3f, %.3f) m is cut by the image border in every view: "
            "looking from (%.3f, %.3f) m" % (p.x, p.y, at[0], at[1])
        )
        look(*at)
    for p in unexplained():  # out of reach, too long for a view, or past the looks
        if not inside(p, b.leftovers):
            why = "only part of it seen (the image border cut it in every view the arm reaches)"
            b.leftovers.append(replace(p, why=why, cut_by_border=False))


def merge(found: List[Observation], new: List[Observation]) -> List[Observation]:
    """Add to `found` the detections of `new` that are not a sherd already in it."""
    for o in new:
        if all(o.distance_to(p.x, p.y) > SAME_SHERD for p in found):
            found.append(o)
    return found


def survey_pickup_area(b) -> List[Observation]:
    """The lawnmower over the pickup area, views merged. Sherds the gripper failed on
    again and again are left out: they stay where they are, for a person. What the views saw
    on the mat but perception does not offer as sherds (too small, too large) is kept in
    `b.leftovers`, merged the same way: a batch that ends with them there says so. A sherd the
    image border cut in every view gets a look of its own (look_at_cut_sherds)."""
    found: List[Observation] = []
    parts: List[Leftover] = []  # what the image border cut, reaching onto the mat
    b.leftovers = []

    def look(x, y):
        merge(found, survey_at(b, b.pickup, x, y))
        new = b.rig.perception.leftovers(b.pickup.name)
        parts.extend(lo for lo in new if lo.cut_by_border and on_the_mat(b.pickup.area, lo))
        merge(
            b.leftovers,
            [
                lo
                for lo in new
                if not lo.cut_by_border
                and on_the_mat(b.pickup.area, lo)
                and all(o.distance_to(lo.x, lo.y) > SAME_SHERD for o in found)
            ],
        )

    for x, y in b.pickup.area.lawnmower(b.config["survey"]["step"]):
        look(x, y)
    look_at_cut_sherds(b, look, found, parts)
    # a sherd seen whole in a later view is not a leftover of an earlier one
    b.leftovers = [
        lo for lo in b.leftovers if all(o.distance_to(lo.x, lo.y) > SAME_SHERD for o in found)
    ]
    account_for_slips(b, found)
    account_for_vanished(b, found)
    b.seen = apart_from_left(found, b.unpickable)
    # what a later "not seen again" is traced from (bench/heap): size, where, how covered
    b.log(
        "survey: %d seen: %s"
        % (
            len(b.seen),
            ", ".join(
                "%.0fx%.0f mm at (%.3f, %.3f) %.0f%%"
                % (o.length * 1e3, o.width * 1e3, o.x, o.y, o.covered * 100)
                for o in b.seen
            ),
        )
    )
    return list(b.seen)


class Survey(BatchState):
    """Survey the pickup area and queue what is there in the order of the selection policy."""

    def __init__(self, batch):
        super().__init__(batch, ["found", "empty"])

    def run(self):
        b = self.batch
        found = survey_pickup_area(b)
        if not found:
            if lay_flat(b):  # a sherd standing on its edge, pushed over: it may be picked now
                return self.run()
            # a sherd left on a station (one that rode onto the scale on the last sherd, where
            # no later station gave the pan time to settle empty) is taken to the mat first
            if any(p.while_away() for p in b.plugins if not p.stays):
                return self.run()
            b.empty_surveys += 1
            if b.empty_surveys >= b.config["recovery"]["max_empty_surveys"]:
                if b.renumber is not None:  # its number must not stay unfinished
                    b.sherd, b.renumber = b.renumber, None
                    b.sherd.lose(b.renumber_unused)
                for lo in b.leftovers:
                    b.event(None, "not_taken", describe_leftover(lo))
                return "empty"
            return self.run()
        b.empty_surveys = 0
        b.pending = in_pick_order(
            found, b.config["perception"]["selection_policy"], slipped_from=b.slipped_from
        )
        b.pending_stale = False
        return "found"


class NextSherd(BatchState):
    """After a sherd: take the next one already seen, or survey again. A covered sherd is never
    taken from an old survey: what lay on it has been picked since, so it shows more of itself
    now than was measured (and may have moved)."""

    def __init__(self, batch):
        super().__init__(batch, ["pickup", "survey"])

    def label(self):
        return "Next sherd"

    def run(self):
        b = self.batch
        if b.pending and covered(b.pending[0]):
            b.pending = []
        return "pickup" if b.pending else "survey"
