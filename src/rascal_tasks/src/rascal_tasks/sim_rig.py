"""Convenience runner: the simulated rig in one command, for the demo, the end-to-end tests and
the throughput benchmark. It starts exactly what a user starts by hand (DESIGN.md, "Running
it"): a master on a free port, `rosparam load config/rascal.yaml`, then `rosrun` of the
simulator, the arm controller and the detector; and it stops all of them again.

    python3 -m rascal_tasks.sim_rig --scenario config/scenarios/small_3.yaml -- rascal run ...
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time

import yaml
from rascal_workcell.processes import free_port, stop, workspace

NODES = (
    ("rascal_sim", "sim"),
    ("rascal_control", "arm_controller"),
    ("rascal_perception", "sherd_detector"),
)
READY = ("/sim/ground_truth", "/rascal/arm/compute_ik", "/rascal/perception/detect")


class RosMaster:
    """A roscore on a free port with its own log folder; `env` is what child processes need to
    talk to it. The tests' `ros_master` fixture and SimRig both use it."""

    def __init__(self, log_dir=None, timeout=30.0):
        self.port = free_port()
        self.own_log_dir = log_dir is None
        self.log_dir = log_dir or tempfile.mkdtemp(prefix="rascal_roslog_")
        self.uri = "http://127.0.0.1:%d" % self.port
        self.env = dict(
            os.environ,
            ROS_MASTER_URI=self.uri,
            ROS_LOG_DIR=self.log_dir,
            ROS_HOSTNAME="127.0.0.1",
            ROS_HOME=self.log_dir,
            PYTHONUNBUFFERED="1",
        )
        self.env.pop("ROS_IP", None)
        self.proc = subprocess.Popen(
            ["roscore", "-p", str(self.port)],
            env=self.env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        deadline = time.monotonic() + timeout
        while self.run(["rosparam", "get", "/run_id"], check=False).returncode != 0:
            if time.monotonic() > deadline or self.proc.poll() is not None:
                self.stop()
                raise RuntimeError("roscore did not come up on port %d" % self.port)
            time.sleep(0.2)

    def run(self, cmd, check=True, timeout=60.0, **kw):
        """Run a command against this master and wait for it (rosparam, rosservice, ...)."""
        return subprocess.run(
            cmd, env=self.env, capture_output=True, text=True, check=check, timeout=timeout, **kw
        )

    def stop(self):
        stop(self.proc)
        if self.own_log_dir:
            shutil.rmtree(self.log_dir, ignore_errors=True)


class SimRig:
    """The simulated rig. `env` talks to its master; `over`: YAML files loaded over the config
    (a layout's keys); `params` are set after them."""

    def __init__(
        self,
        scenario=None,
        params=None,
        master_env=None,
        log_dir=None,
        nodes=NODES,
        ready=READY,
        ws=None,
        over=(),
    ):
        self.ws = ws or workspace()
        self.procs = []  # the rig's nodes: one that exits while a service is awaited is a fault
        self.clients = []  # `rascal` commands run against the rig: they exit by themselves
        self.own_log_dir = log_dir is None
        # A folder of its own, also under a shared master's: its ROS_HOME is the rig's. The
        # detector restores the station backgrounds it finds there (BackgroundStore), and a
        # rig of another scenario that restored them saw a sherd on the empty scale.
        self.log_dir = tempfile.mkdtemp(prefix="rascal_sim_rig_", dir=log_dir)
        self.logs = {}
        self.master = None
        if master_env is None:
            self.master = RosMaster(log_dir=self.log_dir)
            self.env = self.master.env
        else:
            self.env = dict(master_env, ROS_HOME=self.log_dir)
        try:
            self.run(["rosparam", "load", os.path.join(self.ws, "config", "rascal.yaml")])
            for layer in over:  # e.g. config/layouts/one_station.yaml: merged over it
                self.run(["rosparam", "load", os.path.abspath(layer)])
            self.set_param("/use_sim_time", True)
            self.run(
                [
                    "rosparam",
                    "set",
                    "/robot_description",
                    "-t",
                    os.path.join(self.ws, "src", "rascal_description", "urdf", "wx250s.urdf"),
                ]
            )
            if scenario:
                self.set_param("/simulator/scenario", os.path.abspath(scenario))
            for key, value in (params or {}).items():
                self.set_param(key, value)
            for pkg, exe in nodes:
                self.procs.append(self._spawn(exe, ["rosrun", pkg, exe]))
            for name in ready:
                self.wait_for_service(name)
        except BaseException:
            self.stop()
            raise

    def _spawn(self, name, cmd):
        log = open(os.path.join(self.log_dir, name + ".out"), "w")
        self.logs[name] = log.name
        return subprocess.Popen(
            cmd,
            env=self.env,
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
            cwd=self.ws,
        )

    def run(self, cmd, check=True, timeout=120.0, **kw):
        return subprocess.run(
            cmd,
            env=self.env,
            capture_output=True,
            text=True,
            check=check,
            timeout=timeout,
            cwd=self.ws,
            **kw,
        )

    def set_param(self, key, value):
        self.run(
            [
                "rosparam",
                "set",
                key,
                yaml.safe_dump(value, default_flow_style=True).strip().removesuffix("...").strip(),
            ]
        )

    def wait_for_service(self, name, timeout=90.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if name in self.run(["rosservice", "list"], check=False).stdout.split():
                return
            for p in self.procs:
                if p.poll() is not None:
                    raise RuntimeError(
                        "%s exited (%d) before %s came up:\n%s"
                        % (p.args[-1], p.returncode, name, self.tail())
                    )
            time.sleep(0.3)
        raise RuntimeError("service %s did not come up:\n%s" % (name, self.tail()))

    def tail(self, n=12) -> str:
        out = []
        for name, path in self.logs.items():
            with open(path, errors="replace") as f:
                out.append("--- %s\n%s" % (name, "".join(f.readlines()[-n:])))
        return "\n".join(out)

    def rascal(self, *args, **popen):
        """Start `rosrun rascal_tasks rascal ARGS...` against this rig (returns the Popen)."""
        popen.setdefault("stdout", subprocess.PIPE)
        popen.setdefault("stderr", subprocess.STDOUT)
        proc = subprocess.Popen(
            ["rosrun", "rascal_tasks", "rascal", *args],
            env=self.env,
            text=True,
            start_new_session=True,
            cwd=self.ws,
            **popen,
        )
        self.clients.append(proc)
        return proc

    def stop(self):
        for p in reversed(self.clients + self.procs):
            stop(p)
        self.clients = []
        self.procs = []
        if self.master is not None:
            self.master.stop()
            self.master = None
        if self.own_log_dir and os.environ.get("RASCAL_KEEP_LOGS") is None:
            shutil.rmtree(self.log_dir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(
        description="Start the simulated rig, run one command against " "it, stop everything."
    )
    p.add_argument("--scenario", help="scenario YAML (default: simulator.scenario of the config)")
    p.add_argument("--rtf", type=float, help="simulator real-time factor (0 = fast as possible)")
    p.add_argument(
        "--over",
        action="append",
        default=[],
        metavar="YAML",
        help="loaded over config/rascal.yaml, e.g. config/layouts/one_station.yaml",
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=YAML",
        help="extra parameter, e.g. /archive/root=/tmp/archive",
    )
    p.add_argument("command", nargs=argparse.REMAINDER, help="-- command to run, e.g. rosrun ...")
    args = p.parse_args(argv)
    params = {}
    if args.rtf is not None:
        params["/simulator/real_time_factor"] = args.rtf
    for item in args.set:
        key, _, value = item.partition("=")
        params[key] = yaml.safe_load(value)
    cmd = [c for c in args.command if c != "--"]
    with SimRig(scenario=args.scenario, params=params, over=args.over) as rig:
        if not cmd:
            print("rig up; Ctrl-C to stop (ROS_MASTER_URI=%s)" % rig.env["ROS_MASTER_URI"])
            try:
                while True:
                    time.sleep(1)
            except KeyboardInterrupt:
                return 0
        return subprocess.call(cmd, env=rig.env, cwd=rig.ws)


if __name__ == "__main__":
    sys.exit(main())
