"""The station workflow: one bag's sherds, each picked, carried through the stations and recorded.

    HOME -> CALIBRATE -> RESUME -> SURVEY -> PICKUP -> [TRANSLATE -> PLACE -> <station> -> REPICK]*
         -> SURVEY ... -> PARK (when the pickup area stays empty)

The per-station states are generated from the config's station list (`stations.py` holds the
plug-ins). Every measurement is written when taken, and the row's status moves picked ->
weighed -> photographed -> done | lost, so a restart of the same context resumes the sherd that
was in progress instead of numbering it again. No ROS here: the rig, recorder, archive and
progress callback are injected.
"""
import contextlib
import math
import threading
from dataclasses import dataclass, field
from typing import Callable, List, Optional

from rascal_tasks.rig import Observation, Rig, RigError, Timings
from rascal_tasks.stations import STATION_PLUGINS
from rascal_tasks.survey import lawnmower

try:  # a rig with real smach uses it; ours has the same names and semantics
    import smach
except ImportError:  # pragma: no cover - depends on the machine
    from rascal_tasks import smach

# Wrist camera offset from ee_gripper_link when the gripper points down, along the gripper's
# yaw direction: camera_link sits 0.055 m "above" gripper_link (rascal_description URDF).
CAMERA_OFFSET = 0.055
# Finger opening limits between the fingertips (facts §1.4: 30..74 mm).
MIN_OPENING, MAX_OPENING = 0.030, 0.074
# Two detections closer than this are the same sherd seen from two survey poses.
SAME_SHERD = 0.02
# ee_gripper_link height above the pickup mat where Home lets go of a sherd found in the fingers
# after a restart: fingertips 4.4 mm lower, so a sherd up to ~2 cm thick drops a few mm at most.
PUT_BACK_HEIGHT = 0.025


@dataclass
class SherdInProgress:
    seq: int
    observation: Observation
    grasp_yaw: float
    grasp_height: float  # ee height above the surface when closing
    width: float  # sherd width across the fingers (m)
    station_index: int = -1  # last station done (-1: just picked)
    where: str = "pickup"  # station it was last seen at
    last_xy: tuple = (0.0, 0.0)
    picked_xy: Optional[tuple] = None  # where in the pickup area it was picked (unknown on resume)
    drops: int = 0
    mass: Optional[float] = None
    timings: Timings = field(default_factory=Timings)


class BatchAborted(Exception):
    pass


