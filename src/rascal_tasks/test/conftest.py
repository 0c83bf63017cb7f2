"""Test set-up for rascal_tasks: makes `import rascal_tasks` work without sourcing a catkin
devel space, and gives the smach tests a log-capturing fixture."""

import os
import sys

import pytest
from catalogue_helpers import FakeClock

_SRC = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "src")
try:
    import rascal_tasks  # noqa: F401
except ImportError:
    sys.path.insert(0, _SRC)


class LogCapture:
    def __init__(self):
        self.records = []

    def make(self, level):
        return lambda msg: self.records.append((level, str(msg)))

    def lines(self, level):
        return [m for lv, m in self.records if lv == level]


@pytest.fixture
def logs():
    """Captures the core's log lines; restores the default loggers and shutdown hook after."""
    from rascal_tasks import smach

    cap = LogCapture()
    smach.set_loggers(cap.make("info"), cap.make("warn"), cap.make("debug"), cap.make("error"))
    yield cap
    smach.set_loggers(
        smach.log.__dict__["_default_info"],
        smach.log.__dict__["_default_warn"],
        smach.log.__dict__["_default_debug"],
        smach.log.__dict__["_default_error"],
    )
    smach.set_shutdown_check(lambda: False)


# --- catalogue fixtures (use the root conftest's `pg_dsn`: a fresh database per test) ---


@pytest.fixture
def migrated_dsn(pg_dsn):
    import psycopg2

    from rascal_tasks.catalogue import migrate

    conn = psycopg2.connect(pg_dsn)
    migrate(conn)
    conn.close()
    return pg_dsn


@pytest.fixture
def catalogue(migrated_dsn):
    from rascal_tasks.catalogue import Catalogue

    cat = Catalogue.connect(migrated_dsn, rig="test-rig", config_hash="cafe0123", clock=FakeClock())
    yield cat
    cat.close()
