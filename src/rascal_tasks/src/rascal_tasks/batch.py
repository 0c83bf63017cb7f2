"""What every state of a batch shares (`Batch`), and how a state turns failures into outcomes
(`BatchState`, following the rule of `failures.py`). No ROS here: the rig, recorder and
progress callback are injected.
"""

import contextlib
import threading
from dataclasses import dataclass
from typing import Callable, List, Optional, Tuple

from rascal_tasks.catalogue.errors import CatalogueError
from rascal_tasks.failures import LOSE_SHERD, SherdFailure, classify
from rascal_tasks.rig import Observation, Rig, RigError, Timings
from rascal_tasks.sherd_record import SherdRecord
from rascal_tasks.stations import STATION_PLUGINS

try:  # a rig with real smach uses it; ours has the same names and semantics
    import smach
except ImportError:  # pragma: no cover - depends on the machine
    from rascal_tasks import smach


# Events after which the machine ends the batch: the last one is why (batch.stop_reason).
STOPPING_EVENTS = ("rig_error", "stopped", "database_error", "park_failed")


# Why a sherd of the bag was looked for and not seen again (the batch event's kind and the key of
# the batch_ended log): it slipped out of the fingers while lifted; it lay near the mat's edge
# and a grasp beside it may have pushed it off.
SLIPPED_AWAY = "slipped_away"
PUSHED_OFF = "not_seen_again"


@dataclass(frozen=True)
class NotSeenAgain:
    """A sherd on the pickup mat, never recorded, that the survey after it did not see again:
    it may lie beside the mat, for a person to look for."""

    kind: str  # SLIPPED_AWAY or PUSHED_OFF
    x: float  # [m] where it was last seen, in base_link
    y: float
    seen: Observation  # how it was seen there (its size)


