"""A held sherd's way through the stations: TRANSLATE_i carries it, PLACE_i sets it down,
STATION_i runs the station's plug-in (`stations.py`), REPICK_i picks it up again; PUT_BACK_i
takes two sherds lifted as one back to the pickup mat, apart. No ROS here.
"""

import math
from typing import Optional, Tuple

from rascal_tasks.batch import BatchState
from rascal_tasks.failures import SherdFailure
from rascal_tasks.manipulation import grasp, grasp_where_set_down, release
from rascal_tasks.rig import Observation
from rascal_tasks.selection import STACKED
from rascal_tasks.singulation import lay_flat_at
from rascal_tasks.stations import ScaleStation
from rascal_tasks.survey import survey_at
from rascal_tasks.wrist import station_yaw


class Translate(BatchState):
    """Carry the sherd to a station at travel height and, when the station is ready for it,
    on down to where it is let go in the same motion; a drop on the way goes to RECOVER."""

    def __init__(self, batch, index):
        super().__init__(batch, ["arrived", "dropped"])
        self.index = index

    def label(self):
        return "Translate→%s" % self.batch.station_names[self.index]

    def run(self):
        b = self.batch
        plugin = b.plugins[self.index]
        s = b.sherd
        # the station may get ready for it meanwhile (a scale whose pan has stood empty since
        # the last sherd left it is tared now: with the camera over the scale no later
        # station's work gave it the time)
        plugin.while_away(arm_free=False)
        st = plugin.target(s)
        yaw = station_yaw(b.config, st, s.grasp_yaw)
        steps = [(*st.place_at, b.travel_z(), yaw, False)]
        lower = not plugin.release_from_above and plugin.ready_for_place(s, by_arrival=True)
        if lower:  # on down to where it is let go, as one motion with the carry
            steps.append((*st.place_at, place_z(b, st, s), yaw, True))
        b.move_through(steps)
        if lower:
            b.lowered_at = st
        if not b.rig.gripper.holding():
            b.sherd.dropped("while carrying to %s" % st.name)
            return "dropped"
        return "arrived"


class Place(BatchState):
    """Set the sherd down at the station's spot (or let it fall into the discard box); the
    carry may have lowered it there already (Translate)."""

    def __init__(self, batch, index):
        super().__init__(batch, ["placed"])
        self.index = index

    def label(self):
        return "Place@%s" % self.batch.station_names[self.index]

    def run(self):
        b = self.batch
        plugin = b.plugins[self.index]
        s = b.sherd
        st = plugin.target(s)
        yaw = station_yaw(b.config, st, s.grasp_yaw)
        lowered = b.lowered_at is st  # the carry brought it down already
        if lowered and not plugin.ready_for_place(s):
            # no longer ready (the scale's pan moved since its tare): back up, for the station
            # to get ready with the sherd well clear of it
            b.log("sherd %s: the %s not ready on the arrival: backed up" % (s.seq, st.name))
            b.move_down(*st.place_at, b.travel_z(), yaw, linear=True)
            lowered = False
        plugin.before_place(s)
        if not plugin.release_from_above and not lowered:
            b.move_down(*st.place_at, place_z(b, st, s), yaw, linear=True)
        with b.phase("grasping"):
            # picked up again as wide as the fingers held it (a chord longer than its width)
            s.width = release(b, s.width)
        after = b.next_stays(self.index)
        if after is not None:
            # the next station works on it here (the camera over the scale): straight up, and
            # out of its way while this one measures (the scale settles meanwhile), as one motion
            b.lift_later(*st.place_at, yaw)
            s.placed(st, yaw)
            plugin.while_lifting(s)
            after.make_way(s)
            return "placed"
        if plugin.hover_after_place:  # where repick's grasp starts its descent (no move then)
            b.move_down(*st.place_at, hover_z(b, st, s), yaw, linear=True)
        elif not plugin.release_from_above:
            b.move_down(*st.place_at, b.travel_z(), yaw, linear=True)
        s.placed(st, yaw)
        return "placed"


def hover_z(b, st, s) -> float:
    """Where the gripper waits above sherd `s` lying at station `st`: the repick's descent
    starts here."""
    return st.surface_z + s.grasp_height + b.config["arm"]["approach_offset"]


def place_z(b, st, s) -> float:
    """Where the gripper lets the held sherd `s` go at station `st`: just clear of it."""
    return st.surface_z + s.grasp_height + b.config["arm"]["place_clearance"]


