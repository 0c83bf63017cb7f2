"""Starting the whole simulated rig for end-to-end tests, the way a user would (rosrun)."""
import os
import subprocess
import time

import yaml

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONFIG = os.path.join(WORKSPACE, "config", "rascal.yaml")
URDF = os.path.join(WORKSPACE, "src", "rascal_description", "urdf", "wx250s.urdf")
SCENARIOS = os.path.join(WORKSPACE, "config", "scenarios")


def migrate(dsn):
    subprocess.run(["rosrun", "rascal_tasks", "rascal", "--dsn", dsn, "db", "migrate"],
                   check=True, capture_output=True, text=True)


class SimRig:
    """Master + parameters + sim + arm_controller + sherd_detector; the test runs `rascal`."""

    def __init__(self, ros_master, rosrun, scenario, archive, params=None):
        self.master = ros_master
        self.rosrun = rosrun
        run = ros_master.run
        run(["rosparam", "load", CONFIG])
        run(["rosparam", "set", "/use_sim_time", "true"])
        run(["rosparam", "set", "/robot_description", "-t", URDF])
        run(["rosparam", "set", "/simulator/scenario", scenario])
        run(["rosparam", "set", "/archive/root", str(archive)])
        for key, value in (params or {}).items():
            run(["rosparam", "set", key, yaml.safe_dump(value, default_flow_style=True).strip()])
        self.logs = {}
        for pkg, exe in (("rascal_sim", "sim"), ("rascal_control", "arm_controller"),
                         ("rascal_perception", "sherd_detector")):
            log = open(os.path.join(ros_master.log_dir, exe + ".out"), "w")
            self.logs[exe] = log.name
            rosrun(pkg, exe, stdout=log, stderr=subprocess.STDOUT)
        self.wait_for_service("/rascal/perception/detect")
        self.wait_for_service("/rascal/arm/compute_ik")
        self.wait_for_service("/sim/ground_truth")

    def wait_for_service(self, name, timeout=60.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.master.run(["rosservice", "list"], check=False).stdout.split().count(name):
                return
            time.sleep(0.3)
        raise AssertionError("service %s did not come up; logs: %s" % (name, self.tail()))

    def tail(self, n=15):
        out = []
        for exe, path in self.logs.items():
            with open(path, errors="replace") as f:
                out.append("--- %s\n%s" % (exe, "".join(f.readlines()[-n:])))
        return "\n".join(out)

    def rascal(self, *args, dsn, timeout=900, **popen):
        """Start `rosrun rascal_tasks rascal --dsn DSN ARGS...` (returns the Popen)."""
        return self.rosrun("rascal_tasks", "rascal", "--dsn", dsn, *args, **popen)

    def ground_truth(self):
        """name -> (x, y, mass kg) from the simulator's test-only service."""
        code = ("import rospy, json; from rascal_msgs.srv import GetGroundTruth;"
                "rospy.wait_for_service('/sim/ground_truth', 10);"
                "r = rospy.ServiceProxy('/sim/ground_truth', GetGroundTruth)();"
                "print(json.dumps({s.name: [s.pose.position.x, s.pose.position.y, s.mass]"
                " for s in r.sherds}))")
        out = self.master.run(["/usr/bin/python3", "-c", code]).stdout
        return yaml.safe_load(out)

    def inject(self, fault, duration=0.0):
        code = ("import rospy; from rascal_msgs.srv import InjectFault;"
                "rospy.wait_for_service('/sim/inject_fault', 10);"
                "r = rospy.ServiceProxy('/sim/inject_fault', InjectFault)(%d, %f);"
                "print(r.success, r.message)" % (fault, duration))
        return self.master.run(["/usr/bin/python3", "-c", code]).stdout

    def joint_positions(self):
        code = ("import rospy; from sensor_msgs.msg import JointState;"
                "rospy.init_node('probe', anonymous=True);"
                "m = rospy.wait_for_message('/joint_states', JointState, 10);"
                "print(list(m.position[:6]))")
        return yaml.safe_load(self.master.run(["/usr/bin/python3", "-c", code]).stdout)
