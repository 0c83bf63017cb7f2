"""Joint and gripper limits read from the URDF (rascal_description/urdf/wx250s.urdf), so no Python
module writes them down again. The C++ side reads the same file (rascal_workcell::GripperGeometry,
rascal_control::KinematicModel). No ROS here: the file is found next to this package, or given.
"""
import functools
import os
import xml.etree.ElementTree as ET
from typing import List, Optional, Tuple

URDF_PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                         "rascal_description", "urdf", "wx250s.urdf")
ARM_JOINTS = ("waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate")
FINGER_JOINT = "left_finger"


@functools.lru_cache(maxsize=4)
def _joints(urdf_xml: Optional[str]) -> dict:
    if urdf_xml is None:
        with open(os.path.normpath(URDF_PATH), encoding="utf-8") as f:
            urdf_xml = f.read()
    out = {}
    for joint in ET.fromstring(urdf_xml).iter("joint"):
        limit = joint.find("limit")
        if limit is not None and "lower" in limit.attrib:
            out[joint.get("name")] = (float(limit.get("lower")), float(limit.get("upper")))
    return out


def _limits(name: str, urdf_xml: Optional[str]) -> Tuple[float, float]:
    joints = _joints(urdf_xml)
    if name not in joints:
        raise ValueError("URDF: no joint %s with lower/upper limits" % name)
    return joints[name]


def arm_joint_limits(urdf_xml: Optional[str] = None) -> List[Tuple[float, float]]:
    """[(lower, upper)] in radians for waist .. wrist_rotate."""
    return [_limits(j, urdf_xml) for j in ARM_JOINTS]


def finger_limits(urdf_xml: Optional[str] = None) -> Tuple[float, float]:
    """(closed, open) position of the left finger from the centreline, metres."""
    return _limits(FINGER_JOINT, urdf_xml)


def opening_limits(urdf_xml: Optional[str] = None) -> Tuple[float, float]:
    """(closed, fully open) distance between the fingers, metres (facts §1.4: 30 .. 74 mm)."""
    lo, hi = finger_limits(urdf_xml)
    return 2.0 * lo, 2.0 * hi
