"""A whole batch on the field drivers: `rosrun rascal_drivers rig --emulated` (arm_driver on the
Dynamixel bus emulator, scale_driver on the MT-SICS scale emulator, wrist_camera_driver on
librealsense's software device, archival_camera_driver on the emulated DSLR, all fed by the
simulator) runs `rascal run` as `make demo RIG=emulated` does, is interrupted with SIGINT
(Ctrl-C) once a sherd lies weighed, parks the arm, and a second `rascal run` finishes the
batch: every sherd of small_3 recorded once, numbered 1-3, each with the mass of a different
true sherd within 0.2 g. Slow: the simulator runs behind the emulators at about a quarter of
real time."""

import json
import os
import signal
import subprocess

import pytest
from rig_helpers import SMALL, WORKSPACE, rows

from rascal_tasks import exit_codes

pytestmark = pytest.mark.timeout(1200)

TRUTH = (
    "import rospy, json; from rascal_msgs.srv import GetGroundTruth;"
    "rospy.wait_for_service('/sim/ground_truth', 10);"
    "r = rospy.ServiceProxy('/sim/ground_truth', GetGroundTruth)();"
    "print(json.dumps({s.name: [s.pose.position.x, s.pose.position.y, s.mass]"
    " for s in r.sherds}))"
)


INTERRUPT = os.path.join(WORKSPACE, "test", "emulated_interrupt.py")
SLEEP = [0.0, -1.80, 1.55, 0.0, 0.8, 0.0]  # arm.named_poses.sleep of config/rascal.yaml
ARM = ("waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate")


def test_an_emulated_batch_interrupted_and_resumed_records_every_sherd_once(tmp_path, pg_dsn):
    truth_file, result_file = tmp_path / "truth.json", tmp_path / "result.json"
    # the truth is read before the batch moves anything, on the rig's own master
    command = '/usr/bin/python3 -c "%s" > %s && /usr/bin/python3 %s %s > %s' % (
        TRUTH,
        truth_file,
        INTERRUPT,
        "EMU-3",
        result_file,
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
    # the cameras were the field drivers, on the emulated devices
    wrist, dslr = (
        (tmp_path / "log" / n).read_text()
        for n in ("wrist_camera_driver.log", "archival_camera_driver.log")
    )
    assert "started: emulated:/emulated" in wrist, logs
    assert "started: gphoto2 emulated:/emulated" in dslr, logs
    result = json.loads(result_file.read_text())
    tails = (result["first_tail"], result["second_tail"])
    # Ctrl-C mid-batch: a sherd weighed, the arm parked, nothing recorded lost
    assert "weighed" in result["statuses_at_interrupt"], result
    assert result["first_code"] == exit_codes.INTERRUPTED, tails
    parked = [result["joints"][j] for j in ARM]
    assert max(abs(a - b) for a, b in zip(parked, SLEEP, strict=True)) < 0.05, parked
    assert result["second_code"] == exit_codes.COMPLETE, tails
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
