"""A lab scale on a pseudo-terminal, speaking MT-SICS or the A&D standard format.

The load on the pan is set by the test (or by a simulator bridge); the displayed value settles
toward it (first order, `settle_time`), carries seeded noise, is quantised to the readability and
is called stable once it has stayed within the readability for `stable_after`. It tares, zeroes,
overloads above `capacity`, underloads below zero gross (pan off), answers unknown commands
the way the scale does (ES / EC,E01), and can be unplugged (the pty closed) or made to send
garbage. No ROS here.
"""

import os
import random
import select
import time
from typing import Optional

from rascal_drivers.pty_device import PtyDevice


class ScaleEmulator(PtyDevice):
    def __init__(
        self,
        protocol: str,
        link: Optional[str] = None,
        readability: float = 1e-4,
        capacity: float = 0.62,
        settle_time: float = 0.15,
        stable_after: float = 0.3,
        noise: float = 2e-5,
        seed: int = 7,
    ):
        self.protocol = protocol
        self.readability = readability
        self.capacity = capacity
        self.settle_time = settle_time
        self.stable_after = stable_after
        self.noise = noise
        self.random = random.Random(seed)
        self.load = 0.0  # [kg] gross mass on the pan
        self.shown = 0.0  # [kg] gross value the sensor reads now
        self.tare_offset = 0.0
        self.pan_on = True
        self.silent = False  # powered off: says nothing
        self.garbage_next = 0  # the next N replies are line noise
        self.commands = []
        self._within_since = time.monotonic()
        super().__init__(link)

    def put(self, mass: float) -> None:
        with self.lock:
            self.load = mass

    # ------------------------------------------------------------------ the scale
    def _update(self, dt: float) -> None:
        target = self.load if self.pan_on else -0.05
        a = min(1.0, dt / self.settle_time) if self.settle_time > 0 else 1.0
        self.shown += a * (target - self.shown)
        if abs(self.shown - target) > self.readability / 2:
            self._within_since = time.monotonic()

    def _net(self) -> float:
        noisy = self.shown - self.tare_offset + self.random.gauss(0.0, self.noise)
        return round(noisy / self.readability) * self.readability

    def _stable(self) -> bool:
        return time.monotonic() - self._within_since >= self.stable_after

    def _weight_reply(self, stable_only: bool) -> str:
        gross = self.shown
        if gross > self.capacity:
            return "S +" if self.protocol == "mt_sics" else "OL,+9999999 g"
        if gross < -0.01:
            return "S -" if self.protocol == "mt_sics" else "OL,-9999999 g"
        stable = self._stable()
        grams = self._net() * 1000.0
        if self.protocol == "mt_sics":
            if stable_only and not stable:
                return "S I"
            return "S %s %10.1f g" % ("S" if stable else "D", grams)
        if stable_only and not stable:
            return "EC,E11"
        return "%s,%+09.1f  g" % ("ST" if stable else "US", grams)

    def _tare_reply(self) -> str:
        if not self._stable():
            return "T I" if self.protocol == "mt_sics" else "EC,E11"
        if self.shown > self.capacity:
            return "T +" if self.protocol == "mt_sics" else "EC,E11"
        self.tare_offset = self.shown
        if self.protocol == "mt_sics":
            return "T S %10.1f g" % (self.tare_offset * 1000.0)
        return "\x06"

    def _answer(self, command: str) -> str:
        self.commands.append(command)
        if self.protocol == "mt_sics":
            if command == "SI":
                return self._weight_reply(False)
            if command == "S":
                return self._weight_reply(True)
            if command == "T":
                return self._tare_reply()
            if command == "Z":
                if not self._stable():
                    return "Z I"
                self.tare_offset = self.shown
                return "Z A"
            return "ES"
        if command == "Q" or command == "SI":
            return self._weight_reply(False)
        if command == "S":
            return self._weight_reply(True)
        if command in ("T", "R"):
            return self._tare_reply()
        return "EC,E01"

    def _run(self) -> None:
        buffer = b""
        last = time.monotonic()
        while not self._stop.is_set():
            try:
                ready, _, _ = select.select([self.master], [], [], 0.01)
                if ready:
                    buffer += os.read(self.master, 1024)
            except OSError:
                return
            now = time.monotonic()
            with self.lock:
                self._update(now - last)
                last = now
                while b"\n" in buffer:
                    raw, buffer = buffer.split(b"\n", 1)
                    command = raw.decode("ascii", errors="replace").strip()
                    if self.silent or not command:
                        continue
                    reply = self._answer(command)
                    if self.garbage_next:
                        self.garbage_next -= 1
                        reply = "\x13\x8f?? ##"
                    try:
                        os.write(self.master, reply.encode("latin-1") + b"\r\n")
                    except OSError:
                        return
