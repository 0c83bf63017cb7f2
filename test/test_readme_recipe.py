"""The README's "Running on the rig" recipe, as a user copies it: its code block is read from
README.md, its order checked, and everything before the first node (master, wait, parameters,
check_config, `rascal db migrate`) run in bash against a real roscore and a fresh PostgreSQL
database. The one change: `roscore` gets a free port (-p), so the test never meets another
master on 11311."""

import os
import re
import signal
import subprocess
import tempfile

import psycopg2
import pytest

from rascal_tasks.sim_rig import free_port

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
README = os.path.join(WORKSPACE, "README.md")

pytestmark = pytest.mark.timeout(180)


def recipe():
    """The lines of the first code block under '## Running on the rig'."""
    with open(README, encoding="utf-8") as f:
        text = f.read()
    section = text.split("## Running on the rig", 1)[1].split("\n## ", 1)[0]
    block = re.search(r"^```\n(.*?)^```", section, re.S | re.M)
    assert block, "no code block under 'Running on the rig'"
    return [line for line in block.group(1).splitlines() if line.strip()]


def _index(lines, pattern):
    hits = [i for i, line in enumerate(lines) if re.search(pattern, line)]
    assert hits, "the recipe has no line matching %r" % pattern
    return hits[0]


def test_recipe_is_in_order_and_copyable():
    lines = recipe()
    order = [
        r"^source devel/setup\.bash",
        r"^roscore &",
        r"until rostopic list",
        r"^rosparam load config/rascal\.yaml",
        r"^rosparam set /use_sim_time true",
        r"^rosrun rascal_tasks check_config",
        r"^rosrun rascal_tasks rascal db migrate",
        r"^rosrun rascal_sim sim",
        r"^rosrun rascal_tasks rascal run --context",
    ]
    at = [_index(lines, p) for p in order]
    assert at == sorted(at), list(zip(order, at, strict=True))
    assert "timeout" in lines[at[2]]  # the wait has a deadline
    for line in lines:
        command = line.split("  #", 1)[0].strip()
        assert not re.search(r"<[\w-]+>", command), "a placeholder to fill in: " + line
        if command.startswith("rosrun") and not command.startswith("rosrun rascal_tasks"):
            assert command.endswith("&"), "a node must run in the background: " + line
    assert lines[-1].startswith("rosrun rascal_tasks rascal run"), lines[-1]
    with open(README, encoding="utf-8") as f:  # nothing left outside the block to copy
        assert "In simulation also" not in f.read()


def test_recipe_up_to_the_nodes_runs_against_a_real_master_and_database(pg_dsn):
    lines = recipe()
    first_node = _index(lines, r"^rosrun rascal_sim sim")
    port = free_port()
    script = ["set -e"] + [
        line.replace("roscore &", "roscore -p %d >/dev/null 2>&1 &" % port)
        for line in lines[:first_node]
    ]
    logs = tempfile.mkdtemp(prefix="rascal_recipe_")
    env = dict(
        os.environ,
        ROS_MASTER_URI="http://127.0.0.1:%d" % port,
        ROS_HOSTNAME="127.0.0.1",
        ROS_LOG_DIR=logs,
        ROS_HOME=logs,
        RASCAL_DSN=pg_dsn,
    )
    env.pop("ROS_IP", None)
    proc = subprocess.Popen(
        ["bash", "-c", "\n".join(script)],
        cwd=WORKSPACE,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # roscore is in this group: stopped with it below
    )
    try:
        out, _ = proc.communicate(timeout=150)
        assert proc.returncode == 0, out
        get = subprocess.run(
            ["rosparam", "get", "/use_sim_time"], env=env, capture_output=True, text=True
        )
        assert get.stdout.strip() == "true", get.stdout + get.stderr
        get = subprocess.run(
            ["rosparam", "get", "/archive/root"], env=env, capture_output=True, text=True
        )
        assert get.stdout.strip() == "var/archive", get.stdout + get.stderr
    finally:
        try:
            os.killpg(proc.pid, signal.SIGINT)
        except ProcessLookupError:
            pass
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
    assert "applied migration 0001_initial.sql" in out, out
    with psycopg2.connect(pg_dsn) as conn, conn.cursor() as cur:
        cur.execute("SELECT count(*) FROM schema_migrations")
        assert cur.fetchone()[0] >= 6
