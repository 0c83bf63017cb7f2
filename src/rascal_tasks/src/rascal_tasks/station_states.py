"""A held sherd's way through the stations: TRANSLATE_i carries it, PLACE_i sets it down,
STATION_i runs the station's plug-in (`stations.py`), REPICK_i picks it up again. No ROS here.
"""

from rascal_tasks.batch import BatchState
from rascal_tasks.failures import SherdFailure
from rascal_tasks.manipulation import grasp, opening_for
from rascal_tasks.rig import Observation
from rascal_tasks.survey import survey_at


class Translate(BatchState):
    """Carry the sherd to a station at travel height; a drop on the way goes to RECOVER."""

    def __init__(self, batch, index):
        super().__init__(batch, ["arrived", "dropped"])
        self.index = index

    def label(self):
        return "Translate→%s" % self.batch.station_names[self.index]

    def run(self):
        b = self.batch
        st = b.plugins[self.index].target(b.sherd)
        b.move_down(*st.place_at, b.travel_z(), b.sherd.grasp_yaw)
        if not b.rig.gripper.holding():
            b.sherd.dropped("while carrying to %s" % st.name)
            return "dropped"
        return "arrived"


class Place(BatchState):
    """Set the sherd down at the station's spot (or let it fall into the discard box)."""

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
        plugin.before_place(s)
        if not plugin.release_from_above:
            z = st.surface_z + s.grasp_height + b.config["arm"]["place_clearance"]
            b.move_down(*st.place_at, z, s.grasp_yaw, linear=True)
        with b.phase("grasping"):
            b.rig.gripper.open(opening_for(s.width, b.config["arm"]["grasp_margin"]))
        if plugin.hover_after_place:
            b.move_down(
                *st.place_at, z + b.config["arm"]["approach_offset"], s.grasp_yaw, linear=True
            )
        elif not plugin.release_from_above:
            b.move_down(*st.place_at, b.travel_z(), s.grasp_yaw, linear=True)
        s.placed(st)
        return "placed"


class AtStation(BatchState):
    """Runs the station plug-in (weigh, photograph, discard); after the last station the sherd
    is done. A plug-in's 'failed' is this sherd's failure (failures.py)."""

    next_sherd = "lost"

    def __init__(self, batch, index):
        super().__init__(batch, ["done", "dropped", "lost"])
        self.index = index

    def label(self):
        return "At %s" % self.batch.station_names[self.index]

    def run(self):
        b = self.batch
        plugin = b.plugins[self.index]
        s = b.sherd
        if plugin.station.type == "archival_camera":
            # the photo's analysis learns the chart's and bar's sizes (not where they lie)
            use = getattr(b.recorder, "use_archival_station", None)
            if use is not None and getattr(b.recorder, "archival_geometry", 0) is None:
                use(plugin.station)
        outcome = plugin.after_place(s)
        if outcome == "missing":
            s.dropped("not at the %s after placing" % plugin.station.name)
            return "dropped"
        if outcome == "failed":
            raise SherdFailure("the %s station failed for it" % plugin.station.name, plugin.station)
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
        b = self.batch
        s = b.sherd
        st = b.config.stations[b.station_names[self.index]]
        x, y = s.last_xy
        blind = Observation(
            x,
            y,
            s.grasp_yaw,
            s.observation.length,
            s.width,
            0.0,
            x,
            y,
            st.surface_z + s.grasp_height,
            s.grasp_yaw,
            opening_for(s.width, b.config["arm"]["grasp_margin"]),
        )
        o = blind
        for _attempt in range(b.config["recovery"]["max_grasp_attempts"]):
            if grasp(b, o, st):
                return "held"
            seen = survey_at(b, st, x, y)
            if not seen:
                break
            o = seen[0]
            s.grasped_as(o, st)
        s.lose("could not pick it up again at %s" % st.name)
        return "lost"
