"""`rascal doctor` against the device emulators (servo bus and scale on pseudo-terminals, an
image sequence for OpenCV, a recording of librealsense's software device) and with devices
missing. The CLI tests run `rosrun rascal_tasks rascal doctor` as an operator would (no master:
the doctor runs before the rig is started)."""

import os
import subprocess

import cv2
import numpy as np
import pytest
import yaml

from rascal_drivers import control_table as ct
from rascal_drivers import d435_emulator, doctor, workspace_venv
from rascal_drivers.parameters import read_section
from rascal_drivers.scale_emulator import ScaleEmulator
from rascal_drivers.servo_bus_emulator import EmulatedServo, ServoBusEmulator, wx250s_servos

workspace_venv.add()
rs = pytest.importorskip("pyrealsense2")

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
CONFIG = os.path.join(WORKSPACE, "config", "rascal.yaml")


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = str(tmp_path_factory.mktemp("d435") / "wrist.db3")
    d435_emulator.record(path, [d435_emulator.mat_with_sherd()] * 4, rs)
    return path


def image_sequence(folder):
    for i in range(3):
        image = np.full((480, 640, 3), 40 * i, np.uint8)
        cv2.imwrite(os.path.join(folder, "frame_%03d.png" % i), image)
    return os.path.join(folder, "frame_%03d.png")


def site_config(tmp_path, drivers):
    """config/rascal.yaml with `drivers` merged in, written beside a config/ folder."""
    with open(CONFIG, encoding="utf-8") as f:
        data = yaml.safe_load(f)
    for device, values in drivers.items():
        data["drivers"][device].update(values)
    (tmp_path / "config").mkdir(exist_ok=True)
    path = tmp_path / "config" / "rascal.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return str(path)


def doctor_cli(config, *args):
    env = dict(os.environ)
    env.pop("ROS_MASTER_URI", None)  # the doctor needs no master
    return subprocess.run(
        ["rosrun", "rascal_tasks", "rascal", "--config", config, "doctor", *args],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    )


def section(which, **values):
    return read_section(values, "drivers." + which)


def test_every_emulated_device_passes(tmp_path, recording):
    bus = ServoBusEmulator(wx250s_servos(), link=str(tmp_path / "ttyDXL")).start()
    scale = ScaleEmulator("a_and_d", link=str(tmp_path / "ttyScale")).start()
    try:
        scale.put(0.0252)
        config = site_config(
            tmp_path,
            {
                "arm": {"device": bus.link},
                "scale": {"device": scale.link, "protocol": "a_and_d"},
                "archival_camera": {"kind": "opencv", "device": image_sequence(str(tmp_path))},
                "wrist_camera": {"source": recording},
            },
        )
        res = doctor_cli(config)
    finally:
        bus.stop()
        scale.stop()
    lines = res.stdout.strip().splitlines()
    assert res.returncode == 0, res.stdout + res.stderr
    assert all(ln.startswith("ok ") for ln in lines[:-1]), res.stdout
    text = res.stdout
    assert "servo 9 (gripper): XL430-W250, firmware v46, torque off" in text
    assert "all 9 servos answer at 1000000 baud" in text
    assert "stable at 25.2 g" in text
    assert "answers, 640x480 px" in text and "colour 640x480 and depth" in text
    assert lines[-1].startswith("doctor: every device answers (16 checks")


def test_missing_devices_each_give_one_line_with_a_fix(tmp_path):
    config = site_config(
        tmp_path,
        {
            "arm": {"device": str(tmp_path / "ttyDXL")},
            "scale": {"device": str(tmp_path / "ttyScale")},
            "archival_camera": {"kind": "opencv", "device": "/dev/video_rascal_missing"},
            "wrist_camera": {"source": "usb"},
        },
    )
    res = doctor_cli(config)
    assert res.returncode == 3, res.stdout + res.stderr
    lines = res.stdout.strip().splitlines()
    assert len(lines) == 5, res.stdout  # one per device, then the summary
    for line, device in zip(lines, doctor.DEVICES, strict=False):
        assert line.startswith("FAIL") and device in line and "; fix: " in line, line
    assert "ttyDXL does not exist; fix: plug the U2D2" in lines[0]
    assert "/dev/ttyScale" in lines[1]
    assert "no RealSense camera on USB" in lines[3]
    assert lines[-1].startswith("doctor: 4 of 4 checks failed")
    # the DSLR (kind gphoto2, the default): libgphoto2 finds none on this machine
    dslr_config = site_config(tmp_path, {"archival_camera": {"kind": "gphoto2"}})
    res = doctor_cli(dslr_config, "--device", "archival_camera")
    assert res.returncode == 3, res.stdout + res.stderr
    dslr = res.stdout.strip().splitlines()[0]
    assert dslr.startswith("FAIL  archival_camera  DSLR: no DSLR found by libgphoto2"), dslr
    assert "drivers.archival_camera.kind: opencv" in dslr


