"""An in-memory rig and recorder for master-free runs of the whole batch machine (imported by
name; not a conftest).

`World` holds sherds lying on the stations of the config. The arm moves at once (1 s of the
fake clock per move) unless `refuse(x, y, z, yaw, linear)` returns a RigError code; the gripper
holds the sherd under the fingertips when it closes low enough and sets it down (or drops it)
where it opens; the wrist camera sees the sherds of a station within 0.15 m of it (and, like
the detector, offers none narrower than perception.min_sherd_size, but says it); the scale
weighs what lies on it. `Recorder` keeps the catalogue's status rules in memory.
"""

import math
import os
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple


from rascal_tasks import rig, workflow
from rascal_tasks.config import load_config
from rascal_tasks.catalogue.errors import StatusError
from rascal_tasks.manipulation import MAX_OPENING, MIN_OPENING
from rascal_tasks.sorting import SherdValues, choose_bin
from rascal_tasks.singulation import FINGERTIP
from rascal_tasks.survey import CAMERA_OFFSET

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
VIEW_RADIUS = 0.15  # m around the wrist camera's axis
DOUBLE_APART = 0.05  # m between two sherds set down together on the pickup mat
GRASP_ABOVE = 0.005  # grasp_z above the station surface that perception plans


@dataclass
class Sherd:
    name: str
    x: float
    y: float
    length: float = 0.05
    width: float = 0.04
    height: float = 0.01
    thickness: float = 0.007  # wall (the height as it lies adds its curvature)
    mass: float = 0.020  # kg
    station: Optional[str] = "pickup"  # None: on the table, off every station
    support: float = 0.0  # top of the sherd it lies on, above the station (0: on the station)
    # standing on its long edge along x (seen from above: length x thickness, width tall); a
    # sweep of the fingers through it below its top lays it flat, unless it is `wedged`
    standing: bool = False
    wedged: bool = False
    # picked up leaning steeply, it hangs from the fingers by its lower edge and stands where it
    # is first set down on a station
    stands_when_set_down: bool = False
    # the fingers close on it this wide (a chord across longer than its width seen from above:
    # a grasp turned to clear neighbours); None: its width
    held_width: Optional[float] = None
    # a sherd under it that the wrist camera sees as part of it (one outline from above) lifts
    # the wall the depth measures by this much, until it is set down elsewhere
    lifted_wall: float = 0.0
    # [rad] perception turns its grasp this far off closing across its width (neighbours in
    # the way): the detection's grasp_yaw
    grasp_turn: float = 0.0
    # the share of its outline perception sees under another sherd (the detection's covered)
    covered: float = 0.0
    # perception found a grasp of it whose fingers clear its neighbours (the detection's)
    grasp_clear: bool = True

    @property
    def chord(self) -> float:
        return self.width if self.held_width is None else self.held_width


def riding_world(config) -> "World":
    """b (5 g) lies on a's edge and rides along on a's first grasp (World.doubles): 25 g, within
    what one 50 x 40 mm sherd with a 7 mm wall can weigh; c lies apart."""
    world = World(
        config,
        [
            Sherd("a", 0.10, 0.22),
            Sherd("b", 0.13, 0.22, mass=0.005, support=0.01),
            Sherd("c", 0.25, 0.30),
        ],
    )
    world.doubles = {"a": "b"}
    return world