class Batch:
    """Everything the states share: config, rig, recorder, archive, and the sherd in hand."""

    def __init__(self, config, rig: Rig, recorder, context: str,
                 progress: Optional[Callable[[str], None]] = None, log=None):
        self.config = config
        self.rig = rig
        self.recorder = recorder  # rascal_tasks.recorder.Recorder, bound to `context`
        self.context = context
        self.progress = progress or (lambda state: None)
        self.log = log or (lambda msg: None)
        self.sherd: Optional[SherdInProgress] = None
        # Time spent for the sherd in progress (or the next one: surveying counts for it).
        self.timings = Timings()
        self.state_times = {}  # state label -> seconds, for the summary and the benchmark
        self.stop_requested = threading.Event()  # set on Ctrl-C: stop at the next rig call
        self.misses = {}  # rounded (x, y) -> pickups that failed there
        self.unpickable: List[tuple] = []  # where sherds were left after repeated failures
        self.pending: List[Observation] = []
        self.put_back: Optional[tuple] = None  # (seq, x, y): a sherd Home took out of the fingers
        self.empty_surveys = 0
        self.completed = 0
        self.lost = 0
        self.started = rig.clock.now()
        self.station_names = config.station_order()
        self.plugins = [STATION_PLUGINS[config.stations[n].type](config.stations[n], self)
                        for n in self.station_names]
        self.pickup = next(s for s in config.stations.values() if s.type == "pickup")

    # -- helpers used by states and plug-ins ----------------------------------------------------
    @contextlib.contextmanager
    def phase(self, name: str):
        t0 = self.rig.clock.now()
        try:
            yield
        finally:
            self.timings.add(name, self.rig.clock.now() - t0)

    def finish_sherd(self, completed: bool):
        if completed:
            self.completed += 1
        else:
            self.lost += 1
        self.sherd = None
        self.timings = Timings()

    def event(self, sherd, kind: str, detail: str = ""):
        """Log what happened; a sherd's events also go into its catalogue notes."""
        self.log("%s %s: %s" % ("sherd %d" % sherd.seq if sherd else "batch", kind, detail))
        if sherd is not None:
            self.recorder.note(sherd.seq, "%s: %s" % (kind, detail))

    def check_stop(self):
        if self.stop_requested.is_set():
            raise RigError("batch", "PREEMPTED", "stop requested")

    def move_down(self, x, y, z, yaw, linear=False):
        self.check_stop()
        with self.phase("locomotion"):
            self.rig.arm.move_down(x, y, z, yaw, linear=linear)

    def survey_at(self, station, x, y) -> List[Observation]:
        """Put the wrist camera over (x, y) of a station and detect what is there."""
        yaw = math.atan2(y, x)
        ex, ey = x - CAMERA_OFFSET * math.cos(yaw), y - CAMERA_OFFSET * math.sin(yaw)
        self.move_down(ex, ey, station.surface_z + self.config["survey"]["z"], yaw)
        with self.phase("perception"):
            self.rig.clock.sleep(self.config["survey"]["settle_time"])
            return self.rig.perception.detect(station.name)

    def survey_pickup_area(self) -> List[Observation]:
        """The lawnmower over the pickup area, views merged. Sherds the gripper failed on
        again and again are left out: they stay where they are, for a person."""
        found: List[Observation] = []
        for x, y in lawnmower(self.pickup.area.center, self.pickup.area.size,
                              self.config["survey"]["step"]):
            _merge(found, self.survey_at(self.pickup, x, y))
        return [o for o in found if all(o.distance_to(*xy) > 2 * SAME_SHERD
                                        for xy in self.unpickable)]

    def travel_z(self) -> float:
        return self.config["arm"]["travel_z"]

    def per_sherd(self) -> float:
        done = self.completed + self.lost
        return (self.rig.clock.now() - self.started) / done if done else 0.0


def in_pick_order(found: List[Observation], policy: str) -> List[Observation]:
    """The perception's selection policy over the merged survey (the detector orders each
    frame; a survey merges several). Python's sort is stable: detection order breaks ties."""
    if policy == "largest":
        return sorted(found, key=lambda o: -o.length * o.width)
    if policy == "most_isolated":
        def gap(o):  # to the nearest neighbour, edge to edge along the line of centres
            return min((o.distance_to(p.x, p.y) - (o.length + p.length) / 2
                        for p in found if p is not o), default=math.inf)
        return sorted(found, key=lambda o: -gap(o))
    # nearest to the arm's base first: the shortest reach, the least time
    return sorted(found, key=lambda o: math.hypot(o.x, o.y))


def opening_for(width: float, margin: float) -> float:
    return min(MAX_OPENING, max(MIN_OPENING, width + margin))


def _merge(found: List[Observation], new: List[Observation]) -> List[Observation]:
    for o in new:
        if all(o.distance_to(p.x, p.y) > SAME_SHERD for p in found):
            found.append(o)
    return found


