"""What the station workflow needs from the rig, as plain Python.

The workflow core talks only to these small interfaces; `ros_rig.py` implements them over ROS
(the arm controller's actions, the detector's services, the scale topic, the archival camera
service). Tests can run the core against the simulator through the same adapters. No ROS here.
"""

import math
from dataclasses import dataclass, field
from typing import List, Optional, Tuple


class RigError(Exception):
    """A device did not do what was asked; `reason` is the device's one-line explanation."""

    def __init__(self, device: str, code: str, reason: str):
        super().__init__("%s: %s: %s" % (device, code, reason))
        self.device = device
        self.code = code
        self.reason = reason


@dataclass
class Observation:
    """One sherd as perception saw it, in base_link (metres, radians)."""

    x: float
    y: float
    yaw: float  # major axis
    length: float
    width: float
    height: float  # top surface above the station surface
    grasp_x: float
    grasp_y: float
    grasp_z: float  # ee_gripper_link height for closing
    grasp_yaw: float  # gripper yaw so the fingers close across the minor axis
    grasp_width: float  # opening before closing
    colour: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    score: float = 1.0
    thickness: float = 0.0  # wall thickness from depth (0 = not measured)
    vessel_diameter: float = 0.0  # the vessel's outer diameter from the curvature (0 = not told)
    vessel_diameter_sigma: float = 0.0  # its 1-sigma uncertainty
    covered: float = 0.0  # share of its outline under another sherd lying on it (a heap)
    grasp_clear: bool = True  # perception found a grasp whose fingers clear its neighbours
    support: float = 0.0  # top of what it lies on above the station surface (a sherd in a heap)

    @property
    def grasp_turn(self) -> float:
        """How far its grasp is turned off closing across its minor axis (rad, within +-pi/2):
        perception turns it where a neighbour blocks a finger (a heap)."""
        return math.remainder(self.grasp_yaw - self.yaw, math.pi)

    @property
    def grasp_shift(self) -> float:
        """How far off its centre its grasp closes, a fraction of its half-length: perception
        moves it along the sherd where a neighbour beside the middle blocks a finger (a heap)."""
        return math.hypot(self.grasp_x - self.x, self.grasp_y - self.y) / max(1e-3, self.length / 2)

    @property
    def own_height(self) -> float:
        """Its height as it lies, from what it rests on (in a heap: not the sherd under it)."""
        return max(self.height - self.support, 0.0)

    def distance_to(self, x: float, y: float) -> float:
        return math.hypot(self.x - x, self.y - y)


@dataclass
class Leftover:
    """Something perception saw at a station but does not offer as a sherd to pick (too small or
    too large by perception.min/max_sherd_size, not measurable, or only partly in view), in
    base_link."""

    x: float
    y: float
    length: float  # [m] about: from the image
    width: float
    why: str  # one line naming the rule
    surface_z: float = 0.0  # [m] of the surface it lies on
    yaw: float = 0.0  # [rad] its long side's direction
    height: float = 0.0  # [m] its top above the surface (0: not seen)
    on_edge: bool = False  # taller than wide: standing on its edge (singulation.topple)
    # only part of it in view, the image border cuts it (position and size the part's): a view
    # centred on it sees it whole (survey.look_at_cut_sherds)
    cut_by_border: bool = False

    def distance_to(self, x: float, y: float) -> float:
        return math.hypot(self.x - x, self.y - y)


@dataclass
class ScaleReading:
    mass: float  # kg, tared, as the scale shows it
    stable: bool  # the scale's own stability flag (stations.ScaleStation does not trust it alone)
    stamp: float = 0.0  # s (rig clock): when the reading was taken


@dataclass
class Capture:
    path: str
    stamp: float  # shutter time, s
    width: int
    height: int


@dataclass
class GraspResult:
    holding: bool
    width: float  # m, opening at the end


@dataclass
class Timings:
    """Seconds (rig clock) spent per phase, the paper's Fig. 10 breakdown."""

    locomotion: float = 0.0
    grasping: float = 0.0
    data_collection: float = 0.0
    perception: float = 0.0
    phases: dict = field(default_factory=dict)
    started: float = 0.0  # rig clock when this sherd's time began (not a phase)

    def add(self, phase: str, seconds: float):
        setattr(self, phase, getattr(self, phase) + seconds)

    def total(self) -> float:
        return self.locomotion + self.grasping + self.data_collection + self.perception

    def as_dict(self) -> dict:
        return {
            "locomotion": round(self.locomotion, 3),
            "grasping": round(self.grasping, 3),
            "data_collection": round(self.data_collection, 3),
            "perception": round(self.perception, 3),
        }


