"""Fixtures shared by every test tier (pytest loads this for all tests in the workspace).

- Core tests need none of these.
- Wiring tests use `ros_master` (a roscore on a free port, with its own ROS_LOG_DIR) and
  `rosrun` (start a node the way a user would; every process is stopped at teardown).
- Catalogue and end-to-end tests use `pg_dsn`: a throw-away database on the PostgreSQL server
  that `scripts/setup.sh` started.
"""

import os
import subprocess

import pytest

from rascal_tasks.sim_rig import RosMaster, stop

WORKSPACE = os.path.dirname(os.path.abspath(__file__))
CONFIG = os.path.join(WORKSPACE, "config", "rascal.yaml")
PG_ADMIN_DSN = os.environ.get(
    "RASCAL_TEST_PG_DSN", "postgresql://rascal:rascal@127.0.0.1:5432/rascal"
)


class Rosrun:
    """Starts nodes with `rosrun` (as on the field rig) and stops them all at teardown."""

    def __init__(self, master):
        self.master = master
        self.procs = []

    def __call__(self, package, executable, *args, env=None, **popen_kw):
        e = dict(self.master.env, **(env or {}))
        popen_kw.setdefault("stdout", subprocess.PIPE)
        popen_kw.setdefault("stderr", subprocess.STDOUT)
        proc = subprocess.Popen(
            ["rosrun", package, executable, *args],
            env=e,
            text=True,
            start_new_session=True,
            **popen_kw,
        )
        self.procs.append(proc)
        return proc

    def stop_all(self):
        for p in reversed(self.procs):
            stop(p)


@pytest.fixture(scope="session")
def ros_master_session():
    m = RosMaster()
    yield m
    m.stop()


@pytest.fixture
def ros_master(ros_master_session):
    """A running master; parameters are cleared between tests."""
    ros_master_session.run(["rosparam", "delete", "/"], check=False)
    yield ros_master_session


@pytest.fixture
def rosrun(ros_master):
    r = Rosrun(ros_master)
    yield r
    r.stop_all()


@pytest.fixture
def pg_dsn():
    """A fresh, empty database for one test; dropped afterwards."""
    pytest.importorskip("psycopg2")
    from rascal_tasks.catalogue.scratch import scratch_database

    with scratch_database(PG_ADMIN_DSN) as dsn:
        yield dsn
