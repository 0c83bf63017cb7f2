"""One sherd's record: what the batch knows of the sherd in progress, and every catalogue write
for it.

A sherd is numbered once it is in the gripper (`SherdRecord.picked`), or taken over from a killed
run (`SherdRecord.resumed`). Its status then moves picked -> weighed -> photographed -> done, or
to lost; `mass_unstable` stands for weighed when the scale gave no trustworthy mass (no mass is
recorded, the row says why). `done` and `lost` both end in `_finish`, the one place that counts
completed and lost sherds. No ROS here.
"""

import dataclasses
import math
from typing import Optional, Tuple

from rascal_tasks.mass_and_size import wall_heavier_than
from rascal_tasks.rig import Observation, Timings
from rascal_tasks.wrist import wrist_angle

FINAL = ("done", "lost")


class SherdRecord:
    def __init__(self, batch, seq: int, status: str = "picked"):
        self.batch = batch  # rascal_tasks.batch.Batch: its recorder, log and counts
        self.seq = seq
        self.status = status  # catalogue status, as far as this run knows
        self.observation: Optional[Observation] = None  # its detection (for its likeness)
        self._size: Optional[Observation] = None  # the detection its size was recorded from
        self.grasp_yaw = 0.0
        self.turn = 0.0  # of the next grasp (Observation.grasp_turn)
        self.grasp_height = 0.0  # ee height above the surface when closing
        self.width = 0.0  # across the fingers (m): seen from above, or as they last held it
        self.station_index = -1  # last station done (-1: none yet)
        self.where = "pickup"  # station it was last seen at
        self.last_xy: Tuple[float, float] = (0.0, 0.0)
        self.picked_xy: Optional[tuple] = None  # where it was picked (None: unknown on resume)
        # picked from among others (selection.among_others): what reaches the scale is looked at
        self.among_others = False
        # seen alone where it was set down (the scale's look: measured_alone): its take-up there
        self.seen_set_down: Optional[Observation] = None
        # its mass said the wall the pickup measured was not one wall (stations.ScaleStation.
        # _wall_doubted): something it lay on may have come up with it
        self.wall_doubted = False
        # the station it was last taken up from high on its edge (manipulation.rider_z), where
        # what it lay on may have stayed: the scale reads that before the row is done
        self.parted_on: Optional[str] = None
        # seen alone on a station, its wall there still more than its mass allows for one sherd
        # of its outline (measured_alone): two lying as one, perhaps, if the take-up high on its
        # edge leaves nothing behind (stations.ScaleStation.while_away flags it)
        self.wall_doubted_alone = False
        self.drops = 0
        self.mass: Optional[float] = None
        self.bin: Optional[str] = None  # the sorting bin it goes into (stations.DiscardStation)
        # The batch's timings since the last sherd ended: surveying counts for this one.
        self.timings: Timings = batch.timings
        self._stage_from = batch.timings.started  # rig clock when its last stage ended

    @classmethod
    def picked(cls, batch, o: Observation, station, attempts: int) -> "SherdRecord":
        """Number a sherd now in the gripper, picked as `o` from `station`."""
        seconds = batch.rig.clock.now() - batch.timings.started  # finding and picking it
        rec = cls(batch, batch.recorder.new_sherd((o.x, o.y), attempts=attempts, seconds=seconds))
        rec._stage_from = batch.timings.started + seconds
        rec.seen(o, station)
        rec.picked_xy = (o.x, o.y)
        rec.record_dimensions(o)
        return rec

    def taken_over(self, o: Observation, station):
        """Its number goes to the sherd just picked as `o` (this one, not measured, lies among the
        bag's sherds again: two put back apart, station_states.PutBack, or one dropped back onto
        the mat that the recovery could not grasp); where it was picked and its size are
        recorded afresh."""
        self.seen(o, station)
        self.picked_xy = (o.x, o.y)
        self.drops = 0  # the recovery's bound is this sherd's (the row keeps every drop)
        self.batch.recorder.taken_over(self.seq, (o.x, o.y))
        self.record_dimensions(o)

    @classmethod
    def resumed(cls, batch, seq: int, status: str) -> "SherdRecord":
        """A sherd a killed run left unfinished; where it is, is not known yet."""
        return cls(batch, seq, status)

    @property
    def finished(self) -> bool:
        return self.status in FINAL

    # -- what is known of it ---------------------------------------------------------------------
    def seen(self, o: Observation, station):
        """Detected as `o` lying on `station`."""
        self.observation, self.where, self.last_xy = o, station.name, (o.x, o.y)
        self.grasped_as(o, station)

    def grasped_as(self, o: Observation, station):
        """The next grasp follows the detection `o` on `station`."""
        self.grasp_yaw, self.width = o.grasp_yaw, o.width
        self.turn = o.grasp_turn
        # (above the station's surface: for a sherd taken from the top of a heap this includes
        # what it lay on; handling it above its own support instead gave more drops in two heap
        # runs, so it is not changed until that is understood: see the README's heap row)
        self.grasp_height = o.grasp_z - station.surface_z

    def taken_up_at(self, z: float, station):
        """Taken up again from `station` by fingers closed at `z`: later stations grasp it there."""
        self.grasp_height = z - station.surface_z

    def placed(self, station, yaw: float):
        """Set down on `station` by a gripper turned to `yaw`: picked up again as it lies, across
        its minor axis. A grasp turned off that axis (neighbours in the way on the mat) closes on
        a longer chord nearer its narrow ends, and slips more; on the station nothing is in the
        way, so the next grasp is turned back (heap seed 36: half the model's slip chance of the
        batch was in such grasps, repeated at each station). Unless it is too narrow across for
        the fingers to hold (manipulation.holdable): then by the chord it was held by (a chip
        between fingertip pads; small_10 with pads: taken up across its 16.5 mm four times in
        vain at the scale, recorded lost and left on the pan)."""
        from rascal_tasks.manipulation import holdable  # manipulation -> survey -> here

        self.where, self.last_xy = station.name, tuple(station.place_at)
        self.seen_set_down = None
        if self.observation is not None and not holdable(self.batch.config, self.observation.width):
            self.grasp_yaw, self.turn = yaw, 0.0
            return
        x, y = self.last_xy
        back = (yaw - self.turn, yaw - self.turn + math.pi)  # the fingers are alike
        self.grasp_yaw = math.remainder(
            min(back, key=lambda g: abs(wrist_angle(x, y, g) - wrist_angle(x, y, yaw))),
            2.0 * math.pi,
        )
        self.turn = 0.0

    def station_done(self, index: int):
        self.station_index = index

    # -- catalogue writes (each commits) ---------------------------------------------------------
    @property
    def size(self) -> Optional[Observation]:
        """The detection its size was last recorded from (its pickup's until then)."""
        return self._size or self.observation

    def record_dimensions(self, o: Observation):
        self._size = o
        self.batch.recorder.dimensions(
            self.seq,
            o.length,
            o.width,
            o.thickness,
            o.own_height,
            diameter=(o.vessel_diameter, o.vessel_diameter_sigma),
        )

    def record_mass(self, kg: float, stable: bool = True):
        """A settled mass (stations.ScaleStation's rule); an unstable one is never recorded."""
        if not stable:
            raise ValueError(
                "SherdRecord.record_mass: sherd %d: an unstable reading is not a mass; "
                "use record_mass_unstable" % self.seq
            )
        self.batch.recorder.mass(self.seq, kg, True, seconds=self._stage())
        self.mass, self.status = kg, "weighed"
        self._check_wall()

    def record_mass_by_difference(self, kg: float):
        """Weighed with a sherd that then stayed on the pan: its own mass is the difference
        (weighed or photographed still; the status stays)."""
        self.batch.recorder.mass_by_difference(self.seq, kg, self.mass)
        self.mass = kg
        self._check_wall()

    def measured_alone(self, o: Observation):
        """Seen alone as `o` where it was set down on a station (the scale's look, stations.
        ScaleStation): its size is recorded from there, not from where it lay among others (a
        sherd partly under another is seen whole only now; its wall, on the flat pan, is not
        lifted by what it lay on). The detection for its likeness stays the pickup's; it is
        taken up by this one's grasp (manipulation.placed_observation)."""
        self.seen_set_down = o
        self.record_dimensions(o)
        if self.mass is not None and self._check_wall():
            self.wall_doubted_alone = True

    def _check_wall(self) -> bool:
        """A recorded wall that its mass says cannot be one wall (mass_and_size.
        wall_heavier_than) is taken back out of the row, the figure kept in a note; True then."""
        why = wall_heavier_than(self.size, self.mass)
        if not why:
            return False
        self.batch.event(self, "wall_not_recorded", why)  # the note keeps the figure
        self.record_dimensions(dataclasses.replace(self.size, thickness=0.0))
        return True

    def record_mass_unstable(self, reason: str):
        """The scale gave no trustworthy mass: the row says why and has no mass."""
        self.batch.recorder.mass_unstable(self.seq, reason, seconds=self._stage())
        self.mass, self.status = None, "mass_unstable"

    def spool_path(self) -> str:
        return self.batch.recorder.spool_path(self.seq)

    def record_photo(self, path: str) -> str:
        archived = self.batch.recorder.photo(self.seq, path, seconds=self._stage())
        self.status = "photographed"
        return archived

    def dropped(self, where: str):
        self.drops += 1
        self.batch.event(self, "dropped", where)
        self.batch.recorder.drop(self.seq, where)

    def _stage(self) -> float:
        """Seconds (rig clock) since its last stage ended: the catalogue's t_weigh_s, t_photo_s,
        t_discard_s (each with the carrying there; t_pick_s is since the last sherd ended)."""
        now = self.batch.rig.clock.now()
        seconds, self._stage_from = max(0.0, now - self._stage_from), now
        return seconds

    def note(self, text: str):
        self.batch.recorder.note(self.seq, text)

    def done(self):
        self._must_be_open("done")
        self.batch.recorder.done(self.seq, seconds=self._stage(), timings=self.timings.as_dict())
        self._finish("done")

    def lose(self, reason: str):
        """The one way a sherd is recorded lost."""
        self._must_be_open("lost")
        self.batch.event(self, "lost", reason)
        self.batch.recorder.lost(self.seq, reason, timings=self.timings.as_dict())
        self._finish("lost")

    def _must_be_open(self, status: str):
        if self.finished:
            raise RuntimeError(
                "SherdRecord.%s: sherd %d is %s already"
                % ("done" if status == "done" else "lose", self.seq, self.status)
            )

    def _finish(self, status: str):
        """Counts the sherd: the only place `completed` and `lost` change."""
        self.status = status
        b = self.batch
        if status == "done":
            b.completed += 1
        else:
            b.lost += 1
        if b.sherd is self:
            b.sherd = None
        b.timings = Timings(started=b.rig.clock.now())  # the next sherd's time starts now
