"""Faults in the field around `rascal run` (issue 13): a second run on the same rig or context,
where the database and configuration come from, no master, a node that was not started, a bag
that cannot be finished, the database going away mid-batch, and nodes killed at random
mid-batch. Whole batches in simulation (real nodes, real PostgreSQL), as in test_batch_e2e.py.
Run alone with `pytest -m faults`."""

import os
import random
import signal
import socket
import subprocess
import time

import psycopg2
import pytest
import yaml
from rig_helpers import (
    assert_masses_match,
    SMALL,
    WORKSPACE,
    block_database,
    call,
    ground_truth,
    rascal,
    rows,
    wait_until,
)

from rascal_tasks.sim_rig import NODES, RosMaster, stop

pytestmark = [pytest.mark.faults, pytest.mark.timeout(900)]

PG_ADMIN_DSN = os.environ.get(
    "RASCAL_TEST_PG_DSN", "postgresql://rascal:rascal@127.0.0.1:5432/rascal"
)
UNREACHABLE_DSN = "postgresql://rascal:rascal@127.0.0.1:1/nowhere"


def finish(proc, timeout=600):
    """Wait for a `rascal` process; (exit code, output)."""
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        raise AssertionError(
            "rascal did not end within %d s:\n%s" % (timeout, out[-3000:])
        ) from None
    return proc.returncode, out


def error_lines(out):
    return [line for line in out.splitlines() if line.startswith("error: ")]


def contexts(dsn):
    with psycopg2.connect(dsn) as conn, conn.cursor() as cur:
        cur.execute("SELECT context_id FROM contexts")
        return {r[0] for r in cur.fetchall()}


def _statuses(recorded):
    return [(r["seq"], r["status"], r["mass_g"], r["lost_reason"]) for r in recorded]


def assert_each_sherd_once(recorded, truth):
    """The catalogue equals the sherds: one done row per scenario sherd, none lost or left
    unfinished, each mass within 0.2 g of a different sherd's true mass."""
    assert [r["seq"] for r in recorded] == list(range(1, len(truth) + 1)), _statuses(recorded)
    assert all(r["status"] == "done" for r in recorded), _statuses(recorded)
    assert_masses_match(recorded, truth)


def assert_no_sherd_twice(recorded, truth, code):
    """After faults: one row per scenario sherd (none recorded twice, none missing), every
    recorded mass within 0.2 g of a different sherd's true mass. A sherd the rig lost while
    carrying it (it fell where no station is) may be recorded lost, with what was measured:
    then the run ended 1 (a person must look), never 0."""
    summary = _statuses(recorded)
    assert len(recorded) == len(truth), summary
    assert [r["seq"] for r in recorded] == list(range(1, len(truth) + 1)), summary
    assert all(r["status"] in ("done", "lost") for r in recorded), summary
    assert_masses_match(recorded, truth)
    complete = all(r["status"] == "done" for r in recorded)
    assert code == (0 if complete else 1), (code, summary)


# --- one run per rig and per context ---


def test_second_run_on_the_rig_or_the_context_is_refused_naming_the_first(
    rig_factory, db, tmp_path
):
    # paced, and the other rig's master made ready first: the first run must still be running
    # when the second is tried from there (as fast as it runs, the three sherds were recorded
    # before that master had started, once in CI)
    rig = rig_factory(archive=tmp_path / "archive", params={"/simulator/real_time_factor": 1.0})
    truth = ground_truth(rig)
    other = RosMaster()
    try:
        other.run(["rosparam", "load", os.path.join(WORKSPACE, "config", "rascal.yaml")])
        other.run(["rosparam", "set", "/rig/name", "sim-rig-2"])
        _both_locks_refused(rig, other, db, truth)
    finally:
        other.stop()


