#!/usr/bin/python3
"""Test helper for test_archival_camera_node.py: calls /archival_camera/capture as the task
layer does, once per PATH, and prints one JSON line (a list). Usage: capture_client.py PATH..."""

import json
import sys

import rospy

from rascal_msgs.srv import CaptureArchival


def main():
    rospy.init_node("capture_client", anonymous=True)
    rospy.wait_for_service("/archival_camera/capture", timeout=10.0)
    capture = rospy.ServiceProxy("/archival_camera/capture", CaptureArchival)
    out = []
    for path in sys.argv[1:]:
        res = capture(path=path)
        out.append(
            {
                "success": res.success,
                "message": res.message,
                "path": res.path,
                "width": res.width,
                "height": res.height,
            }
        )
    print(json.dumps(out))


if __name__ == "__main__":
    main()
