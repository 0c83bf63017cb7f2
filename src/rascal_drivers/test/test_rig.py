"""The one start command, `rosrun rascal_drivers rig`, as an operator runs it: the field rig on
device emulators (servo bus and scale on pseudo-terminals, an image sequence for the archival
camera, a D435 recording), started in order and stopped by Ctrl-C; a missing device stops the
start with the driver's own line; a master already running is named. Each test checks that
nothing it started is left running (the master's port is closed again)."""

import os
import re
import signal
import socket
import subprocess
import time

import cv2
import numpy as np
import pytest

from rascal_drivers import d435_emulator, workspace_venv
from rascal_drivers.scale_emulator import ScaleEmulator
from rascal_drivers.servo_bus_emulator import ServoBusEmulator, wx250s_servos

workspace_venv.add()
rs = pytest.importorskip("pyrealsense2")


def port_open(port):
    with socket.socket() as s:
        s.settimeout(0.5)
        return s.connect_ex(("127.0.0.1", port)) == 0


def ignoring_sigint():
    # as a shell starts a background job (`cmd &`, a CI run): SIGINT ignored, inherited by
    # every node, and Python then installs no KeyboardInterrupt; Ctrl-C must still stop it all
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def start_rig(tmp_path, env, *sets, port="0"):
    args = ["rosrun", "rascal_drivers", "rig", "--port", port, "--log-dir", str(tmp_path / "log")]
    for item in sets:
        args += ["--set", item]
    return subprocess.Popen(
        args,
        env=dict(env, ROS_HOME=str(tmp_path / "ros_home")),  # what the nodes keep stays the test's
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
        preexec_fn=ignoring_sigint,
    )


def read_until(proc, marker, timeout):
    lines, deadline = [], time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        lines.append(line.rstrip("\n"))
        if marker in line:
            return lines
    return lines


def rig_env(pg_dsn):
    env = dict(os.environ, RASCAL_DSN=pg_dsn, ROS_HOSTNAME="127.0.0.1", PYTHONUNBUFFERED="1")
    env.pop("ROS_IP", None)
    return env


def master_port(lines):
    for line in lines:
        m = re.search(r"master up at http://127.0.0.1:(\d+)", line)
        if m:
            return int(m.group(1))
    return None


def test_the_field_rig_starts_in_order_on_the_emulators_and_stops_on_ctrl_c(tmp_path, pg_dsn):
    frames = tmp_path / "frames"
    frames.mkdir()
    for i in range(2):
        cv2.imwrite(str(frames / ("f_%03d.png" % i)), np.full((480, 640, 3), 60 * i, np.uint8))
    recording = str(tmp_path / "wrist.db3")
    d435_emulator.record(recording, [d435_emulator.mat_with_sherd()] * 4, rs)
    bus = ServoBusEmulator(wx250s_servos(), link=str(tmp_path / "ttyDXL")).start()
    scale = ScaleEmulator("mt_sics", link=str(tmp_path / "ttyScale")).start()
    rig = None
    try:
        rig = start_rig(
            tmp_path,
            rig_env(pg_dsn),
            "/drivers/arm/device=" + bus.link,
            # the emulators' threads share this test process: on a machine loaded by other work
            # a reply can come later than the rig's 0.2 s without the bus being lost
            "/drivers/arm/bus_timeout=1.0",
            "/drivers/scale/device=" + scale.link,
            "/drivers/archival_camera/kind=opencv",
            "/drivers/archival_camera/device=" + str(frames / "f_%03d.png"),
            "/drivers/wrist_camera/source=" + recording,
        )
        lines = read_until(rig, "rig: Ctrl-C stops everything", 150)
        text = "\n".join(lines)
        assert len(lines) > 1 and lines[-2].startswith("rig: ready (field devices)"), text
        order = [ln.split()[1] for ln in lines if ln.endswith(" up") and "master" not in ln]
        assert order == [
            "arm_driver",
            "scale_driver",
            "archival_camera_driver",
            "wrist_camera_driver",
            "arm_controller",
            "sherd_detector",
        ], text
        port = master_port(lines)
        log = tmp_path / "log" / "arm_driver.log"
        assert bus.servos[1].get("torque_enable") == 1, log.read_text()  # the driver holds it
        os.killpg(rig.pid, signal.SIGINT)  # Ctrl-C in the rig's terminal
        rest = rig.communicate(timeout=60)[0]
        logs = {p.name: p.read_text()[-300:] for p in (tmp_path / "log").glob("*.log")}
        assert rig.returncode == 0, (rest, logs)
        assert rest.strip().splitlines()[-1] == "rig: stopped", rest
        assert all(bus.servos[i].get("torque_enable") == 0 for i in range(1, 10))
        assert "torque off on every servo" in log.read_text()
        assert not port_open(port)
    finally:
        if rig is not None and rig.poll() is None:
            os.killpg(rig.pid, signal.SIGKILL)
        bus.stop()
        scale.stop()


def test_a_missing_device_stops_the_start_with_the_drivers_line(tmp_path, pg_dsn):
    rig = start_rig(tmp_path, rig_env(pg_dsn), "/drivers/arm/device=" + str(tmp_path / "none"))
    out = rig.communicate(timeout=90)[0]
    assert rig.returncode == 3, out
    lines = out.strip().splitlines()
    error = [ln for ln in lines if ln.startswith("rig: error:")]
    assert len(error) == 1, out
    assert "arm_driver exited (1) while starting: arm_driver: drivers.arm.device:" in error[0]
    assert "does not exist; plug in the U2D2" in error[0]
    assert lines[-1] == "rig: stopped"
    assert not port_open(master_port(lines))


def test_a_master_already_running_is_named(ros_master, tmp_path):
    rig = start_rig(tmp_path, dict(os.environ), port=str(ros_master.port))
    out = rig.communicate(timeout=30)[0]
    assert rig.returncode == 3, out
    assert "a ROS master already runs at http://127.0.0.1:%d" % ros_master.port in out
    assert port_open(ros_master.port)  # someone else's master is left alone
