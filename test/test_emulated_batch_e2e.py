"""A whole batch on the field drivers: `rosrun rascal_drivers rig --emulated` (arm_driver on the
Dynamixel bus emulator, scale_driver on the MT-SICS scale emulator, both fed by the simulator)
runs `rascal run` as `make demo RIG=emulated` does. Every sherd of small_3 is recorded once,
each with the mass of a different true sherd within 0.2 g. Slow: the simulator runs behind the
emulators at about a quarter of real time."""

import json
import os
import signal
import subprocess

import pytest
from rig_helpers import SMALL, WORKSPACE, rows

pytestmark = pytest.mark.timeout(1200)

TRUTH = (
    "import rospy, json; from rascal_msgs.srv import GetGroundTruth;"
    "rospy.wait_for_service('/sim/ground_truth', 10);"
    "r = rospy.ServiceProxy('/sim/ground_truth', GetGroundTruth)();"
    "print(json.dumps({s.name: [s.pose.position.x, s.pose.position.y, s.mass]"
    " for s in r.sherds}))"
)


def test_an_emulated_batch_records_every_sherd_with_its_mass(tmp_path, pg_dsn):
    truth_file = tmp_path / "truth.json"
    # the truth is read before the batch moves anything, on the rig's own master
    command = '/usr/bin/python3 -c "%s" > %s && rosrun rascal_tasks rascal run --context %s' % (
        TRUTH,
        truth_file,
        "EMU-3",
    )
    env = dict(os.environ, RASCAL_DSN=pg_dsn, ROS_HOSTNAME="127.0.0.1", PYTHONUNBUFFERED="1")
    env.pop("ROS_IP", None)
    args = ["rosrun", "rascal_drivers", "rig", "--emulated", "--port", "0"]
    args += ["--log-dir", str(tmp_path / "log")]
    args += ["--set", "/simulator/scenario=" + SMALL]
    args += ["--set", "/archive/root=" + str(tmp_path / "archive")]
    rig = subprocess.Popen(
        [*args, "--", "bash", "-c", command],
        env=env,
        cwd=WORKSPACE,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    try:
        out = rig.communicate(timeout=1100)[0]
    except subprocess.TimeoutExpired:
        os.killpg(rig.pid, signal.SIGINT)
        out = rig.communicate(timeout=60)[0]
        raise AssertionError("the emulated batch did not end:\n" + out[-4000:]) from None
    finally:
        if rig.poll() is None:
            os.killpg(rig.pid, signal.SIGKILL)
    logs = {p.name: p.read_text()[-600:] for p in (tmp_path / "log").glob("*.log")}
    assert rig.returncode == 0, (out[-4000:], logs)
    assert out.strip().splitlines()[-1] == "rig: stopped", out[-2000:]
    truth = json.loads(truth_file.read_text())
    recorded = rows(pg_dsn, "EMU-3")
    assert [r["seq"] for r in recorded] == [1, 2, 3], out[-3000:]
    assert all(r["status"] == "done" for r in recorded), recorded
    left = dict(truth)
    for r in recorded:  # the nearest true sherd to where it was picked up, each once
        name = min(
            left,
            key=lambda n: (left[n][0] - r["pickup_x_m"]) ** 2 + (left[n][1] - r["pickup_y_m"]) ** 2,
        )
        assert abs(r["mass_g"] - left.pop(name)[2] * 1000) < 0.2, (r["seq"], name, r["mass_g"])
