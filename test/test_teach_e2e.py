"""End-to-end test of teaching by demonstration (issue 17 item 6): `rascal teach discard` jogs the
simulated arm with commands on its standard input and saves the measured place into a copy of
the site file; a batch run with that file's taught place drops every sherd there. A real master,
the simulator, arm controller and detector started with rosrun, real PostgreSQL.
"""

import math
import os
import shutil
import subprocess

import pytest
import yaml
from rig_helpers import ground_truth, joint_positions, run_batch

from rascal_tasks import exit_codes

pytestmark = pytest.mark.timeout(900)

SHIPPED = os.path.join(
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "config", "rascal.yaml"
)
SLEEP = [0.0, -1.80, 1.55, 0.0, 0.8, 0.0]
CENTRE = (0.02, -0.31)  # the shipped discard box
JOGS = "x-30\ny-25\nx+500\nyaw+90\nshow\nsave\n"  # x+500 leaves the box: refused, ignored
TAUGHT = (CENTRE[0] - 0.030, CENTRE[1] - 0.025, math.radians(90))


def test_a_taught_place_is_saved_measured_and_used_by_the_next_batch(rig_factory, db, tmp_path):
    site = tmp_path / "rascal.yaml"
    shutil.copy(SHIPPED, site)
    rig = rig_factory(archive=tmp_path / "archive")
    proc = rig.rascal("--config", str(site), "teach", "discard", stdin=subprocess.PIPE)
    out, _ = proc.communicate(JOGS, timeout=300)
    assert proc.returncode == exit_codes.COMPLETE, out + rig.tail()
    assert "refused: x+500: would leave the station" in out, out
    assert (tmp_path / "rascal.yaml.bak").read_text() == open(SHIPPED).read()
    x, y, yaw = yaml.safe_load(site.read_text())["stations"]["discard"]["taught_place"]
    assert math.hypot(x - TAUGHT[0], y - TAUGHT[1]) <= 0.002, (x, y, out)
    assert abs(yaw - TAUGHT[2]) <= math.radians(1.0), (yaw, out)
    assert all(abs(a - b) < 0.05 for a, b in zip(joint_positions(rig), SLEEP, strict=True))

    rig.set_param("/stations/discard/taught_place", [x, y, yaw])
    code, out = run_batch(rig, db, "TEACH-3")
    assert code == exit_codes.COMPLETE, out[-3000:] + rig.tail()
    for name, (sx, sy, _) in ground_truth(rig).items():
        # dropped from travel height into the box: nearer the taught place than the centre
        taught, centre = math.hypot(sx - x, sy - y), math.hypot(sx - CENTRE[0], sy - CENTRE[1])
        assert taught < centre, (name, sx, sy)
