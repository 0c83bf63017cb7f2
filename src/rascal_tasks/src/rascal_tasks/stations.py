"""Station plug-ins: what happens once a sherd is at a station.

A station type is a class registered under the `type` used in config/rascal.yaml; the workflow
builds its states from the config's station list, so a new kind of station (a profile scanner,
a second camera) is a new class here plus a config entry, not an edit of the state machine.
No ROS here: plug-ins use the rig interfaces (`rig.py`) and write through the sherd's record
(`sherd_record.py`).
"""

import enum
import os
from typing import Callable, Dict, List, NamedTuple, Optional, Tuple, Type

from rascal_tasks.archival import exposure
from rascal_tasks.archival.exposure import Exposure
from rascal_tasks.mass_and_size import more_than_one_sherd, wall_heavier_than
from rascal_tasks.rig import RigError, ScaleReading
from rascal_tasks.wrist import same_grasp_yaws, standby_yaw

STATION_PLUGINS: Dict[str, Type["StationPlugin"]] = {}
# The smallest sherd worth recording: 2 x 2 cm, 4 mm wall at 1.8 g/cm^3 is about 2.9 g
# (shared/facts/sherds_and_colour.md §2). A lighter steady reading means the sherd is not on the
# scale; an unsteady one means nothing.
MIN_SHERD_MASS = 0.001  # kg
SCALE_POLL = 0.05  # s (rig clock) between looks at the scale's readings
# Two sherds the wrist camera sees on the scale are put back apart this often for one row
# (the mass bound's put back counts too); then recorded, flagged for a person.
LOOK_PUT_BACKS = 2
_STAMP_SLACK = 1e-3  # s: readings 10 Hz apart stamped a little early or late still cover


def station_type(name: str):
    """Class decorator: register a plug-in for stations of config `type: <name>`."""

    def register(cls):
        STATION_PLUGINS[name] = cls
        cls.type_name = name
        return cls

    return register


class StationPlugin:
    """Base class. `status` is the catalogue status a sherd reaches when this station is done."""

    type_name = ""
    status = ""
    # True: the sherd is released from travel height and never picked up again (discard box).
    release_from_above = False
    # True: after placing, the gripper waits just above the sherd (nothing to keep out of view),
    # so picking it up again is a short descent instead of a trip from travel height.
    hover_after_place = False

    def __init__(self, station, batch, index: int):
        self.station = station  # rascal_tasks.config.Station
        self.batch = batch  # rascal_tasks.batch.Batch
        self.index = index  # its place in the batch's station order (batch.plugins)
        # the station the sherd lies on while this one works: this one, or the scale for a
        # camera over it (`over_scale`: Batch sets it), where the sherd stays
        self.lies_at = station

    @property
    def stays(self) -> bool:
        """The sherd is not carried here: it lies where the station before set it down."""
        return self.lies_at is not self.station

    def target(self, sherd):
        """The station the sherd is carried to and set down at: this one (the discard station
        may send it to a sorting bin instead)."""
        return self.station

    def before_place(self, sherd) -> None:
        """Called with the sherd (a SherdRecord) in the gripper above the station (e.g. tare
        the scale)."""

    def ready_for_place(self, sherd, by_arrival: bool = False) -> bool:
        """Whether the held `sherd` may be lowered onto this station without the arm stopping
        above it first (before_place then needs the arm nowhere in particular). `by_arrival`:
        whether it looks set to be by the time the carry gets there (Place asks again there)."""
        return True

    def while_away(self, arm_free: bool = True) -> bool:
        """Called while the arm works at a later station, the sherd gone from this one, or
        carries the next sherd here, or surveys the pickup mat: a station may start here,
        without waiting, what its next sherd needs (the scale tares its empty pan).
        `arm_free`: nothing in the gripper (the station may use the arm). True when it put
        something on the pickup mat (a sherd left on the scale)."""
        return False

    def hand_over(self) -> bool:
        """Whether the sherd was picked up off `lies_at` while this station waited (the
        camera's transfer) and is held at travel height above it: REPICK has nothing to do.
        Asked once, by REPICK: the sherd is the next station's from then on."""
        return False

    def missed_blind(self) -> bool:
        """Whether REPICK's blind grasp was tried here while this station waited, and missed:
        REPICK then looks before it grasps (the same two blind grasps again would miss alike).
        Asked once, by REPICK."""
        return False

    def measure_here(
        self, sherd, measure: Callable[[], str], look: Callable[[], Optional[str]] = lambda: None
    ) -> str:
        """For a station that `stays`: the station before measures the sherd lying here,
        `look()` first (an outcome that ends it, or None), then `measure()` (its after_place's
        work, its outcome returned); this one may work around it meanwhile (the camera over the
        scale shoots while the pan settles)."""
        return look() or measure()

    def while_lifting(self, sherd) -> None:
        """The sherd just let go here, the arm about to rise from it, and a station that
        `stays` works on it next (the camera over the scale): a last look at it before the arm
        goes out of that one's way (the scale's look for a second sherd)."""

    def make_way(self, sherd) -> None:
        """For a station that `stays`: the sherd was just set down by the station before, the
        gripper still low at it, going straight up as the first part of its next move
        (Batch.lift_later); it may go where this station needs it while the one before
        measures (the camera's standby)."""

    def reach_back(self, sherd) -> None:
        """The arm back at `sherd`, lying here, the fingers open around it, ready to pick it up
        (manipulation.reach): for a plug-in to run while it waits with the arm away."""
        # imported here: manipulation -> survey -> batch imports this module
        from rascal_tasks.manipulation import placed_observation, reach

        reach(self.batch, placed_observation(self.batch, sherd, self.lies_at))

    def after_place(self, sherd) -> str:
        """Called with the sherd placed and the gripper back at travel height; records what it
        measured through `sherd` (SherdRecord). Returns 'done'; 'missing' when the sherd is
        evidently not there (it is searched for like a drop); 'double' when it is two sherds
        lifted as one (they are put back apart, station_states.PutBack); or 'failed' when the
        station could not do its job for this sherd. A failed sherd that lies where the next
        sherd is placed stops the batch with the arm parked, unfinished, for a person to look
        (a restart resumes it); elsewhere (the discard box) it is recorded lost and the batch
        goes on (`failures.classify`). A RigError raised here stops the batch."""
        raise NotImplementedError


