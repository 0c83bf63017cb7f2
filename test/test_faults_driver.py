"""Field faults of the arm's side, injected into whole batches (`pytest -m faults`): the real
master, simulator, arm controller and detector started with rosrun, PostgreSQL, and `rascal run`
as a user types it (see test_batch_e2e.py).

- The simulator (on the rig: the arm driver) is killed and started again mid-batch. The world
  is kept as it was, as a restarted driver on the rig would find it (the new simulator is given
  the sherds where the old one had them, through its test-only /sim/spawn). The controller must
  notice the restart, refuse every goal, and the run stop with exit code 3 and one line naming
  the driver; nothing lost, nothing twice; a rerun, while the new simulator's clock is still
  behind the old one's, acknowledges the restart, calibrates anew and finishes the bag with
  each sherd once (its moves really run: none "done in 0.0 s").
- arm_controller is killed mid-batch. The run must not wait for it for ever: it stops within
  30 s with exit code 3 and a line naming arm_controller; once it runs again, a rerun finishes
  the bag with each sherd once.
- The run and the detector die together while a weighed sherd lies on the scale. The restarted
  detector restores its backgrounds; the rerun finds that sherd on the scale and records each
  sherd once.
"""

import json
import os
import re
import signal
import subprocess
import sys
import time

import pytest
import yaml
from rig_helpers import (
    assert_masses_match,
    SMALL,
    WORKSPACE,
    ground_truth,
    inject,
    rows,
    run_batch,
    run_until,
    run_until_weighed,
)

pytestmark = [pytest.mark.faults, pytest.mark.timeout(900)]

# rascal_msgs/srv/InjectFault.srv
SCALE_GLITCH_ON_LOAD = 4  # garbage, unstable readings from when the next sherd lands

# What the run's one error line says about the arm driver (arm_controller's words).
DRIVER_FAULT = (
    r"arm driver restarted \(.*re-run `rascal run`|driver silent: no /joint_states|"
    r"no arm joints on /joint_states within .* s; is the driver running\?|"
    r"no driver subscribes to /arm/joint_trajectory; is it running\?"
)


def error_lines(out):
    return [line for line in out.splitlines() if line.startswith("error:")]


def summary(recorded):
    return [(r["seq"], r["status"], r["lost_reason"], r["notes"]) for r in recorded]


def rerun_finishes_once_each(rig, db, context, truth):
    code, out = run_batch(rig, db, context)
    assert code == 0, out[-3000:] + rig.tail()
    recorded = rows(db, context)
    why = "%s\n%s\nworld now: %s" % (summary(recorded), out[-3000:], ground_truth(rig))
    assert [r["seq"] for r in recorded] == [1, 2, 3], why
    assert [r["status"] for r in recorded] == ["done"] * 3, why
    assert_masses_match(recorded, truth)
    return out


def node(rig, executable):
    return next(p for p in rig.procs if p.args[0] == "rosrun" and p.args[2] == executable)


def kill(rig, executable):
    proc = node(rig, executable)
    os.killpg(proc.pid, signal.SIGKILL)  # no clean-up of any kind: a crash or a pulled cable
    proc.wait()
    rig.procs.remove(proc)


def restart(rig, package, executable):
    """`rosrun package executable` again, as a person would; stopped with the rig."""
    rig.procs.insert(0, rig._spawn(executable + "_restarted", ["rosrun", package, executable]))


# Watches the simulator's ground truth (every 50 ms of wall time) until the first sherd lies still
# in the discard box and none is held: the arm is then on its way to the next sherd. Prints the
# world then (name -> [x, y, yaw]) and exits.
WATCH_DISCARD = """
import json, math, sys, time
import rospy
from rascal_msgs.srv import GetGroundTruth
x0, x1, y0, y1 = %r
rospy.init_node('fault_watch', anonymous=True)
rospy.wait_for_service('/sim/ground_truth', 30)
truth = rospy.ServiceProxy('/sim/ground_truth', GetGroundTruth, persistent=True)
last, calm, deadline = {}, 0, time.monotonic() + 600
while time.monotonic() < deadline:
    now = {}
    for s in truth().sherds:
        p, q = s.pose.position, s.pose.orientation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        now[s.name] = [p.x, p.y, yaw, s.held]
    still = last and all(math.dist(now[n][:2], last[n][:2]) < 5e-4 for n in now)
    boxed = [n for n, (x, y, _, held) in now.items() if x0 < x < x1 and y0 < y < y1 and not held]
    calm = calm + 1 if still and boxed and not any(v[3] for v in now.values()) else 0
    if calm >= 3:
        print(json.dumps({n: v[:3] for n, v in now.items()}), flush=True)
        sys.exit(0)
    last = now
    time.sleep(0.05)
sys.exit(1)
"""