class World:
    def __init__(self, config, sherds: List[Sherd]):
        self.config = config
        self.sherds = list(sherds)
        self.held: Optional[Sherd] = None
        self.grasped_at = (0.0, 0.0)
        self.at = (0.0, 0.0, 0.3, 0.0)  # ee_gripper_link x, y, z, yaw
        self.closes: List[tuple] = []  # (x, y) of every close of the fingers
        self.t = 0.0
        self.moves: List[tuple] = []
        self.chains: List[list] = []  # the steps of each move_through (each also in `moves`)
        self.named: List[str] = []  # named poses gone to (park: "sleep")
        self.refuse = lambda x, y, z, yaw, linear: None
        self.slips: Dict[str, tuple] = {}  # sherd name -> where it falls when carried away
        self.slips_again: Dict[str, int] = {}  # sherd name -> times more it falls there so
        # sherd name -> where it falls when it slips out while lifted ((x, y), or None: off
        # every station, on the table beside the mat)
        self.lift_slips: Dict[str, Optional[tuple]] = {}
        self.camera_refusals = 0  # captures to refuse before one succeeds
        self.camera_refuses = lambda exposure_ev: False  # and any capture this says
        self.transfer_failures = 0  # captures to fail after their shutter, in the transfer
        self.at_shutter: List[tuple] = []  # where the gripper (x, y, z, yaw) was at each shutter
        self.in_view_at_shutter: List[list] = []  # names of the sherds lying in the photo
        self.transfer_moves: List[list] = []  # the moves made during each capture's transfer
        # photos written (into `photo_folder`) when set: a grey frame with a white patch of
        # `photo_light` x 255 x 2^EV (clipped at 255), of 1 % of the frame; the EVs asked for
        self.photo_folder: Optional[str] = None
        self.photo_light = 0.8
        self.exposures: List[float] = []
        self.tare = 0.0
        self.scale_settle = 0.0  # [s] readings unsteady this long after the load changed
        self.scale_load, self.scale_changed = 0.0, -1e9
        # sherd name -> the sherd lying under it that its first grasp lifts too (a heap); set
        # down together, the second lands `DOUBLE_APART` from the first
        self.doubles: Dict[str, str] = {}
        # grasped sherd -> (a neighbour, where its grasp shoves it): a nudge, or off the mat
        self.knock_off: Dict[str, Tuple[str, Tuple[float, float]]] = {}
        # set down together on the mat, the two stay one on the other (else they fall apart)
        self.stay_stacked = False
        self.held_extra: Optional[Sherd] = None
        self.opening: Optional[float] = None  # where the last open sent the fingers (None: closed)
        self.bad_holds: Dict[str, int] = {}  # sherd name -> grasps on it that close on nothing
        # the wrist camera sees this far around its axis; with `view_cuts`, a sherd reaching
        # beyond it is cut by the image border as by the detector: not offered, said as a part
        self.view_radius = VIEW_RADIUS
        self.view_cuts = False

    def closes_at(self, x: float, y: float, within: float = 0.01) -> int:
        """How many times the fingers closed within `within` of (x, y)."""
        return sum(math.hypot(cx - x, cy - y) < within for cx, cy in self.closes)

    def station_at(self, x, y):
        for st in self.config.stations.values():
            if st.area.has((x, y)):
                return st
        return None

    def lying(self, station: str) -> List[Sherd]:
        return [
            s
            for s in self.sherds
            if s is not self.held and s is not self.held_extra and s.station == station
        ]

    def put(self, s: Sherd, x, y):
        st = self.station_at(x, y)
        s.x, s.y, s.station = x, y, st.name if st else None
        s.support = s.lifted_wall = 0.0
        if s.stands_when_set_down and st is not None and st.name != "pickup":
            s.standing, s.stands_when_set_down = True, False

    def sweep(self, a, b, z):
        """The closed fingers moved level from `a` to `b` at ee height `z`: a standing sherd whose
        middle they passed within 10 mm of, below its top, falls over that way (half its
        height on)."""
        dx, dy = b[0] - a[0], b[1] - a[1]
        n = math.hypot(dx, dy)
        if n == 0:
            return
        st = self.station_at(*a)
        for s in self.lying(st.name if st else "pickup"):
            top = self.config.stations[s.station].surface_z + s.width
            t = ((s.x - a[0]) * dx + (s.y - a[1]) * dy) / n
            off = abs((s.x - a[0]) * dy - (s.y - a[1]) * dx) / n
            if not s.standing or s.wedged or not 0 < t < n or off > 0.01 or z - FINGERTIP > top:
                continue
            s.standing = False
            self.put(s, s.x + dx / n * s.width / 2, s.y + dy / n * s.width / 2)

    def rig(self) -> rig.Rig:
        return rig.Rig(
            _Arm(self), _Gripper(self), _Perception(self), _Scale(self), _Camera(self), _Clock(self)
        )