def settled(readings: List[ScaleReading], window: float, readability: float):
    """The weighing rule, on `readings` (oldest first): the last `window` seconds as one reading
    (their mean, stamped with the last one), or None unless readings cover that whole window
    (one is at or before its start), every one of them lies within `readability` of every
    other, and the scale itself calls the last one stable."""
    if not readings or not readings[-1].stable:
        return None
    last = readings[-1]
    start = last.stamp - window + _STAMP_SLACK
    first = max((i for i, r in enumerate(readings) if r.stamp <= start), default=None)
    if first is None:
        return None  # not watched for a whole window yet
    masses = [r.mass for r in readings[first:]]
    if max(masses) - min(masses) > readability + 1e-9:
        return None
    return ScaleReading(round(sum(masses) / len(masses), 7), True, last.stamp)


def reads_zero(readings: List[ScaleReading], window: float, readability: float) -> bool:
    """The tare check's rule, on the `readings` since a tare (oldest first): they span a whole
    `window`, every one reads zero within `readability` (the last digit either way: a tared
    empty pan's own noise flips it, so `settled`'s spread of one digit would refuse a good
    tare about one window in seven), and the scale calls the last one stable. A pan still
    swinging when it was tared drifts off zero by more than the digit and fails it."""
    if not readings or not readings[-1].stable:
        return False
    if readings[-1].stamp - readings[0].stamp < window - _STAMP_SLACK:
        return False
    return all(abs(r.mass) <= readability + 1e-9 for r in readings)


