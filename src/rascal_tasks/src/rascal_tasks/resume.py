"""The start of a batch, and a restart after a killed run: HOME (a sherd left in the fingers is
set down), CALIBRATE (background models, kept where a sherd lies), RESUME (the unfinished sherd
found and carried on with). No ROS in here.
"""

from rascal_tasks.batch import BatchState
from rascal_tasks.manipulation import grasp, grasp_retrying
from rascal_tasks.recovery import unlikeness
from rascal_tasks.rig import Timings
from rascal_tasks.sherd_record import SherdRecord
from rascal_tasks.survey import camera_over, survey_at, survey_pickup_area

# ee_gripper_link height above the pickup mat where Home lets go of a sherd found in the fingers
# after a restart: fingertips 4.4 mm lower, so a sherd up to ~2 cm thick drops a few mm at most.
PUT_BACK_HEIGHT = 0.025

# A sherd that fell from the fingers when the run died, found again on the pickup area, is
# known only by the size the wrist camera measured before (within ~1 mm in the simulator; a
# sherd landing on its other face shows about the same outline): a detection is taken for it
# only when both its length and its width are this close.
SAME_SIZE_M = 0.003
SAME_SIZE_FRACTION = 0.06


class Home(BatchState):
    """Open the gripper over the pickup area.

    After a killed run the fingers may still hold its unfinished sherd (or be open around it):
    a close tells. That sherd is set down where it was picked up, which is free, and Resume
    picks it up again; the stations must be calibrated with nothing in the wrist camera's view."""

    def __init__(self, batch):
        super().__init__(batch, ["done"])

    def run(self):
        b = self.batch
        # A driver that restarted since the last run: this run calibrates anew, so the
        # controller may take goals again.
        acknowledged = b.rig.arm.acknowledge_restart()
        if acknowledged.startswith("driver restart acknowledged"):
            b.event(None, "driver_restart_acknowledged", acknowledged)
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
                b.event(
                    None,
                    "put_back",
                    "sherd %d was in the gripper; set down at its pickup "
                    "spot (%.3f, %.3f) m" % (seq, x, y),
                )
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
            if plugin.stays:
                continue  # it sees the station before: learnt there (config.route)
            camera_over(b, st, *st.place_at)
            if not plugin.release_from_above:
                seen = b.rig.perception.detect_if_calibrated(st.name)
                if seen:
                    b.event(
                        None,
                        "calibration_kept",
                        "%d sherd(s) lying at the %s: its "
                        "background model from before is kept" % (len(seen), st.name),
                    )
                    continue
            b.rig.perception.calibrate(st.name)
            if st.type == "discard":
                b.rig.perception.calibrate(b.pickup.name)
        b.timings = Timings(started=b.rig.clock.now())  # set-up is the batch's, not the sherd's
        return "done"


class Resume(BatchState):
    """After a restart: find the sherd a killed run left unfinished and carry on with it.

    Outcomes name the state to go on with: TRANSLATE_k (it was in the gripper; Home set it
    down at its pickup spot and it is picked up again),
    STATION_i (it lies placed at station i, not yet measured there), REPICK_i (it lies at
    station i, measured), or SURVEY (nothing unfinished, or it is lost).

    A sherd that was on its way from the pickup area to the first station when the run died
    fell from the fingers: onto the first station, or back onto the pickup area, where the
    next survey would take it for a new sherd and record it twice. There it is looked for by
    its size and, found, carried on with under its own number (with a note saying how it was
    known); only a sherd found nowhere is recorded lost."""

    next_sherd = "SURVEY"

    def __init__(self, batch):
        n = len(batch.plugins)
        super().__init__(
            batch,
            ["SURVEY"]
            + ["%s_%d" % (k, i) for i in range(n) for k in ("TRANSLATE", "STATION")]
            + ["REPICK_%d" % i for i in range(n - 1)],
        )

    def run(self):
        b = self.batch
        rows = b.recorder.unfinished()
        if not rows:
            return "SURVEY"
        seq, status, pickup_xy = rows[0]
        statuses = [p.status for p in b.plugins]
        done = statuses.index(status) if status in statuses else -1
        b.event(None, "resume", "sherd %d was %s" % (seq, status))
        s = b.sherd = SherdRecord.resumed(b, seq, status)
        if b.put_back and b.put_back[0] == seq:
            return self.pick_put_back(s, done)
        for i in range(max(done, 0), len(b.plugins)):
            plugin = b.plugins[i]
            st = plugin.lies_at
            if plugin.release_from_above:
                break
            if plugin.stays and i > done:
                continue  # where the station before looked
            seen = survey_at(b, st, *st.place_at)
            if seen:
                s.seen(seen[0], st)
                s.station_done(done)
                if i != done:
                    return "STATION_%d" % i
                # measured here; a camera over the scale shoots it where it lies
                stays = b.next_stays(i) is not None
                return ("STATION_%d" if stays else "REPICK_%d") % (i + stays)
        if done < 0 and self.pick_fallen(s, pickup_xy):
            return "TRANSLATE_0"
        s.lose("not found after restart (was %s)" % status)
        return "SURVEY"

    def pick_fallen(self, s: SherdRecord, pickup_xy) -> bool:
        """Look over the pickup area for the sherd `s` that fell from the fingers, by the size
        the wrist camera measured; pick up the one most like it. True when it is held."""
        b = self.batch
        size = b.recorder.wrist_size(s.seq)
        if size is None:
            return False
        length, width = size

        def alike(c):
            return abs(c.length - length) <= max(SAME_SIZE_M, SAME_SIZE_FRACTION * length) and abs(
                c.width - width
            ) <= max(SAME_SIZE_M, SAME_SIZE_FRACTION * width)

        candidates = [c for c in survey_pickup_area(b) if alike(c)]
        if not candidates:
            return False

        def unlike(c, _last=None):
            return unlikeness(c, length, width, pickup_xy)

        o, _tries, held = grasp_retrying(b, min(candidates, key=unlike), b.pickup, like=unlike)
        if not held:
            return False
        s.seen(o, b.pickup)
        s.picked_xy = (o.x, o.y)
        text = (
            "fell from the gripper when the run stopped; found again on the pickup area at "
            "(%.3f, %.3f) m by its size (%.1f x %.1f mm; %d detection(s) of that size)"
            % (o.x, o.y, o.length * 1000, o.width * 1000, len(candidates))
        )
        b.event(s, "refound", text)
        s.note(text)
        return True

    def pick_put_back(self, s: SherdRecord, done: int) -> str:
        b = self.batch
        _, x, y = b.put_back
        near = [
            o
            for o in survey_at(b, b.pickup, x, y)
            if o.distance_to(x, y) < b.config["recovery"]["search_radius"]
        ]
        # a camera over the scale works where the scale set the sherd down: it goes back onto
        # the scale (weighed again), not to the camera's spot as a station of its own
        to = done + 1
        while 0 < to < len(b.plugins) and b.plugins[to].stays:
            to -= 1
        for o in sorted(near, key=lambda o: o.distance_to(x, y))[:1]:
            if grasp(b, o, b.pickup):
                s.seen(o, b.pickup)
                s.picked_xy = (o.x, o.y)
                s.station_done(to - 1)
                return "TRANSLATE_%d" % to
        s.lose("set down at its pickup spot after restart, not picked up again")
        return "SURVEY"