class BatchState(smach.State):
    """A state with the batch at hand; checks for preemption between rig calls."""

    def __init__(self, batch: Batch, outcomes):
        smach.State.__init__(self, outcomes=list(outcomes) + ["preempted", "aborted"])
        self.batch = batch

    def execute(self, userdata):
        b = self.batch
        label = self.label()
        b.progress(label)
        if self.preempt_requested():
            self.service_preempt()
            return "preempted"
        t0 = b.rig.clock.now()
        try:
            return self.run()
        except RigError as e:
            if e.code == "PREEMPTED" or self.preempt_requested():
                self.service_preempt()
                return "preempted"
            self.batch.event(self.batch.sherd, "rig_error", str(e))
            return "aborted"
        finally:
            b.state_times[label] = b.state_times.get(label, 0.0) + b.rig.clock.now() - t0

    def label(self) -> str:
        return type(self).__name__

    def run(self) -> str:
        raise NotImplementedError


class Home(BatchState):
    """Open the gripper over the pickup area.

    After a killed run the fingers may still hold its unfinished sherd (or be open around it):
    a close tells. That sherd is set down where it was picked up, which is free, and Resume
    picks it up again; the stations must be calibrated with nothing in the wrist camera's view."""

    def __init__(self, batch):
        super().__init__(batch, ["done"])

    def run(self):
        b = self.batch
        rows = b.recorder.unfinished()
        if rows:
            with b.phase("grasping"):
                in_hand = b.rig.gripper.close().holding
            if in_hand:
                seq, _status, (x, y) = rows[0]
                b.move_down(x, y, b.travel_z(), 0.0)
                # a short drop: after a restart the grasp height is not known
                b.move_down(x, y, b.pickup.surface_z + PUT_BACK_HEIGHT, 0.0, linear=True)
                with b.phase("grasping"):
                    b.rig.gripper.open()
                b.move_down(x, y, b.travel_z(), 0.0, linear=True)
                b.put_back = (seq, x, y)
                b.event(None, "put_back", "sherd %d was in the gripper; set down at its pickup "
                        "spot (%.3f, %.3f) m" % (seq, x, y))
        with b.phase("grasping"):
            b.rig.gripper.open()
        b.move_down(*b.pickup.area.center, b.travel_z(), 0.0)
        return "done"


class Calibrate(BatchState):
    """Learn each station's background from an image of it. The pickup area is full of sherds,
    so its background (the same mat) is learnt where the discard box's mat shows.

    A station where the scale or the camera already sees a sherd keeps the model it had: that
    is a killed run's sherd (or one left by hand), and learning it as background would hide it."""

    def __init__(self, batch):
        super().__init__(batch, ["done"])

    def run(self):
        b = self.batch
        for plugin in b.plugins:
            st = plugin.station
            yaw = math.atan2(st.place_at[1], st.place_at[0])
            x, y = st.place_at
            b.move_down(x - CAMERA_OFFSET * math.cos(yaw), y - CAMERA_OFFSET * math.sin(yaw),
                        st.surface_z + b.config["survey"]["z"], yaw)
            if not plugin.release_from_above:
                seen = b.rig.perception.detect_if_calibrated(st.name)
                if seen:
                    b.event(None, "calibration_kept", "%d sherd(s) lying at the %s: its "
                            "background model from before is kept" % (len(seen), st.name))
                    continue
            b.rig.perception.calibrate(st.name)
            if st.type == "discard":
                b.rig.perception.calibrate(b.pickup.name)
        b.timings = Timings()  # set-up is the batch's, not the first sherd's
        return "done"


