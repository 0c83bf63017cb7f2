"""Joint limits, gripper limits, link lengths and the wrist camera's offset read from the URDF
(rascal_description/urdf/wx250s.urdf), so no Python module writes them down again. The C++ side
reads the same file (rascal_workcell::GripperGeometry, rascal_control::KinematicModel). No ROS
here: the file is found next to this package, or given.
"""

import functools
import math
import os
from dataclasses import dataclass
import xml.etree.ElementTree as ET
from typing import List, Optional, Tuple

URDF_PATH = os.path.join(
    os.path.dirname(os.path.abspath(__file__)),
    "..",
    "..",
    "..",
    "rascal_description",
    "urdf",
    "wx250s.urdf",
)
ARM_JOINTS = ("waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate")
FINGER_JOINT = "left_finger"


@functools.lru_cache(maxsize=4)
def _robot(urdf_xml: Optional[str]):
    if urdf_xml is None:
        with open(os.path.normpath(URDF_PATH), encoding="utf-8") as f:
            urdf_xml = f.read()
    return ET.fromstring(urdf_xml)


def _joint(name: str, urdf_xml: Optional[str]):
    joint = _robot(urdf_xml).find("joint[@name='%s']" % name)
    if joint is None:
        raise ValueError("URDF: no joint %s" % name)
    return joint


def _limits(name: str, urdf_xml: Optional[str]) -> Tuple[float, float]:
    limit = _joint(name, urdf_xml).find("limit")
    if limit is None or "lower" not in limit.attrib:
        raise ValueError("URDF: joint %s has no lower/upper limits" % name)
    return float(limit.get("lower")), float(limit.get("upper"))


def _origin(name: str, urdf_xml: Optional[str]) -> Tuple[float, float, float]:
    origin = _joint(name, urdf_xml).find("origin")
    return tuple(float(v) for v in origin.get("xyz").split()) if origin is not None else (0, 0, 0)


@dataclass(frozen=True)
class ArmGeometry:
    """The wx250s's planar chain when the gripper points down (metres)."""

    shoulder_z: float  # shoulder axis above base_link
    upper_arm: float  # shoulder axis -> elbow axis
    forearm: float  # elbow axis -> wrist_angle axis
    wrist_to_ee: float  # wrist_angle axis -> ee_gripper_link


def arm_geometry(urdf_xml: Optional[str] = None) -> ArmGeometry:
    o = {
        j: _origin(j, urdf_xml)
        for j in (
            "waist",
            "shoulder",
            "elbow",
            "forearm_roll",
            "wrist_angle",
            "wrist_rotate",
            "ee_arm",
            "gripper",
            "gripper_bar",
            "ee_bar",
            "ee_gripper",
        )
    }
    return ArmGeometry(
        shoulder_z=o["waist"][2] + o["shoulder"][2],
        upper_arm=math.hypot(o["elbow"][0], o["elbow"][2]),
        forearm=o["forearm_roll"][0] + o["wrist_angle"][0],
        wrist_to_ee=sum(
            o[j][0]
            for j in ("wrist_rotate", "ee_arm", "gripper", "gripper_bar", "ee_bar", "ee_gripper")
        ),
    )


def arm_joint_limits(urdf_xml: Optional[str] = None) -> List[Tuple[float, float]]:
    """[(lower, upper)] in radians for waist .. wrist_rotate."""
    return [_limits(j, urdf_xml) for j in ARM_JOINTS]


def finger_limits(urdf_xml: Optional[str] = None) -> Tuple[float, float]:
    """(closed, open) position of the left finger from the centreline, metres."""
    return _limits(FINGER_JOINT, urdf_xml)


def opening_limits(urdf_xml: Optional[str] = None, pads: float = 0.0) -> Tuple[float, float]:
    """(closed, fully open) distance between the fingers, metres (facts §1.4: 30 .. 74 mm), with
    `pads` [m] fitted inside each finger (arm.gripper.fingertip_pads; GripperGeometry::pad)."""
    lo, hi = finger_limits(urdf_xml)
    return 2.0 * (lo - pads), 2.0 * (hi - pads)


def camera_offset(urdf_xml: Optional[str] = None) -> float:
    """How far the wrist camera sits from the gripper's axis, metres: with the gripper pointing
    down it is that far out along the gripper's yaw direction (camera_mount's z)."""
    return _origin("camera_mount", urdf_xml)[2]


def _finger_box(urdf_xml: Optional[str]):
    """left_finger_link's collision box: (its origin's x, its size [x, y, z]), metres."""
    link = _robot(urdf_xml).find("link[@name='left_finger_link']/collision")
    box = link.find("geometry/box") if link is not None else None
    if box is None:
        raise ValueError("URDF: left_finger_link needs a box collision")
    origin = link.find("origin")
    x = float(origin.get("xyz").split()[0]) if origin is not None else 0.0
    return x, [float(v) for v in box.get("size").split()]


def fingertip_offset(urdf_xml: Optional[str] = None) -> float:
    """How far the fingertips reach below ee_gripper_link with the gripper pointing down, metres:
    the far end of left_finger_link's collision box along the approach axis, from the ee_gripper
    joint (as rascal_workcell::GripperGeometry reads it; 4.4 mm on the wx250s)."""
    x, size = _finger_box(urdf_xml)
    return x + size[0] / 2 - _origin("ee_gripper", urdf_xml)[0]


def finger_thickness(urdf_xml: Optional[str] = None) -> float:
    """A finger's thickness along the closing direction, metres (its box's y; 8 mm)."""
    return _finger_box(urdf_xml)[1][1]


def finger_width(urdf_xml: Optional[str] = None) -> float:
    """A finger's width across the closing direction, metres (its box's z; 20 mm)."""
    return _finger_box(urdf_xml)[1][2]
