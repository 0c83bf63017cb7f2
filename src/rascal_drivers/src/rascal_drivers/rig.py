"""One start command for the rig: `rosrun rascal_drivers rig [--emulated] [-- COMMAND ...]`.

Starts, in order, what README.md's recipe starts by hand, each with rosrun (no roslaunch), and
waits until each is healthy before the next, with a deadline per step:

1. the ROS master (roscore) on --port (11311: the port `rascal run` finds by default);
2. the configuration (`rosparam load`), the URDF as /robot_description, `check_config`, and the
   catalogue's tables (`rascal db migrate`);
3. the field drivers (arm_driver, scale_driver, archival_camera_driver, wrist_camera_driver),
   each healthy when its topic or service is up; or, with --emulated, the simulator (its device
   topics and services under /emulated), the device emulators fed by it (emulated_devices: the
   servo bus and the scale on pseudo-terminals), and the same four drivers: arm_driver and
   scale_driver on the pseudo-terminals, wrist_camera_driver on librealsense's software device
   fed with the simulator's wrist images, archival_camera_driver on a DSLR emulated at
   python3-gphoto2's boundary whose pictures the simulator takes;
4. arm_controller and sherd_detector.

Then it runs COMMAND (and stops the rig when it ends, with its exit code), or waits for Ctrl-C.
A step that fails, or a node that dies while the rig runs, is one line naming it and the node's
own last line (the drivers' lines name the key or the device to fix); every process started is
stopped, in reverse order (SIGINT to its process group, SIGKILL after 10 s). Exit status: the
command's, else 0 after Ctrl-C, 3 when a step failed or a node died. Logs: --log-dir (default
var/log/rig-<UTC time>/<node>.log). No rospy here: the master is asked over XML-RPC.
"""

import argparse
import os
import signal
import socket
import subprocess
import sys
import time
import xmlrpc.client
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

from rascal_drivers.parameters import EMULATED
from rascal_workcell.processes import free_port, stop, workspace

FAULT = 3
SIM_NS = "/emulated"
SIM_REMAPS = (
    "/joint_states:=%s/joint_states" % SIM_NS,
    "/arm/joint_trajectory:=%s/arm/joint_trajectory" % SIM_NS,
    "/gripper/command:=%s/gripper/command" % SIM_NS,
    "/scale/mass:=%s/scale/mass" % SIM_NS,
    "/scale/tare:=%s/scale/tare" % SIM_NS,
    "/archival_camera/capture:=%s/archival_camera/capture" % SIM_NS,
    "/archival_camera/exposed:=%s/archival_camera/exposed" % SIM_NS,
    "/camera/color/image_raw:=%s/camera/color/image_raw" % SIM_NS,
    "/camera/color/camera_info:=%s/camera/color/camera_info" % SIM_NS,
    "/camera/aligned_depth_to_color/image_raw:=%s/camera/aligned_depth_to_color/image_raw" % SIM_NS,
    "/camera/aligned_depth_to_color/camera_info:=%s/camera/aligned_depth_to_color/camera_info"
    % SIM_NS,
    "/camera/depth/color/points:=%s/camera/depth/color/points" % SIM_NS,
)


class RigError(RuntimeError):
    """One line: which step failed and what to do."""


@dataclass
class Node:
    name: str  # for the log and the lines
    argv: List[str]
    ready: Tuple[str, ...]  # ("service", name) | ("topic", name) | ("paths", p1, ...)
    deadline: float  # [s] to become healthy
    hint: str = ""  # what to check when it does not


@dataclass
class Started:
    node: Node
    proc: subprocess.Popen
    log: str


def field_nodes() -> List[Node]:
    return [
        Node(
            "arm_driver",
            ["rosrun", "rascal_drivers", "arm_driver"],
            ("topic", "/joint_states"),
            20.0,
            "is the arm switched on and the U2D2 plugged in? run rascal doctor",
        ),
        Node(
            "scale_driver",
            ["rosrun", "rascal_drivers", "scale_driver"],
            ("service", "/scale/tare"),
            15.0,
            "is the scale switched on and its cable plugged in? run rascal doctor",
        ),
        Node(
            "archival_camera_driver",
            ["rosrun", "rascal_drivers", "archival_camera_driver"],
            ("service", "/archival_camera/capture"),
            30.0,
            "is the camera switched on and plugged in? run rascal doctor",
        ),
        Node(
            "wrist_camera_driver",
            ["rosrun", "rascal_drivers", "wrist_camera_driver"],
            ("topic", "/camera/color/image_raw"),
            20.0,
            "is the wrist camera's cable in a USB 3 port? run rascal doctor",
        ),
    ]