class _Arm(rig.Arm):
    def __init__(self, world):
        self.w = world

    def move_down(self, x, y, z, yaw, linear=False):
        code = self.w.refuse(x, y, z, yaw, linear)
        if code:
            raise rig.RigError("arm", code, "goal (%.3f, %.3f, %.3f)" % (x, y, z))
        if linear and self.w.at[2] == z:
            self.w.sweep(self.w.at[:2], (x, y), z)
        self.w.at = (x, y, z, yaw)
        self.w.moves.append((x, y, z, yaw, linear))
        self.w.t += 1.0
        return 1.0

    def move_through(self, steps, blend_above):
        self.w.chains.append(list(steps))  # one after the other, as the base class does
        return super().move_through(steps, blend_above)

    def go(self, named):
        self.w.named.append(named)
        self.w.t += 1.0
        return 1.0

    def stop(self):
        pass


class _Gripper(rig.Gripper):
    def __init__(self, world):
        self.w = world

    def open(self, width=None):
        target = MAX_OPENING if width is None else width
        if self.w.held is not None and target < self.w.held.chord:
            return 0.5  # sent narrower than it is held: the fingers press on, let go of nothing
        self.w.opening = target
        if self.w.held is not None:
            s, self.w.held = self.w.held, None
            x, y = self.w.at[:2]
            self.w.put(s, x, y)
            if self.w.held_extra is not None:
                extra, self.w.held_extra = self.w.held_extra, None
                # on the mat they fall apart (towards its middle); elsewhere they stay together
                st = self.w.station_at(x, y)
                if self.w.stay_stacked:  # the first lands on the second
                    self.w.put(extra, x, y)
                    s.support = extra.height
                    return 0.5
                if st is not None and st.type == "pickup":
                    y += DOUBLE_APART if y <= st.area.center[1] else -DOUBLE_APART
                self.w.put(extra, x, y)
        return 0.5

    def close(self):
        self.w.opening = None
        x, y, z, _ = self.w.at
        self.w.closes.append((x, y))
        st = self.w.station_at(x, y)
        lying = self.w.lying(st.name if st else None)
        for s in sorted(lying, key=lambda s: -s.support):  # the top one of a stack
            if math.hypot(s.x - x, s.y - y) < 0.01 and z <= st.surface_z + s.support + s.height:
                if s.standing or self.w.bad_holds.get(s.name, 0) > 0:  # standing: too thin across
                    if not s.standing:
                        self.w.bad_holds[s.name] -= 1
                    break
                self.w.held, self.w.grasped_at = s, (x, y)
                knocked = self.w.knock_off.pop(s.name, None)
                if knocked is not None:  # the fingers came down on a neighbour and shoved it
                    name, xy = knocked
                    n = next(p for p in self.w.sherds if p.name == name)
                    if n.station == "pickup":
                        self.w.put(n, *xy)
                partner = self.w.doubles.pop(s.name, None)
                if partner is not None:
                    self.w.held_extra = next(p for p in self.w.sherds if p.name == partner)
                return rig.GraspResult(True, s.chord)
        return rig.GraspResult(False, MIN_OPENING)

    def holding(self):
        s = self.w.held
        x, y = self.w.at[:2]
        if s is not None and s.name in self.w.lift_slips:
            self.w.held = None  # slipped out while lifted
            where = self.w.lift_slips.pop(s.name)
            if where is None:
                s.station = None
            else:
                self.w.put(s, *where)
        if (
            s is not None
            and s.name in self.w.slips
            and math.hypot(x - self.w.grasped_at[0], y - self.w.grasped_at[1]) > 0.05
        ):
            self.w.held = None  # slipped out on the way
            if self.w.slips_again.get(s.name, 0) > 0:
                self.w.slips_again[s.name] -= 1
                self.w.put(s, *self.w.slips[s.name])
            else:
                self.w.put(s, *self.w.slips.pop(s.name))
        return self.w.held is not None

    def width(self):
        if self.w.held is not None:
            return self.w.held.chord
        return MIN_OPENING if self.w.opening is None else self.w.opening


