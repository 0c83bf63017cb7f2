"""Tests of the archival camera: the OpenCV path with a real OpenCV source, an image sequence
(no camera is attached to the test machine); the gphoto2 path against a DSLR emulated at
python3-gphoto2's boundary (gphoto2_emulator; libgphoto2 itself finds no DSLR here), and the
node (master on a free port)."""

import json
import os
import subprocess

import cv2
import numpy as np
import pytest

from rascal_drivers.archival_camera import CaptureError, OpenCvCamera, check_image, store_png
from rascal_drivers.parameters import read_section
from rascal_tasks.sim_rig import stop

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
CONFIG = os.path.join(WORKSPACE, "config", "rascal.yaml")
CLIENT = os.path.join(HERE, "capture_client.py")
PREFIX = "drivers.archival_camera"


def frames(folder, count=2, size=(640, 480)):
    for i in range(count):
        image = np.zeros((size[1], size[0], 3), np.uint8)
        cv2.rectangle(image, (100 + 50 * i, 100), (600, 400), (30, 80 + 50 * i, 200), -1)
        cv2.imwrite(os.path.join(folder, "frame_%03d.png" % i), image)
    return os.path.join(folder, "frame_%03d.png")


def test_opencv_captures_a_checked_png_at_the_asked_path(ros_master, rosrun, tmp_path):
    source = frames(str(tmp_path))
    ros_master.run(["rosparam", "load", CONFIG])
    ros_master.run(["rosparam", "set", "/drivers/archival_camera/kind", "opencv"])
    ros_master.run(["rosparam", "set", "/drivers/archival_camera/device", source])
    node = rosrun("rascal_drivers", "archival_camera_driver")
    first, second, none = (str(tmp_path / "archive" / n) for n in ("1.png", "2.png", "none.png"))
    res = ros_master.run(["/usr/bin/python3", CLIENT, first, second, none], timeout=40)
    got = json.loads(res.stdout.strip().splitlines()[-1])
    stop(node)
    assert got[0]["success"], got
    assert (got[0]["path"], got[0]["width"], got[0]["height"]) == (first, 640, 480)
    for path, frame in ((first, "frame_000.png"), (second, "frame_001.png")):
        stored = cv2.imread(path)  # each capture is the next frame itself, losslessly
        assert np.array_equal(stored, cv2.imread(str(tmp_path / frame)))
    # the source runs dry after its last frame: a one-line refusal, and no file
    assert not got[2]["success"] and "no frame from" in got[2]["message"], got
    assert "\n" not in got[2]["message"] and not os.path.exists(none)


def test_a_camera_that_is_not_there_is_named_in_one_line(ros_master):
    ros_master.run(["rosparam", "load", CONFIG])
    for kind, device, message in (("gphoto2", "/dev/video0", "no DSLR found by libgphoto2"),):
        ros_master.run(["rosparam", "set", "/drivers/archival_camera/kind", kind])
        ros_master.run(["rosparam", "set", "/drivers/archival_camera/device", device])
        res = subprocess.run(
            ["rosrun", "rascal_drivers", "archival_camera_driver"],
            env=ros_master.env,
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert res.returncode == 1
        lines = [ln for ln in res.stderr.strip().splitlines() if ln.strip()]
        assert len(lines) == 1 and message in lines[0], res.stderr


def test_opencv_names_a_device_it_cannot_open():
    camera = OpenCvCamera(cv2, read_section({"kind": "opencv", "device": "/dev/video97"}, PREFIX))
    with pytest.raises(CaptureError, match="drivers.archival_camera.device: OpenCV cannot open"):
        camera.open()


def test_an_empty_or_undecodable_file_is_never_reported_as_an_image(tmp_path):
    (tmp_path / "empty.png").write_bytes(b"")
    (tmp_path / "junk.png").write_bytes(b"not a png at all")
    for name in ("empty.png", "junk.png", "missing.png"):
        with pytest.raises(CaptureError):
            check_image(cv2, str(tmp_path / name))
    with pytest.raises(CaptureError, match="empty image"):
        store_png(cv2, np.zeros((0, 0, 3), np.uint8), str(tmp_path / "out.png"))
    assert not (tmp_path / "out.png").exists()


def _dslr(tmp_path, shoot=None):
    """A DSLR emulated at python3-gphoto2's boundary whose source paints a grey frame (or runs
    `shoot`), and GphotoCamera on it, set to 1/60 s at ISO 100."""
    from rascal_drivers.archival_camera import GphotoCamera
    from rascal_drivers.gphoto2_emulator import EmulatedGphoto2

    def grey(path, exposure_ev):
        cv2.imwrite(path, np.full((30, 40, 3), 128, np.uint8))

    gp = EmulatedGphoto2(cv2, shoot or grey, str(tmp_path / "card"), (1 / 60, 100))
    cfg = read_section({"kind": "gphoto2", "exposure": 1 / 60, "iso": 100}, PREFIX)
    return gp, GphotoCamera(gp, cv2, cfg)


def test_a_dslr_shot_a_stop_darker_gets_half_the_shutter_time(tmp_path):
    gp, camera = _dslr(tmp_path)
    camera.open()
    for ev in (0.0, -1.0, -2.0, 0.0):
        assert camera.capture(str(tmp_path / "a.png"), ev) == (40, 30)
    # the nearest third-stop speeds the camera offers, and the light they give the source
    assert [shot[0] for shot in gp.shots] == ["1/60", "1/125", "1/250", "1/60"]
    assert [round(shot[2], 2) for shot in gp.shots] == [0.0, -1.06, -2.06, 0.0]
    assert len(os.listdir(tmp_path / "card")) == 4  # the JPEGs left on the card


def test_a_dslr_says_its_shutter_closed_before_the_download_and_not_when_it_failed(tmp_path):
    gp, camera = _dslr(tmp_path)
    camera.open()
    said = []
    download = camera.camera.file_get

    def file_get(*args):  # the image leaves the camera only after the word
        said.append("download")
        return download(*args)

    camera.camera.file_get = file_get
    camera.capture(str(tmp_path / "a.png"), 0.0, lambda: said.append("exposed"))
    assert said == ["exposed", "download"]

    def refuses(path, exposure_ev):
        raise RuntimeError("arm in view")

    gp.shoot = refuses
    with pytest.raises(CaptureError):
        camera.capture(str(tmp_path / "b.png"), 0.0, lambda: said.append("exposed"))
    assert said == ["exposed", "download"]


def test_dslr_faults_are_one_line_and_leave_no_file(tmp_path):
    def refuses(path, exposure_ev):
        raise RuntimeError("arm in view")

    gp, camera = _dslr(tmp_path, refuses)
    camera.open()
    out = str(tmp_path / "a.png")
    with pytest.raises(CaptureError, match=r"did not capture or download \(\[-7\] I/O problem"):
        camera.capture(out)
    assert not os.path.exists(out)
    gp.plugged = False  # the camera switched off or its cable pulled mid-batch
    gp.shoot = lambda path, ev: cv2.imwrite(path, np.zeros((3, 3, 3), np.uint8))
    with pytest.raises(CaptureError, match=r"\[-7\] I/O problem") as e:
        camera.capture(out)
    assert "\n" not in str(e.value) and not os.path.exists(out)
    camera.close()
    with pytest.raises(CaptureError, match="no DSLR found by libgphoto2"):
        camera.open()  # nothing on the bus
    # a white balance the body does not offer is named by its key
    gp.plugged = True
    camera.config = dict(camera.config, white_balance=12000.0)
    with pytest.raises(CaptureError, match="drivers.archival_camera.white_balance"):
        camera.open()
