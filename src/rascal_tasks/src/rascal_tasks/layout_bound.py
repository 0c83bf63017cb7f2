"""The physical bound of a station layout: the seconds one sherd takes at the arm's and the
stations' limits, to set the measured seconds per sherd against (issue 18, item 2).

Every move of the workflow's sequence (a look at the sherd, pickup, scale, archival camera with
its standby, discard; approach, descent, lift at each) is timed as the synchronised trapezoid
of its slowest joint at the servos' limits (facts/timing.md: pi rad/s, 5 rad/s^2) between joint
vectors from the arm's own IK, with the wrist turned the least (yaw along the arm: a symmetric
grasp); the gripper's strokes only as wide as the grasp margin; the stations' own times from the
simulator's models (the scale's settling, the camera's shutter and transfer). Two figures:

- `serial`: that sequence with the waits as the workflow runs them today (the shutter with
  the arm at standby, the transfer overlapped by the way back over the sherd, the grasp and
  the lift, `ArchivalCameraStation`; the tare is done while the arm is at the later stations,
  `ScaleStation.while_away`);
- `bound`: the same moves with only what cannot overlap arm motion (the loaded scale settling
  while the arm hovers, the shutter): no planner margin, no transfer wait.

With the camera over the scale (`over_scale`, the one-station layout) the sherd is set down
once: the scale settles while the arm lifts and goes to standby, the shutter, and the way back
down round the sherd (ArchivalCameraStation.measure_here); then the grasp and the lift for the
discard box, all during the transfer.

Moves the workflow makes as one motion (`Batch.move_through`, with arm.blend_z > 0: the carry
and the descent at a station, the lift from the scale and the way to standby)
are timed as one move from where the first starts to where the last ends: no motion through
those points can be faster, whatever corner it cuts.

Pickup spots are averaged over a grid of the pickup area. The batch's own moves are shared by its
sherds, as the measured seconds per sherd share them: from the sleep pose over the pickup area,
the wrist camera over each station to learn its background, the first lawnmower survey, the
surveys that find the mat empty (recovery.max_empty_surveys) and the park (`batch`); `cycle` is
the figure without them (one survey shared, as before they were counted).

No ROS here: `rosrun rascal_tasks layout_bound` (scripts/) gives `bound_of` the
arm controller's IK.
"""

import math
from dataclasses import dataclass, replace
from typing import Callable, Dict, List, Tuple

from rascal_tasks.config import Config
from rascal_tasks.joint_motion import move_time
from rascal_tasks.survey import gripper_for_camera_over

# rascal_sim ScaleSensor (timing.md): first-order settling, readings every 0.1 s
SCALE_TIME_CONSTANT = 0.3  # [s]
SCALE_PERIOD = 0.1  # [s]
# rascal_sim ArchivalCamera (timing.md): the arm stays out of view for the shutter
SHUTTER = 0.2  # [s]
TRANSFER = 1.5  # [s] image download after the shutter; the arm may move meanwhile
# A representative sherd (facts/sherds_and_colour.md: 20-70 mm, 5-60 g): its mass sets the
# scale's settling, its grasp height the descents.
TYPICAL_MASS = 0.02  # [kg]
GRASP_HEIGHT = 0.008  # [m] ee_gripper_link above the surface when closing
PICKUP_GRID = (5, 3)  # pickup spots averaged over, along x and y


def scale_settle(mass: float, window: float, readability: float) -> float:
    """Seconds from a load landing until a whole `window` of readings stays within
    `readability`: the first-order approach's change over the window falls below it."""
    decay = 1.0 - math.exp(-window / SCALE_TIME_CONSTANT)
    t = SCALE_TIME_CONSTANT * math.log(max(1.0, mass * decay / readability))
    return math.ceil((t + window) / SCALE_PERIOD) * SCALE_PERIOD


@dataclass
class Step:
    what: str
    pose: Tuple[float, float, float]  # x, y, z of ee_gripper_link [m]
    wait: float = 0.0  # [s] after arriving (gripper stroke, station) in the bound
    serial_wait: float = 0.0  # [s] more as the workflow runs today: in series, but for...
    overlaps_next: int = 0  # ...this many next moves (and their waits), made meanwhile
    # `wait` runs on during this many next moves (and the waits between them: the shutter
    # while the scale settles): only its excess over them counts
    wait_during: int = 0
    blends: bool = False  # one motion with the step before (which then has no wait of its own)