class _Perception(rig.Perception):
    def __init__(self, world):
        self.w = world
        self.calibrated: List[str] = []

    def calibrate(self, station):
        self.calibrated.append(station)

    def _camera(self):
        x, y, _, yaw = self.w.at
        return x + CAMERA_OFFSET * math.cos(yaw), y + CAMERA_OFFSET * math.sin(yaw)

    def _cut(self, s) -> bool:
        """Whether the view's edge cuts `s` (only with World.view_cuts)."""
        cx, cy = self._camera()
        return (
            self.w.view_cuts and math.hypot(s.x - cx, s.y - cy) + s.length / 2 > self.w.view_radius
        )

    def _in_view(self, station, cut=False):
        """The sherds whose centre is in view; those the view's edge cuts only with `cut`."""
        cx, cy = self._camera()
        return [
            s
            for s in self.w.lying(station)
            if math.hypot(s.x - cx, s.y - cy) < self.w.view_radius and (cut or not self._cut(s))
        ]

    def _part(self, s, surface) -> rig.Leftover:
        """The part of `s` in view: half of it, on the camera's side."""
        cx, cy = self._camera()
        d = math.hypot(s.x - cx, s.y - cy) or 1.0
        k = s.length / 4 / d
        return rig.Leftover(
            s.x + k * (cx - s.x),
            s.y + k * (cy - s.y),
            s.length / 2,
            s.width,
            "cut by the image border",
            surface,
            cut_by_border=True,
        )

    def _pickable(self, s):
        return not s.standing and s.width >= self.w.config["perception"]["min_sherd_size"]

    def leftovers(self, station):
        """Like the detector: what is narrower than min_sherd_size is said, not offered; one
        standing on its edge is as wide as it is thick and as tall as it is wide."""
        surface = self.w.config.stations[station].surface_z
        return [
            rig.Leftover(
                s.x,
                s.y,
                s.length,
                s.thickness if s.standing else s.width,
                "narrower than perception.min_sherd_size",
                surface,
                0.0,
                s.width if s.standing else s.height,
                s.standing,
            )
            for s in self._in_view(station)
            if not self._pickable(s)
        ] + [self._part(s, surface) for s in self._in_view(station, cut=True) if self._cut(s)]

    def detect(self, station):
        surface = self.w.config.stations[station].surface_z
        return [
            rig.Observation(
                s.x,
                s.y,
                0.0,
                s.length,
                s.width,
                s.support + s.height,
                s.x,
                s.y,
                surface + s.support + GRASP_ABOVE,
                s.grasp_turn,
                s.width + 0.012,
                thickness=s.thickness + s.lifted_wall,
                support=s.support,
                covered=s.covered,
                grasp_clear=s.grasp_clear,
            )
            for s in self._in_view(station)
            if self._pickable(s)
        ]

    def detect_if_calibrated(self, station):
        return self.detect(station) if station in self.calibrated else None


