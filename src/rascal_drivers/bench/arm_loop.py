#!/usr/bin/python3
"""Prints the arm driver's control-loop figures against the servo-bus emulator.

Runs the emulator in its own process (as a real bus is its own device) and the driver core
with the node's pacing at drivers.arm.loop_rate for DURATION seconds, following a slow sine on
every joint; prints the cycle period (median, p99, max) and the bus time per cycle.
Usage: bench/arm_loop.py [DURATION_S]   (after `source devel/setup.bash`)
"""

import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

from rascal_drivers import workspace_venv
from rascal_drivers.arm_bus import ArmBus, config_from_section
from rascal_drivers.arm_driver import ArmDriver
from rascal_drivers.parameters import read_section

workspace_venv.add()
import dynamixel_sdk  # noqa: E402


def main() -> None:
    duration = float(sys.argv[1]) if len(sys.argv) > 1 else 10.0
    link = os.path.join(tempfile.mkdtemp(prefix="rascal_bench_"), "ttyDXL")
    emulator = subprocess.Popen(["rosrun", "rascal_drivers", "servo_bus_emulator", link])
    try:
        deadline = time.monotonic() + 10.0
        while not os.path.exists(link) and time.monotonic() < deadline:
            time.sleep(0.05)
        section = read_section({"device": link}, "drivers.arm")
        bus = ArmBus(config_from_section(section), dynamixel_sdk)
        bus.open()
        bus.configure()
        driver = ArmDriver(bus)
        period = 1.0 / section["loop_rate"]
        starts, busy = [], []
        t0 = next_time = time.monotonic()
        driver.cycle(t0)
        points = [(k * 0.05, [0.3 * math.sin(k * 0.05)] * 6) for k in range(int(duration / 0.05))]
        driver.on_trajectory(
            ["waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate"],
            points,
            t0,
        )
        while time.monotonic() - t0 < duration:
            start = time.monotonic()
            starts.append(start)
            driver.cycle(start)
            busy.append(time.monotonic() - start)
            next_time += period
            delay = next_time - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            else:
                next_time = time.monotonic()
        bus.torque_off()
        bus.close()
    finally:
        emulator.terminate()
        emulator.wait(timeout=10)
    periods = sorted(b - a for a, b in zip(starts, starts[1:], strict=False))
    busy.sort()

    def p(values, q):
        return values[min(len(values) - 1, int(q * len(values)))] * 1000.0

    print(
        "arm loop at %.0f Hz for %.0f s: %d cycles (%.1f Hz); period median %.2f ms, p99 %.2f ms, "
        "max %.2f ms; bus time per cycle median %.2f ms, p99 %.2f ms"
        % (
            section["loop_rate"],
            duration,
            len(starts),
            len(starts) / duration,
            statistics.median(periods) * 1000.0,
            p(periods, 0.99),
            periods[-1] * 1000.0,
            statistics.median(busy) * 1000.0,
            p(busy, 0.99),
        )
    )


if __name__ == "__main__":
    main()