class AtStation(BatchState):
    """Runs the station plug-in (weigh, photograph, discard); after the last station the sherd
    is done. A plug-in's 'failed' is this sherd's failure (failures.py); 'double' (the scale
    weighed two sherds) goes to PUT_BACK."""

    next_sherd = "lost"

    def __init__(self, batch, index):
        super().__init__(batch, ["done", "dropped", "lost", "double"])
        self.index = index

    def label(self):
        return "At %s" % self.batch.station_names[self.index]

    def run(self):
        b = self.batch
        plugin = b.plugins[self.index]
        s = b.sherd
        for earlier in b.plugins[: self.index]:
            if earlier.lies_at is not plugin.lies_at:  # not the scale with the sherd on it
                earlier.while_away()
        if plugin.station.type == "archival_camera":
            # the photo's analysis learns the chart's and bar's sizes (not where they lie)
            use = getattr(b.recorder, "use_archival_station", None)
            if use is not None and getattr(b.recorder, "archival_geometry", 0) is None:
                use(plugin.station, plugin.lies_at)
        outcome = plugin.after_place(s)
        if outcome == "missing":
            s.dropped("not at the %s after placing" % plugin.station.name)
            return "dropped"
        if outcome == "failed":
            raise SherdFailure("the %s station failed for it" % plugin.station.name, plugin.station)
        if outcome == "double":
            return "double"
        if outcome != "done":
            self.report("station_failed", "%s: unknown outcome %r" % (plugin.station.name, outcome))
            return "aborted"
        s.station_done(self.index)
        if self.index == len(b.plugins) - 1:
            s.done()
        return "done"


class Repick(BatchState):
    """Pick the sherd up again where it was placed; re-detect it if the blind grasp misses."""

    next_sherd = "lost"

    def __init__(self, batch, index):
        super().__init__(batch, ["held", "lost"])
        self.index = index

    def label(self):
        return "Repick@%s" % self.batch.station_names[self.index]

    def run(self):
        return "held" if repick(self.batch, self.index) else "lost"


def repick(b, index, blind=True) -> bool:
    """Pick the sherd in progress up again where it was set down at station `index`: blind
    first (where it was placed, as it was held: grasp_where_set_down; unless the station tried
    that already while it waited, and missed, or not `blind`), then from a fresh look on each
    miss (a look that sees it standing on its edge pushes it over first: lay_flat_at). False,
    with the sherd recorded lost, when it could not be taken."""
    s = b.sherd
    plugin = b.plugins[index]
    st = plugin.lies_at
    if plugin.hand_over() and b.rig.gripper.holding():
        return True  # picked up while the station waited (the camera's transfer)
    x, y = s.last_xy
    looks = b.config["recovery"]["max_grasp_attempts"] - 1
    if not blind:
        looks += 1
    elif not plugin.missed_blind() and grasp_where_set_down(b, s, st):
        return True
    for _attempt in range(looks):
        seen = survey_at(b, st, x, y)
        if not seen and lay_flat_at(b, st, x, y):
            seen = survey_at(b, st, x, y)
        if not seen:
            break
        o = seen[0]
        s.grasped_as(o, st)
        if grasp(b, o, st):
            return True
    s.lose("could not pick it up again at %s" % st.name)
    return False


class PutBack(BatchState):
    """Two sherds were lifted as one (the scale weighed more than one sherd of the size seen can
    weigh): both are picked up again and set down low over the freest spot of the pickup mat,
    where they fall apart, and the area is surveyed again. The row keeps its number, with no
    mass: the next sherd picked takes it over (its dimensions recorded afresh), so there is no
    gap and no row of two."""

    next_sherd = "lost"
    AT_MOST = 3  # fetches of what stays on the scale: the two sherds, and one more try

    def __init__(self, batch, index):
        super().__init__(batch, ["surveyed", "lost"])
        self.index = index

    def label(self):
        return "Put back from %s" % self.batch.station_names[self.index]

    def run(self):
        b = self.batch
        s = b.sherd
        st = b.plugins[self.index].lies_at
        # looked at first: the grasp that lifted the two, repeated blind, closes on the top
        # one far off its centre (heap seed 39: a slip chance of 0.84)
        if not repick(b, self.index, blind=False):
            return "lost"  # recorded lost (the two lie at the station, for a person)
        first = free_spot(b.pickup.area, b.seen)
        spots = [first] if self._set_down(*first) else []
        if not spots:
            # what the grasp took fell on the way (back onto the station, or where a later
            # survey finds it): the station is looked at again below, like one it left there
            s.dropped("putting two sherds lifted as one back on the pickup mat")
        plugin = b.plugins[self.index]
        if isinstance(plugin, ScaleStation):
            # the grasp took one of the two, or the carry dropped it back: what the pan still
            # holds is fetched too, each set down apart (the two, and one more try)
            for _ in range(self.AT_MOST):
                if not plugin.holds_something():
                    break
                spot = clear_to_mat(b, st, self._spot_beside(spots))
                if spot is not None:
                    spots.append(spot)
            else:
                if plugin.holds_something():
                    raise SherdFailure(
                        "the second of two sherds lifted as one stays on the %s" % st.name, st
                    )
        if spots == [first]:
            # both came in the one grasp and were set down together: if one still lies on the
            # other, the top one is taken apart (set down together they may not fall apart,
            # and the next grasp would take the two again)
            top = self._lying_on_another(*spots[0])
            if top is not None and grasp(b, top, b.pickup):  # (not asked back where it lay)
                spot = self._spot_beside(spots)
                if self._set_down(*spot, top):
                    spots.append(spot)
        b.put_back_at.extend(spots)  # a sherd picked there is looked at on the scale
        where = ", ".join("(%.3f, %.3f) m" % p for p in spots)
        text = "two sherds in one grasp: %s; this number goes to the next sherd picked" % (
            "put back apart at %s" % where if spots else "they fell on the way back to the mat"
        )
        b.event(s, "put_back", text)
        s.note(text)
        b.number_to_next_pick(s, "put back on the pickup mat as two sherds and not seen again")
        return "surveyed"

    def _spot_beside(self, taken):
        """The freest spot of the pickup mat once something lies at each of `taken` too."""
        b = self.batch
        here = [Observation(*xy, 0.0, 0.1, 0.1, 0.0, *xy, 0.0, 0.0, 0.0) for xy in taken]
        return free_spot(b.pickup.area, b.seen + here)

    def _lying_on_another(self, x, y):
        """The sherd near (x, y) of the pickup mat that lies on another one, or None."""
        b = self.batch
        near = [
            c
            for c in survey_at(b, b.pickup, x, y)
            if c.distance_to(x, y) < b.config["recovery"]["search_radius"]
        ]
        on_top = [c for c in near if c.support > STACKED]
        return max(on_top, key=lambda c: c.height) if on_top else None

    def _set_down(self, x, y, held=None) -> bool:
        """Carry what is in the fingers to (x, y) of the pickup mat and let it go just above;
        `held`: the Observation it was grasped as (default: the sherd in progress). False when
        the fingers came there empty."""
        b = self.batch
        s = b.sherd
        if held is None:
            return set_down_on_mat(b, x, y, s.grasp_yaw, s.grasp_height, s.width)
        height = held.grasp_z - b.pickup.surface_z
        return set_down_on_mat(b, x, y, held.grasp_yaw, height, held.width)