class _Scale(rig.Scale):
    def __init__(self, world):
        self.w = world

    def _load(self):
        return sum(s.mass for s in self.w.lying("scale"))

    def tare(self):
        self.w.tare = self._load()

    def readings(self, since):
        """A perfect scale: a steady reading of what lies on it now, every 0.1 s of the clock;
        with `scale_settle`, readings are unsteady that long after the load was seen to change
        (at the first look after it)."""
        load = self._load()
        if load != self.w.scale_load:
            self.w.scale_load, self.w.scale_changed = load, self.w.t
        first = math.floor(max(since, self.w.t - 30.0) / 0.1 + 1e-9) + 1
        last = math.floor(self.w.t / 0.1 + 1e-9)
        settle = self.w.scale_settle
        steady = self.w.scale_changed + settle
        mass = load - self.w.tare
        return [
            rig.ScaleReading(mass, settle <= 0 or k * 0.1 >= steady, k * 0.1)
            for k in range(first, last + 1)
        ]


class _Camera(rig.ArchivalCamera):
    """Refuses before its shutter (`camera_refusals`, `camera_refuses`) or after it, in the
    transfer (`transfer_failures`); `at_shutter` keeps where the gripper was at each shutter,
    `transfer_moves` the arm's moves during each transfer."""

    def __init__(self, world):
        self.w = world

    def capture_while(self, path, exposure_ev, during):
        if self.w.camera_refusals > 0 or self.w.camera_refuses(exposure_ev):
            self.w.camera_refusals = max(0, self.w.camera_refusals - 1)
            raise rig.RigError("/archival_camera/capture", "REFUSED", "cannot write " + path)
        self.w.at_shutter.append(self.w.at)
        view = next(s for s in self.w.config.stations.values() if s.type == "archival_camera")
        self.w.in_view_at_shutter.append(
            [s.name for s in self.w.sherds if s is not self.w.held and view.area.has((s.x, s.y))]
        )
        moved = len(self.w.moves)
        during()  # the transfer: the arm may move
        self.w.transfer_moves.append(self.w.moves[moved:])
        if self.w.transfer_failures > 0:
            self.w.transfer_failures -= 1
            raise rig.RigError("/archival_camera/capture", "REFUSED", "cannot write " + path)
        return self.capture(path, exposure_ev)

    def capture(self, path, exposure_ev=0.0):
        self.w.exposures.append(exposure_ev)
        if self.w.photo_folder is None:
            return rig.Capture(path, self.w.t, 2000, 1500)
        import cv2
        import numpy as np

        img = np.full((150, 200, 3), 90, np.uint8)
        img[:15, :20] = min(255, round(self.w.photo_light * 255 * 2.0**exposure_ev))
        path = os.path.join(self.w.photo_folder, os.path.basename(path))
        cv2.imwrite(path, img)
        return rig.Capture(path, self.w.t, 200, 150)


class _Clock(rig.Clock):
    def __init__(self, world):
        self.w = world

    def now(self):
        return self.w.t

    def sleep(self, seconds):
        self.w.t += seconds


@dataclass
class Row:
    seq: int
    status: str = "picked"
    pickup_xy: tuple = (0.0, 0.0)
    mass: Optional[float] = None
    mass_missing_reason: Optional[str] = None
    image: Optional[str] = None
    lost_reason: Optional[str] = None
    drops: int = 0
    notes: List[str] = field(default_factory=list)
    size: tuple = (None, None, None)  # length, width, thickness [m] the wrist camera measured
    bin: Optional[str] = None
    seconds: Dict[str, Optional[float]] = field(default_factory=dict)  # pick, weigh, photo, discard