class Batch:
    """Everything the states share: config, rig, recorder, and the sherd in hand."""

    def __init__(
        self,
        config,
        rig: Rig,
        recorder,
        context: str,
        progress: Optional[Callable[[str], None]] = None,
        log=None,
    ):
        self.config = config
        self.rig = rig
        self.recorder = recorder  # rascal_tasks.recorder.Recorder, bound to `context`
        self.context = context
        self.progress = progress or (lambda state: None)
        self.log = log or (lambda msg: None)
        self.sherd: Optional[SherdRecord] = None
        # Time spent for the sherd in progress (or the next one: surveying counts for it).
        self.timings = Timings(started=rig.clock.now())
        self._phases: List[float] = []  # the phases running now, innermost last (phase())
        self.state_times = {}  # state label -> seconds, for the summary and the benchmark
        self.stop_requested = threading.Event()  # set on Ctrl-C: stop at the next rig call
        self.misses = {}  # rounded (x, y) -> pickups that failed there
        self.last_pose = None  # (x, y, yaw) of the last top-down move (wrist.route_yaw)
        # the grasp (an Observation) the arm stands ready to close on, open around the sherd:
        # a station brought it there while it waited (manipulation.grasp); any move clears it
        self.poised: Optional[Observation] = None
        # (x, y, yaw): the gripper is low at (x, y) and goes straight up to travel height before
        # its next move, blended into it (lift_later); None when it is not
        self.lift_pending: Optional[tuple] = None
        # the station the last move lowered the held sherd at, ready to let go (Translate)
        self.lowered_at = None
        self.unpickable: List[tuple] = []  # where sherds were left after repeated failures
        # where unmeasured sherds lay that slipped out of the fingers on their way from the
        # pickup mat as often as the recovery allows (recovery.Recover): taken after the others
        self.slipped_from: List[tuple] = []
        self.lift_slips: List[Observation] = []  # grasped sherds that slipped out while lifted
        self.unchecked_slips: List[Observation] = []  # ... not yet looked for by a survey
        self.pushed = set()  # rounded (x, y) where a sherd was pushed apart (singulation.py)
        self.pushed_to: List[tuple] = []  # ((x, y) where it should lie now, its Observation)
        self.pending: List[Observation] = []
        self.pending_stale = False  # a grasp on the pickup mat since `pending` was surveyed
        self.put_back: Optional[tuple] = None  # (seq, x, y): a sherd Home took out of the fingers
        self.put_back_doubles = {}  # seq -> times its grasp was put back as two sherds in one
        self.put_back_at = []  # (x, y) of the pickup mat where a put back set sherds down
        self.two_seen = []  # seqs recorded with a second sherd seen on the scale (put back twice)
        self.maybe_two = []  # seqs recorded as one outline whose wall its mass rules out (a note)
        # seqs photographed over the scale with a sherd on the pan that stayed there when it was
        # lifted off (stations.ScaleStation._left_on_pan)
        self.photo_with_another = []
        # (station name, kg, seq weighed with it): a sherd that stayed on a station's pan and
        # could not be taken to the mat (stations.ScaleStation._left_on_pan), for a person
        self.left_on_station: List[tuple] = []
        # an unmeasured sherd back among the bag's on the mat: its number goes to the next pick
        self.renumber: Optional[SherdRecord] = None
        self.renumber_unused = ""  # why that row is recorded lost if the mat empties first
        self.seen: List[Observation] = []  # the last survey of the pickup area, merged
        # (x, y) where sherds were taken off the pickup mat since that survey
        self.taken_since_survey: List[tuple] = []
        # ((x, y) a push sent it to, its Observation) for the pushes since that survey
        self.pushed_since_survey: List[tuple] = []
        # sherds that slipped while lifted, or lay near the mat's edge, and were not seen again
        self.not_seen_again: List[NotSeenAgain] = []
        # (id, id) of the sherds told apart by colour and logged so (each pair said once)
        self.said_another: set = set()
        # what the last survey saw on the mat but perception did not offer (rig.Leftover)
        self.leftovers: List = []
        self.empty_surveys = 0
        self.stop_reason: Optional[str] = None  # detail of the last STOPPING_EVENTS event
        self.park_failed = False  # workflow.Park could not park the arm
        self.completed = 0  # changed only by SherdRecord._finish
        self.lost = 0  # changed only by SherdRecord._finish
        self.started = rig.clock.now()
        self.station_names = config.station_order()
        self.plugins = [
            STATION_PLUGINS[config.stations[n].type](config.stations[n], self, i)
            for i, n in enumerate(self.station_names)
        ]
        for before, plugin in zip(self.plugins, self.plugins[1:], strict=False):
            if plugin.station.over_scale:  # the camera shoots the sherd where the scale has it
                plugin.lies_at = before.lies_at
        self.pickup = next(s for s in config.stations.values() if s.type == "pickup")

    @contextlib.contextmanager
    def phase(self, name: str):
        """Time spent in `name` (rig.Timings); a phase inside another (the arm moving during
        a capture's transfer) counts as the inner one only, so the phases add up to the time."""
        t0 = self.rig.clock.now()
        self._phases.append(0.0)  # seconds spent in phases nested inside this one
        try:
            yield
        finally:
            spent = self.rig.clock.now() - t0
            self.timings.add(name, spent - self._phases.pop())
            if self._phases:
                self._phases[-1] += spent

    def not_seen(self, kind: str) -> List[Tuple[float, float]]:
        """Where the sherds not seen again for `kind` (SLIPPED_AWAY, PUSHED_OFF) were last seen."""
        return [(u.x, u.y) for u in self.not_seen_again if u.kind == kind]

    def event(self, sherd: Optional[SherdRecord], kind: str, detail: str = ""):
        """Log what happened; a sherd's events also go into its catalogue notes."""
        self.log("%s %s: %s" % ("sherd %d" % sherd.seq if sherd else "batch", kind, detail))
        if kind in STOPPING_EVENTS:
            self.stop_reason = detail
            self.park_failed = self.park_failed or kind == "park_failed"
        if sherd is not None:
            sherd.note("%s: %s" % (kind, detail))

    def check_stop(self):
        if self.stop_requested.is_set():
            raise RigError("batch", "PREEMPTED", "stop requested")

    def move_down(self, x, y, z, yaw, linear=False):
        if self.lift_pending is not None:
            return self.move_through([(x, y, z, yaw, linear)])
        self.check_stop()
        self.last_pose = None  # unknown until the arm got there
        self.poised = self.lowered_at = None
        with self.phase("locomotion"):
            self.rig.arm.move_down(x, y, z, yaw, linear=linear)
        self.last_pose = (x, y, yaw)

    def move_through(self, steps):
        """To each of `steps` ((x, y, z, yaw, linear) as move_down's) in turn, as one motion:
        the next move starts before the one before has stopped wherever the gripper stays above
        arm.blend_z (rig.Arm.move_through); a pending lift (lift_later) goes first."""
        steps = self.take_lift() + list(steps)
        self.check_stop()
        self.last_pose = None
        self.poised = self.lowered_at = None
        with self.phase("locomotion"):
            self.rig.arm.move_through(steps, self.config["arm"]["blend_z"])
        x, y, _z, yaw, _linear = steps[-1]
        self.last_pose = (x, y, yaw)

    def lift_later(self, x, y, yaw):
        """The gripper, low at (x, y), goes straight up to travel height as the first part of
        the next move (move_down, move_through), blended into it: for a lift whose next move
        follows at once, with nothing to check in between."""
        self.lift_pending = (x, y, yaw)

    def take_lift(self) -> list:
        """The pending lift (lift_later) as move steps, taken: for the caller to make first;
        none when there is none."""
        if self.lift_pending is None:
            return []
        x, y, yaw = self.lift_pending
        self.lift_pending = None
        return [(x, y, self.travel_z(), yaw, True)]

    def number_to_next_pick(self, s: "SherdRecord", unused: str):
        """The sherd in progress, not measured, lies among the bag's sherds on the pickup mat
        again: its row's number goes to the next sherd picked there (no gap, no row of two, no
        row lost for a sherd recorded later); `unused`: why that row is recorded lost if the mat
        empties first (survey.Survey)."""
        self.renumber, self.renumber_unused = s, unused
        self.sherd, self.pending = None, []

    def travel_z(self) -> float:
        return self.config["arm"]["travel_z"]

    def route(self) -> list:
        """The stations a sherd is carried to and set down at, in order (config Stations)."""
        return [self.config.stations[n] for n in self.config.route()]

    def next_stays(self, i: int):
        """The plug-in after station `i` when it works on the sherd where `i` left it (`stays`:
        the camera over the scale), else None."""
        after = self.plugins[i + 1] if i + 1 < len(self.plugins) else None
        return after if after is not None and after.stays else None

    def in_the_way(self, station) -> bool:
        """Whether a sherd left lying on `station` lies where a later sherd is placed."""
        return any(p.station is station and not p.release_from_above for p in self.plugins)

    def per_sherd(self) -> float:
        done = self.completed + self.lost
        return (self.rig.clock.now() - self.started) / done if done else 0.0


