#!/usr/bin/python3
"""Test helper for test_arm_controller.py: runs one scenario against a live arm_controller with the
rascal_control Python client, in its own process (rospy can init only once per process), and
prints one JSON line. Usage: wiring_client.py <scenario>"""

import json
import math
import sys
import time

import rospy
from sensor_msgs.msg import JointState

from rascal_control import Arm, ControlError, Gripper
from rascal_control.deadline import DONE, Deadline, wait_for

ARM = ("waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate")


def joints():
    msg = rospy.wait_for_message("/joint_states", JointState, timeout=10.0)
    pos = dict(zip(msg.name, msg.position, strict=False))
    return [pos[n] for n in ARM]


def error_dict(e):
    return {"error": type(e).__name__, "code": e.code, "message": e.message}


def pose_error(arm, x, y, z):
    p = arm.get_ee_pose().pose.position
    return math.dist((p.x, p.y, p.z), (x, y, z))


def pose_goal(arm):
    arm.move_to(Arm.top_down(0.30, 0.10, 0.15, yaw=0.3))
    time.sleep(0.2)
    first = pose_error(arm, 0.30, 0.10, 0.15)
    arm.move_to(Arm.top_down(0.25, -0.05, 0.10, yaw=-0.2), motion="linear")
    time.sleep(0.2)
    return {"joint_error": first, "linear_error": pose_error(arm, 0.25, -0.05, 0.10)}


def linear_path(arm):
    """Executed path of a linear move: every /joint_states message of the move through FK."""
    a, b = (0.20, 0.20, 0.12), (0.35, -0.10, 0.05)
    arm.move_to(Arm.top_down(*a, yaw=0.2))
    samples = []
    sub = rospy.Subscriber(
        "/joint_states",
        JointState,
        lambda m: samples.append(dict(zip(m.name, m.position, strict=False))),
    )
    result = arm.move_to(Arm.top_down(*b, yaw=-0.4), motion="linear")
    sub.unregister()
    ab = [q - p for p, q in zip(a, b, strict=True)]
    worst = 0.0
    for s in samples[::2]:
        p = arm.compute_fk([s[n] for n in ARM]).pose.position
        ap = (p.x - a[0], p.y - a[1], p.z - a[2])
        u = max(
            0.0, min(1.0, sum(x * y for x, y in zip(ap, ab, strict=True)) / sum(x * x for x in ab))
        )
        worst = max(worst, math.dist((p.x, p.y, p.z), [a[i] + u * ab[i] for i in range(3)]))
    return {"samples": len(samples), "deviation": worst, "duration": result.duration}


def chain(arm):
    """A lift, a carry and a descent as one goal, blended above 0.06 m: every /joint_states
    message of it through FK; how far below 0.06 m the path strays from the two verticals,
    and the lowest height it crossed between them (a corner cut: below the 0.10 m travel)."""
    a, b, travel = (0.15, 0.25), (0.25, -0.25), 0.10
    arm.move_to(Arm.top_down(*a, 0.03, yaw=0.3))
    samples = []
    sub = rospy.Subscriber(
        "/joint_states",
        JointState,
        lambda m: samples.append(dict(zip(m.name, m.position, strict=False))),
    )
    poses = [Arm.top_down(*a, travel, 0.3), Arm.top_down(*b, travel, 0.0)]
    poses.append(Arm.top_down(*b, 0.04, 0.0))
    arm.move_through(poses, ["linear", "joint", "linear"], blend_above=0.06)
    sub.unregister()
    time.sleep(0.2)
    stray, crossed, between = 0.0, travel, 0
    for s in samples:
        p = arm.compute_fk([s[n] for n in ARM]).pose.position
        off = min(math.dist((p.x, p.y), a), math.dist((p.x, p.y), b))
        if p.z < 0.06 - 0.001:
            stray = max(stray, off)
        elif off > 0.01:
            crossed, between = min(crossed, p.z), between + 1
    return {
        "samples": len(samples),
        "between": between,
        "stray": stray,
        "crossed": crossed,
        "goal_error": pose_error(arm, *b, 0.04),
    }


def unreachable(arm):
    before = joints()
    start = time.monotonic()
    try:
        arm.move_to(Arm.top_down(1.0, 0.0, 0.15))
        out = {"error": None}
    except ControlError as e:
        out = error_dict(e)
    out["seconds"] = time.monotonic() - start
    rospy.sleep(0.3)
    out["moved"] = max(abs(a - b) for a, b in zip(before, joints(), strict=True))
    return out


def collision(arm):
    arm.go("home")
    rospy.sleep(0.5)  # the servos finish settling inside the goal tolerance
    before = joints()
    out = {"error": None}
    try:
        arm.move_to(Arm.top_down(0.25, 0.20, -0.06))  # wrist into the table
    except ControlError as e:
        out = error_dict(e)
    rospy.sleep(0.3)
    out["moved"] = max(abs(a - b) for a, b in zip(before, joints(), strict=True))
    return out


