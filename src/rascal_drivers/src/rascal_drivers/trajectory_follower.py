"""Samples the controller's joint trajectory at the driver's loop rate.

The controller sends /arm/joint_trajectory already timed (positions at time_from_start, sampled
every arm.command_period); the driver writes the interpolated goal positions every cycle, so
the servos' own profile only smooths between samples. Semantics follow the simulator: a new
trajectory replaces the current one, joints not named keep their goal, stamp 0 = start now, no
points = stop where the arm is. No ROS here: times are float seconds.
"""

import bisect
from typing import Dict, List, Optional, Sequence, Tuple


class TrajectoryFollower:
    def __init__(self, joints: Sequence[str]):
        self.joints = list(joints)
        self._times: List[float] = []
        self._points: List[List[float]] = []
        self._index: List[int] = []  # trajectory column of each of our joints, -1 if absent
        self._start = 0.0
        self.goal: Optional[List[float]] = None  # the last goal written

    def replace(
        self,
        names: Sequence[str],
        points: Sequence[Tuple[float, Sequence[float]]],
        start: float,
        current: Sequence[float],
    ) -> None:
        """points: (time_from_start [s], positions in the order of `names`)."""
        base = list(self.goal if self.goal is not None else current)
        if not points:
            self.stop(current)
            return
        self._index = [list(names).index(j) if j in names else -1 for j in self.joints]
        self._times = [t for t, _ in points]
        self._points = [
            [p[i] if i >= 0 else base[k] for k, i in enumerate(self._index)] for _, p in points
        ]
        self._start = start

    def stop(self, current: Sequence[float]) -> None:
        self._times, self._points = [], []
        self.goal = list(current)

    @property
    def active(self) -> bool:
        return bool(self._times)

    def sample(self, now: float, current: Sequence[float]) -> List[float]:
        """The goal for this cycle; holds the last goal (or `current`) when nothing runs."""
        if not self._times:
            if self.goal is None:
                self.goal = list(current)
            return self.goal
        t = now - self._start
        if t < 0:  # stamped in the future: hold until it starts
            return self.goal if self.goal is not None else list(current)
        if t >= self._times[-1]:
            goal = self._points[-1]
        elif t <= self._times[0]:
            goal = self._points[0]
        else:
            i = bisect.bisect_right(self._times, t)
            t0, t1 = self._times[i - 1], self._times[i]
            a = (t - t0) / (t1 - t0) if t1 > t0 else 1.0
            p0, p1 = self._points[i - 1], self._points[i]
            goal = [x0 + a * (x1 - x0) for x0, x1 in zip(p0, p1, strict=True)]
        self.goal = list(goal)
        return self.goal

    def as_dict(self) -> Dict[str, float]:
        return dict(zip(self.joints, self.goal or [], strict=False))