class BatchState(smach.State):
    """A state with the batch at hand. Checks for preemption between rig calls, and turns what
    goes wrong into an outcome: a failure of this sherd that `failures.classify` lets the batch
    survive records the sherd lost and takes `next_sherd`; anything else aborts (the machine
    parks the arm)."""

    next_sherd: Optional[str] = None  # outcome after a sherd failure (None: it always stops)

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
            try:  # nested: a database error while recording a loss still parks the arm
                return self.run()
            except SherdFailure as f:
                return self.after_sherd_failure(f)
        except RigError as e:
            if e.code == "PREEMPTED" or self.preempt_requested():
                self.service_preempt()
                return "preempted"
            self.report("rig_error", str(e))
            return "aborted"
        except CatalogueError as e:
            b.event(None, "database_error", str(e))  # not into the notes: the database failed
            return "aborted"
        finally:
            b.state_times[label] = b.state_times.get(label, 0.0) + b.rig.clock.now() - t0

    def after_sherd_failure(self, f: SherdFailure) -> str:
        b = self.batch
        if classify(f, left_in_the_way=b.in_the_way(f.station)) == LOSE_SHERD and self.next_sherd:
            return self.sherd_failed(f)
        self.report(
            "stopped",
            "%s; it lies on the %s, unfinished: a restart resumes it" % (f.reason, f.station.name),
        )
        return "aborted"

    def sherd_failed(self, failure: SherdFailure) -> str:
        """The sherd in hand is lost (it lies where it harms nothing); go on with the next."""
        self.batch.sherd.lose(failure.reason)
        return self.next_sherd

    def report(self, kind: str, detail: str):
        """An event against the sherd in hand, in the log alone if its notes cannot be written."""
        try:
            self.batch.event(self.batch.sherd, kind, detail)
        except CatalogueError:
            self.batch.event(None, kind, detail)

    def label(self) -> str:
        return type(self).__name__

    def run(self) -> str:
        raise NotImplementedError