class Resume(BatchState):
    """After a restart: find the sherd a killed run left unfinished and carry on with it.

    Outcomes name the state to go on with: TRANSLATE_k (it was in the gripper; Home set it
    down at its pickup spot and it is picked up again),
    STATION_i (it lies placed at station i, not yet measured there), REPICK_i (it lies at
    station i, measured), or SURVEY (nothing unfinished, or it is lost)."""

    def __init__(self, batch):
        n = len(batch.plugins)
        super().__init__(batch, ["SURVEY"] + ["%s_%d" % (k, i) for i in range(n)
                                              for k in ("TRANSLATE", "STATION")]
                         + ["REPICK_%d" % i for i in range(n - 1)])

    def run(self):
        b = self.batch
        rows = b.recorder.unfinished()
        if not rows:
            return "SURVEY"
        seq, status, _pickup_xy = rows[0]
        statuses = [p.status for p in b.plugins]
        done = statuses.index(status) if status in statuses else -1
        b.event(None, "resume", "sherd %d was %s" % (seq, status))
        if b.put_back and b.put_back[0] == seq:
            return self.pick_put_back(seq, done)
        for i in range(max(done, 0), len(b.plugins)):
            st = b.plugins[i].station
            if b.plugins[i].release_from_above:
                break
            seen = b.survey_at(st, *st.place_at)
            if seen:
                o = seen[0]
                b.sherd = SherdInProgress(seq, o, o.grasp_yaw, o.grasp_z - st.surface_z,
                                          o.width, station_index=done, where=st.name,
                                          last_xy=(o.x, o.y), timings=b.timings)
                return ("REPICK_%d" if i == done else "STATION_%d") % i
        b.recorder.lost(seq, "not found after restart (was %s)" % status)
        b.lost += 1
        return "SURVEY"

    def pick_put_back(self, seq, done):
        b = self.batch
        _, x, y = b.put_back
        near = [o for o in b.survey_at(b.pickup, x, y)
                if o.distance_to(x, y) < b.config["recovery"]["search_radius"]]
        for o in sorted(near, key=lambda o: o.distance_to(x, y))[:1]:
            if grasp(b, o, b.pickup.surface_z):
                b.sherd = SherdInProgress(seq, o, o.grasp_yaw, o.grasp_z - b.pickup.surface_z,
                                          o.width, station_index=done, last_xy=(o.x, o.y),
                                          picked_xy=(o.x, o.y), timings=b.timings)
                return "TRANSLATE_%d" % (done + 1)
        b.recorder.lost(seq, "set down at its pickup spot after restart, not picked up again")
        b.lost += 1
        return "SURVEY"


class Survey(BatchState):
    def __init__(self, batch):
        super().__init__(batch, ["found", "empty"])

    def run(self):
        b = self.batch
        found = b.survey_pickup_area()
        if not found:
            b.empty_surveys += 1
            if b.empty_surveys >= b.config["recovery"]["max_empty_surveys"]:
                return "empty"
            return self.run()
        b.empty_surveys = 0
        b.pending = in_pick_order(found, b.config["perception"]["selection_policy"])
        return "found"


class Pickup(BatchState):
    """Pick the next sherd from the pickup area; number it once it is in the gripper."""

    def __init__(self, batch):
        super().__init__(batch, ["held", "missed"])

    def run(self):
        b = self.batch
        o, tries, held = grasp_retrying(b, b.pending.pop(0), b.pickup)
        if held:
            seq = b.recorder.new_sherd((o.x, o.y), attempts=tries)
            b.sherd = SherdInProgress(seq, o, o.grasp_yaw, o.grasp_z - b.pickup.surface_z,
                                      o.width, last_xy=(o.x, o.y), picked_xy=(o.x, o.y),
                                      timings=b.timings)
            b.recorder.dimensions(seq, o.length, o.width, o.height)
            return "held"
        attempts = b.config["recovery"]["max_grasp_attempts"]
        b.pending = []  # the area changed under us: survey again
        key = (round(o.x, 2), round(o.y, 2))
        b.misses[key] = b.misses.get(key, 0) + 1
        if b.misses[key] >= 2:
            b.unpickable.append((o.x, o.y))
            b.event(None, "unpickable", "sherd at (%.3f, %.3f) m left in the pickup area after "
                    "%d failed grasps" % (o.x, o.y, 2 * attempts))
        return "missed"


