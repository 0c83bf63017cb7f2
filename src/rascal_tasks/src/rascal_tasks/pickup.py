"""PICKUP: the next sherd of the survey is grasped from the pickup area and, once it is in the
gripper, numbered. No ROS in here.
"""

import dataclasses
import math
from typing import Optional, Tuple

from rascal_tasks.batch import BatchState
from rascal_tasks.manipulation import grasp_retrying, holdable, openings
from rascal_tasks.rig import Observation
from rascal_tasks.sherd_record import SherdRecord
from rascal_tasks.singulation import part_from_neighbours
from rascal_tasks.selection import (
    among_others,
    apart_from_left,
    covered,
    itself,
    taken_again,
)
from rascal_tasks.survey import reachable_look_yaws, survey_at
from rascal_tasks.wrist import route_yaw, same_grasp_yaws


class Pickup(BatchState):
    """Pick the next sherd from the pickup area; number it once it is in the gripper."""

    next_sherd = "missed"

    def __init__(self, batch):
        super().__init__(batch, ["held", "missed"])

    def run(self):
        b = self.batch
        # the first station may get ready for this sherd meanwhile (the scale's tare, then
        # checked by the time the sherd is carried there: lowered onto it without a stop)
        b.plugins[0].while_away(arm_free=False)
        o = surveyed = b.pending.pop(0)
        if b.pending_stale:
            # the mat changed since the survey (a grasp here): the sherd is grasped where the
            # wrist camera sees it now, never where it lay before
            o = look_again(b, o)
            if o is None:
                b.pending = []
                return "missed"
        b.pending_stale = True
        if self.parted_first(o):
            return "missed"
        if too_short_to_hold(b, o):
            return self.left_unheld(o)
        slips = len(b.lift_slips)
        o, tries, held = grasp_retrying(b, o, b.pickup, taken_for=surveyed)
        # a sherd that slipped out while lifted has no number yet: the next survey must see it
        # again (survey.account_for_slips), unless the retry took it at once
        b.unchecked_slips += [s for s in b.lift_slips[slips:] if not (held and taken_again(o, s))]
        if held:
            if b.renumber is not None:  # two were put back: this one takes over that number
                b.sherd, b.renumber = b.renumber, None
                b.sherd.taken_over(o, b.pickup)
            else:
                b.sherd = SherdRecord.picked(b, o, b.pickup, tries)
            b.sherd.among_others = among_others(o, b.seen + b.leftovers, b.put_back_at)
            b.log(  # what a heap's rows are traced from (bench/heap)
                "sherd %d picked as %.0f x %.0f mm, top %.1f mm on %.1f mm, wall %.1f mm, %.0f %% "
                "covered, grasped %.0f deg off its width%s%s"
                % (
                    b.sherd.seq,
                    o.length * 1000,
                    o.width * 1000,
                    o.height * 1000,
                    o.support * 1000,
                    o.thickness * 1000,
                    o.covered * 100,
                    abs(math.degrees(o.grasp_turn)),
                    "" if o.grasp_clear else ", no grasp clear of its neighbours",
                    ", among others" if b.sherd.among_others else "",
                )
            )
            return "held"
        attempts = b.config["recovery"]["max_grasp_attempts"]
        others, b.pending = b.pending, []  # the area changed under us: survey again
        key = miss_spot(b, o)
        b.misses[key] = b.misses.get(key, 0) + 1
        if b.misses[key] >= 2 and self.singulate(o, others, key):
            return "missed"
        if b.misses[key] >= 2:
            b.unpickable.append((o.x, o.y))
            b.event(
                None,
                "unpickable",
                "sherd at (%.3f, %.3f) m left in the pickup area after "
                "%d failed grasps" % (o.x, o.y, 2 * attempts),
            )
        return "missed"

    def parted_first(self, o: Observation) -> bool:
        """No grasp of `o` clears its neighbours (perception's grasp_clear false: every grasp
        found comes down on one, or closes along its length where one turned so far clears
        them), and it lies uncovered: first in the pick order, so no sherd lying free has a
        clear grasp either. It is pushed apart from its neighbours before any grasp
        (singulation.part_from_neighbours: once a sherd and a spot, within the batch's pushes)
        and the area surveyed again; one pushed so before is grasped as it is. Grasped so, the
        fingers come down on a neighbour or close along its length, and in heaps those turned
        pickups (slip chances 0.3-0.6 in the simulator) gave most of the drops to expect beyond
        the 0.02 of every grasp (docs/heap_runs.md, session 44)."""
        b = self.batch
        others = [c for c in b.pending if not itself(c, o)]
        if o.grasp_clear or covered(o) or not others:
            return False
        if not part_from_neighbours(
            b,
            o,
            others,
            miss_spot(b, o),
            "before a grasp: none of its grasps clears them (turned %.0f deg off its width)"
            % abs(math.degrees(o.grasp_turn)),
        ):
            b.log(  # for tracing a run
                "the sherd at (%.3f, %.3f) m has no grasp clear of its neighbours and is not "
                "pushed (pushed before; no push whose fingers and path are clear of them and that "
                "keeps it on the mat; or the batch's pushes spent): grasped as it is" % (o.x, o.y)
            )
            return False
        b.pending = []
        return True

    def singulate(self, o, others, key) -> bool:
        """Failed twice here: pushed apart from its neighbours (singulation.part_from_neighbours).
        True when it was pushed."""
        attempts = self.batch.config["recovery"]["max_grasp_attempts"]
        return part_from_neighbours(
            self.batch, o, others, key, "after %d failed grasps" % (2 * attempts)
        )

    def left_unheld(self, o: Observation) -> str:
        """Shorter than the fingers close: no chord of it can be held, so it is left at once and
        said with the fix (stock fingers: 35 closes on nothing for eight 16-25 mm sherds)."""
        b = self.batch
        b.unpickable.append((o.x, o.y))
        pads = b.config["arm"]["gripper"]["fingertip_pads"]
        fix = (
            "thicker fingertip pads than the %.1f mm fitted" % (pads * 1000)
            if pads
            else "fingertip pads"
        )
        b.event(
            None,
            "unpickable",
            "sherd at (%.3f, %.3f) m left in the pickup area: %.0f x %.0f mm is shorter than the "
            "fingers can hold (they close to %.0f mm); fit %s (arm.gripper.fingertip_pads) for "
            "sherds this small, or record it by hand"
            % (o.x, o.y, o.length * 1000, o.width * 1000, openings(b.config)[0] * 1000, fix),
        )
        return "missed"

    def sherd_failed(self, failure):
        """Its grasp was refused: it has no number (it never left the mat), and another try
        would be refused too, so it is left for a person at once."""
        b = self.batch
        o = failure.observation
        b.pending = []
        b.unpickable.append((o.x, o.y))
        b.event(
            None,
            "unpickable",
            "sherd at (%.3f, %.3f) m left in the pickup area: %s" % (o.x, o.y, failure.reason),
        )
        return "missed"