def discard_box():
    with open(os.path.join(WORKSPACE, "config", "rascal.yaml")) as f:
        stations = yaml.safe_load(f)["stations"]
    st = next(s for s in stations.values() if s["type"] == "discard")
    (x, y), (lx, ly) = st["position"], st["size"]
    return (x - lx / 2, x + lx / 2, y - ly / 2, y + ly / 2)


def world_as_scenario(world, box):
    """small_3 with every sherd where `world` has it; those in the discard box dropped onto each
    other from a little above (they may have landed on one another)."""
    with open(SMALL) as f:
        scenario = yaml.safe_load(f)
    scenario["name"] = "small_3_after_restart"
    dropped = 0
    for s in scenario["sherds"]:
        x, y, yaw = world[s["name"]]
        s["pose"] = [x, y, yaw]
        if box[0] < x < box[1] and box[2] < y < box[3]:
            s["drop_height"] = 0.005 + 0.025 * dropped
            dropped += 1
    return yaml.safe_dump(scenario)


def spawn(rig, scenario_yaml):
    """The sherds of `scenario_yaml` into the (restarted) simulator: [success, message]."""
    code = (
        "import rospy; from rascal_msgs.srv import SpawnScenario;"
        "rospy.init_node('fault_spawn', anonymous=True);"  # retries a killed node's service
        "rospy.wait_for_service('/sim/spawn', 60);"
        "r = rospy.ServiceProxy('/sim/spawn', SpawnScenario)('', %r);"
        "print([r.success, r.message])" % scenario_yaml
    )
    out = rig.run(["/usr/bin/python3", "-c", code]).stdout
    return yaml.safe_load(out.strip().splitlines()[-1])  # after rospy's own lines


# --- the task's side, without a master


@pytest.mark.parametrize("code", ["DRIVER_RESTARTED", "TRACKING_ERROR"])
def test_a_restarted_driver_or_an_arm_off_its_path_stops_the_batch(code):
    from rascal_tasks.failures import STOP, classify
    from rascal_tasks.rig import RigError

    # even on a grasp target (where UNREACHABLE would lose only the sherd)
    assert classify(RigError("arm", code, "arm driver restarted"), sherd_target=True) == STOP


def test_home_acknowledges_a_driver_restart_once_per_run():
    sys.path.insert(0, os.path.join(WORKSPACE, "src", "rascal_tasks", "test"))
    import fake_rig

    from rascal_tasks.config import load_config
    from rascal_tasks.resume import Home
    from rascal_tasks.workflow import Batch

    cfg = load_config(os.path.join(WORKSPACE, "config", "rascal.yaml"))
    r = fake_rig.World(cfg, []).rig()
    calls, log = [], []
    r.arm.acknowledge_restart = lambda: calls.append(1) or "driver restart acknowledged (x)"
    batch = Batch(cfg, r, recorder=fake_rig.Recorder(), context="T", log=log.append)
    assert Home(batch).run() == "done"
    assert calls == [1]
    assert "batch driver_restart_acknowledged: driver restart acknowledged (x)" in log
    assert fake_rig.World(cfg, []).rig().arm.acknowledge_restart() == ""  # the default: no-op


# --- whole batches