def grasp_retrying(b: Batch, o: Observation, station, like=None):
    """Grasp `o` at `station`; after a miss, detect again around it and grasp the detection
    nearest it (or least `like`), up to recovery.max_grasp_attempts in all.
    Returns (the last observation tried, grasps made, whether it is held)."""
    rec = b.config["recovery"]
    like = like or (lambda c, last: c.distance_to(last.x, last.y))
    for attempt in range(rec["max_grasp_attempts"]):
        if grasp(b, o, station.surface_z):
            return o, attempt + 1, True
        if attempt + 1 == rec["max_grasp_attempts"]:
            break
        near = [c for c in b.survey_at(station, o.x, o.y)
                if c.distance_to(o.x, o.y) < rec["search_radius"]]
        if not near:
            break
        o = min(near, key=lambda c, last=o: like(c, last))
    return o, attempt + 1, False


def grasp(b: Batch, o: Observation, surface_z: float) -> bool:
    """Open to the planned width (it includes the grasp margin), descend, close, lift."""
    with b.phase("grasping"):
        b.rig.gripper.open(opening_for(o.grasp_width, 0.0))
    approach = o.grasp_z + b.config["arm"]["approach_offset"]
    b.move_down(o.grasp_x, o.grasp_y, approach, o.grasp_yaw)
    b.move_down(o.grasp_x, o.grasp_y, o.grasp_z, o.grasp_yaw, linear=True)
    with b.phase("grasping"):
        held = b.rig.gripper.close().holding
    b.move_down(o.grasp_x, o.grasp_y, b.travel_z(), o.grasp_yaw, linear=True)
    if held and not b.rig.gripper.holding():
        held = False  # slipped out while lifting
    if not held:
        with b.phase("grasping"):
            b.rig.gripper.open(opening_for(o.grasp_width, 0.0))
    return held


class Translate(BatchState):
    """Carry the sherd to a station at travel height; a drop on the way goes to RECOVER."""

    def __init__(self, batch, index):
        super().__init__(batch, ["arrived", "dropped"])
        self.index = index

    def label(self):
        return "Translate→%s" % self.batch.station_names[self.index]

    def run(self):
        b = self.batch
        st = b.config.stations[b.station_names[self.index]]
        b.move_down(*st.place_at, b.travel_z(), b.sherd.grasp_yaw)
        if not b.rig.gripper.holding():
            return dropped(b, "while carrying to %s" % st.name)
        return "arrived"


def dropped(b: Batch, where: str) -> str:
    b.sherd.drops += 1
    b.event(b.sherd, "dropped", where)
    b.recorder.drop(b.sherd.seq, where)
    return "dropped"


class Place(BatchState):
    def __init__(self, batch, index):
        super().__init__(batch, ["placed"])
        self.index = index

    def label(self):
        return "Place@%s" % self.batch.station_names[self.index]

    def run(self):
        b = self.batch
        plugin = b.plugins[self.index]
        st = plugin.station
        s = b.sherd
        plugin.before_place(s)
        if not plugin.release_from_above:
            z = st.surface_z + s.grasp_height + b.config["arm"]["place_clearance"]
            b.move_down(*st.place_at, z, s.grasp_yaw, linear=True)
        with b.phase("grasping"):
            b.rig.gripper.open(opening_for(s.width, b.config["arm"]["grasp_margin"]))
        if plugin.hover_after_place:
            b.move_down(*st.place_at, z + b.config["arm"]["approach_offset"], s.grasp_yaw,
                        linear=True)
        elif not plugin.release_from_above:
            b.move_down(*st.place_at, b.travel_z(), s.grasp_yaw, linear=True)
        s.where, s.last_xy = st.name, st.place_at
        return "placed"


class AtStation(BatchState):
    """Runs the station plug-in (weigh, photograph, discard) and records what it measured."""

    def __init__(self, batch, index):
        super().__init__(batch, ["done", "dropped"])
        self.index = index

    def label(self):
        return "At %s" % self.batch.station_names[self.index]

    def run(self):
        b = self.batch
        outcome = b.plugins[self.index].after_place(b.sherd)
        if outcome == "missing":
            return dropped(b, "not at the %s after placing" % b.station_names[self.index])
        if outcome != "done":
            b.event(b.sherd, "station_failed", b.station_names[self.index])
            return "aborted"
        b.sherd.station_index = self.index
        if self.index == len(b.plugins) - 1:
            b.finish_sherd(completed=True)
        return "done"


