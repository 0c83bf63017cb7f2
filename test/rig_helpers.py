"""Helpers of the end-to-end tests: the simulated rig (rascal_tasks.sim_rig) on the test's
master, the catalogue, and the simulator's test-only services."""

import os
import signal
import subprocess
import time

import psycopg2
import psycopg2.extras
import yaml

from rascal_tasks.sim_rig import SimRig

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENARIOS = os.path.join(WORKSPACE, "config", "scenarios")
SMALL = os.path.join(SCENARIOS, "small_3.yaml")  # three sherds, one of them the scanned fragment


def start_rig(ros_master, scenario, archive, params=None, **kw):
    """The simulated rig on the test's master; `kw` goes to SimRig (nodes=, ready=)."""
    params = dict({"/archive/root": str(archive)}, **(params or {}))
    return SimRig(
        scenario=scenario,
        params=params,
        master_env=ros_master.env,
        log_dir=ros_master.log_dir,
        **kw,
    )


def run_batch(rig, dsn, context, timeout=800):
    """`rascal run --context` to its end: (exit code, output). A batch that has not ended
    after `timeout` seconds is interrupted and the test fails with its output."""
    proc = rig.rascal("--dsn", dsn, "run", "--context", context)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=60)
        raise AssertionError("batch did not finish:\n%s\n%s" % (out[-3000:], rig.tail())) from None
    return proc.returncode, out


def rascal(rig, *args, env=None):
    """Start `rosrun rascal_tasks rascal ARGS...` against `rig` with extra environment `env`
    (stdout and stderr together, text); the rig stops it at teardown."""
    proc = subprocess.Popen(
        ["rosrun", "rascal_tasks", "rascal", *args],
        env=dict(rig.env, **(env or {})),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
        cwd=rig.ws,
    )
    rig.clients.append(proc)
    return proc


def wait_until(predicate, timeout, what, poll=0.2):
    """Poll `predicate()` until it is true; AssertionError naming `what` after `timeout` s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return
        time.sleep(poll)
    raise AssertionError("%s: not within %.0f s" % (what, timeout))


def database_name(dsn):
    return dsn.rsplit("/", 1)[1]


def block_database(admin_dsn, dsn, allow):
    """`allow=False`: refuse new connections to the database of `dsn` and end the ones it has
    (what a restart of PostgreSQL does to a client, without stopping the server other tests
    share); `allow=True`: accept connections again. Run from a connection to `admin_dsn`."""
    name = database_name(dsn)
    admin = psycopg2.connect(admin_dsn)
    admin.autocommit = True
    try:
        with admin.cursor() as cur:
            # a generated test database's name, never user input
            cur.execute(
                "ALTER DATABASE %s ALLOW_CONNECTIONS %s" % (name, "true" if allow else "false")
            )
            if not allow:
                cur.execute(
                    "SELECT pg_terminate_backend(pid) FROM pg_stat_activity "
                    "WHERE datname = %s AND pid <> pg_backend_pid()"
                    " AND backend_type = 'client backend'",
                    (name,),
                )
    finally:
        admin.close()


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


def run_until(rig, db, context, reached, what, timeout=600):
    """`rascal run --context CONTEXT` started; returned, still running, as soon as
    `reached(rows of CONTEXT)` is true (polled every 50 ms)."""
    proc = rig.rascal("--dsn", db, "run", "--context", context)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        if reached(rows(db, context)):
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the batch ended before %s" % what
    return proc


def run_until_weighed(rig, db, context, timeout=600):
    """`rascal run --context CONTEXT` started; returned, still running, as soon as its first sherd
    is recorded weighed (it then lies on the scale, or is being lifted off it)."""
    return run_until(
        rig,
        db,
        context,
        lambda recorded: any(r["status"] == "weighed" for r in recorded),
        "a sherd was weighed",
        timeout,
    )


def call(rig, code):
    """Run a few lines of rospy against the rig; returns what they print, as YAML."""
    return yaml.safe_load(rig.run(["/usr/bin/python3", "-c", code]).stdout)


def picked_sherd(truth, row) -> str:
    """The scenario sherd (a name of `ground_truth`'s answer taken before the batch) that the
    catalogue row was picked up as: the nearest to where the row says it was picked."""
    return min(
        truth,
        key=lambda n: (truth[n][0] - row["pickup_x_m"]) ** 2
        + (truth[n][1] - row["pickup_y_m"]) ** 2,
    )


def assert_masses_match(recorded, truth, tolerance_g=0.2):
    """Every recorded mass (rows without one are skipped) is within `tolerance_g` of a different
    scenario sherd's true mass (`ground_truth`'s answer). Matched one to one as a whole, not
    greedily: two sherds 0.1 g apart would otherwise be paired crosswise (CI at 3b5372f: a row
    of 20.57 g taken by the 20.68 g sherd's twin left with 20.78 g)."""
    masses = [(r["seq"], r["mass_g"]) for r in recorded if r["mass_g"] is not None]
    owner = {}  # sherd name -> index into masses

    def place(i, seen):  # Kuhn's augmenting path: the sherds are few
        for name, (_x, _y, kg) in truth.items():
            if name in seen or abs(kg * 1000 - masses[i][1]) >= tolerance_g:
                continue
            seen.add(name)
            if name not in owner or place(owner[name], seen):
                owner[name] = i
                return True
        return False

    unmatched = [masses[i] for i in range(len(masses)) if not place(i, set())]
    assert not unmatched, (
        "recorded (seq, g) with no sherd of their own within %.1f g: %s; truth %s"
        % (tolerance_g, unmatched, {n: round(t[2] * 1000, 2) for n, t in truth.items()})
    )


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