def emulated_nodes(links: Sequence[str]) -> List[Node]:
    return [
        Node(
            "sim",
            ["rosrun", "rascal_sim", "sim", *SIM_REMAPS],
            ("service", "/sim/ground_truth"),
            90.0,
            "is rascal_sim built? (make demo builds it)",
        ),
        Node(
            "emulated_devices",
            ["rosrun", "rascal_drivers", "emulated_devices"],
            ("paths", *links),
            40.0,
        ),
        Node(
            "arm_driver",
            ["rosrun", "rascal_drivers", "arm_driver"],
            ("topic", "/joint_states"),
            20.0,
        ),
        Node(
            "scale_driver",
            ["rosrun", "rascal_drivers", "scale_driver"],
            ("service", "/scale/tare"),
            15.0,
        ),
        Node(
            "archival_camera_driver",
            ["rosrun", "rascal_drivers", "archival_camera_driver"],
            ("service", "/archival_camera/capture"),
            45.0,
        ),
        Node(
            "wrist_camera_driver",
            ["rosrun", "rascal_drivers", "wrist_camera_driver"],
            ("topic", "/camera/color/image_raw"),
            45.0,
        ),
    ]


def task_nodes() -> List[Node]:
    return [
        Node(
            "arm_controller",
            ["rosrun", "rascal_control", "arm_controller"],
            ("service", "/rascal/arm/compute_ik"),
            60.0,
            "is rascal_control built?",
        ),
        Node(
            "sherd_detector",
            ["rosrun", "rascal_perception", "sherd_detector"],
            ("service", "/rascal/perception/detect"),
            60.0,
            "is rascal_perception built?",
        ),
    ]


def last_line(path: str) -> str:
    """The node's last meaningful line (its one-line error, when it gave one)."""
    try:
        with open(path, errors="replace") as f:
            lines = [ln.strip() for ln in f if ln.strip()]
    except OSError:
        return ""
    for ln in reversed(lines):
        if "Traceback" not in ln and not ln.startswith(("File ", "^", "...")):
            return ln
    return ""