def test_a_bad_config_is_one_line_and_exit_2(tmp_path):
    config = site_config(tmp_path, {"scale": {"protocol": "sartorius"}})
    res = doctor_cli(config)
    assert res.returncode == 2, res.stdout + res.stderr
    assert "drivers.scale.protocol" in res.stderr and len(res.stderr.strip().splitlines()) == 1


def test_servo_faults_missing_ids_and_torque_are_named(tmp_path):
    servos = [s for s in wx250s_servos() if s.dxl_id != 7]  # wrist_angle renumbered to 17
    servos.append(EmulatedServo(17, ct.XM430_W350))
    servos[0].set("torque_enable", 1)
    bus = ServoBusEmulator(servos, link=str(tmp_path / "ttyDXL")).start()
    try:
        bus.servos[4].inject_hardware_error(5)  # the elbow overloaded
        items = doctor.check_arm(section("arm", device=bus.link, connect_timeout=0.3))
    finally:
        bus.stop()
    by_what = {i.what: i for i in items}
    assert (
        by_what["servo 1 (waist)"].status == "ok"
        and "torque on" in by_what["servo 1 (waist)"].detail
    )
    elbow = by_what["servo 4 (elbow)"]
    assert elbow.status == "FAIL" and "hardware error: overload" in elbow.detail
    assert "power off" in elbow.fix
    wrist = by_what["servo 7 (wrist_angle)"]
    assert wrist.status == "FAIL" and "does not answer a ping" in wrist.detail
    assert "a servo answers as ID 17" in wrist.fix and "drivers.arm.ids" in wrist.fix
    assert "servo bus" not in by_what  # the all-present line only when all nine answer


def test_a_wrong_model_and_a_silent_bus_are_named(tmp_path):
    servos = wx250s_servos()
    servos[8] = EmulatedServo(9, ct.XM430_W350)  # an XM where the gripper's XL430 belongs
    bus = ServoBusEmulator(servos, link=str(tmp_path / "ttyDXL")).start()
    try:
        items = doctor.check_arm(section("arm", device=bus.link, connect_timeout=0.3))
        gripper = [i for i in items if i.what == "servo 9 (gripper)"][0]
        assert gripper.status == "FAIL" and "expected XL430-W250" in gripper.detail
        items = doctor.check_arm(
            section(
                "arm",
                device=bus.link,
                ids=[11, 12, 13, 14, 15, 16, 17, 18, 19],
                connect_timeout=0.3,
            )
        )
    finally:
        bus.stop()
    last = items[-1]
    assert last.status == "FAIL" and "none of IDs 11,12" in last.detail and "12 V" in last.fix


def test_the_scale_in_the_wrong_protocol_silent_or_unsteady(tmp_path, monkeypatch):
    scale = ScaleEmulator("a_and_d", link=str(tmp_path / "ttyScale")).start()
    try:
        cfg = section("scale", device=scale.link, protocol="mt_sics", disconnect_timeout=0.5)
        answering = doctor.check_scale(cfg)[-1]
        assert answering.status == "FAIL" and "drivers.scale.protocol" in answering.fix
        assert "A&D" in answering.detail or "a_and_d" in answering.detail, answering.line()
        cfg = section("scale", device=scale.link, protocol="a_and_d", disconnect_timeout=0.5)
        scale.silent = True
        silent = doctor.check_scale(cfg)[-1]
        assert silent.status == "FAIL" and "no valid reply" in silent.detail, silent.line()
        scale.silent = False
        scale.settle_time = 30.0  # a draught, a wobbling table: the reading creeps on
        scale.put(0.1)
        monkeypatch.setattr(doctor, "SCALE_STABLE_WITHIN", 0.5)
        unsteady = doctor.check_scale(cfg)[-1]
        assert unsteady.status == "FAIL" and "not stable within" in unsteady.detail
        assert "draught shield" in unsteady.fix
    finally:
        scale.stop()


def test_cameras_left_on_the_emulated_rig_are_a_warning_with_the_fix(tmp_path):
    config = site_config(
        tmp_path,
        {
            "archival_camera": {"kind": "gphoto2", "device": "emulated:/emulated"},
            "wrist_camera": {"source": "emulated:/emulated"},
        },
    )
    for device, fix in (
        ("archival_camera", "drivers.archival_camera.device back to /dev/video0"),
        ("wrist_camera", "drivers.wrist_camera.source: usb"),
    ):
        res = doctor_cli(config, "--device", device)
        line = res.stdout.strip().splitlines()[0]
        assert line.startswith("warn") and "emulated (emulated:/emulated" in line, line
        assert fix in line, line
