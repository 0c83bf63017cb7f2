"""Makes the workspace's .venv packages importable in a node started by rosrun.

Nodes run under /usr/bin/python3 (Debian's rospy lives there); dynamixel-sdk and pyrealsense2
are pinned in requirements.txt and installed into .venv, which scripts/setup.sh builds from the
same interpreter. No ROS here.
"""

import glob
import os
import sys

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))


def add() -> None:
    pattern = os.path.join(WORKSPACE, ".venv", "lib", "python3*", "site-packages")
    for path in glob.glob(pattern):
        if path not in sys.path:
            sys.path.append(path)