def set_down_on_mat(b, x, y, yaw, height, width) -> bool:
    """Carry what is in the fingers (held `height` above what it lies on, `width` wide) to
    (x, y) of the pickup mat and let it go just above. False, with the fingers opened above,
    when they came there empty: it fell on the way, and lies where it fell, not at (x, y)."""
    b.move_down(x, y, b.travel_z(), yaw)
    if not b.rig.gripper.holding():
        with b.phase("grasping"):
            release(b, width)
        return False
    low = b.pickup.surface_z + height + b.config["arm"]["place_clearance"]
    b.move_down(x, y, low, yaw, linear=True)
    with b.phase("grasping"):
        release(b, width)
    b.move_down(x, y, b.travel_z(), yaw, linear=True)
    return True


def clear_to_mat(b, st, spot=None) -> Optional[Tuple[float, float]]:
    """A sherd left lying on station `st` (the fingers empty) taken back to `spot` of the
    pickup mat (default: its freest), set down as it was grasped, where a later survey finds it
    like any other; that spot, or None when the wrist camera sees nothing there or it could not
    be picked up (a refused grasp included)."""
    seen = survey_at(b, st, *st.place_at)
    if not seen:
        return None
    o = seen[0]
    try:
        if not grasp(b, o, st):
            return None
    except SherdFailure:
        return None  # its grasp was refused: it stays, and is said
    x, y = spot or free_spot(b.pickup.area, b.seen)
    b.pending_stale = True  # the mat changed (or what fell on the way lies somewhere): look again
    if not set_down_on_mat(b, x, y, o.grasp_yaw, o.grasp_z - st.surface_z, o.width):
        return None
    return x, y


def free_spot(area, seen, step=0.01, inset=0.035):
    """The point of `area` (config.Rect; at least `inset` from its edges: half a large sherd)
    with the most room around it: farthest from the outlines of the sherds `seen` there (their
    centres less half their length) and from the mat's edge alike. The edge counts as an
    outline because what is set down there can fall apart or roll over it (heap_20 seed 59: two
    put back 35 mm from the edge, where the heap left the most room, rolled to it and one was
    pushed off by a later grasp beside it); an empty mat's freest spot is its middle."""
    sx, sy = area.size
    nx, ny = max(1, int((sx - 2 * inset) / step)), max(1, int((sy - 2 * inset) / step))
    grid = [  # in the mat's own frame
        (-sx / 2 + inset + i * (sx - 2 * inset) / nx, -sy / 2 + inset + j * (sy - 2 * inset) / ny)
        for i in range(nx + 1)
        for j in range(ny + 1)
    ]
    grid.sort(key=lambda p: math.hypot(*p))  # of equal room, the middlemost
    best, room = area.center, -1.0
    for lx, ly in grid:
        x, y = area.to_table((lx, ly))
        edge = min(sx / 2 - abs(lx), sy / 2 - abs(ly))
        r = min([o.distance_to(x, y) - o.length / 2 for o in seen] + [edge])
        if r > room + 1e-9:
            best, room = (x, y), r
    return best