class Repick(BatchState):
    """Pick the sherd up again where it was placed; re-detect it if the blind grasp misses."""

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
        blind = Observation(x, y, s.grasp_yaw, s.observation.length, s.width, 0.0, x, y,
                            st.surface_z + s.grasp_height, s.grasp_yaw,
                            opening_for(s.width, b.config["arm"]["grasp_margin"]))
        o = blind
        for _attempt in range(b.config["recovery"]["max_grasp_attempts"]):
            if grasp(b, o, st.surface_z):
                return "held"
            seen = b.survey_at(st, x, y)
            if not seen:
                break
            o = seen[0]
            s.grasp_yaw, s.width = o.grasp_yaw, o.width
            s.grasp_height = o.grasp_z - st.surface_z
        return lose(b, "could not pick it up again at %s" % st.name)


def lose(b: Batch, reason: str) -> str:
    b.event(b.sherd, "lost", reason)
    b.recorder.lost(b.sherd.seq, reason, timings=b.timings.as_dict())
    b.finish_sherd(completed=False)
    return "lost"


class Recover(BatchState):
    """A dropped sherd: look where it was last seen; then, if it was on its way from the pickup
    area, where it was picked up and over the whole pickup area (a grasp that slips while lifting
    drops it back there), or, if it was already measured, at the station it was carried to (it
    was never above the pickup area again, and a sherd from there would put another sherd's
    mass or photo in its row). Of what is found, the one most like it (position, then size) is
    taken, so another sherd lying near is not; what lies off a station is left for a person."""

    def __init__(self, batch):
        super().__init__(batch, ["held", "lost"])

    def run(self):
        b = self.batch
        s = b.sherd
        if s.drops > b.config["recovery"]["max_searches"]:
            return lose(b, "dropped %d times" % s.drops)
        station, candidates, ref = self.search(s)
        like = s.observation
        if not candidates:
            return lose(b, "not found where it was last seen (%s)%s" % (
                s.where, ", nor in the pickup area" if s.station_index < 0 else ""))

        def unlikeness(c):
            # A drop scatters a sherd by centimetres; its size is measured within ~3 mm, so a
            # size difference weighs four times a distance.
            return c.distance_to(*ref) + 4 * (abs(c.length - like.length)
                                              + abs(c.width - like.width))

        o, tries, held = grasp_retrying(b, min(candidates, key=unlikeness), station,
                                        like=lambda c, _last: unlikeness(c))
        if not held:
            return lose(b, "found but could not be picked up (%d grasps)" % tries)
        b.event(s, "recovered", "picked up again at the %s, (%.3f, %.3f) m" % (
            station.name, o.x, o.y))
        s.grasp_yaw, s.width = o.grasp_yaw, o.width
        s.grasp_height = o.grasp_z - station.surface_z
        if station is b.pickup and s.station_index < 0:
            # Picked afresh from the pickup area: what is in the gripper now is what gets measured.
            s.observation, s.where, s.last_xy = o, b.pickup.name, (o.x, o.y)
            b.recorder.dimensions(s.seq, o.length, o.width, o.height)
        return "held"

    def search(self, s: SherdInProgress):
        """(station, detections, reference point) of the first place that shows something."""
        b = self.batch
        where = b.config.stations.get(s.where, b.pickup)
        places = [(where, s.last_xy)]
        if s.station_index >= 0:
            # Lifted from a station after it was measured: it was never above the pickup area
            # again. It fell where it was lifted, or where it was carried to.
            nxt = s.station_index + 1
            if nxt < len(b.plugins) and b.plugins[nxt].station is not where:
                places.append((b.plugins[nxt].station, b.plugins[nxt].station.place_at))
        elif s.picked_xy is not None and (where is not b.pickup or s.picked_xy != s.last_xy):
            places.append((b.pickup, s.picked_xy))
        for station, xy in places:
            seen = b.survey_at(station, *xy)
            # What the wrist camera sees beyond the station (the table around the scale) lies
            # at another height than the station's surface the grasp is planned from.
            on = [o for o in seen if station.area.has((o.x, o.y))]
            for o in seen:
                if o not in on:
                    b.event(s, "seen_off_station", "a sherd at (%.3f, %.3f) m, off the %s: "
                            "left for a person" % (o.x, o.y, station.name))
            if on:
                return station, on, xy
        if s.station_index >= 0:
            return where, [], s.last_xy
        return b.pickup, b.survey_pickup_area(), s.picked_xy or s.last_xy


