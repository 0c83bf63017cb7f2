"""The emulated rig: the simulator's arm and scale behind the device emulators.

The simulator runs with its device topics moved under a namespace (/emulated/joint_states,
/emulated/arm/joint_trajectory, /emulated/gripper/command, /emulated/scale/mass); this bridge
puts the servo-bus emulator and the scale emulator in front of them, so arm_driver and
scale_driver talk Dynamixel Protocol 2.0 and MT-SICS/A&D over pseudo-terminals to a physical
arm and scale, and the controller, detector and task layer run on the drivers' topics:

- servo goals -> simulated arm: the Goal Position each servo holds (as arm_driver wrote it) is
  sent to the simulator as a short trajectory starting at that goal with the goals' rate (the
  arm joints, when a goal changed) or as a gripper command (when the gripper's goal changed);
- simulated arm -> servos: the simulator's joint angles (and the finger, through the horn
  linkage) become each servo's Present Position, so a sherd between the fingers stops the
  gripper's horn where the simulated fingers stop;
- simulated scale -> scale emulator: the load on the emulated pan follows the simulator's
  reading (a change beyond the readability, or any unsteady reading); the emulator settles,
  quantises and tares it as a scale does.

Offsets of drivers.arm.offsets are applied as on the rig (servo angle = URDF angle + offset).
No ROS here: the node (scripts/emulated_devices) passes messages in and publishes what comes out.
"""

from typing import Dict, List, Optional, Sequence, Tuple

from rascal_drivers import arm_bus
from rascal_drivers import control_table as ct
from rascal_drivers import finger_linkage

FEED_FORWARD = False  # send the servos' rate too: the simulated arm then overshoots each stop
HORIZON = 0.03  # [s] each command to the simulated arm: the goal now, extrapolated this far
VELOCITY_WINDOW = 0.04  # [s] wall: the servos' rate is taken over this long (ticks are coarse)
STOPPED_AFTER = 0.04  # [s] wall: unchanged this long = the servos have stopped
RATE_WINDOW = 1.0  # [s] wall: the simulator's pace (ROS seconds per wall second) over this long
SCALE_HYSTERESIS = 2e-4  # [kg] a steady simulated reading moves the pan load beyond this only


