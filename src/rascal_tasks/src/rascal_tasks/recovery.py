"""RECOVER_i: a sherd dropped on its way, looked for and picked up again, or recorded lost.
No ROS in here.
"""

import math

from rascal_tasks.batch import BatchState
from rascal_tasks.manipulation import grasp_retrying, holdable
from rascal_tasks.pickup import miss_spot
from rascal_tasks.rig import Observation
from rascal_tasks.selection import slipped_here, turned
from rascal_tasks.sherd_record import SherdRecord
from rascal_tasks.singulation import part_from_neighbours
from rascal_tasks.survey import survey_at, survey_pickup_area


def unlikeness(c: Observation, length: float, width: float, ref) -> float:
    """How unlike a detection `c` is a sherd of `length` x `width` (m) last seen at `ref`.
    A drop scatters a sherd by centimetres; its size is measured within ~3 mm, so a size
    difference weighs four times a distance."""
    return c.distance_to(*ref) + 4 * (abs(c.length - length) + abs(c.width - width))


def unlike(like: Observation, c: Observation, ref) -> float:
    """How unlike detection `c` is the sherd seen as `like`, last seen at `ref` (unlikeness)."""
    return unlikeness(c, like.length, like.width, ref)


class Recover(BatchState):
    """A dropped sherd: look where it was last seen; then, if it was on its way from the pickup
    area, where it was picked up and over the whole pickup area (a grasp that slips while lifting
    drops it back there), or, if it was already measured, at the station it was carried to (it
    was never above the pickup area again, and a sherd from there would put another sherd's
    mass or photo in its row). Of what is found, the one most like it (position, then size) is
    taken, so another sherd lying near is not; what lies off a station is left for a person.
    One found on the pickup mat before it was measured that the grasps fail on is not lost: it
    lies among the bag's sherds, and its number goes to the next sherd picked ('returned').
    One measured at every station, dropped on its way to the discard box, is looked for only
    where it was lifted (where the next sherd goes): not seen there, it is recorded done, said
    on its row ('done'): its row is whole, and a sherd in the box is where it was going."""

    next_sherd = "lost"

    def __init__(self, batch):
        super().__init__(batch, ["held", "lost", "returned", "done"])

    def run(self):
        b = self.batch
        s = b.sherd
        too_often = s.drops > b.config["recovery"]["max_searches"]
        if too_often and s.station_index >= 0:
            return self.lose("dropped %d times" % s.drops)
        station, candidates, ref = self.search(s)
        like = s.observation
        if too_often:
            return self.too_often(s, station, candidates, ref)
        if not candidates and self.measured(s):
            return self.done_unseen(s)
        if not candidates:
            return self.lose(
                "not found where it was last seen (%s)%s"
                % (s.where, ", nor in the pickup area" if s.station_index < 0 else "")
            )

        def like_it(c, _last=None):
            return unlike(like, c, ref)

        it = min(candidates, key=like_it)
        if self.turned_amid_others(s, station, it, candidates):
            return self.taken_later(s, it)
        if self.pushed_apart(s, station, it, candidates):
            return self.returned(
                s,
                "dropped again on its way from the pickup mat by a grasp turned %.0f deg off its "
                "width" % abs(math.degrees(it.grasp_turn)),
                "pushed apart from its neighbours at (%.3f, %.3f) m" % (it.x, it.y),
            )
        o, tries, held = grasp_retrying(b, it, station, like=like_it)
        if not held:
            why = "found but could not be picked up (%d grasps)" % tries
            if station is b.pickup and s.station_index < 0:
                return self.returned(s, "dropped back onto the pickup mat, %s" % why)
            return self.lose(why)
        b.event(
            s, "recovered", "picked up again at the %s, (%.3f, %.3f) m" % (station.name, o.x, o.y)
        )
        s.grasped_as(o, station)
        if station is b.pickup and s.station_index < 0:
            # Picked afresh from the pickup area: what is in the gripper now is what gets measured.
            s.seen(o, b.pickup)
            s.record_dimensions(o)
        return "held"

    def too_often(self, s: SherdRecord, station, candidates, ref) -> str:
        """`s`, not measured yet, slipped out of the fingers on its way from the pickup mat as
        often as recovery.max_searches allows. Lying on the mat again, it is not lost (heap_20
        seed 60: a sherd grasped along its length amid its neighbours was recorded lost twice,
        three drops each, and then recorded under a third number): its number goes to the next
        sherd picked, and it is taken after the others (selection.in_pick_order), whose going
        may leave it a grasp that holds; slipping as often from there again, it is left for a
        person. Not seen on the mat: lost."""
        b = self.batch
        if station is not b.pickup or not candidates:
            return self.lose("dropped %d times" % s.drops)
        c = min(candidates, key=lambda c: unlike(s.observation, c, ref))
        again = slipped_here(c, b.slipped_from)
        b.slipped_from.append((c.x, c.y))
        why = "dropped %d times on its way from the pickup mat" % s.drops
        if again:
            b.unpickable.append((c.x, c.y))
            b.event(
                None,
                "unpickable",
                "sherd at (%.3f, %.3f) m left in the pickup area: it slipped out of the fingers "
                "%d times on its way, twice over; lay it apart from the others, or record it by "
                "hand" % (c.x, c.y, s.drops),
            )
        return self.returned(
            s,
            why,
            "it lies there again at (%.3f, %.3f) m%s"
            % (c.x, c.y, "" if again else ", taken after the others"),
        )

    def turned_amid_others(self, s: SherdRecord, station, it: Observation, candidates) -> bool:
        """Whether `s`, not measured yet and dropped back onto the pickup mat, would be grasped
        again as it slipped: `it`, its detection there, still has a grasp turned off its minor
        axis (selection.turned: neighbours in the way), other sherds lie there to take first,
        and it has not been put off so before (selection.SLIPPED_HERE of a spot of
        `slipped_from`). heap_25_offcentre seed 71: a 62 x 32 mm sherd among others grasped
        along its length, slip chance 0.62, dropped three times in a row by the same grasp
        before it was taken after the others; once they are gone its grasp closes across."""
        return self._turned_amid(s, station, it, candidates) and not slipped_here(
            it, self.batch.slipped_from
        )

    def _turned_amid(self, s: SherdRecord, station, it: Observation, candidates) -> bool:
        """Whether `s`, not measured yet, lies on the pickup mat again as `it`, whose grasp is
        turned off its minor axis (selection.turned), with other sherds there (nothing else
        there: nothing will clear its neighbours), and wide enough to be held across
        (manipulation.holdable: one narrower is turned because the fingers cannot hold it across,
        not for its neighbours, and neither their going nor a push gives it a grasp across;
        heap_22_corner seed 113: a 48 x 30 mm sherd put off, dropped again and pushed)."""
        if station is not self.batch.pickup or s.station_index >= 0 or not turned(it):
            return False
        if not holdable(self.batch.config, it.width):
            return False
        return any(c is not it for c in candidates)

    def pushed_apart(self, s: SherdRecord, station, it: Observation, candidates) -> bool:
        """Whether `s`, not measured yet, dropped back onto the pickup mat by a grasp turned amid
        its neighbours after it was put off so once (turned_amid_others) and picked again before
        they were gone, was pushed apart from them (singulation.part_from_neighbours) instead of
        grasped so a third time. heap_22_corner seed 85: a sherd lying on another, seen as a
        50 x 17 mm part of itself, 48 % covered, was grasped along its length seven times at
        slip chances 0.80-0.90 (three drops) before it held; a push takes a sherd off the one
        it lies on, and the next survey sees both apart."""
        b = self.batch
        if not self._turned_amid(s, station, it, candidates):
            return False
        if not slipped_here(it, b.slipped_from):
            return False
        return part_from_neighbours(
            b,
            it,
            [c for c in candidates if c is not it],
            miss_spot(b, it),
            "after it slipped out of the fingers twice on its way, grasped %.0f deg off its width"
            % abs(math.degrees(it.grasp_turn)),
        )

    def taken_later(self, s: SherdRecord, it: Observation) -> str:
        """`s` (turned_amid_others) left on the mat for after the others: its number goes to
        the next sherd picked; picked again from there, it is handled as any other."""
        self.batch.slipped_from.append((it.x, it.y))
        return self.returned(
            s,
            "dropped on its way from the pickup mat by a grasp turned %.0f deg off its width to "
            "clear its neighbours" % abs(math.degrees(it.grasp_turn)),
            "it lies there again at (%.3f, %.3f) m, taken after the others, whose going may "
            "leave it a grasp across" % (it.x, it.y),
        )

    def returned(self, s: SherdRecord, why: str, where: str = "") -> str:
        """`s`, not measured, lies among the bag's sherds on the pickup mat again (`why`, and
        `where`, said on its row): its number goes to the next sherd picked."""
        self.batch.event(
            s,
            "returned_to_mat",
            "%s%s; this number goes to the next sherd picked"
            % (why, ", " + where if where else ""),
        )
        self.batch.number_to_next_pick(s, "%s, not picked again" % why)
        return "returned"

    def measured(self, s: SherdRecord) -> bool:
        """Whether every station after the last one done with `s` only lets it fall (the
        discard box): nothing is left to measure."""
        later = self.batch.plugins[s.station_index + 1 :]
        return s.station_index >= 0 and all(p.release_from_above for p in later)

    def done_unseen(self, s: SherdRecord) -> str:
        """`s`, measured, not where it was lifted: recorded done, where it may lie said."""
        box = self.batch.plugins[s.station_index + 1].target(s)
        self.batch.event(
            s,
            "not_seen_discarded",
            "dropped on its way to the %s and not on the %s it was lifted from: it lies in the "
            "box or on the table near the way; every measurement was taken before"
            % (box.name, s.where),
        )
        s.done()
        return "done"

    def lose(self, reason: str) -> str:
        self.batch.sherd.lose(reason)
        return "lost"

    def search(self, s: SherdRecord):
        """(station, detections, reference point) of the first place that shows something."""
        b = self.batch
        where = b.config.stations.get(s.where, b.pickup)
        places = [(where, s.last_xy)]
        if s.station_index >= 0:
            # Lifted from a station after it was measured: it was never above the pickup area
            # again. It fell where it was lifted, or where it was carried to.
            nxt = s.station_index + 1
            if self.measured(s):
                pass  # one in the box is where it was going; none is picked out of it
            elif nxt < len(b.plugins) and b.plugins[nxt].lies_at is not where:
                places.append((b.plugins[nxt].lies_at, b.plugins[nxt].lies_at.place_at))
        elif s.picked_xy is not None and (where is not b.pickup or s.picked_xy != s.last_xy):
            places.append((b.pickup, s.picked_xy))
        for station, xy in places:
            seen = survey_at(b, station, *xy)
            # What the wrist camera sees beyond the station (the table around the scale) lies
            # at another height than the station's surface the grasp is planned from.
            on = [o for o in seen if station.area.has((o.x, o.y))]
            for o in seen:
                if o not in on:
                    b.event(
                        s,
                        "seen_off_station",
                        "a sherd at (%.3f, %.3f) m, off the %s: "
                        "left for a person" % (o.x, o.y, station.name),
                    )
            if on:
                return station, on, xy
        if s.station_index >= 0:
            return where, [], s.last_xy
        return b.pickup, survey_pickup_area(b), s.picked_xy or s.last_xy
