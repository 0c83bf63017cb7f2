"""Helpers of the end-to-end tests: the simulated rig (rascal_tasks.sim_rig) on the test's
master, the catalogue, and the simulator's test-only services."""

import os
import subprocess

import psycopg2
import psycopg2.extras
import yaml

from rascal_tasks.sim_rig import SimRig

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENARIOS = os.path.join(WORKSPACE, "config", "scenarios")


def start_rig(ros_master, scenario, archive, params=None):
    params = dict({"/archive/root": str(archive)}, **(params or {}))
    return SimRig(
        scenario=scenario, params=params, master_env=ros_master.env, log_dir=ros_master.log_dir
    )


def migrate(dsn):
    subprocess.run(
        ["rosrun", "rascal_tasks", "rascal", "--dsn", dsn, "db", "migrate"],
        check=True,
        capture_output=True,
        text=True,
    )


def rows(dsn, context):
    with (
        psycopg2.connect(dsn) as conn,
        conn.cursor(cursor_factory=psycopg2.extras.RealDictCursor) as cur,
    ):
        cur.execute("SELECT * FROM sherds WHERE context_id = %s ORDER BY seq", (context,))
        return cur.fetchall()


def call(rig, code):
    """Run a few lines of rospy against the rig; returns what they print, as YAML."""
    return yaml.safe_load(rig.run(["/usr/bin/python3", "-c", code]).stdout)


def ground_truth(rig):
    """name -> [x, y, mass kg] from the simulator's test-only service."""
    return call(
        rig,
        "import rospy, json; from rascal_msgs.srv import GetGroundTruth;"
        "rospy.wait_for_service('/sim/ground_truth', 10);"
        "r = rospy.ServiceProxy('/sim/ground_truth', GetGroundTruth)();"
        "print(json.dumps({s.name: [s.pose.position.x, s.pose.position.y, s.mass]"
        " for s in r.sherds}))",
    )


def inject(rig, fault, duration=0.0):
    return call(
        rig,
        "import rospy; from rascal_msgs.srv import InjectFault;"
        "rospy.wait_for_service('/sim/inject_fault', 10);"
        "r = rospy.ServiceProxy('/sim/inject_fault', InjectFault)(%d, %f);"
        "print([r.success, r.message])" % (fault, duration),
    )


def joint_positions(rig):
    return call(
        rig,
        "import rospy; from sensor_msgs.msg import JointState;"
        "rospy.init_node('probe', anonymous=True);"
        "m = rospy.wait_for_message('/joint_states', JointState, 10);"
        "print(list(m.position[:6]))",
    )
