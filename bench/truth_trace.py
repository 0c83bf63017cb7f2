#!/usr/bin/python3
"""Where every simulated sherd is, over a batch: polls the simulator's ground truth (SIMULATOR
ONLY, as the benches may) and appends one JSON line per poll in which a sherd moved more than
2 mm or was taken or let go: {"t": simulated s, "w": POSIX s, "moved": {name: [x, y, z,
held]}}; the first line says what each sherd is: {"sherds": {name: [g, length mm, width mm,
wall mm]}}. Run by
bench/heap beside a batch, so every row can be told which sherd it weighed; stopped by SIGTERM.

    /usr/bin/python3 bench/truth_trace.py OUT.jsonl
"""

import json
import signal
import sys
import time

import rospy
from rascal_msgs.srv import GetGroundTruth

MOVED_M = 0.002
PERIOD_S = 0.1  # wall: a sherd rests on the scale for a second or more of simulated time


def main(path):
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    rospy.init_node("bench_truth_trace", anonymous=True, disable_signals=True)
    truth = rospy.ServiceProxy("/sim/ground_truth", GetGroundTruth)
    last = {}
    with open(path, "w") as out:
        while True:
            try:
                sherds = truth().sherds
            except rospy.ServiceException:
                time.sleep(PERIOD_S)
                continue
            if not last:
                sizes = {
                    s.name: [s.mass * 1e3, s.length * 1e3, s.width * 1e3, s.thickness * 1e3]
                    for s in sherds
                }
                out.write(json.dumps({"sherds": sizes}) + "\n")
            moved = {}
            for s in sherds:
                p = s.pose.position
                now = [round(p.x, 4), round(p.y, 4), round(p.z, 4), bool(s.held)]
                before = last.get(s.name)
                if (
                    before is None
                    or before[3] != now[3]
                    or max(abs(a - b) for a, b in zip(before[:3], now[:3], strict=True)) > MOVED_M
                ):
                    moved[s.name] = now
                    last[s.name] = now
            if moved:
                out.write(
                    json.dumps({"t": rospy.get_time(), "w": time.time(), "moved": moved}) + "\n"
                )
                out.flush()
            time.sleep(PERIOD_S)


if __name__ == "__main__":
    main(sys.argv[1])