class Recorder:
    """The catalogue's rows and status rules, in memory; `writes` lists every call in order."""

    AFTER = {
        "picked": ("picked",),  # taken over by the next pick (two put back apart)
        "weighed": ("picked", "mass_unstable", "weighed"),
        "mass_unstable": ("picked", "mass_unstable"),
        "photographed": ("mass_unstable", "weighed", "photographed"),
        "done": ("photographed",),
        "lost": ("picked", "mass_unstable", "weighed", "photographed"),
    }

    def __init__(self, unfinished=()):
        self.sherds: Dict[int, Row] = {}
        self._unfinished = list(unfinished)
        for seq, status, xy in self._unfinished:
            self.sherds[seq] = Row(seq, status, xy)
        self.writes: List[tuple] = []

    def _move(self, seq, status):
        row = self.sherds[seq]
        if row.status not in self.AFTER[status]:
            raise StatusError("sherd %d is %r: cannot record %r" % (seq, row.status, status))
        row.status = status
        self.writes.append((status, seq))
        return row

    def new_sherd(self, pickup_xy, attempts=1, seconds=None):
        seq = max(self.sherds, default=0) + 1
        self.sherds[seq] = Row(seq, pickup_xy=tuple(pickup_xy))
        self.sherds[seq].seconds["pick"] = seconds
        self.writes.append(("picked", seq))
        return seq

    def dimensions(self, seq, length, width, thickness, height=None, diameter=(0.0, 0.0)):
        self.sherds[seq].size = (length, width, thickness or None)
        self.writes.append(("dimensions", seq))

    def sort(self, seq, bins, default, wait_for_photo=False):
        """The catalogue's sorting (Recorder.sort) on this row; no colour: no photo analysis."""
        row = self.sherds[seq]
        values = SherdValues(
            *row.size,
            mass=row.mass,
            flags=frozenset(["dropped"] * bool(row.drops) + ["mass_unstable"] * (row.mass is None)),
        )
        decision = choose_bin(bins, default, values)
        row.bin = decision.bin
        self.writes.append(("sorted", seq, decision.bin))
        return decision

    def mass(self, seq, kg, stable=True, seconds=None):
        assert stable, "an unstable reading is never recorded as a mass"
        row = self._move(seq, "weighed")
        row.mass, row.mass_missing_reason = kg, None
        row.seconds["weigh"] = seconds

    def mass_by_difference(self, seq, kg, weighed):
        row = self.sherds[seq]
        if row.status not in ("weighed", "photographed"):
            raise StatusError(
                "sherd %d is %r: cannot record a mass by difference" % (seq, row.status)
            )
        assert abs(row.mass - weighed) < 1e-9, (row.mass, weighed)
        row.mass = kg
        self.writes.append(("mass_by_difference", seq))

    def mass_unstable(self, seq, reason, seconds=None):
        row = self._move(seq, "mass_unstable")
        row.mass, row.mass_missing_reason = None, reason
        row.seconds["weigh"] = seconds

    def spool_path(self, seq):
        return "/spool/T-%d.png" % seq

    def photo(self, seq, image_path, seconds=None):
        self._move(seq, "photographed").image = image_path
        self.sherds[seq].seconds["photo"] = seconds
        return image_path

    def done(self, seq, seconds=None, timings=None):
        self._move(seq, "done").seconds["discard"] = seconds

    def lost(self, seq, reason, timings=None):
        self._move(seq, "lost").lost_reason = reason

    def drop(self, seq, station):
        self.sherds[seq].drops += 1

    def taken_over(self, seq, pickup_xy):
        row = self._move(seq, "picked")
        row.pickup_xy = tuple(pickup_xy)

    def grasp_attempt(self, seq, station):
        pass

    def note(self, seq, text):
        self.sherds[seq].notes.append(text)

    def unfinished(self):
        return self._unfinished

    def status(self) -> Dict[int, str]:
        return {seq: row.status for seq, row in sorted(self.sherds.items())}


def shipped_config(*over):
    """config/rascal.yaml of this workspace, loaded as `rascal run` loads it, with the files
    `over` (relative to the workspace) merged over it."""
    return load_config(
        os.path.join(WORKSPACE, "config", "rascal.yaml"),
        over=[os.path.join(WORKSPACE, layer) for layer in over],
    )


def run_batch(config, world: World, recorder: Optional[Recorder] = None):
    """The whole batch machine against `world`: (outcome, batch, recorder)."""
    recorder = recorder or Recorder()
    batch = workflow.Batch(config, world.rig(), recorder, context="T", log=print)
    return workflow.build_machine(batch).execute(), batch, recorder