class Park(BatchState):
    def __init__(self, batch):
        super().__init__(batch, ["done"])

    def execute(self, userdata):  # parks even when preempted
        try:
            park(self.batch)
        except RigError as e:
            self.batch.event(None, "park_failed", str(e))
            return "aborted"
        return "done"


def park(b: Batch):
    b.rig.arm.go("sleep")


def build_machine(batch: Batch):
    """The state machine for one batch; outcomes: finished, preempted, aborted.

    States are numbered by the station's place in the config (TRANSLATE_0 goes to the first
    station after pickup); any state that is preempted or aborts goes through a PARK state."""
    sm = smach.StateMachine(outcomes=["finished", "preempted", "aborted"])
    n = len(batch.plugins)
    fail = {"preempted": "PARK_PREEMPTED", "aborted": "PARK_ABORTED"}

    def add(label, state, **transitions):
        smach.StateMachine.add(label, state, {**transitions, **fail}
                               if not label.startswith("PARK") else transitions)

    with sm:
        add("HOME", Home(batch), done="CALIBRATE")
        add("CALIBRATE", Calibrate(batch), done="RESUME")
        resume = Resume(batch)
        add("RESUME", resume, **{o: o for o in resume.get_registered_outcomes()
                                 if o not in fail})
        add("SURVEY", Survey(batch), found="PICKUP", empty="PARK")
        add("PICKUP", Pickup(batch), held="TRANSLATE_0", missed="SURVEY")
        for i in range(n):
            last = i == n - 1
            add("TRANSLATE_%d" % i, Translate(batch, i),
                arrived="PLACE_%d" % i, dropped="RECOVER_%d" % i)
            add("PLACE_%d" % i, Place(batch, i), placed="STATION_%d" % i)
            add("STATION_%d" % i, AtStation(batch, i),
                done="SURVEY_NEXT" if last else "REPICK_%d" % i, dropped="RECOVER_%d" % i)
            if not last:
                add("REPICK_%d" % i, Repick(batch, i),
                    held="TRANSLATE_%d" % (i + 1), lost="SURVEY_NEXT")
            add("RECOVER_%d" % i, Recover(batch), held="TRANSLATE_%d" % i, lost="SURVEY_NEXT")
        add("SURVEY_NEXT", _Next(batch), pickup="PICKUP", survey="SURVEY")
        add("PARK", Park(batch), done="finished", aborted="aborted", preempted="preempted")
        add("PARK_PREEMPTED", Park(batch), done="preempted", aborted="aborted",
            preempted="preempted")
        add("PARK_ABORTED", Park(batch), done="aborted", aborted="aborted", preempted="aborted")
    return sm


class _Next(BatchState):
    """After a sherd: take the next one already seen, or survey again."""

    def __init__(self, batch):
        super().__init__(batch, ["pickup", "survey"])

    def label(self):
        return "Next sherd"

    def run(self):
        return "pickup" if self.batch.pending else "survey"
