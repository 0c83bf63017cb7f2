"""The wrist camera driver against an emulated D435: librealsense's software_device recorded
with the SDK's recorder and played back through the real pipeline, rs.align and rs.pointcloud.
Core tests (no master) and wiring tests (the node started with rosrun)."""

import json
import os
import subprocess

import numpy as np
import pytest

from rascal_drivers import d435_emulator, workspace_venv
from rascal_drivers.parameters import read_section
from rascal_drivers.wrist_camera import CameraError, RealSenseCamera, check_config
from rascal_tasks.sim_rig import stop

workspace_venv.add()
rs = pytest.importorskip("pyrealsense2")

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
CONFIG = os.path.join(WORKSPACE, "config", "rascal.yaml")
CLIENT = os.path.join(HERE, "wrist_client.py")
SHIFT = round(615.0 * 0.015 / 0.39)  # colour sees the sherd this far right of the depth imager
SHERD_U, SHERD_V = 320 + SHIFT, 240  # the sherd's centre in the colour image


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = str(tmp_path_factory.mktemp("d435") / "wrist.db3")
    d435_emulator.record(path, [d435_emulator.mat_with_sherd()] * 8, rs)
    return path


def test_depth_is_aligned_to_colour_with_the_colour_intrinsics_and_cloud(recording):
    cfg = read_section({"source": recording}, "drivers.wrist_camera")
    camera = RealSenseCamera(rs, cfg)
    camera.open()
    frame = camera.frame(with_cloud=True)
    camera.close()
    assert frame.colour.shape == (480, 640, 3) and frame.depth_mm.shape == (480, 640)
    i = frame.intrinsics
    assert (i.fx, i.fy, i.cx, i.cy) == (615.0, 615.0, 320.0, 240.0)
    # aligned: the sherd's depth lies under the sherd's colour, at both of its ends
    for u in (SHERD_U - 35, SHERD_U, SHERD_U + 35):
        assert tuple(frame.colour[SHERD_V, u]) == d435_emulator.SHERD_RGB
        assert frame.depth_mm[SHERD_V, u] == 390
    assert frame.depth_mm[SHERD_V, 40] == 400  # the mat
    # the SDK's deprojection: x = (u - cx) z / fx in the colour optical frame
    k = SHERD_V * 640 + SHERD_U
    valid = (frame.depth_mm.reshape(-1) > 0)[: k + 1].sum() - 1
    x, y, z = frame.points[valid]
    assert z == pytest.approx(0.390, abs=1e-4)
    assert x == pytest.approx((SHERD_U - 320.0) * 0.39 / 615.0, abs=1e-4) and abs(y) < 1e-3
    assert tuple(frame.point_colours[valid]) == d435_emulator.SHERD_RGB


def test_a_rate_the_d435_lacks_is_named():
    cfg = read_section({"rate": 25}, "drivers.wrist_camera")
    with pytest.raises(
        ValueError, match="drivers.wrist_camera.rate: expected one of 6, 15, 30, 60"
    ):
        check_config(cfg)


def test_no_camera_and_no_recording_are_named_in_one_line(tmp_path):
    for source, message in (
        ("usb", "no RealSense D435 found"),
        (str(tmp_path / "missing.db3"), "drivers.wrist_camera.source: cannot play"),
    ):
        camera = RealSenseCamera(rs, read_section({"source": source}, "drivers.wrist_camera"))
        with pytest.raises(CameraError, match=message) as e:
            camera.open()
        assert "\n" not in str(e.value)


def test_the_node_publishes_the_simulators_topics(ros_master, rosrun, recording):
    ros_master.run(["rosparam", "load", CONFIG])
    ros_master.run(["rosparam", "set", "/drivers/wrist_camera/source", recording])
    node = rosrun("rascal_drivers", "wrist_camera_driver")
    res = ros_master.run(["/usr/bin/python3", CLIENT, str(SHERD_U), str(SHERD_V)], timeout=40)
    assert res.returncode == 0, res.stderr
    got = json.loads(res.stdout.strip().splitlines()[-1])
    stop(node)
    assert got["encodings"] == ["rgb8", "16UC1"] and got["size"] == [640, 480, 640, 480]
    assert set(got["frames"]) == {"camera_color_optical_frame"}
    assert got["K"] == got["K_depth"] == [615.0, 0.0, 320.0, 0.0, 615.0, 240.0, 0.0, 0.0, 1.0]
    assert got["depth_at"] == 390 and tuple(got["colour_at"]) == d435_emulator.SHERD_RGB
    assert got["fields"] == ["x", "y", "z", "rgb"]
    assert got["points"] == got["valid_depth"] > 0.9 * 640 * 480  # valid points only
    assert got["nearest_point"] == pytest.approx(
        [(SHERD_U - 320) * 0.39 / 615, 0.0, 0.39], abs=1e-4
    )
    assert tuple(got["nearest_rgb"]) == d435_emulator.SHERD_RGB
    assert np.isfinite(got["nearest_point"]).all()


def test_the_node_without_a_camera_exits_with_one_line(ros_master):
    ros_master.run(["rosparam", "load", CONFIG])
    res = subprocess.run(
        ["rosrun", "rascal_drivers", "wrist_camera_driver"],
        env=ros_master.env,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert res.returncode == 1
    lines = [ln for ln in res.stderr.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and "no RealSense D435 found" in lines[0], res.stderr