def test_a_restarted_simulator_stops_the_run_and_a_rerun_records_each_sherd_once(
    rig_factory, db, tmp_path
):
    # Paced at real time until the fault, so the moment between two sherds can be caught.
    rig = rig_factory(archive=tmp_path / "archive", params={"/simulator/real_time_factor": 1.0})
    truth = ground_truth(rig)
    box = discard_box()
    watch = subprocess.Popen(
        ["/usr/bin/python3", "-c", WATCH_DISCARD % (box,)],
        env=rig.env,
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    proc = rig.rascal("--dsn", db, "run", "--context", "FAULT-SIM")
    deadline = time.monotonic() + 400
    while watch.poll() is None and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    if watch.poll() is None:
        os.killpg(watch.pid, signal.SIGKILL)
    world_out, _ = watch.communicate()
    if watch.returncode != 0 or proc.poll() is not None:
        proc.kill()
        raise AssertionError(
            "no sherd reached the discard box with the run going on:\n%s\n%s"
            % (proc.communicate()[0][-3000:], rig.tail())
        )
    world = json.loads(world_out)
    kill(rig, "sim")
    # Still at real time: the rerun then starts while the new simulator's clock is behind the
    # old one's, so every goal of the rerun is stamped (in ROS time) before the controller's
    # last goal, which actionlib's SimpleActionServer cancels unrun with an empty result,
    # code 0 = OK in 0.0 s: the field's "moves done in 0.0 s without moving".
    restart(rig, "rascal_sim", "sim")
    assert spawn(rig, world_as_scenario(world, box))[0] is True

    t0 = time.monotonic()
    out, _ = proc.communicate(timeout=120)
    print(out[-4000:])
    assert proc.returncode == 3, out[-3000:] + rig.tail()
    assert time.monotonic() - t0 < 60
    # One line naming the driver: refused as restarted, or (when the new simulator took longer
    # to come up than the run took to give up) silent or not listening.
    lines = error_lines(out)
    assert len(lines) == 1, lines
    assert re.search(DRIVER_FAULT, lines[0]), lines
    with open(rig.logs["arm_controller"]) as f:
        assert "arm driver restarted (" in f.read(), rig.tail()  # noticed, whatever the timing
    recorded = rows(db, "FAULT-SIM")
    assert [r["status"] for r in recorded] == ["done"], summary(recorded)  # no false `lost`

    out = rerun_finishes_once_each(rig, db, "FAULT-SIM", truth)
    assert "driver restart acknowledged (" in out, out[-3000:]


def test_a_killed_arm_controller_stops_the_run_in_bounded_time_and_a_rerun_finishes(
    rig_factory, db, tmp_path
):
    rig = rig_factory(archive=tmp_path / "archive")
    truth = ground_truth(rig)
    proc = run_until_weighed(rig, db, "FAULT-CTRL")
    kill(rig, "arm_controller")
    t0 = time.monotonic()
    try:
        out, _ = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.send_signal(signal.SIGKILL)
        out, _ = proc.communicate()
        raise AssertionError(
            "the run waited more than 30 s for a dead arm_controller:\n" + out
        ) from None
    print(out[-4000:])
    assert time.monotonic() - t0 < 30
    assert proc.returncode == 3, out[-3000:] + rig.tail()
    lines = error_lines(out)
    assert len(lines) == 1 and "arm_controller" in lines[0], lines
    statuses = [r["status"] for r in rows(db, "FAULT-CTRL")]
    assert "lost" not in statuses, statuses

    restart(rig, "rascal_control", "arm_controller")
    rig.wait_for_service("/rascal/arm/compute_ik")
    rerun_finishes_once_each(rig, db, "FAULT-CTRL", truth)


def test_a_restarted_detector_finds_the_sherd_a_killed_run_left_on_the_scale(
    rig_factory, db, tmp_path
):
    """The run and the detector die together while a sherd lies on the scale (a laptop crash).
    The restarted detector restores the backgrounds it had learnt (BackgroundStore), so the
    rerun's Calibrate sees the sherd on the scale and keeps the scale's model instead of
    learning the sherd as background, and Resume carries on with it: each sherd recorded once.
    Without the kept backgrounds that sherd was recorded lost and the next ones put on it.

    The kill must find the sherd lying there with the gripper away from it: the scale is made
    to read unsteadily when the sherd lands (longer than one scale.stable_timeout of 4 s), and
    the run is killed once its first reading was noted unsteady, while the arm hovers waiting
    for the next (a kill as soon as the sherd is weighed raced the repick's descent)."""
    rig = rig_factory(archive=tmp_path / "archive", params={"/simulator/real_time_factor": 1.0})
    truth = ground_truth(rig)
    ok, message = inject(rig, SCALE_GLITCH_ON_LOAD, 5.0)
    assert ok, message
    proc = run_until(
        rig,
        db,
        "FAULT-DET",
        lambda recorded: any("scale_unstable: attempt 1" in (r["notes"] or "") for r in recorded),
        "a reading on the scale was noted unsteady",
    )
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    kill(rig, "sherd_detector")
    restart(rig, "rascal_perception", "sherd_detector")
    rig.wait_for_service("/rascal/perception/detect")
    kept = os.path.join(rig.env["ROS_HOME"], "rascal", "backgrounds")
    assert sorted(os.listdir(kept)) == [
        "camera.yml.gz",
        "discard.yml.gz",
        "pickup.yml.gz",
        "scale.yml.gz",
    ], kept

    out = rerun_finishes_once_each(rig, db, "FAULT-DET", truth)
    assert "sherd(s) lying at the scale: its background model from before is kept" in out, out
    assert "sherd 1 was picked" in out, out[-3000:]
    assert "sherd 1 tare_unchecked: lying on the scale after a restart" in out, out[-3000:]