@station_type("scale")
class ScaleStation(StationPlugin):
    """Weighs the sherd. A mass is recorded only when the reading held within the scale's
    readability for `scale.stable_window` seconds (`settled`) on a platform tared after it had
    settled empty, the tare checked (the empty platform then reads 0 within the readability).
    An unsettled tare is done again, and an unsettled reading is read again, `scale.rereads`
    times; then the sherd is recorded `mass_unstable`, without a mass, and goes on to the next
    station. Only a settled reading below MIN_SHERD_MASS means the sherd is not there."""

    status = "weighed"  # or mass_unstable: weighed, but no trustworthy mass
    hover_after_place = True

    def __init__(self, station, batch, index):
        super().__init__(station, batch, index)
        self._tared_for = None  # seq of the sherd the scale was tared (and checked) for
        self._last = None  # the SherdRecord placed on the scale last (it may be done since)
        self._before_tare = 0.0  # kg, what the settled empty pan read before the last tare
        self._early_tare = None  # (clock time, empty reading before it) of while_away's tare
        self._early_look = None  # (seq, outcome) of while_lifting's look at the pan

    def _cfg(self):
        return self.batch.config["scale"]

    def _settle(self, since: float) -> Tuple[Optional[ScaleReading], Optional[ScaleReading]]:
        """Waits up to scale.stable_timeout for the readings taken after `since` to settle;
        returns (the settled reading or None, the last reading). RigError when the scale sends
        nothing at all."""
        b, cfg = self.batch, self._cfg()
        clock = b.rig.clock
        deadline = clock.now() + cfg["stable_timeout"]
        last = None
        while True:
            b.check_stop()
            readings = b.rig.scale.readings(since)
            if readings:
                last = readings[-1]
                reading = settled(readings, cfg["stable_window"], cfg["readability"])
                if reading is not None:
                    return reading, last
            if clock.now() >= deadline:
                break
            clock.sleep(SCALE_POLL)
        if last is None:
            raise RigError(
                "/scale/mass",
                "TIMEOUT",
                "no scale reading for %.1f s; is the scale (its driver, or the simulator) "
                "running?" % cfg["stable_timeout"],
            )
        return None, last

    def holds_something(self) -> bool:
        """Whether the pan (tared empty before the sherd) settles at a sherd's mass or more."""
        reading, _ = self._settle(self.batch.rig.clock.now())
        return reading is not None and reading.mass >= MIN_SHERD_MASS

    def _unsteady(self, last) -> str:
        cfg = self._cfg()
        return "not within %.1f g for %.1f s in %.1f s (last reading %.1f g)" % (
            cfg["readability"] * 1000,
            cfg["stable_window"],
            cfg["stable_timeout"],
            last.mass * 1000,
        )

    def _settled_now(self, since: float) -> Optional[ScaleReading]:
        """The weighing rule on the readings since `since`, as they are now (no waiting)."""
        cfg = self._cfg()
        return settled(
            self.batch.rig.scale.readings(since), cfg["stable_window"], cfg["readability"]
        )

    def while_away(self, arm_free=True):
        """Tares the empty pan while the arm is at the next stations, or carries the next
        sherd here (it takes a whole stable window after the tare to check it: that wait was
        spent standing above the scale with the next sherd). Only a pan that has read steady
        for a whole window is tared; otherwise the next sherd's tare is done above the scale as
        before. A sherd left on the pan is taken off it only with the arm free."""
        if self._early_tare is not None:
            return False
        b, cfg = self.batch, self._cfg()
        last = self._last
        if arm_free and last is not None and last.parted_on == self.station.name:
            # taken up high on its edge (manipulation.rider_z): the sherd it lay on may lie on
            # the pan still, weighed with it; read (waited for, within stable_timeout) while
            # that row is open, to be taken out of it by difference (heap_20 seed 59: left
            # there and weighed over by the next sherd, the row kept both masses)
            last.parted_on = None
            left, _ = self._settle(b.rig.clock.now() - cfg["stable_window"] - 1.0)
            if left is not None and left.mass >= MIN_SHERD_MASS:
                return self._left_on_pan(left.mass)
            if last.wall_doubted_alone:
                self._maybe_two(last, left)
        # steady within the last digit either way (the empty pan's noise flips it both ways
        # about one window in seven): a pan still moving when tared is caught by the check
        # after the tare (reads_zero), which allows no more
        empty = settled(
            b.rig.scale.readings(b.rig.clock.now() - cfg["stable_window"] - 1.0),
            cfg["stable_window"],
            2 * cfg["readability"],
        )
        if empty is None:
            return False
        if empty.mass >= MIN_SHERD_MASS:
            # taken to the mat (the next sherd's tare is done above the scale), or, with the
            # arm busy, left for a call with the arm free (the survey before the batch ends)
            return arm_free and self._left_on_pan(empty.mass)
        try:
            b.rig.scale.tare()
        except RigError as e:  # tared again, and said, when the next sherd is above the scale
            b.log("early tare of the scale failed: %s" % e)
            return False
        self._early_tare = (b.rig.clock.now(), empty.mass)
        return False

    def _maybe_two(self, sherd, left) -> None:
        """`sherd`, seen as one outline on the pan whose wall there its mass still rules out for
        one sherd (SherdRecord.wall_doubted_alone), was taken up high on its edge and left
        nothing behind (`left`: the pan's settled reading since, None when it did not settle):
        two sherds of one outline may have come up together (heap_20 seed 64: a sherd wholly on
        one of its size, 50.2 g, seen as one on the pan, both lifted by the lower one's edge,
        weighed as one row, exit 0). Its row stands as weighed, with a note saying so, and the
        batch ends incomplete: a person looks, rather than a row of two passing as one sherd."""
        b = self.batch
        why = (
            "seen as one outline on the %s, its wall there more than %.1f g allows for "
            "one sherd of that outline, and nothing stayed on the pan when it was taken up high on "
            "its edge%s; a person should check that this row is one sherd"
            % (
                self.station.name,
                (sherd.mass or 0.0) * 1000,
                "" if left is not None else " (the pan did not settle)",
            )
        )
        b.maybe_two.append(sherd.seq)
        b.event(sherd, "maybe_two", why)  # (the event is the row's note too)

    def _left_on_pan(self, kg: float) -> bool:
        """`kg` lies on the pan, settled, since the sherd weighed here was lifted off it: a
        sherd that came with it (lying on it in a heap) and stayed. Its mass was weighed with
        the sherd's, whose own is the difference (recorded while the sherd is not yet done,
        the catalogue's event keeping both figures; else noted). The other is taken back to
        the pickup mat, to be recorded as its own sherd (station_states.clear_to_mat). True
        when the pan was cleared."""
        b = self.batch
        s = self._last  # the sherd in progress, or done since (the camera over the scale)
        itself = s is not None and (
            s.status == "lost"  # the grasps on it failed here
            or (s.mass is not None and abs(kg - s.mass) <= 2 * self._cfg()["readability"])
        )
        if itself:
            # most likely that sherd itself (recorded lost here, or dropped back unseen): taken
            # to the mat, it would be picked and recorded a second time, as a new row
            b.log(
                "%.1f g lies on the scale after sherd %s (%s, %s) left it: most likely that "
                "sherd; left for a person"
                % (kg * 1000, s.seq, s.status, "%.1f g" % (s.mass * 1000) if s.mass else "no mass")
            )
            return False
        if any(
            st == self.station.name and abs(kg - left) <= 2 * self._cfg()["readability"] + 1e-9
            for st, left, _ in b.left_on_station
        ):
            return False  # that one, said already (its row's mass corrected once, not again)
        if s is not None and s.mass is not None and self._tared_for == s.seq:
            own = s.mass - kg
            text = (
                "%.1f g stayed on the scale when it was lifted off: weighed with it (%.1f g); "
                "its own mass by difference %.1f g" % (kg * 1000, s.mass * 1000, own * 1000)
            )
            # still on its way (not yet done): the row's mass is corrected, the event keeps both
            # (heap_mixed_20 seed 55: 16.5 g weighed, 7.3 g its own, photographed already)
            if own >= MIN_SHERD_MASS and s.status in ("weighed", "photographed"):
                s.record_mass_by_difference(round(own, 7))
                text += ", recorded"
            if b.next_stays(self.index) is not None:
                # the camera over the scale shot it before it was lifted, the other one on the
                # pan with it, under it or beside it (heap_22_corner seed 124: a 36 x 35 mm sherd
                # under a 50 x 40 mm one, the pan's look saw one outline)
                b.photo_with_another.append(s.seq)
                text += (
                    "; its archival photo was taken with that one on the pan too: the photo and "
                    "the size from it may show both"
                )
            b.event(s, "left_on_scale", text)
        # imported here: station_states imports this module
        from rascal_tasks.station_states import clear_to_mat

        spot = clear_to_mat(b, self.station)
        if spot is None:
            # weighed over (the next tare takes it in) and left for a person: the batch ends
            # incomplete naming it (heap_22_corner seed 98: a 9.5 g rider the wrist camera did
            # not see on the pan; the batch ended "finished", exit 0, the rider unrecorded)
            b.left_on_station.append((self.station.name, kg, s.seq if s is not None else None))
            b.event(
                s,
                "left_on_scale",
                "not seen or not picked up there: weighed over it, left for a person",
            )
            return False
        b.event(
            s,
            "cleared",
            "what stayed on the scale taken to the pickup mat at "
            "(%.3f, %.3f) m, to be recorded as its own sherd" % spot,
        )
        return True

    def _early_tare_holds(self, sherd) -> bool:
        """Whether while_away's tare (if any) still holds: since it, the pan has read zero
        within the readability for a whole window. Used once: a sherd placed after it needs a
        tare of its own. One that settled off zero is said on `sherd`'s row (a tare that caught
        the pan swinging); one not yet steady is only logged (the arm came back soon)."""
        early, self._early_tare = self._early_tare, None
        if early is None:
            return False
        if self._zero_since(early[0]):
            self._before_tare = early[1]
            return True
        off = self._settled_now(early[0])
        if off is not None and abs(off.mass) > self._cfg()["readability"] + 1e-9:
            self.batch.event(
                sherd,
                "tare_failed",
                "the tare made while away: the empty platform reads %.1f g after it; tared "
                "again above the scale" % (off.mass * 1000),
            )
        else:
            self.batch.log(
                "sherd %d: the pan not at zero for a window since the tare made while away: "
                "tared again above the scale" % sherd.seq
            )
        return False

    def _zero_since(self, tared_at: float) -> Optional[bool]:
        """The readings since the tare at `tared_at`: True when they read zero for a whole
        window, the last stable (`reads_zero`); False while every one so far reads zero within
        the readability; None once one does not."""
        readings = self.batch.rig.scale.readings(tared_at)
        readability = self._cfg()["readability"]
        if any(abs(r.mass) > readability + 1e-9 for r in readings):
            return None
        return reads_zero(readings, self._cfg()["stable_window"], readability)

    def _tare_once(self) -> Optional[str]:
        """Tare after a settled empty reading, then check it; None when it took, else why not."""
        b, cfg = self.batch, self._cfg()
        now = b.rig.clock.now()
        empty, last = self._settle(now - cfg["stable_window"] - 1.0)  # what it read till now too
        if empty is None:
            return "empty platform %s" % self._unsteady(last)
        self._before_tare = empty.mass
        b.rig.scale.tare()
        zero, last = self._settle(b.rig.clock.now())
        if zero is None:
            return "after the tare %s" % self._unsteady(last)
        if abs(zero.mass) > cfg["readability"] + 1e-9:
            return "the empty platform reads %.1f g after the tare" % (zero.mass * 1000)
        return None

    def ready_for_place(self, sherd, by_arrival=False):
        """Only with the tare made while away holding (the pan at zero for a window): a tare
        made now needs the sherd well clear of the pan, the arm above it. By the arrival: that
        tare made, and every reading since it zero so far. On the arrival, a carry quicker than
        a window since the tare waits out the rest of it where it is (a sherd touching the pan
        would read), until the tare is stable_timeout old at most."""
        early = self._early_tare
        if early is None:
            return False
        if by_arrival:
            return self._zero_since(early[0]) is not None
        clock = self.batch.rig.clock
        while True:
            zero = self._zero_since(early[0])
            if zero:
                return True
            if zero is None:
                return False  # off zero: tared again, the sherd clear of the pan
            if clock.now() >= early[0] + self._cfg()["stable_timeout"]:
                return False
            self.batch.check_stop()
            clock.sleep(SCALE_POLL)

    def before_place(self, sherd):
        self._tared_for = None
        b = self.batch
        if self._early_tare_holds(sherd):
            self._tared(sherd)
            return
        with b.phase("data_collection"):
            for attempt in range(1 + self._cfg()["rereads"]):
                problem = self._tare_once()
                if problem is None:
                    self._tared(sherd)
                    return
                b.event(sherd, "tare_failed", "attempt %d: %s" % (attempt + 1, problem))
        # Recorded before placing: a restart that finds it lying on the scale does not weigh it.
        self._mass_unstable(sherd, "the scale could not be tared (%s)" % problem)

    def _tared(self, sherd):
        """The pan is tared and checked for `sherd`."""
        self._tared_for, self._last = sherd.seq, sherd
        if self._before_tare >= MIN_SHERD_MASS:
            # a sherd the wrist camera did not see there (or a zero that moved): the tare takes
            # it away, but the archaeologist is told, on this row
            self.batch.event(
                sherd,
                "pan_loaded",
                "the empty pan read %.1f g before the tare for this sherd: something lies on "
                "the scale (or its zero moved); weighed tared over it" % (self._before_tare * 1000),
            )

    def after_place(self, sherd):
        b = self.batch
        since = b.rig.clock.now()
        after = b.next_stays(self.index)  # the camera over the scale shoots while it settles

        def weigh():
            return self._weigh(sherd, since)

        def look():
            early, self._early_look = self._early_look, None
            if early is not None and early[0] == sherd.seq:
                return early[1]  # looked at on the way up from it (while_lifting)
            return self._looked_at(sherd, back_to_hover=after is None)

        if after is None:
            return look() or weigh()
        return after.measure_here(sherd, weigh, look)

    def while_lifting(self, sherd):
        """With the camera over the scale: the look for a second sherd on the way up from it,
        before the arm goes to standby for the photo, not from standby during the transfer
        (the photo then never shows the arm, and the transfer only reaches back). Either way a
        look cost 2.4-3.1 s there (heap_20 seeds 45, 46, 39), against 0.6 s with the stations
        apart, where it overlaps the pan's settling."""
        if sherd.among_others:
            self._early_look = (sherd.seq, self._looked_at(sherd, back_to_hover=False))

    def _looked_at(self, sherd, back_to_hover: bool, anyway: bool = False) -> Optional[str]:
        """A sherd picked from among others (SherdRecord.among_others), or any (`anyway`), is
        looked at on the pan while it settles: "double" when the wrist camera sees two sherds
        there (`_two_on_pan`; put back LOOK_PUT_BACKS times at most: PutBack), else None, the
        arm back above the sherd (`back_to_hover`, where the repick's descent starts) and the
        pan left to settle. Seen as two again after that: recorded, flagged (`two_seen`), the
        batch incomplete."""
        b = self.batch
        if not (sherd.among_others or anyway):
            return None
        two, seen = self._two_on_pan(sherd)
        if len(seen) == 1:
            sherd.measured_alone(seen[0])
        times = b.put_back_doubles.get(sherd.seq, 0)
        if two and times < LOOK_PUT_BACKS:
            b.put_back_doubles[sherd.seq] = times + 1
            b.event(sherd, "two_in_one", two)
            from rascal_tasks.survey import came_up_with  # survey imports batch, which imports this

            came_up_with(b, sherd, len(seen) - 1)
            return "double"
        if two:  # two outlines are no heavy sherd: recorded as weighed, and a person must look
            b.two_seen.append(sherd.seq)
            b.event(sherd, "two_seen", two)
            sherd.note(
                "looked at on the scale: %s; put back %d times and seen alike again" % (two, times)
            )
        if back_to_hover:
            from rascal_tasks.station_states import hover_z  # station_states imports this module

            x, y = sherd.last_xy
            b.move_down(x, y, hover_z(b, self.station, sherd), sherd.grasp_yaw, linear=True)
        return None

    def _weigh(self, sherd, since: float) -> str:
        """after_place's weighing, on the readings from `since` (the sherd set down) on."""
        b, cfg = self.batch, self._cfg()
        if self._tared_for != sherd.seq:
            if sherd.status == "mass_unstable":
                return "done"  # the tare failed (recorded), or so recorded before a restart
            # after a restart, found lying on the scale: the run before tared and checked it
            b.event(sherd, "tare_unchecked", "lying on the scale after a restart")
        reading = last = None
        with b.phase("data_collection"):
            for attempt in range(1 + cfg["rereads"]):
                reading, last = self._settle(since)
                if reading is not None:
                    break
                b.event(
                    sherd, "scale_unstable", "attempt %d: %s" % (attempt + 1, self._unsteady(last))
                )
        if reading is None:
            self._mass_unstable(
                sherd,
                "the reading did not hold within %.1f g for %.1f s in %d attempts of %.1f s"
                % (
                    cfg["readability"] * 1000,
                    cfg["stable_window"],
                    1 + cfg["rereads"],
                    cfg["stable_timeout"],
                ),
            )
            return "done"
        if reading.mass < MIN_SHERD_MASS:
            # A steady empty pan: the sherd slipped away unnoticed on the way; look for it.
            b.event(
                sherd, "scale_empty", "reads %.1f g, steady, after placing" % (reading.mass * 1000)
            )
            return "missing"
        too_heavy = more_than_one_sherd(sherd.size, reading.mass)
        if too_heavy and b.put_back_doubles.get(sherd.seq, 0) == 0:
            # two sherds lifted as one (a heap): no mass for this row; they are put back apart
            # (station_states.PutBack) and the sherd keeps its number for the next pick
            b.put_back_doubles[sherd.seq] = 1
            b.event(sherd, "two_in_one", too_heavy)
            from rascal_tasks.survey import came_up_with

            came_up_with(b, sherd, 1)
            return "double"
        if not too_heavy and self._wall_doubted(sherd, reading.mass):
            return "double"
        sherd.record_mass(reading.mass)
        if too_heavy:  # put back once already and as heavy again: one heavy sherd, flagged
            b.event(sherd, "mass_too_high", too_heavy)
            sherd.note("mass checked: %s; put back once and weighed alike again" % too_heavy)
        return "done"

    def _wall_doubted(self, sherd, kg: float) -> bool:
        """A sherd not looked at on the pan whose mass `kg` says the wall the pickup measured
        was not one wall (mass_and_size.wall_heavier_than: it lay on something seen as part of
        it), or whose wall the pickup did not measure, is looked at now: what it lay on may have
        come up with it (heap_20 seed 64: 23 g wholly over 27 g, over a third sherd, weighed as
        one row; an outline and a mass of one).
        True when the look saw two there ("double"). One seen alone gets its wall from the flat
        pan (SherdRecord.measured_alone) instead of none, and is taken up high on its edge
        (manipulation.placed_observation): one lying on it is lifted off it, and the other,
        left on the pan, weighed out of the row by difference (_left_on_pan)."""
        if sherd.among_others:
            return False
        if wall_heavier_than(sherd.size, kg):
            why = "its wall doubted"
        elif sherd.size is not None and sherd.size.thickness <= 0.0:
            # no wall measured, so no mass bound either: a rider as wide as the one under it
            # shows one outline with no step (heap_25_offcentre seed 95: 67 x 55 mm, 35.5 g,
            # two sherds in one row); looked at as if its wall were doubted
            why = "no wall measured"
        else:
            return False
        b = self.batch
        b.log("sherd %d: %.1f g, %s: the pan looked at" % (sherd.seq, kg * 1000, why))
        sherd.wall_doubted = True
        over = b.next_stays(self.index) is not None
        if over:  # the camera over the scale: the fingers stand round it (measure_here), go up
            from rascal_tasks.station_states import hover_z  # station_states imports this module

            x, y = sherd.last_xy
            b.move_down(x, y, hover_z(b, self.station, sherd), sherd.grasp_yaw, linear=True)
        return self._looked_at(sherd, back_to_hover=not over, anyway=True) == "double"

    def _two_on_pan(self, sherd) -> Tuple[str, list]:
        """Why the wrist camera's look at the pan shows two sherds where `sherd` was set down, or
        "", and what it saw there. For a sherd picked from among others (SherdRecord.
        among_others): a light sherd lying on the one grasped rides along within the mass bound
        (heap_mixed_20 seed 51: 10 g on 29 g weighed as one row). Two detections, not one
        outline larger than the sherd was picked as: a sherd partly under another when picked
        shows whole on the pan (heap_20 seed 45: 46 x 28 mm picked, 48 x 44 mm on the pan, one
        sherd, put back in vain)."""
        # imported here: survey -> batch imports this module
        from rascal_tasks.survey import reachable_look_yaws, survey_at

        b = self.batch
        x, y = sherd.last_xy
        # the gripper kept turned as it set the sherd down (or by pi: the fingers are alike), so
        # the look turns no wrist; facing away from the base only where neither is in reach
        # (with the camera over the scale a look costs 2.4-3.1 s either way, the climb to the
        # survey height and back: heap_20 seeds 45, 46, 39, one station)
        z = self.station.surface_z + b.config["survey"]["z"]
        yaw = next(iter(reachable_look_yaws(x, y, z, same_grasp_yaws(sherd.grasp_yaw))), None)
        radius = b.config["recovery"]["search_radius"]
        seen = [c for c in survey_at(b, self.station, x, y, yaw) if c.distance_to(x, y) < radius]
        b.log(
            "sherd %d, picked from among others: the %s looked at, %d seen"
            % (sherd.seq, self.station.name, len(seen))
        )
        if len(seen) >= 2:
            return "two sherds in one grasp? the wrist camera sees %d sherds on the %s (%s)" % (
                len(seen),
                self.station.name,
                ", ".join("%.0f x %.0f mm" % (c.length * 1000, c.width * 1000) for c in seen),
            ), seen
        return "", seen

    def _mass_unstable(self, sherd, reason: str):
        """No trustworthy mass: recorded so (no mass value), and the sherd goes on."""
        self.batch.log("sherd %d mass_unstable: %s" % (sherd.seq, reason))
        if sherd.status == "weighed":  # a mass taken before stands (a re-weigh that failed)
            sherd.note("mass_unstable: %s; the mass recorded before stands" % reason)
        else:
            sherd.record_mass_unstable(reason)