def _both_locks_refused(rig, other, db, truth):
    """While a run records F-LOCK on `rig`: a second run on that rig is refused by the rig lock,
    one from `other` (its own master) by the context lock; the first then finishes."""
    first = rascal(rig, "--dsn", db, "run", "--context", "F-LOCK")
    wait_until(lambda: rows(db, "F-LOCK"), 120, "the first run picking a sherd")

    # the same rig, another context: the rig lock
    t0 = time.monotonic()
    code, out = finish(rascal(rig, "--dsn", db, "run", "--context", "F-LOCK-2"), timeout=60)
    assert code == 4, out
    assert time.monotonic() - t0 < 20
    (line,) = error_lines(out)
    assert "rig sim-rig-1 is in use by another `rascal run`" in line, line
    assert "pid %d on host %s" % (first.pid, socket.gethostname()) in line, line
    assert "context F-LOCK" in line and "since " in line, line
    assert "F-LOCK-2" not in contexts(db)  # nothing written, nothing moved

    # the same context from another rig (its own master): the context lock
    r = subprocess.run(
        ["rosrun", "rascal_tasks", "rascal", "--dsn", db, "run", "--context", "F-LOCK"],
        env=other.env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 4, r.stdout + r.stderr
    (line,) = error_lines(r.stderr)
    assert "context F-LOCK is being recorded by another `rascal run`" in line, line
    assert "pid %d on host %s" % (first.pid, socket.gethostname()) in line, line
    assert "rig sim-rig-1" in line, line

    # the first run was not disturbed
    code, out = finish(first)
    assert code == 0, out[-3000:] + rig.tail()
    assert_each_sherd_once(rows(db, "F-LOCK"), truth)


# --- where the configuration and the database come from ---


def _config_from_the_parameter_server(rig, path, **changes):
    """The configuration the nodes run with (rosparam get /), with `changes` ("a.b": value)."""
    with open(os.path.join(WORKSPACE, "config", "rascal.yaml")) as f:
        sections = list(yaml.safe_load(f))
    server = yaml.safe_load(rig.run(["rosparam", "get", "/"]).stdout)
    cfg = {k: server[k] for k in sections if k in server}
    for key, value in changes.items():
        *parents, leaf = key.split(".")
        node = cfg
        for p in parents:
            node = node[p]
        node[leaf] = value
    path.write_text(yaml.safe_dump(cfg))
    return str(path)


def test_rascal_dsn_and_config_are_honoured(rig_factory, db, tmp_path):
    rig = rig_factory(archive=tmp_path / "archive", params={"/database/dsn": UNREACHABLE_DSN})

    # $RASCAL_DSN wins over the parameter server's database.dsn ...
    code, out = finish(
        rascal(rig, "run", "--context", "F-ENV", env={"RASCAL_DSN": UNREACHABLE_DSN + "2"}), 60
    )
    assert code == 3, out
    (line,) = error_lines(out)
    assert "nowhere2 (from RASCAL_DSN)" in line and "cannot connect" in line, line
    # ... and --dsn over $RASCAL_DSN
    code, out = finish(
        rascal(rig, "--dsn", UNREACHABLE_DSN + "3", "run", "--context", "F-ENV", env={}), 60
    )
    assert code == 3 and "nowhere3 (from --dsn)" in out, out

    # --config: its database.dsn and archive.root are used ...
    archive = tmp_path / "other_archive"
    cfg = _config_from_the_parameter_server(
        rig, tmp_path / "site.yaml", **{"database.dsn": db, "archive.root": str(archive)}
    )
    proc = rascal(rig, "--config", cfg, "run", "--context", "F-CFG")
    wait_until(lambda: rows(db, "F-CFG"), 120, "a run with --config picking a sherd")
    proc.send_signal(signal.SIGINT)
    code, out = finish(proc, 120)
    assert code == 130, out[-3000:]
    assert archive.is_dir()
    # ... and a key the nodes read must agree with the parameter server
    moved = _config_from_the_parameter_server(
        rig, tmp_path / "moved.yaml", **{"database.dsn": db, "stations.scale.position": [0.3, 0.02]}
    )
    code, out = finish(rascal(rig, "--config", moved, "run", "--context", "F-CFG"), 60)
    assert code == 2, out
    (line,) = error_lines(out)
    assert "stations.scale.position is [0.3, 0.02], but the parameter server" in line, line
    assert "rosparam load" in line, line


# --- what is missing at start ---


def test_no_master_is_one_line_within_seconds(tmp_path):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port, ROS_LOG_DIR=str(tmp_path))
    t0 = time.monotonic()
    r = subprocess.run(
        ["rosrun", "rascal_tasks", "rascal", "--dsn", UNREACHABLE_DSN, "run", "--context", "F-NM"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert time.monotonic() - t0 < 10
    assert r.returncode == 3, r.stderr
    assert r.stderr.strip() == (
        "error: no ROS master at http://127.0.0.1:%d; start roscore (and the rig's nodes) first"
        % port
    )


def test_arm_controller_not_started_is_named_within_the_deadline(rig_factory, db, tmp_path):
    rig = rig_factory(
        archive=tmp_path / "archive",
        params={"/rig/node_wait": 3.0},
        nodes=[n for n in NODES if n[1] != "arm_controller"],
        ready=("/sim/ground_truth", "/rascal/perception/detect"),
    )
    t0 = time.monotonic()
    code, out = finish(rascal(rig, "--dsn", db, "run", "--context", "F-NOARM"), 60)
    assert code == 3, out
    assert time.monotonic() - t0 < 3.0 + 15
    (line,) = error_lines(out)
    assert line.startswith("error: arm_controller not running: no /rascal/arm/move"), line
    assert line.endswith("start it with rosrun rascal_control arm_controller"), line
    assert "Traceback" not in out


# --- a bag that cannot be finished ---


def test_sherd_that_cannot_be_picked_up_ends_incomplete(rig_factory, db, tmp_path):
    with open(SMALL) as f:
        scenario = yaml.safe_load(f)
    # sherd_01 as it is, and a sherd far above the gripper's 0.25 kg working payload (a thick
    # slab of dense fabric, 30 mm): it slips out of the fingers nearly every time it is lifted
    heavy = {
        "name": "slab",
        "pose": [0.24, 0.27, 0.2],
        "length": 0.085,
        "width": 0.055,
        "thickness": 0.03,
        "density": 3000,
        "munsell": "5YR 5/4",
    }
    scenario["sherds"] = [scenario["sherds"][1], heavy]
    path = tmp_path / "unpickable.yaml"
    path.write_text(yaml.safe_dump(scenario))
    rig = rig_factory(scenario=str(path), archive=tmp_path / "archive")
    truth = ground_truth(rig)
    assert truth["slab"][2] > 0.25, truth
    code, out = finish(rascal(rig, "--dsn", db, "run", "--context", "F-LEFT"))
    assert code == 1, out[-3000:] + rig.tail()
    summary = [line for line in out.splitlines() if line.startswith("batch F-LEFT incomplete: ")]
    assert len(summary) == 1, out[-3000:]
    assert "left on the pickup mat" in summary[0] or "recorded lost" in summary[0], summary
    assert "a person must look" in summary[0], summary
    done = [r for r in rows(db, "F-LEFT") if r["status"] == "done"]
    assert any(abs(r["mass_g"] - truth["sherd_01"][2] * 1000) < 0.2 for r in done), done


# --- the database goes away mid-batch ---


def test_database_lost_mid_batch_is_waited_for_and_the_batch_finishes(rig_factory, db, tmp_path):
    rig = rig_factory(archive=tmp_path / "archive")
    truth = ground_truth(rig)
    proc = rascal(rig, "--dsn", db, "run", "--context", "F-DB")
    wait_until(
        lambda: any(r["status"] == "weighed" for r in rows(db, "F-DB")), 300, "a sherd weighed"
    )
    block_database(PG_ADMIN_DSN, db, allow=False)  # like a restart of PostgreSQL
    try:
        time.sleep(8.0)
    finally:
        block_database(PG_ADMIN_DSN, db, allow=True)
    code, out = finish(proc)
    assert code == 0, out[-3000:] + rig.tail()
    assert "database lost (" in out and "database back after" in out, out[-3000:]
    assert_each_sherd_once(rows(db, "F-DB"), truth)


def test_database_gone_for_longer_than_retry_for_exits_3(rig_factory, db, tmp_path):
    rig = rig_factory(archive=tmp_path / "archive", params={"/database/retry_for": 3.0})
    proc = rascal(rig, "--dsn", db, "run", "--context", "F-DB3")
    wait_until(lambda: rows(db, "F-DB3"), 300, "a sherd picked")
    block_database(PG_ADMIN_DSN, db, allow=False)
    try:
        code, out = finish(proc, 120)
    finally:
        block_database(PG_ADMIN_DSN, db, allow=True)
    assert code == 3, out[-3000:]
    (line,) = error_lines(out)
    assert "database: still unreachable after" in line and "--context F-DB3" in line, line
    # nothing recorded is lost: a rerun finishes the batch
    code, out = finish(rascal(rig, "--dsn", db, "run", "--context", "F-DB3"))
    assert code == 0, out[-3000:]
    assert [r["status"] for r in rows(db, "F-DB3")] == ["done"] * 3


# --- the archive checked against the catalogue ---


def test_verify_names_a_missing_sidecar_and_repair_rewrites_it(db, tmp_path):
    from rascal_tasks.catalogue import Catalogue, ImageArchive

    archive = ImageArchive(str(tmp_path / "archive"))
    cat = Catalogue.connect(db, rig="rig-1", config_hash="cafe")
    cat.open_context("F-V", "site")
    s = cat.new_sherd("F-V", pickup_xy=(0.1, 0.25))
    cat.record_mass(s["sherd_id"], 21.5)
    cat.archive_photo(s["sherd_id"], archive, b"\x89PNG\r\n\x1a\nX")
    cat.record_done(s["sherd_id"], archive=archive)
    cat.close()

    def verify(*args):
        return subprocess.run(
            ["rosrun", "rascal_tasks", "rascal", "--dsn", db, "verify", "--archive", archive.root]
            + list(args),
            capture_output=True,
            text=True,
            timeout=60,
        )

    r = verify()
    assert r.returncode == 0 and "matches the catalogue" in r.stdout, r.stdout + r.stderr
    (sidecar,) = (tmp_path / "archive" / "F-V").glob("*.json")
    sidecar.unlink()
    r = verify("--context", "F-V")
    assert r.returncode == 1, r.stdout + r.stderr
    assert "F-V-1: sidecar" in r.stdout and "is missing" in r.stdout, r.stdout
    r = verify("--context", "F-V", "--repair")
    assert r.returncode == 0 and "repaired: F-V-1: rewrote missing sidecar" in r.stdout, r.stdout
    assert sidecar.exists()
    r = verify("--context", "../x")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr


# --- nodes killed at random mid-batch ---

# About 20 s a run on the 2 cores this was written on; 32-75 s a run (45 s typical) on the
# slower machine of session 29. Each victim is killed twice, once in the first half of the
# batch's ~15 s and once in the second, in an order and at times drawn from the seed: a random
# draw of 12 victims (sessions 27-29) killed the simulator 6 times and the detector once, for
# more time than these 8 take. The test's own timeout leaves twice the typical run.
KILL_SEED = 13
VICTIMS = ("rascal", "sim", "arm_controller", "sherd_detector")
KILL_WINDOW = (0.5, 14.0)  # [s] of wall time after the run starts (a batch: ~15 s)
KILL_RUNS = 2 * len(VICTIMS)
SPAWN = (
    "import rospy, sys; from rascal_msgs.srv import SpawnScenario;"
    "rospy.wait_for_service('/sim/spawn', 10);"
    "r = rospy.ServiceProxy('/sim/spawn', SpawnScenario)('', sys.stdin.read());"
    "print([r.success, r.message])"
)
# The simulator's world and the arm's joints, polled while a batch runs: what the restarted
# simulator is given back when the simulator is the node that was killed.
WATCH = """
import json, os, rospy
from rascal_msgs.srv import GetGroundTruth
from sensor_msgs.msg import JointState
rospy.init_node('world_watch', anonymous=True)
rospy.wait_for_service('/sim/ground_truth', 10)
truth = rospy.ServiceProxy('/sim/ground_truth', GetGroundTruth, persistent=True)
joints = {}
rospy.Subscriber('/joint_states', JointState, lambda m: joints.update(zip(m.name, m.position)))
while not rospy.is_shutdown():
    try:
        r = truth()
    except Exception:
        break
    q = r.sherds
    doc = {'joints': dict(joints), 'sherds': [
        [s.name, s.pose.position.x, s.pose.position.y, s.pose.orientation.z, s.pose.orientation.w]
        for s in q]}
    with open(os.environ['WATCH_FILE'] + '.tmp', 'w') as f:
        json.dump(doc, f)
    os.replace(os.environ['WATCH_FILE'] + '.tmp', os.environ['WATCH_FILE'])
"""


def _restart(rig, name):
    """Start the node `name` of the rig again (it was killed) and wait until it serves."""
    pkg, exe = next(n for n in NODES if n[1] == name)
    i = next(i for i, p in enumerate(rig.procs) if p.args[-1] == exe)
    stop(rig.procs[i])
    node = rig.procs[i] = rig._spawn(exe, ["rosrun", pkg, exe])
    ready = {
        "sim": "/sim/ground_truth",
        "arm_controller": "/rascal/arm/compute_ik",
        "sherd_detector": "/rascal/perception/detect",
    }[name]
    deadline = time.monotonic() + 60
    while ready not in rig.run(["rosservice", "list"], check=False).stdout.split():
        assert node.poll() is None and time.monotonic() < deadline, (name, rig.tail())
        time.sleep(0.3)


def _node(rig, name):
    return next(p for p in rig.procs if p.args[-1] == name)


def _world_back(rig, scenario, watch_file):
    """After the simulator was killed: the sherds where they were (one held falls from where the
    fingers were) and the arm where it was (its servos hold their position when the driver
    dies), the world's last state as the watcher saw it; then the other nodes restarted. Killed
    before the watcher's first look (no file: each run starts without one), the world is as it
    was spawned (F-KILL-06, killed at 0.7 s, was given the world of the run before it, with two
    of its sherds in the discard box, and its rerun rightly recorded the one left on the mat)."""
    import json
    import math

    sherds = scenario["sherds"]  # as spawned, the arm at its initial joints (already set)
    if os.path.exists(watch_file):
        with open(watch_file) as f:
            last = json.load(f)
        by_name = {s["name"]: dict(s) for s in scenario["sherds"]}
        sherds = []
        for name, x, y, qz, qw in last["sherds"]:
            s = dict(by_name[name])
            s["pose"] = [x, y, 2.0 * math.atan2(qz, qw)]
            sherds.append(s)
        arm = ["waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate"]
        if all(j in last["joints"] for j in arm):
            rig.set_param("/simulator/initial_joints", [last["joints"][j] for j in arm])
    # the new simulator's clock starts again at 0: the nodes on simulated time start again too
    for name in ("sim", "arm_controller", "sherd_detector"):
        _restart(rig, name)
    doc = dict(scenario, sherds=sherds)
    return rig.run(["/usr/bin/python3", "-c", SPAWN], input=yaml.safe_dump(doc)).stdout


@pytest.mark.timeout(KILL_RUNS * 90)
def test_random_node_killed_mid_batch_then_rerun_records_each_sherd_once(rig_factory, db, tmp_path):
    """KILL_RUNS batches of small_3 at full simulator speed; in each a node is killed with
    SIGKILL at a random time (each node twice, early and late in the batch), the node is started
    again (the simulator with its world as it was) and `rascal run` rerun until it ends 0 or 1;
    the catalogue then holds every sherd of the scenario exactly once with its true mass
    (`assert_no_sherd_twice`)."""
    rng = random.Random(KILL_SEED)
    order = [(v, half) for v in VICTIMS for half in (0, 1)]
    rng.shuffle(order)
    with open(SMALL) as f:
        scenario = yaml.safe_load(f)
    rig = rig_factory(archive=tmp_path / "archive", params={"/simulator/real_time_factor": 0.0})
    initial_joints = yaml.safe_load(
        rig.run(["rosparam", "get", "/simulator/initial_joints"]).stdout
    )
    watch_file = str(tmp_path / "world.json")
    report = []
    t_start = time.monotonic()
    for run in range(KILL_RUNS):
        context = "F-KILL-%02d" % run
        if run:  # a fresh bag on the mat
            rig.set_param("/simulator/initial_joints", initial_joints)
            out = rig.run(["/usr/bin/python3", "-c", SPAWN], input=yaml.safe_dump(scenario))
            assert "True" in out.stdout, out.stdout + out.stderr
        truth = call(
            rig,
            "import rospy, json; from rascal_msgs.srv import GetGroundTruth;"
            "rospy.wait_for_service('/sim/ground_truth', 10);"
            "r = rospy.ServiceProxy('/sim/ground_truth', GetGroundTruth)();"
            "print(json.dumps({s.name: [s.pose.position.x, s.pose.position.y, s.mass]"
            " for s in r.sherds}))",
        )
        t_run = time.monotonic()
        if os.path.exists(watch_file):
            os.remove(watch_file)  # the run before's world is not this one's
        victim, half = order[run]
        lo, hi = KILL_WINDOW
        delay = rng.uniform(lo + half * (hi - lo) / 2, lo + (half + 1) * (hi - lo) / 2)
        watch = subprocess.Popen(
            ["/usr/bin/python3", "-c", WATCH],
            env=dict(rig.env, WATCH_FILE=watch_file),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        proc = rascal(rig, "--dsn", db, "run", "--context", context)
        time.sleep(delay)
        killed = proc.poll() is None
        if killed:
            target = proc if victim == "rascal" else _node(rig, victim)
            os.killpg(target.pid, signal.SIGKILL)
        stop(watch)
        t_kill = time.monotonic()
        try:  # a killed node: the run ends by itself, arm parked
            code, out = finish(proc, 120)
        except AssertionError as e:
            raise AssertionError("\n".join(report + [context, str(e), rig.tail(30)])) from None
        killed_out = out  # what the killed run said: a row it wrote may be why a rerun fails
        note = (
            "%s killed after %.1f s: exit %s %.1f s later"
            % (victim, delay, code, time.monotonic() - t_kill)
            if killed
            else "no kill"
        )
        if killed and victim != "rascal":
            assert code == 3, "\n".join(report + [context + ": " + note, out[-3000:]])
            if victim == "sim":
                _world_back(rig, scenario, watch_file)
            else:
                _restart(rig, victim)
        reruns = 0
        while code not in (0, 1):
            if reruns and "its last batch finished complete" in out:
                # `rascal` was killed after its batch was recorded finished, before it exited
                # (CI at c393eb1: killed at 13.9 s): the rerun rightly refuses that context
                code = 0
                break
            reruns += 1
            assert reruns <= 3, note + "\n" + out[-3000:] + rig.tail()
            try:
                code, out = finish(rascal(rig, "--dsn", db, "run", "--context", context), 240)
            except AssertionError as e:
                raise AssertionError(
                    "\n".join(report + [context + ": " + note, str(e), rig.tail(30)])
                ) from None
        report.append(
            "%s: %s, %d rerun(s), exit %d, %.0f s"
            % (context, note, reruns, code, time.monotonic() - t_run)
        )
        print(report[-1], flush=True)
        recorded = rows(db, context)
        try:
            assert_no_sherd_twice(recorded, truth, code)
        except AssertionError as e:
            raise AssertionError(
                "\n".join(report + [str(e), "killed run:", killed_out[-3000:], "last run:"])
                + "\n"
                + out[-3000:]
            ) from None
    print("\n".join(report))
    print("%d runs in %.0f s" % (KILL_RUNS, time.monotonic() - t_start))
