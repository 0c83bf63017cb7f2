"""Fixtures of the whole-rig tests in this folder (the workspace's conftest.py holds the
master and the database): `db`, a migrated throw-away catalogue, and `rig_factory`, which
starts the simulator, arm_controller and sherd_detector with rosrun (rig_helpers.start_rig)
and stops every rig it started. A failed test's report ends with each rig's node output
(the simulator's grasp and miss lines, the controller's warnings: what the batch's output
cannot say)."""

import pytest
from rig_helpers import SMALL, migrate, start_rig


@pytest.fixture
def db(pg_dsn):
    migrate(pg_dsn)
    return pg_dsn


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    report = (yield).get_result()
    if report.when == "call" and report.failed:
        for r in getattr(item, "rascal_rigs", []):
            report.sections.append(("rig " + r.log_dir, r.tail(40)))


@pytest.fixture
def rig_factory(ros_master, request):
    rigs = request.node.rascal_rigs = []

    def make(scenario=SMALL, archive=None, params=None, **kw):
        rigs.append(start_rig(ros_master, scenario, archive, params, **kw))
        return rigs[-1]

    yield make
    for r in rigs:
        r.stop()