class Rig:
    def __init__(
        self,
        ws: str,
        port: int = 11311,
        emulated: bool = False,
        log_dir: Optional[str] = None,
        config: Optional[str] = None,
        params: Optional[Dict[str, str]] = None,
        say=None,
    ):
        self.ws = ws
        self.port = port or free_port()
        self.emulated = emulated
        stamp = time.strftime("%Y%m%d-%H%M%S", time.gmtime())
        self.log_dir = log_dir or os.path.join(ws, "var", "log", "rig-" + stamp)
        self.config = config or os.path.join(ws, "config", "rascal.yaml")
        self.params = dict(params or {})
        self.say = say or (lambda line: print(line, file=sys.stderr, flush=True))
        self.uri = "http://127.0.0.1:%d" % self.port
        self.env = dict(os.environ, ROS_MASTER_URI=self.uri, PYTHONUNBUFFERED="1")
        if emulated:
            self.env.setdefault("ROS_HOSTNAME", "127.0.0.1")
        self.started: List[Started] = []
        self.master: Optional[subprocess.Popen] = None
        self.links = (
            os.path.join(self.log_dir, "ttyDXL"),
            os.path.join(self.log_dir, "ttyScale"),
        )

    # ------------------------------------------------------------------ master
    def _state(self):
        proxy = xmlrpc.client.ServerProxy(self.uri)
        socket.setdefaulttimeout(2.0)
        try:
            code, _, state = proxy.getSystemState("/rig")
        finally:
            socket.setdefaulttimeout(None)
        return state if code == 1 else None

    def _master_up(self) -> bool:
        try:
            return self._state() is not None
        except (OSError, xmlrpc.client.Error):
            return False

    def start_master(self, deadline: float = 30.0) -> None:
        if self._master_up():
            raise RigError(
                "a ROS master already runs at %s; stop it (or the rig that started it) first, "
                "or pass --port" % self.uri
            )
        os.makedirs(self.log_dir, exist_ok=True)
        log = open(os.path.join(self.log_dir, "roscore.log"), "w")
        self.master = subprocess.Popen(
            ["roscore", "-p", str(self.port)],
            env=self.env,
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
            cwd=self.ws,
        )
        end = time.monotonic() + deadline
        while not self._master_up():
            if self.master.poll() is not None or time.monotonic() > end:
                raise RigError(
                    "roscore did not come up on port %d within %.0f s: %s"
                    % (self.port, deadline, last_line(log.name) or "no output")
                )
            time.sleep(0.2)
        self.say("rig: master up at %s" % self.uri)

    # ------------------------------------------------------------------ configuration
    def _run(self, argv: List[str], what: str, timeout: float = 60.0) -> None:
        try:
            res = subprocess.run(
                argv, env=self.env, cwd=self.ws, capture_output=True, text=True, timeout=timeout
            )
        except subprocess.TimeoutExpired:
            raise RigError("%s did not finish within %.0f s" % (what, timeout)) from None
        if res.returncode != 0:
            lines = res.stderr.strip() or res.stdout.strip() or "exit %d" % res.returncode
            raise RigError("%s failed: %s" % (what, lines.splitlines()[-1]))

    def load_configuration(self) -> None:
        urdf = os.path.join(self.ws, "src", "rascal_description", "urdf", "wx250s.urdf")
        self._run(["rosparam", "load", self.config], "rosparam load %s" % self.config)
        self._run(["rosparam", "set", "/robot_description", "-t", urdf], "loading the URDF")
        params = dict(self.params)
        if self.emulated:
            params.setdefault("/use_sim_time", "true")
            # the emulators and the drivers run on the wall clock, the simulator on its own:
            # at a quarter speed it keeps its pace on a busy 2-core machine instead of catching up
            # in bursts (a burst moves the arm faster than the driver's clock stamps it)
            params.setdefault("/simulator/real_time_factor", "0.25")
            # three Python processes share the emulators' bus with the simulator's renderer on
            # this machine: a reply may come late without the line being lost
            params.setdefault("/drivers/arm/bus_timeout", "1.0")
            params["/drivers/arm/device"] = self.links[0]
            params["/drivers/scale/device"] = self.links[1]
            params["/drivers/wrist_camera/source"] = EMULATED + SIM_NS
            params["/drivers/archival_camera/kind"] = "gphoto2"
            params["/drivers/archival_camera/device"] = EMULATED + SIM_NS
            # the simulator at a quarter speed on a busy machine may pause its frames for a
            # second or two of wall time; a camera that long silent on the rig is unplugged
            params.setdefault("/drivers/wrist_camera/frame_timeout", "10.0")
        for key, value in params.items():
            self._run(["rosparam", "set", key, value], "rosparam set %s" % key)
        self._run(["rosrun", "rascal_tasks", "check_config"], "check_config")
        self._run(["rosrun", "rascal_tasks", "rascal", "db", "migrate"], "rascal db migrate")
        self.say("rig: configuration %s and URDF loaded, checked; catalogue ready" % self.config)

    # ------------------------------------------------------------------ nodes
    def _healthy(self, ready: Tuple[str, ...]) -> bool:
        kind, names = ready[0], ready[1:]
        if kind == "paths":
            return all(os.path.exists(p) for p in names)
        try:
            state = self._state()
        except (OSError, xmlrpc.client.Error):
            return False
        if state is None:
            return False
        publishers, _, services = state
        listed = {t for t, nodes in (publishers if kind == "topic" else services) if nodes}
        return all(n in listed for n in names)

    def start_node(self, node: Node) -> None:
        log = os.path.join(self.log_dir, node.name + ".log")
        with open(log, "w") as out:
            proc = subprocess.Popen(
                node.argv,
                env=self.env,
                stdout=out,
                stderr=subprocess.STDOUT,
                start_new_session=True,
                cwd=self.ws,
            )
        self.started.append(Started(node, proc, log))
        end = time.monotonic() + node.deadline
        while not self._healthy(node.ready):
            if proc.poll() is not None:
                raise RigError(
                    "%s exited (%d) while starting: %s"
                    % (node.name, proc.returncode, last_line(log) or "no output; see " + log)
                )
            if time.monotonic() > end:
                raise RigError(
                    "%s not healthy after %.0f s (no %s %s)%s; its log: %s"
                    % (
                        node.name,
                        node.deadline,
                        node.ready[0],
                        " ".join(node.ready[1:]),
                        "; " + node.hint if node.hint else "",
                        log,
                    )
                )
            time.sleep(0.2)
        self.say("rig: %s up" % node.name)

    def nodes(self) -> List[Node]:
        devices = emulated_nodes(self.links) if self.emulated else field_nodes()
        return devices + task_nodes()

    def start(self) -> None:
        self.start_master()
        self.load_configuration()
        for node in self.nodes():
            self.start_node(node)
        self.say(
            "rig: ready (%s); ROS_MASTER_URI=%s; logs in %s"
            % ("emulated devices" if self.emulated else "field devices", self.uri, self.log_dir)
        )

    def died(self) -> Optional[str]:
        """One line for the first node that exited while the rig runs, else None."""
        for s in self.started:
            if s.proc.poll() is not None:
                return "%s stopped (exit %d): %s" % (
                    s.node.name,
                    s.proc.returncode,
                    last_line(s.log) or "no output",
                )
        return None

    def stop(self) -> None:
        for s in reversed(self.started):
            stop(s.proc)
        self.started = []
        if self.master is not None:
            stop(self.master)
            self.master = None
        for link in self.links if self.emulated else ():
            if os.path.islink(link):
                os.unlink(link)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(
        prog="rig",
        description="Start the rig (master, configuration, drivers, controller, detector) and "
        "stop it again on Ctrl-C or when COMMAND ends.",
    )
    p.add_argument("--emulated", action="store_true", help="the simulator behind the emulators")
    p.add_argument("--port", type=int, default=11311, help="master port (0: a free one)")
    p.add_argument("--config", help="site config (default: config/rascal.yaml)")
    p.add_argument("--log-dir", help="where each node's log goes (default var/log/rig-TIME)")
    p.add_argument(
        "--set", action="append", default=[], metavar="KEY=VALUE", help="extra parameter"
    )
    p.add_argument("command", nargs=argparse.REMAINDER, help="-- command to run on the rig")
    args = p.parse_args(argv)
    params = dict(item.partition("=")[::2] for item in args.set)
    cmd = [c for c in args.command if c != "--"]
    rig = Rig(
        workspace(),
        port=args.port,
        emulated=args.emulated,
        log_dir=args.log_dir,
        config=args.config and os.path.abspath(args.config),
        params=params,
    )
    stopping = {"signal": None}

    def on_signal(signum, _frame):
        stopping["signal"] = signum
        raise KeyboardInterrupt

    # both set here, not left to Python's default: a process started in the background by a
    # shell (`cmd &`, a CI job) inherits SIGINT ignored, and Python then installs no
    # KeyboardInterrupt for it, so Ctrl-C would not stop the rig (CI: killed after 60 s, its
    # nodes left running)
    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    code = 0
    try:
        rig.start()
        if cmd:
            child = subprocess.Popen(cmd, env=rig.env, cwd=os.getcwd())
            told = False
            try:
                while child.poll() is None:
                    why = None if told else rig.died()
                    if why:  # the command sees the fault itself; say which node it was
                        rig.say("rig: %s" % why)
                        told = True
                    time.sleep(0.5)
                code = child.returncode
            except KeyboardInterrupt:
                # Ctrl-C in the terminal reached the command too (same process group): a second
                # one would stop `rascal run` without parking the arm; SIGTERM did not reach it
                if stopping["signal"] == signal.SIGTERM:
                    child.send_signal(signal.SIGINT)
                signal.signal(signal.SIGINT, signal.SIG_IGN)
                code = child.wait()
        else:
            rig.say("rig: Ctrl-C stops everything (park the arm first: rascal run does)")
            while True:
                why = rig.died()
                if why:
                    rig.say("rig: %s; stopping the rig" % why)
                    code = FAULT
                    break
                time.sleep(0.5)
    except RigError as e:
        rig.say("rig: error: %s; stopping what was started" % e)
        code = FAULT
    except KeyboardInterrupt:
        rig.say("rig: interrupted; stopping every node")
        code = 130 if cmd else 0
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # a second Ctrl-C must not cut the stop
        rig.stop()
        rig.say("rig: stopped")
    return code
