"""`rascal rerecord FIND_ID` on the simulated rig (the simulator, arm_controller and
sherd_detector started with rosrun, PostgreSQL): a sherd recorded lost, put back alone on the
pickup mat, is picked, weighed and photographed into a row of its own, linked to the lost one."""

import os
import subprocess

import psycopg2
import pytest
import yaml
from rig_helpers import SMALL, ground_truth, rows

from rascal_tasks import exit_codes
from rascal_tasks.catalogue import Catalogue

pytestmark = pytest.mark.timeout(600)

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def one_sherd_scenario(tmp_path):
    """small_3 with only its first (generated) sherd on the mat: the sherd put back."""
    with open(SMALL) as f:
        scenario = yaml.safe_load(f)
    scenario["name"] = "rerecord_1"
    scenario["sherds"] = scenario["sherds"][:1]
    path = tmp_path / "rerecord_1.yaml"
    path.write_text(yaml.safe_dump(scenario))
    return str(path)


def test_a_lost_sherd_put_back_is_recorded_into_its_own_row(rig_factory, db, tmp_path):
    with open(os.path.join(WORKSPACE, "config", "rascal.yaml")) as f:
        site = yaml.safe_load(f)["rig"]["site"]
    cat = Catalogue.connect(db, rig="rig-1", config_hash="abc")
    cat.open_context("RR-1", site)
    lost = cat.new_sherd("RR-1", pickup_xy=(0.08, 0.25))["sherd_id"]
    cat.record_lost(lost, "not found where it was last seen (scale)")
    cat.close()

    rig = rig_factory(scenario=one_sherd_scenario(tmp_path), archive=tmp_path / "archive")
    truth = ground_truth(rig)
    proc = rig.rascal("--dsn", db, "rerecord", "RR-1-1", "--who", "anna")
    try:
        out, _ = proc.communicate(timeout=500)
    except subprocess.TimeoutExpired:
        proc.kill()
        raise AssertionError("rerecord did not end:\n%s" % rig.tail()) from None
    assert proc.returncode == exit_codes.COMPLETE, out[-3000:] + rig.tail()
    assert "RR-1-1 re-recorded as RR-1-2 (done)" in out

    recorded = rows(db, "RR-1")
    assert [(r["seq"], r["status"]) for r in recorded] == [(1, "lost"), (2, "done")]
    assert recorded[0]["lost_reason"] == "not found where it was last seen (scale)"  # unchanged
    (mass_kg,) = [t[2] for t in truth.values()]
    assert abs(recorded[1]["mass_g"] - mass_kg * 1000) < 0.2
    assert recorded[1]["image_path"] and os.path.isfile(
        os.path.join(tmp_path, "archive", recorded[1]["image_path"])
    )
    conn = psycopg2.connect(db)
    try:
        with conn, conn.cursor() as cur:
            cur.execute("SELECT lost_sherd_id, new_sherd_id, who FROM sherd_rerecords")
            assert cur.fetchall() == [(lost, recorded[1]["sherd_id"], "anna")]
    finally:
        conn.close()
