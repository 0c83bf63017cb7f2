"""The gripper's opening limits from the URDF the rig runs, so no Python module writes them down:
`/robot_description` when this process is a ROS node and the parameter is set, else
rascal_description's urdf/wx250s.urdf (found with rospkg). The parsing is rascal_workcell's
(`urdf_model.opening_limits`: the left_finger joint's limits x 2), the same URDF joint the
controller's GripperGeometry reads.
"""

import os
from typing import Optional, Tuple

from rascal_workcell import urdf_model


def _urdf_xml() -> Optional[str]:
    """The URDF text, or None for rascal_workcell's own copy of rascal_description's file."""
    try:
        import rospy

        if rospy.core.is_initialized() and rospy.has_param("/robot_description"):
            return rospy.get_param("/robot_description")
    except Exception:  # no master, or no rospy: the file
        pass
    try:
        import rospkg

        path = os.path.join(rospkg.RosPack().get_path("rascal_description"), "urdf", "wx250s.urdf")
        with open(path, encoding="utf-8") as f:
            return f.read()
    except Exception:  # no ROS_PACKAGE_PATH: rascal_workcell's copy in the source tree
        return None


def _pads() -> float:
    """arm.gripper.fingertip_pads as the rig's parameter server holds it (0 without one)."""
    try:
        import rospy

        if rospy.core.is_initialized():
            return float(rospy.get_param("/arm/gripper/fingertip_pads", 0.0))
    except Exception:  # no master, or no rospy: the stock fingers
        pass
    return 0.0


def opening_limits() -> Tuple[float, float]:
    """(closed, fully open) distance between the fingertips, metres (30 .. 74 mm on the wx250s,
    less two pads where arm.gripper.fingertip_pads are fitted)."""
    return urdf_model.opening_limits(_urdf_xml(), _pads())