def too_short_to_hold(b, o: Observation) -> bool:
    """Whether even `o`'s longest chord is too short for the fingers (manipulation.holdable)."""
    return not holdable(b.config, o.length)


# Misses this near one spot (its 1 cm grid point) are at that spot: the fingers nudge a sherd
# they miss by millimetres.
SAME_SPOT = 0.01


def miss_spot(b, o: Observation) -> Tuple[float, float]:
    """The spot (x, y rounded to 1 cm) that a failed pickup of `o` counts against: the nearest
    earlier miss's within SAME_SPOT, else its own. By the grid alone a sherd nudged across a
    grid line (0.0849 -> 0.0851 m) started again at no misses: heap seed 39 missed nine grasps,
    three rounds, on a sherd lying across another before the push after two rounds."""
    nearest = min(b.misses, key=lambda k: o.distance_to(*k), default=None)
    if nearest is not None and o.distance_to(*nearest) < SAME_SPOT:
        return nearest
    return (round(o.x, 2), round(o.y, 2))


def look_again(b, o: Observation) -> Optional[Observation]:
    """The wrist camera over `o`, seen by an earlier survey (`look_from`): the detection
    nearest it now (within recovery.search_radius: a neighbour's grasp may have nudged it), or
    None when nothing pickable lies there any more (it was moved away, or now lies under
    another)."""
    radius = b.config["recovery"]["search_radius"]
    near = [
        c
        for c in apart_from_left(survey_at(b, b.pickup, *look_from(b, o)), b.unpickable)
        if c.distance_to(o.x, o.y) < radius
    ]
    if not near:
        b.log("the sherd seen at (%.3f, %.3f) m is not there now: surveying again" % (o.x, o.y))
        return None
    c = min(near, key=lambda c: c.distance_to(o.x, o.y))
    if covered(c):
        b.log("the sherd at (%.3f, %.3f) m is covered now: surveying again" % (c.x, c.y))
        return None
    if itself(c, o):
        return dataclasses.replace(c, **both_views_diameter(o, c))
    return c


def both_views_diameter(a: Observation, b: Observation) -> dict:
    """The vessel diameter of one sherd seen from two views, as Observation fields: the
    inverse-variance mean of the two curvatures (2 / diameter), or the one view that told it.
    One frame's curvature fit scatters by its sigma (bench/perception: within 15 % of the
    truth for 96.6 % of those told); two independent views narrow it."""
    told = [o for o in (a, b) if o.vessel_diameter > 0.0 and o.vessel_diameter_sigma > 0.0]
    if len(told) < 2:
        best = told[0] if told else b
        return {
            "vessel_diameter": best.vessel_diameter,
            "vessel_diameter_sigma": best.vessel_diameter_sigma,
        }
    # curvature k = 2 / D, its sigma 2 sigma_D / D^2
    k = [2.0 / o.vessel_diameter for o in told]
    w = [(o.vessel_diameter**2 / (2.0 * o.vessel_diameter_sigma)) ** 2 for o in told]
    mean = (k[0] * w[0] + k[1] * w[1]) / (w[0] + w[1])
    sigma_k = (w[0] + w[1]) ** -0.5
    diameter = 2.0 / mean
    return {"vessel_diameter": diameter, "vessel_diameter_sigma": diameter**2 * sigma_k / 2.0}


def look_from(b, o: Observation) -> Tuple[float, float, Optional[float]]:
    """Where the wrist camera looks at `o` from, (x, y, gripper yaw or None: facing away from
    the base), the first the arm reaches at the survey height (survey.reachable_look_yaws):
    over it, the gripper turned as its grasp will be along the sherd's way (wrist.route_yaw;
    the fingers are alike turned by pi), so the move down to the grasp turns no wrist; over it,
    facing away from the base; else the survey's view nearest it, which saw it before (the far
    corners of the mat are out of reach at the survey height)."""
    z = b.pickup.surface_z + b.config["survey"]["z"]
    route = b.route()
    g = route_yaw(b.config, b.last_pose, (o.grasp_x, o.grasp_y), o.grasp_yaw, route)
    reachable = reachable_look_yaws(o.x, o.y, z, same_grasp_yaws(g) + (None,))
    if reachable:
        return o.x, o.y, reachable[0]
    area = b.pickup.area
    views = area.lawnmower(b.config["survey"]["step"])
    x, y = min(views, key=lambda v: o.distance_to(*v))
    return x, y, None
