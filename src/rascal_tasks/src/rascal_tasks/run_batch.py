"""`rascal run --context ID`: one bag's batch on the rig (or the simulator), with a live
progress line. The node wrapper of the workflow core: reads and checks the configuration,
connects the catalogue *before* anything moves, wires the rig over ROS, runs the machine, and
turns Ctrl-C into a preempt that parks the arm.
"""

import signal
import sys
import threading
import time

import rospy

from rascal_tasks.catalogue import Catalogue, ImageArchive
from rascal_tasks.catalogue.context_id import validate_context_id
from rascal_tasks.catalogue.errors import CatalogueError
from rascal_tasks.config import ConfigError
from rascal_tasks.recorder import Recorder
from rascal_tasks.rig import Rig, RigError
from rascal_tasks.ros_config import load_from_param_server
from rascal_tasks.workflow import Batch, build_machine, smach


class ProgressLine:
    """`sherd k | state | elapsed | s/sherd` on one terminal line (a plain line per state when
    the output is not a terminal, so logs stay readable)."""

    def __init__(self, out=sys.stdout):
        self.out = out
        self.tty = out.isatty()
        self.batch = None

    def __call__(self, state):
        b = self.batch
        if b is None:
            return
        elapsed = b.rig.clock.now() - b.started
        k = b.sherd.seq if b.sherd else b.completed + b.lost + 1
        per = b.per_sherd()
        line = "sherd %3d | %-22s | %7.1f s | %s" % (
            k,
            state[:22],
            elapsed,
            "%.1f s/sherd" % per if per else "–",
        )
        if self.tty:
            self.out.write("\r" + line + "   ")
        else:
            self.out.write(line + "\n")
        self.out.flush()


def fail(message: str, code: int = 2):
    print("error: %s" % message, file=sys.stderr)
    return code


def run(context: str, dsn: str = None) -> int:
    try:
        validate_context_id(context)
    except CatalogueError as e:
        return fail(str(e))
    rospy.init_node("rascal", disable_signals=True)
    try:
        cfg = load_from_param_server()
    except ConfigError as e:
        return fail(str(e))
    db = cfg["database"]
    dsn = dsn or db["dsn"]
    # The catalogue first: if it is down, nothing may move.
    try:
        catalogue = Catalogue.connect(
            dsn, rig=cfg["rig"]["name"], config_hash=cfg.hash, connect_timeout=db["connect_timeout"]
        )
        catalogue.check_schema()
    except CatalogueError as e:
        return fail(
            "database: %s (database.dsn in config/rascal.yaml; `rascal db migrate` "
            "creates the tables)" % e,
            3,
        )
    archive = ImageArchive(cfg.resolve(cfg["archive"]["root"]))
    try:
        recorder = Recorder(catalogue, archive, context, cfg["rig"]["site"], log=rospy.loginfo)
        rig = make_rig(cfg)
    except (CatalogueError, RigError) as e:
        return fail(str(e), 3)

    progress = ProgressLine()
    batch = Batch(cfg, rig, recorder, context, progress=progress, log=rospy.loginfo)
    progress.batch = batch
    # The machine's own chatter (states added, every transition) goes to the node's log; the
    # terminal shows the progress line and what happened to sherds.
    smach.set_loggers(rospy.logdebug, rospy.logwarn, rospy.logdebug, rospy.logerr)
    machine = build_machine(batch)
    stop = threading.Event()

    def on_sigint(signum, frame):
        if stop.is_set():  # second Ctrl-C: stop the arm where it is
            rig.arm.stop()
            return
        stop.set()
        print("\nstopping: parking the arm (Ctrl-C again stops it where it is)", file=sys.stderr)
        batch.stop_requested.set()
        machine.request_preempt()

    signal.signal(signal.SIGINT, on_sigint)
    signal.signal(signal.SIGTERM, on_sigint)
    wall = time.monotonic()
    outcome = machine.execute()
    print()
    print_summary(batch, recorder, outcome, time.monotonic() - wall)
    catalogue.close()
    return {"finished": 0, "preempted": 130}.get(outcome, 1)


def make_rig(cfg) -> Rig:
    from rascal_tasks.ros_rig import (
        RosArchivalCamera,
        RosArm,
        RosClock,
        RosGripper,
        RosPerception,
        RosScale,
    )

    clock = RosClock()
    return Rig(
        arm=RosArm(),
        gripper=RosGripper(),
        perception=RosPerception(),
        scale=RosScale(clock),
        camera=RosArchivalCamera(),
        clock=clock,
    )


def print_summary(batch, recorder, outcome, wall_seconds):
    rows = recorder.rows()
    sim = batch.rig.clock.now() - batch.started
    n = batch.completed + batch.lost
    print(
        "batch %s: %s — %d recorded, %d lost, %.1f s (%s), wall %.1f s"
        % (
            batch.context,
            outcome,
            batch.completed,
            batch.lost,
            sim,
            "%.1f s/sherd" % (sim / n) if n else "no sherds",
            wall_seconds,
        )
    )
    for x, y in batch.unpickable:
        print("left in the pickup area (could not be picked up): sherd at (%.3f, %.3f) m" % (x, y))
    if batch.state_times:
        print(
            "time per state (s): "
            + ", ".join(
                "%s %.1f" % kv for kv in sorted(batch.state_times.items(), key=lambda kv: -kv[1])
            )
        )
    print(
        "%4s  %-13s %9s %9s %9s %9s %6s  %s"
        % ("seq", "status", "mass g", "length mm", "width mm", "thick mm", "drops", "image")
    )
    for r in rows:
        print(
            "%4d  %-13s %9s %9s %9s %9s %6d  %s"
            % (
                r["seq"],
                r["status"],
                _f(r.get("mass_g")),
                _f(r.get("length_mm")),
                _f(r.get("width_mm")),
                _f(r.get("thickness_mm")),
                r.get("drops") or 0,
                r.get("image_path") or r.get("lost_reason") or "",
            )
        )


def _f(v):
    return "–" if v is None else "%.1f" % v
