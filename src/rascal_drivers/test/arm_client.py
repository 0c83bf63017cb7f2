#!/usr/bin/python3
"""Test helper for test_arm_driver_node.py: talks to a live arm_driver on its raw topics
(/arm/joint_trajectory, /gripper/command, /joint_states), in its own process (rospy can init only
once per process), and prints one JSON line. Usage: arm_client.py move|hold"""

import json
import sys
import time

import rospy
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

ARM = ("waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate")
GOAL = (0.4, -0.5, 0.6, 0.2, 0.7, -0.3)
FINGER = 0.020


def state():
    msg = rospy.wait_for_message("/joint_states", JointState, timeout=5.0)
    return dict(zip(msg.name, msg.position, strict=False))


def send(arm_pub, grip_pub):
    start = [state()[j] for j in ARM]
    traj = JointTrajectory(joint_names=list(ARM))
    for i in range(21):  # 1 s, sampled like arm_controller's command_period
        a = i / 20.0
        traj.points.append(
            JointTrajectoryPoint(
                positions=[s + a * (g - s) for s, g in zip(start, GOAL, strict=True)],
                time_from_start=rospy.Duration(a * 1.0),
            )
        )
    arm_pub.publish(traj)
    grip = JointTrajectory(joint_names=["left_finger"])
    grip.points.append(
        JointTrajectoryPoint(positions=[FINGER], time_from_start=rospy.Duration(0.5))
    )
    grip_pub.publish(grip)


def main():
    rospy.init_node("arm_client", anonymous=True)
    arm_pub = rospy.Publisher("/arm/joint_trajectory", JointTrajectory, queue_size=1)
    grip_pub = rospy.Publisher("/gripper/command", JointTrajectory, queue_size=1)
    deadline = time.monotonic() + 10.0
    while arm_pub.get_num_connections() == 0 or grip_pub.get_num_connections() == 0:
        if time.monotonic() > deadline:
            print(json.dumps({"error": "arm_driver never subscribed"}))
            return
        time.sleep(0.05)
    before = state()
    count = [0]
    rospy.Subscriber("/joint_states", JointState, lambda m: count.__setitem__(0, count[0] + 1))
    send(arm_pub, grip_pub)
    deadline = time.monotonic() + (6.0 if sys.argv[1] == "move" else 1.0)
    reached = False
    while time.monotonic() < deadline:
        now = state()
        reached = all(abs(now[j] - g) < 0.01 for j, g in zip(ARM, GOAL, strict=True)) and (
            abs(now["left_finger"] - FINGER) < 0.0005
        )
        if reached and sys.argv[1] == "move":
            break
        time.sleep(0.05)
    t0, c0 = time.monotonic(), count[0]
    time.sleep(0.5)
    rate = (count[0] - c0) / (time.monotonic() - t0)
    print(json.dumps({"before": before, "after": state(), "reached": reached, "rate": rate}))


if __name__ == "__main__":
    main()