def sequence(cfg: Config, pickup_xy: Tuple[float, float], look: bool = True) -> List[Step]:
    """The moves and waits of one sherd picked at `pickup_xy`, from the discard drop of the
    sherd before to its own (the workflow's order: stations in config order). `look`: the
    wrist camera looks at the sherd first (every pick but a survey's first, pickup.look_again)."""
    arm, scale = cfg["arm"], cfg["scale"]
    margin_stroke = arm["gripper"]["stroke_time"] * arm["grasp_margin"] / 0.044  # of 30..74 mm
    travel, approach = arm["travel_z"], arm["approach_offset"]
    blend = arm["blend_z"] > 0
    steps: List[Step] = []
    px, py = pickup_xy
    z0 = cfg.stations["pickup"].surface_z + GRASP_HEIGHT
    if look:
        steps += camera_over_steps(cfg, [pickup_xy], "look at the sherd")
    steps += [
        Step("approach pickup", (px, py, z0 + approach), wait=margin_stroke),  # open on the way
        Step("descend", (px, py, z0), wait=margin_stroke),  # close
        Step("lift", (px, py, travel)),  # every grasp's lift alone: checked at the top
    ]
    order = cfg.station_order()
    for name, after in zip(order, order[1:] + [None], strict=True):
        st = cfg.stations[name]
        if st.type == "discard":
            x, y = st.place_at
            # let go over it
            steps.append(Step("over discard", (x, y, travel), wait=margin_stroke))
            continue
        if not st.over_scale:  # over the scale (one station) it is shot where it lies
            x, y = st.place_at
            z = st.surface_z + GRASP_HEIGHT + arm["place_clearance"]
            # a scale tared meanwhile: carried and lowered as one motion
            steps.append(Step("over " + name, (x, y, travel)))
            steps.append(Step("place at " + name, (x, y, z), wait=margin_stroke, blends=blend))
        if st.type == "scale":
            settle = scale_settle(TYPICAL_MASS, scale["stable_window"], scale["readability"])
            if after is not None and cfg.stations[after].over_scale:
                # it settles while the arm goes up and out of the camera's view (make_way:
                # one motion, or two), the shutter, and the way back down round the sherd
                # (ArchivalCameraStation.measure_here)
                moves = (1 if blend else 2) + 2
                steps.append(Step("scale settles", (x, y, z), wait=settle, wait_during=moves))
                steps.append(Step("lift", (x, y, travel)))
                continue  # the camera over it takes it from here
            steps.append(Step("hover", (x, y, z + approach), wait=settle))  # while it settles
        elif st.type == "archival_camera":
            if not st.over_scale:
                steps.append(Step("lift", (x, y, travel)))
            sx, sy = arm["standby"]
            steps.append(
                Step(
                    "standby",
                    (sx, sy, travel),
                    wait=SHUTTER,
                    serial_wait=TRANSFER,
                    overlaps_next=3,  # back over it, down, taken up (ArchivalCameraStation)
                    blends=blend and st.over_scale,  # up from the scale and away, one motion
                )
            )
            steps.append(Step("back over " + name, (x, y, z + approach)))
        else:
            steps.append(Step("lift", (x, y, travel)))
        steps.append(Step("descend", (x, y, z), wait=margin_stroke))
        steps.append(Step("lift", (x, y, travel)))
    return steps


def merged(steps: List[Step]) -> List[Step]:
    """`steps` with each run of blended steps as one step: to the run's last pose, with its
    last step's waits."""
    out: List[Step] = []
    for s in steps:
        if s.blends and out:
            prev = out[-1]
            assert not (prev.wait or prev.serial_wait or prev.wait_during), prev.what
            out[-1] = replace(s, what=prev.what + " + " + s.what, blends=False)
        else:
            out.append(s)
    return out


def camera_over_steps(cfg: Config, spots, what: str) -> List[Step]:
    """The wrist camera over each of `spots` of the pickup area at the survey height."""
    st, sv = cfg.stations["pickup"], cfg["survey"]
    out = []
    for x, y in spots:
        ex, ey, _ = gripper_for_camera_over(x, y)
        out.append(Step(what, (ex, ey, st.surface_z + sv["z"]), wait=sv["settle_time"]))
    return out


def survey_steps(cfg: Config) -> List[Step]:
    st = cfg.stations["pickup"]
    spots = st.area.lawnmower(cfg["survey"]["step"])
    return camera_over_steps(cfg, spots, "survey")


def start_steps(cfg: Config) -> List[Step]:
    """A batch's moves before its first sherd, from the sleep pose: over the pickup area
    (resume.Home), the wrist camera over each station a sherd is set down at to learn its
    background (resume.Calibrate), the first survey."""
    pickup, travel = cfg.stations["pickup"], cfg["arm"]["travel_z"]
    steps = [Step("home", (*pickup.area.center, travel))]
    for name in cfg.route():  # the camera over the scale is learnt with the scale
        st = cfg.stations[name]
        ex, ey, _ = gripper_for_camera_over(*st.place_at)
        z = st.surface_z + cfg["survey"]["z"]
        steps.append(Step("learn " + name, (ex, ey, z), wait=cfg["survey"]["settle_time"]))
    return steps + survey_steps(cfg)


