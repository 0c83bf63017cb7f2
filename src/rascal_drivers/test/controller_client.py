#!/usr/bin/python3
"""Test helper for test_arm_driver_node.py: drives arm_controller (running on arm_driver) with
the task layer's own client, rascal_control.Arm/Gripper, in its own process, and prints one JSON
line. Usage: controller_client.py"""

import json

import rospy
from sensor_msgs.msg import JointState

from rascal_control import Arm, Gripper

ARM = ("waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate")


def joints():
    msg = rospy.wait_for_message("/joint_states", JointState, timeout=5.0)
    pos = dict(zip(msg.name, msg.position, strict=False))
    return [pos[n] for n in ARM]


def main():
    rospy.init_node("controller_client", anonymous=True)
    arm, gripper = Arm(wait=20.0), Gripper(wait=20.0)
    out = {}
    arm.go("sleep")
    out["sleep"] = joints()
    arm.move_to(Arm.top_down(0.30, 0.0, 0.12))
    p = arm.compute_fk().pose.position
    out["pose"] = [p.x, p.y, p.z]
    opened = gripper.open()
    out["opened"] = opened.width
    closed = gripper.close()
    out["closed"] = {"width": closed.width, "holding": closed.holding, "message": closed.message}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