class ArmAt(enum.Enum):
    """Where the arm is, for the sherd at the archival camera."""

    ABOVE = "above"  # at travel height: placing the sherd lifted it there
    STANDBY = "standby"  # out of the camera's view (make_way, _standby)
    ROUND = "round"  # low at the sherd, the fingers open round it (_reach_back)
    HOLDING = "holding"  # the sherd picked up, held at travel height above its spot (_take_up)


class Shot(NamedTuple):
    """The photo shot while the scale under the camera weighed (measure_here): its capture, or
    None when the shutter fired and the transfer failed (after_place shoots again)."""

    capture: Optional[object]  # rig.Capture


@station_type("archival_camera")
class ArchivalCameraStation(StationPlugin):
    """The archival photo, shot again a stop darker (twice at most) while its highlights clip
    (archival.exposure); the darker exposure is kept for the batch's next sherds."""

    status = "photographed"
    CAPTURE_ATTEMPTS = 3

    def __init__(self, station, batch, index):
        super().__init__(station, batch, index)
        self.exposure = Exposure()
        self.arm = ArmAt.ABOVE
        self._shot: Optional[Shot] = None  # of `measure_here`, for after_place
        self._missed_blind = False  # _take_up's grasp closed on nothing (missed_blind)

    def hand_over(self):
        held = self.arm is ArmAt.HOLDING
        if held:
            self.arm = ArmAt.ABOVE
        return held

    def missed_blind(self):
        missed, self._missed_blind = self._missed_blind, False
        return missed

    def after_place(self, sherd):
        b = self.batch
        shot, self._shot = self._shot, None
        if shot is None and not self.stays:
            self.arm = ArmAt.ABOVE  # carried here: placing lifted the arm to travel height
        elif shot is None and self.arm is not ArmAt.STANDBY:
            # on the scale, the arm not sent to standby (make_way): after a restart it may be
            # anywhere above the sherd: straight up first
            self.arm = ArmAt.ROUND
        with b.phase("data_collection"):
            capture = shot.capture if shot is not None else None
            if capture is None:
                capture = self._capture(sherd, sherd.spool_path())
            if capture is None:
                return "failed"  # it lies on the camera's spot: the batch stops
            while True:
                seen = exposure.measure(capture.path)
                darker = self.exposure.retake(seen)
                if darker is None:
                    self.exposure.settle(seen)
                    break
                why = "%.1f %% of the photo near clipping" % (100.0 * seen.near_clip_share)
                # a file of its own: a retake that fails leaves the photo taken intact
                base, ext = os.path.splitext(sherd.spool_path())
                retaken = self._capture(sherd, "%s_ev%+.0f%s" % (base, darker, ext))
                if retaken is None:
                    b.event(sherd, "exposure", why + "; shot again darker, failed: it stands")
                    break
                b.event(sherd, "exposure", why + ": shot again at %+.0f EV" % darker)
                _discard(capture.path)
                capture = retaken
            sherd.record_photo(capture.path)
        return "done"

    def _capture(self, sherd, path):
        """The capture at the batch's exposure, taken with the arm at standby; once the shutter
        has closed the arm reaches back for the sherd, its fingers open around it, while the
        image is transferred (rig.ArchivalCamera.capture_while): REPICK only closes them.
        CAPTURE_ATTEMPTS tries; None, with the arm at standby, when all failed."""
        b = self.batch
        for attempt in range(self.CAPTURE_ATTEMPTS):
            self._standby(sherd)
            try:
                return b.rig.camera.capture_while(
                    path, self.exposure.ev, lambda: self._reach_back(sherd)
                )
            except RigError as e:
                b.event(sherd, "capture_failed", "attempt %d: %s" % (attempt + 1, e.reason))
                b.rig.clock.sleep(1.0)
        self._standby(sherd)
        return None

    def measure_here(self, sherd, measure, look=lambda: None):
        """Over the scale: the photo shot as soon as the sherd is set down and the arm at
        standby; during the image's transfer the scale's `look()` runs (a look at the pan for a
        second sherd: its "double" ends it), the arm goes back, the fingers round the sherd,
        `measure()` (the weighing) runs, and a sherd weighed ('done') is taken up
        (`_take_up`). The capture is kept for after_place, which checks its exposure (a retake
        sets the sherd down again); one that failed is taken again there. Refused before the
        shutter: weighed as before, the photo taken after."""
        b = self.batch
        outcome, raised = [], []

        def during():
            try:
                # the scale's look at the pan for a second sherd, from above, before the fingers
                # go round the sherd without touching it while the pan settles (a touch would
                # show in the readings and be waited out)
                outcome.append(look())
                if outcome[0] is None:
                    self._reach_back(sherd, take_up=False)
                    outcome[0] = measure()
                if outcome[0] == "done":
                    self._take_up(sherd)
                else:  # two, or none, on the pan: out of the way, straight up
                    x, y = sherd.last_xy
                    b.move_down(x, y, b.travel_z(), sherd.grasp_yaw, linear=True)
                    self.arm = ArmAt.ABOVE
                    b.poised = None
            except BaseException:
                raised.append(True)  # the scale's or the arm's failure, not the camera's
                raise

        capture = None
        with b.phase("data_collection"):
            try:
                capture = b.rig.camera.capture_while(sherd.spool_path(), self.exposure.ev, during)
            except RigError as e:
                if raised:
                    raise
                b.event(sherd, "capture_failed", "while weighing: %s" % e.reason)
        if not outcome:  # refused before the shutter: nothing ran
            return look() or measure()
        if outcome[0] == "done":
            self._shot = Shot(capture)
        elif capture is not None:
            _discard(capture.path)  # not this sherd's photo: two sherds, or none, on the pan
        return outcome[0]

    def make_way(self, sherd):
        """Out of view while the scale under the camera settles: the shutter needs no move."""
        self.arm = ArmAt.ABOVE  # Place's lift goes first (Batch.lift_later)
        self._standby(sherd)

    def _reach_back(self, sherd, take_up=True):
        """During the transfer: the fingers open around the sherd; and (`take_up`) `_take_up`.
        The transfer's 1.5 s cover the way back, the close and the lift (timing.md)."""
        self.arm = ArmAt.ROUND  # (from wherever the reach stopped, too: up first)
        self.reach_back(sherd)
        if take_up:
            self._take_up(sherd)

    def _take_up(self, sherd):
        """The fingers round the sherd: when no later station works on it here, it is picked
        up (REPICK's grasp, the lift checked), to wait at travel height above its spot for the
        photo: carried on only once the photo is in (a retake sets it down again first)."""
        b = self.batch
        if self.index + 1 < len(b.plugins) and b.next_stays(self.index) is None:
            # imported here: manipulation -> survey -> batch imports this module
            from rascal_tasks.manipulation import grasp_where_set_down

            self.arm = ArmAt.ABOVE  # lifted, held or not: the arm is at travel height
            if grasp_where_set_down(b, sherd, self.lies_at):
                self.arm = ArmAt.HOLDING
            else:
                self._missed_blind = True

    def _set_down_again(self, sherd):
        """The sherd held up during the transfer goes back onto its spot (a retake, a failed
        transfer): lowered, let go, the fingers left around it (`_standby` lifts first)."""
        # imported here: station_states and manipulation import this module
        from rascal_tasks.manipulation import release
        from rascal_tasks.station_states import place_z

        b = self.batch
        self.arm = ArmAt.ABOVE
        if not b.rig.gripper.holding():
            return  # it slipped out above its spot: REPICK looks for it there
        x, y = sherd.last_xy
        b.move_down(x, y, place_z(b, self.lies_at, sherd), sherd.grasp_yaw, linear=True)
        with b.phase("grasping"):
            sherd.width = release(b, sherd.width)
        self.arm = ArmAt.ROUND

    def _standby(self, sherd):
        """Out of the camera's view, the wrist camera facing away too (the sherd was set down
        turned so); from the sherd (a retake, a failed transfer) straight up first, a sherd
        held up during the transfer set down again before."""
        b = self.batch
        if self.arm is ArmAt.HOLDING:
            self._set_down_again(sherd)
        if self.arm is ArmAt.ROUND:
            x, y = sherd.last_xy
            b.lift_later(x, y, sherd.grasp_yaw)  # up and away as one motion
        self.arm = ArmAt.STANDBY
        sx, sy = b.config["arm"]["standby"]
        b.move_down(sx, sy, b.travel_z(), standby_yaw(b.config, self.station))


def _discard(path: str) -> None:
    """A spooled photo that is not the archival one (shot again darker)."""
    try:
        os.unlink(path)
    except OSError:
        pass  # the camera's spool on another machine, or gone already


@station_type("discard")
class DiscardStation(StationPlugin):
    """Nothing to measure: the sherd is done once it is in the box (the last station). With
    sorting bins configured (stations of type bin, sorting.py) the box is the one whose rule
    holds for what the catalogue recorded of the sherd, this station's box when none does; the
    choice and its reason are recorded before the sherd is carried there. A rule on colour
    waits for the sherd's archival analysis (recorder.ANALYSIS_WAIT at most)."""

    status = "done"
    release_from_above = True

    def target(self, sherd):
        b = self.batch
        bins = b.config.bins()
        if not bins:
            return self.station
        if sherd.bin is None:
            with b.phase("data_collection"):
                decision = b.recorder.sort(
                    sherd.seq,
                    bins,
                    self.station.name,
                    wait_for_photo=any(rule.needs_colour for _, rule in bins),
                )
            sherd.bin = decision.bin
            b.event(sherd, "sorted", decision.reason)
        return b.config.stations[sherd.bin]

    def after_place(self, sherd):
        return "done"
