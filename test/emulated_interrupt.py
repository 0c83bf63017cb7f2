#!/usr/bin/python3
"""Test helper of test_emulated_batch_e2e.py, run by `rig --emulated -- ...` on the rig's own
master: starts `rascal run --context CONTEXT`, sends it SIGINT (what Ctrl-C sends) once a sherd
lies weighed, waits for it to end, reads where the arm stopped, then runs the batch again to its
end. Prints one JSON line: the first run's exit code and last lines, the joints after it, the
second run's exit code and last lines. Usage: emulated_interrupt.py CONTEXT (RASCAL_DSN set)."""

import json
import os
import signal
import subprocess
import sys
import time

import psycopg2
import rospy
from sensor_msgs.msg import JointState

WEIGHED_TIMEOUT = 900.0  # [s] wall: the simulator runs at a quarter speed behind the emulators


def statuses(dsn, context):
    with psycopg2.connect(dsn) as conn, conn.cursor() as cur:
        cur.execute("SELECT status FROM sherds WHERE context_id = %s ORDER BY seq", (context,))
        return [r[0] for r in cur.fetchall()]


def batch(context):
    return subprocess.Popen(
        ["rosrun", "rascal_tasks", "rascal", "run", "--context", context],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )


def main():
    context, dsn = sys.argv[1], os.environ["RASCAL_DSN"]
    first = batch(context)
    deadline = time.monotonic() + WEIGHED_TIMEOUT
    while first.poll() is None and time.monotonic() < deadline:
        try:
            if "weighed" in statuses(dsn, context):
                break
        except psycopg2.Error:
            pass  # the tables appear with the batch's first row
        time.sleep(0.2)
    interrupted_at = statuses(dsn, context)
    first.send_signal(signal.SIGINT)
    out1, _ = first.communicate(timeout=300)
    rospy.init_node("emulated_interrupt", anonymous=True)
    joints = rospy.wait_for_message("/joint_states", JointState, timeout=30.0)
    named = dict(zip(joints.name, joints.position, strict=True))
    second = batch(context)
    out2, _ = second.communicate(timeout=1500)
    print(
        json.dumps(
            {
                "statuses_at_interrupt": interrupted_at,
                "first_code": first.returncode,
                "first_tail": out1[-1500:],
                "joints": named,
                "second_code": second.returncode,
                "second_tail": out2[-1500:],
            }
        )
    )


if __name__ == "__main__":
    main()