class Arm:
    """Moves ee_gripper_link with the gripper pointing down (the only way RASCAL holds sherds)."""

    def move_down(self, x: float, y: float, z: float, yaw: float, linear: bool = False) -> float:
        """Move to (x, y, z) with the gripper pointing down at `yaw`; returns seconds taken.
        Raises RigError (UNREACHABLE, COLLISION, TIMEOUT, PREEMPTED)."""
        raise NotImplementedError

    def move_through(self, steps: List[tuple], blend_above: float) -> float:
        """Move down to each of `steps` ((x, y, z, yaw, linear) as move_down's) in turn; a rig
        that can blends them where the gripper stays above `blend_above` [m] (the next move
        starts before the one before has stopped). Here: one move_down after the other.
        Returns seconds taken; raises as move_down."""
        del blend_above
        return sum(self.move_down(*step) for step in steps)

    def go(self, named: str) -> float:
        raise NotImplementedError

    def stop(self) -> None:
        raise NotImplementedError

    def acknowledge_restart(self) -> str:
        """Tell the arm controller this run knows its driver may have restarted and calibrates
        anew: until then a controller that saw the driver restart refuses every goal
        (DRIVER_RESTARTED). Called once when a run starts (HOME); returns the controller's line.
        No-op by default (rigs without such a controller)."""
        return ""


class Gripper:
    def open(self, width: Optional[float] = None) -> float:
        """Open to `width` metres between the fingertips (None: fully); returns seconds."""
        raise NotImplementedError

    def open_while(self, width: Optional[float], during):
        """Open to `width` while `during()` runs (an arm move the caller knows the stroke may
        overlap); returns `during()`'s value once both are done. Here: one after the other."""
        self.open(width)
        return during()

    def close(self) -> GraspResult:
        raise NotImplementedError

    def holding(self) -> bool:
        """Whether the fingers are still stopped short of closed (a sherd is in them)."""
        raise NotImplementedError

    def width(self) -> float:
        """Current opening between the fingertips (m)."""
        raise NotImplementedError


class Perception:
    def calibrate(self, station: str) -> None:
        raise NotImplementedError

    def detect(self, station: str) -> List[Observation]:
        raise NotImplementedError

    def detect_if_calibrated(self, station: str) -> Optional[List[Observation]]:
        """Like detect, but None at once if the station has no background model yet."""
        raise NotImplementedError

    def leftovers(self, station: str) -> List[Leftover]:
        """What the last detect at `station` saw there but did not offer as sherds."""
        return []


class Scale:
    def tare(self) -> None:
        """Zero the scale at its present load; readings taken after it returns are tared.
        Raises RigError when the scale refuses or does not answer."""
        raise NotImplementedError

    def readings(self, since: float) -> List[ScaleReading]:
        """The readings taken after `since` (rig clock, s), oldest first, of those kept (at
        least the last 30 s); never waits. The weighing rule is the station's
        (`stations.ScaleStation`), not the adapter's."""
        raise NotImplementedError


class ArchivalCamera:
    def capture(self, path: str, exposure_ev: float = 0.0) -> Capture:
        """One photo stored at `path`, `exposure_ev` stops from the configured exposure."""
        raise NotImplementedError

    def capture_while(self, path: str, exposure_ev: float, during) -> Capture:
        """`capture`, with `during()` (the arm's way back over the sherd) run once the shutter
        has closed, while the image is still being transferred; returns the capture once both
        are done. Raises the capture's RigError without running `during()` when it fails
        before the shutter closed. Here: one after the other."""
        capture = self.capture(path, exposure_ev)
        during()
        return capture


class Clock:
    def now(self) -> float:
        raise NotImplementedError

    def sleep(self, seconds: float) -> None:
        raise NotImplementedError


@dataclass
class Rig:
    arm: Arm
    gripper: Gripper
    perception: Perception
    scale: Scale
    camera: ArchivalCamera
    clock: Clock
