"""The arm driver's control cycle, between the ROS wrapper and the servo bus.

Holds what the controller asked for (the arm trajectory being followed, the finger target) and
the fault latch. A hardware error stops the arm where it is and refuses every later command
until the driver is restarted: a servo in shutdown has dropped its torque, so carrying on would
move the rest of the arm around a limp joint. No ROS here: times are float seconds.
"""

from typing import List, Optional, Sequence, Tuple

from rascal_drivers.arm_bus import ARM_JOINTS, ArmBus, JointSample
from rascal_drivers.finger_linkage import FINGER_MAX, FINGER_MIN
from rascal_drivers.trajectory_follower import TrajectoryFollower


class ArmDriver:
    def __init__(self, bus: ArmBus):
        self.bus = bus
        self.follower = TrajectoryFollower(ARM_JOINTS)
        self.finger: Optional[float] = None  # target of the left finger [m]
        self.fault = ""
        self.last: Optional[JointSample] = None
        self.limp = False  # arm torque off for teaching by hand (the gripper keeps its own)

    def _arm_now(self) -> List[float]:
        return list(self.last.position[: len(ARM_JOINTS)]) if self.last else []

    def on_trajectory(
        self, names: Sequence[str], points: Sequence[Tuple[float, Sequence[float]]], start: float
    ) -> str:
        """'' when accepted, else why not (one line)."""
        if self.fault:
            return "refused: " + self.fault
        if self.last is None:
            return "refused: no joint state read from the servos yet"
        if not any(n in ARM_JOINTS for n in names):
            return ""
        if self.limp:
            return "refused: the arm is limp for teaching by hand; its torque comes back first"
        self.follower.replace(names, points, start, self._arm_now())
        return ""

    def set_limp(self, limp: bool) -> str:
        """Arm torque off (a person moves the arm by hand) or on again, holding where the arm
        is then; '' when done, else why not (one line)."""
        if self.fault:
            return "refused: " + self.fault
        if self.last is None:
            return "refused: no joint state read from the servos yet"
        if limp == self.limp:
            return ""
        if limp:
            self.follower.stop(self._arm_now())
            self.bus.set_arm_torque(False)
        else:
            sample = self.bus.read_state()  # where the hands left it, not the last cycle's
            if sample is not None:
                self.last = sample
            self.follower.stop(self._arm_now())
            self.bus.set_arm_torque(True)
        self.limp = limp
        return ""

    def on_gripper(self, names: Sequence[str], positions: Optional[Sequence[float]]) -> str:
        """positions: the last point's positions, or None for 'stop where it is'."""
        if self.fault:
            return "refused: " + self.fault
        if self.last is None:
            return "refused: no joint state read from the servos yet"
        if positions is None:
            self.finger = self.last.position[len(ARM_JOINTS)]
            return ""
        if "left_finger" not in names:
            return "refused: /gripper/command names no left_finger joint"
        target = positions[list(names).index("left_finger")]
        self.finger = min(max(target, FINGER_MIN), FINGER_MAX)
        return ""

    def cycle(self, now: float) -> Tuple[Optional[JointSample], str]:
        """One control cycle: read, check, write. Returns (sample or None, a new fault line)."""
        sample = self.bus.read_state()
        if sample is not None:
            self.last = sample
        new_fault = ""
        if not self.fault:
            errors = self.bus.cycle_errors()
            if errors:
                self.fault = (
                    errors + "; the arm is stopped; power-cycle it, then restart arm_driver"
                )
                new_fault = self.fault
                if self.last is not None:  # hold every joint where it is
                    self.follower.stop(self._arm_now())
                    self.finger = self.last.position[len(ARM_JOINTS)]
        if self.last is not None:
            goal = None if self.limp else self.follower.sample(now, self._arm_now())
            self.bus.write_goals(goal, self.finger)
        return sample, new_fault