class SimBridge:
    def __init__(
        self, bus, scale, ids: Dict[str, int], offsets: Dict[str, float], mirror_arm=False
    ):
        """`bus`: a ServoBusEmulator (not yet started is fine), `scale`: a ScaleEmulator.
        mirror_arm False (the emulated rig's choice): the arm servos move by the emulator's own
        motion model and the simulated arm follows their Present Position; only the gripper's
        horn is where the simulated fingers are (a sherd between them stops it). True: every
        servo is where the simulated joint is and the simulator is sent the Goal Positions;
        the simulated arm, acceleration-limited like the controller's plans, then lags and
        overshoots (see README, "Not done")."""
        self.mirror_arm = mirror_arm
        self.bus = bus
        self.scale = scale
        self.ids = ids
        self.offsets = offsets
        self._arm_sent: Optional[Tuple[int, ...]] = None
        self._gripper_sent: Optional[int] = None
        self._scale_stable = False
        self._history: List[Tuple[float, List[float]]] = []  # (wall time, positions) changes
        self._clock: List[Tuple[float, float]] = []  # (wall time, ROS time): the simulator's pace
        self._changed_at = 0.0
        self._moving = False

    @staticmethod
    def initial_ticks(
        names: Sequence[str], positions: Sequence[float], ids, offsets
    ) -> Dict[int, int]:
        """Servo ID -> ticks for the simulator's first joint state (servos start where the
        simulated arm is, as a powered arm's servos report where the links are)."""
        q = dict(zip(names, positions, strict=False))
        ticks = {}
        for role, rad in SimBridge._role_angles(q, offsets).items():
            ticks[ids[role]] = ct.rad_to_ticks(rad)
        return ticks

    @staticmethod
    def _role_angles(q: Dict[str, float], offsets) -> Dict[str, float]:
        angles = {}
        for joint in arm_bus.ARM_JOINTS:
            if joint in q:
                angles[joint] = q[joint] + offsets[joint]
        if "left_finger" in q:
            angles["gripper"] = (
                finger_linkage.angle_from_finger(q["left_finger"]) + offsets["gripper"]
            )
        for shadow, primary in arm_bus.SHADOW_OF.items():
            if primary in angles:
                angles[shadow] = angles[primary]
        return angles

    def on_sim_joints(
        self, names: Sequence[str], positions: Sequence[float], velocities: Sequence[float]
    ) -> None:
        q = dict(zip(names, positions, strict=False))
        v = dict(zip(names, velocities, strict=False)) if velocities else {}
        rate = ct.TICKS_PER_REV / (2.0 * 3.141592653589793)  # ticks per rad
        angles = self._role_angles(q, self.offsets)
        if not self.mirror_arm:
            angles = {r: a for r, a in angles.items() if r == "gripper"}
        with self.bus.lock:
            for role, rad in angles.items():
                servo = self.bus.servos.get(self.ids[role])
                if servo is None:
                    continue
                servo.external_position = rad * rate + ct.CENTRE_TICK
                joint = arm_bus.SHADOW_OF.get(role, role)
                if joint == "gripper":
                    theta = angles["gripper"] - self.offsets["gripper"]
                    finger_rate = finger_linkage.finger_rate(theta, 1.0)
                    speed = v.get("left_finger", 0.0) / finger_rate if finger_rate else 0.0
                else:
                    speed = v.get(joint, 0.0)
                servo.external_velocity = speed * rate

    def _goal(self, role: str, field: str = "goal_position") -> Tuple[int, bool]:
        servo = self.bus.servos[self.ids[role]]
        return servo.get(field), bool(servo.get("torque_enable"))

    def arm_goal(
        self, now: float, wall: Optional[float] = None
    ) -> Optional[Tuple[List[float], List[float]]]:
        """(positions [rad, URDF], velocities [rad/s of ROS time]) for the simulated arm at ROS
        time `now` (wall clock `wall`, default = now) when they changed (or just stopped
        changing) and the servos hold torque; else None. The positions are the servos' (see
        mirror_arm); the velocity is their rate over the last VELOCITY_WINDOW of wall time,
        in ROS time (the simulator may run slower than the wall clock): the simulated arm
        follows it as feed-forward."""
        wall = now if wall is None else wall
        field = "goal_position" if self.mirror_arm else "present_position"
        with self.bus.lock:
            goals = [self._goal(j, field) for j in arm_bus.ARM_JOINTS]
        self._clock.append((wall, now))
        while len(self._clock) > 2 and wall - self._clock[1][0] >= RATE_WINDOW:
            self._clock.pop(0)
        if not all(torque for _, torque in goals):
            self._history.clear()
            return None
        ticks = tuple(t for t, _ in goals)
        rad = [
            ct.ticks_to_rad(t) - self.offsets[j]
            for t, j in zip(ticks, arm_bus.ARM_JOINTS, strict=True)
        ]
        if ticks == self._arm_sent:
            if self._moving and wall - self._changed_at > STOPPED_AFTER:
                self._moving = False
                return rad, [0.0] * len(rad)  # they stopped: hold there, no coasting on
            return None
        self._arm_sent, self._changed_at, self._moving = ticks, wall, True
        self._history.append((wall, rad))
        while len(self._history) > 2 and wall - self._history[1][0] >= VELOCITY_WINDOW:
            self._history.pop(0)
        rate = self.pace()
        t0, q0 = self._history[0]
        dt = (wall - t0) * rate
        if dt <= 0:
            return rad, [0.0] * len(rad)
        cap = 1.5 * arm_bus.VELOCITY_LIMIT
        return rad, [max(-cap, min(cap, (b - a) / dt)) for a, b in zip(q0, rad, strict=True)]

    def pace(self) -> float:
        """ROS (simulated) seconds per wall second over the last RATE_WINDOW (1.0 until known)."""
        if len(self._clock) < 2:
            return 1.0
        (w0, s0), (w1, s1) = self._clock[0], self._clock[-1]
        return (s1 - s0) / (w1 - w0) if w1 - w0 > 0.2 and s1 > s0 else 1.0

    def gripper_goal(self) -> Optional[float]:
        """The left finger's goal [m] when the gripper servo's goal changed; else None."""
        with self.bus.lock:
            ticks, torque = self._goal("gripper")
        if not torque or ticks == self._gripper_sent:
            return None
        self._gripper_sent = ticks
        theta = ct.ticks_to_rad(ticks) - self.offsets["gripper"]
        return min(
            max(finger_linkage.finger_from_angle(theta), finger_linkage.FINGER_MIN),
            finger_linkage.FINGER_MAX,
        )

    def on_sim_scale(self, mass: float, stable: bool) -> None:
        """The simulator's reading [kg] becomes the load on the emulated pan."""
        settled = stable and not self._scale_stable  # the first steady reading is the mass
        self._scale_stable = stable
        if settled or not stable or abs(mass - self.scale.load) > SCALE_HYSTERESIS:
            self.scale.put(mass)