class Overlap:
    """A wait that the next steps are made during: their moves, and the waits between them,
    pass it (and the last one's own wait with `with_last_wait`); what is left of it is waited
    after them."""

    def __init__(self, wait: float = 0.0, steps: int = 0, with_last_wait: bool = False):
        self.left, self.steps, self.with_last_wait = wait, steps, with_last_wait

    def passed(self, move: float, own_wait: float) -> float:
        """One more step made meanwhile; what is left of the wait once it was the last one
        (before its own wait without `with_last_wait`), else 0."""
        if not self.steps:
            return 0.0
        self.steps -= 1
        meanwhile = move + (own_wait if self.steps or self.with_last_wait else 0.0)
        self.left = max(0.0, self.left - meanwhile)
        return 0.0 if self.steps else self.rest()

    def rest(self) -> float:
        """What is left of it, taken (the sequence ended before its steps did)."""
        left, self.left, self.steps = self.left, 0.0, 0
        return left


def timed(steps: List[Step], ik: Callable, start) -> Tuple[float, float, float, list]:
    """(motion, bound waits, serial waits, last joints) of `steps` from the joints `start`."""
    q, motion, waits, serial = start, 0.0, 0.0, 0.0
    serial_over = Overlap()  # a serial wait the next moves are made during (Step.overlaps_next)
    bound_over = Overlap()  # a wait the next moves are made during (Step.wait_during)
    for s in merged(steps):
        q1 = ik(*s.pose, q)
        move = move_time(q, q1)
        motion += move
        own_wait = 0.0 if s.wait_during else s.wait
        serial += serial_over.passed(move, own_wait)
        waits += bound_over.passed(move, own_wait) + own_wait
        if s.wait_during:
            bound_over = Overlap(s.wait, s.wait_during)
        if s.overlaps_next:
            serial_over = Overlap(s.serial_wait, s.overlaps_next, with_last_wait=True)
        else:
            serial += s.serial_wait
        q = q1
    return motion, waits + bound_over.rest(), serial + serial_over.rest(), q


def bound_of(cfg: Config, ik: Callable, sherds: int = 10) -> Dict[str, float]:
    """Seconds per sherd at the limits, averaged over the pickup grid, for a batch of `sherds`
    (one survey finds them all). `ik(x, y, z, seed)` -> joints of ee_gripper_link pointing
    down at (x, y, z), yaw along the arm. `bound`: the sherd's own moves and waits plus its
    share of the batch's (`batch`: from the sleep pose through the stations' background and
    the first survey, the surveys that find the mat empty, recovery.max_empty_surveys, and the
    park), as the measured seconds per sherd count them; `cycle`: the sherd's own plus its
    share of one survey alone (the batch's start and end left out)."""
    st = cfg.stations["pickup"]
    sx, sy = st.area.size
    nx, ny = PICKUP_GRID
    spots = [
        st.area.to_table((-sx / 2 + (i + 0.5) * sx / nx, -sy / 2 + (j + 0.5) * sy / ny))
        for i in range(nx)
        for j in range(ny)
    ]
    dx, dy = cfg.stations["discard"].place_at
    discard = ik(dx, dy, cfg["arm"]["travel_z"], None)  # where every sherd's sequence starts
    totals = {"motion": 0.0, "waits": 0.0, "serial_waits": 0.0}
    # a survey's first sherd is grasped from the survey's detection, the others after a look
    looked = (sherds - 1) / max(1, sherds)
    for spot in spots:
        for look, share in ((True, looked), (False, 1.0 - looked)):
            m, w, s, _ = timed(sequence(cfg, spot, look), ik, discard)
            totals["motion"] += share * m / len(spots)
            totals["waits"] += share * w / len(spots)
            totals["serial_waits"] += share * s / len(spots)
    m, w, _, q = timed(survey_steps(cfg), ik, discard)
    totals["survey"] = (m + w + move_time(q, discard)) / max(1, sherds)
    # the first sherd counted from the discard box as every other, not from the survey's end
    sleep = cfg["arm"]["named_poses"]["sleep"]
    m, w, _, _ = timed(start_steps(cfg), ik, sleep)
    q = discard
    for _ in range(cfg["recovery"]["max_empty_surveys"]):
        mi, wi, _, q = timed(survey_steps(cfg), ik, q)
        m, w = m + mi, w + wi
    totals["batch"] = (m + w + move_time(q, sleep)) / max(1, sherds)
    own = totals["motion"] + totals["waits"]
    totals["cycle"] = own + totals["survey"]
    totals["bound"] = own + totals["batch"]
    totals["serial"] = totals["bound"] + totals["serial_waits"]
    return totals
