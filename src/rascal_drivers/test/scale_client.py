#!/usr/bin/python3
"""Test helper for test_scale_driver_node.py: reads /scale/mass and calls /scale/tare as the task
layer does, in its own process, and prints one JSON line.
Usage: scale_client.py settle EXPECTED_KG [tare]"""

import json
import sys
import time

import rospy
from std_srvs.srv import Trigger

from rascal_msgs.msg import ScaleReading


def settle(expected, timeout=8.0):
    deadline = time.monotonic() + timeout
    msg = None
    while time.monotonic() < deadline:
        msg = rospy.wait_for_message("/scale/mass", ScaleReading, timeout=5.0)
        if msg.stable and abs(msg.mass - expected) <= 2e-4:
            break
    return {"mass": msg.mass, "stable": msg.stable, "frame": msg.header.frame_id}


def main():
    rospy.init_node("scale_client", anonymous=True)
    out = settle(float(sys.argv[2]))
    if sys.argv[3:] == ["tare"]:
        rospy.wait_for_service("/scale/tare", timeout=10.0)
        res = rospy.ServiceProxy("/scale/tare", Trigger)()
        out["tare"] = {"success": res.success, "message": res.message}
        if res.success:
            out["after_tare"] = settle(0.0)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