def no_driver(arm):
    try:
        arm.go("home")
        return {"error": None}
    except ControlError as e:
        return error_dict(e)


def cancel(arm):
    arm.go("home")
    client = arm._move  # the goal is sent asynchronously so it can be cancelled mid-way
    from rascal_msgs.msg import MoveArmGoal

    goal = MoveArmGoal(
        target_type=MoveArmGoal.TARGET_JOINTS,
        joints=[2.5, 0.3, 0.3, 0, 1.0, 0],
        motion=MoveArmGoal.MOTION_JOINT,
        speed_scale=0.3,
    )
    client.send_goal(goal)
    # cancelled only once the controller has taken it and is moving (see GoalRunner.acknowledged)
    moving = wait_for(
        lambda: client.acknowledged() and client.feedback is not None,
        Deadline(10.0, rospy.get_time),
    )
    assert moving == DONE, "the goal was not taken within 10 s: " + moving
    rospy.sleep(0.6)
    client.cancel_goal()
    client.wait_for_result(Deadline(10.0, rospy.get_time))
    result = client.get_result()
    rospy.sleep(0.5)  # braking at the acceleration limit takes < 0.2 s at this speed
    a = joints()
    rospy.sleep(0.5)
    b = joints()
    return {
        "code": result.code,
        "message": result.message,
        "waist": a[0],
        "drift": max(abs(x - y) for x, y in zip(a, b, strict=True)),
    }


def restart(arm, gripper):
    """A driver restart (the simulator's reset puts the arm back at its initial pose at once):
    every goal is refused until acknowledged; then goals run again."""
    from std_srvs.srv import Trigger

    arm.go("home")
    rospy.wait_for_service("/sim/reset", 10.0)
    rospy.ServiceProxy("/sim/reset", Trigger)()
    rospy.sleep(0.2)
    out = {}
    for name, command in (("move", lambda: arm.go("home")), ("gripper", gripper.open)):
        try:
            command()
            out[name] = None
        except ControlError as e:
            out[name] = error_dict(e)
    out["acknowledged"] = arm.acknowledge_restart()
    out["after"] = arm.go("home").code
    out["again"] = arm.acknowledge_restart()
    return out


def gripper_state():
    """The controller's gripper state, the first one stamped after this call."""
    from rascal_msgs.msg import GripperState

    now = rospy.Time.now()
    while True:
        msg = rospy.wait_for_message("/rascal/gripper/state", GripperState, timeout=10.0)
        if msg.header.stamp >= now:
            return msg


def grasp(arm, gripper):
    from rascal_msgs.srv import GetGroundTruth

    rospy.wait_for_service("/sim/ground_truth", 10.0)
    sherds = rospy.ServiceProxy("/sim/ground_truth", GetGroundTruth)().sherds
    # The sherd nearest the middle of the pickup area; fingers across its minor axis.
    s = min(sherds, key=lambda s: math.hypot(s.pose.position.x - 0.16, s.pose.position.y - 0.25))
    q = s.pose.orientation
    yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
    x, y = s.pose.position.x, s.pose.position.y
    top = s.pose.position.z + s.thickness
    gripper.open()
    arm.move_to(Arm.top_down(x, y, top + 0.06, yaw))
    arm.move_to(Arm.top_down(x, y, max(0.013, top - 0.003), yaw), motion="linear", speed_scale=0.5)
    held = gripper.close()
    arm.move_to(Arm.top_down(x, y, top + 0.06, yaw), motion="linear")
    lifted = gripper_state()
    empty_open = gripper.open()
    opened = gripper_state()
    arm.move_to(Arm.top_down(0.30, 0.10, 0.15))  # over the bare table
    empty = gripper.close()
    closed = gripper_state()
    return {
        "held": held.holding,
        "state_lifted": [lifted.holding, lifted.width],
        "state_opened": [opened.holding, opened.width],
        "state_empty": [closed.holding, closed.width],
        "held_width": held.width,
        "held_seconds": held.duration,
        "empty": empty.holding,
        "empty_width": empty.width,
        "open_width": empty_open.width,
        "sherd_width": s.width,
        "sherd": s.name,
    }


def main():
    rospy.init_node("rascal_control_wiring_client", anonymous=True)
    arm, gripper = Arm(wait=30.0), Gripper(wait=30.0)
    scenario = sys.argv[1]
    try:
        if scenario in ("grasp", "restart"):
            out = {"grasp": grasp, "restart": restart}[scenario](arm, gripper)
        else:
            run = {
                "pose_goal": pose_goal,
                "unreachable": unreachable,
                "cancel": cancel,
                "collision": collision,
                "no_driver": no_driver,
                "linear_path": linear_path,
                "chain": chain,
            }[scenario]
            out = run(arm)
    except ControlError as e:
        out = error_dict(e)
    print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
