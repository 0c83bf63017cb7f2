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


def test_a_live_emulated_d435_gives_each_pushed_pair_through_the_sdk_with_its_stamp():
    colour, depth = d435_emulator.mat_with_sherd()
    # the simulator's images come aligned already: colour and depth share the sherd's pixels
    depth = np.where(np.all(colour == d435_emulator.SHERD_RGB, axis=2), 390, 400).astype(np.uint16)
    feed = d435_emulator.LiveD435(rs, 640, 480, 615.0, 615.0, 320.0, 240.0)
    cfg = read_section({"source": "emulated:/emulated"}, "drivers.wrist_camera")
    camera = RealSenseCamera(rs, cfg, feed)
    camera.open()
    got = []
    for k in range(6):  # stamps as the simulator's: late in its time, unevenly spaced
        feed.push(colour, depth, 40.0 + 0.5 * k * k)
        if k >= 1:  # the syncer gives the very first frame of each stream alone
            got.append(camera.frame(with_cloud=True))
    camera.close()
    assert [f.stamp for f in got] == [40.0 + 0.5 * k * k for k in range(1, 6)]
    frame = got[-1]
    assert np.array_equal(frame.colour, colour)
    # the SDK's alignment (identity extrinsics): the same depths, but for its forward
    # projection's holes (about 2 % of the pixels, 0 = no depth, as on a camera)
    same = frame.depth_mm == depth
    assert same.mean() > 0.95 and (same | (frame.depth_mm == 0)).all()
    assert frame.depth_mm[SHERD_V, SHERD_U] == 390 and frame.depth_mm[SHERD_V, 40] == 400
    k = SHERD_V * 640 + SHERD_U
    valid = (frame.depth_mm.reshape(-1) > 0)[: k + 1].sum() - 1
    assert frame.points[valid][2] == pytest.approx(0.390, abs=1e-4)
    assert tuple(frame.point_colours[valid]) == d435_emulator.SHERD_RGB


def test_a_live_emulated_d435_refuses_a_size_the_configuration_does_not_name():
    feed = d435_emulator.LiveD435(rs, 424, 240, 307.0, 307.0, 212.0, 120.0)
    camera = RealSenseCamera(
        rs, read_section({"source": "emulated:/x"}, "drivers.wrist_camera"), feed
    )
    with pytest.raises(CameraError, match=r"drivers.wrist_camera.size: .* set it to \[424, 240\]"):
        camera.open()
    with pytest.raises(ValueError, match="emulated D435 depth: expected"):
        feed.push(np.zeros((240, 424, 3), np.uint8), np.zeros((240, 424), np.float32), 1.0)
    feed.close()


def test_colour_and_depth_are_paired_by_their_stamp():
    pairs = d435_emulator.StampPairs()
    assert pairs.add("colour", "c1", 1.0) is None
    assert pairs.add("colour", "c2", 2.0) is None  # depth of 1.0 still on its way
    assert pairs.add("depth", "d1", 1.0) == ("c1", "d1", 1.0)
    assert pairs.add("depth", "d2", 2.0) == ("c2", "d2", 2.0)
    assert pairs.add("depth", "d9", 9.0) is None and pairs.add("colour", "c3", 3.0) is None
    assert 3.0 not in pairs.waiting or 9.0 in pairs.waiting  # nothing older than 1 s is kept
    assert pairs.add("colour", "c9", 9.0) == ("c9", "d9", 9.0) and pairs.waiting == {}


def test_a_live_emulated_d435_whose_frames_stop_is_named_in_one_line():
    """The simulator stopped (or the camera unplugged): no frame set within frame_timeout."""
    feed = d435_emulator.LiveD435(rs, 640, 480, 615.0, 615.0, 320.0, 240.0)
    cfg = read_section({"source": "emulated:/e", "frame_timeout": 0.3}, "drivers.wrist_camera")
    camera = RealSenseCamera(rs, cfg, feed)
    camera.open()
    colour, depth = d435_emulator.mat_with_sherd()
    feed.push(colour, depth, 1.0)  # only the first pair, which the syncer gives apart
    with pytest.raises(CameraError, match="drivers.wrist_camera.frame_timeout") as e:
        for _ in range(3):
            camera.frame(with_cloud=False)
    assert "\n" not in str(e.value)
    camera.close()
