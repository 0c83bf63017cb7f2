"""Wiring tests of archival_camera_driver (master on a free port). The OpenCV path is tested
with a real OpenCV source, an image sequence (no camera is attached to the test machine); the
gphoto2 path only for its error: libgphoto2 finds no DSLR here."""

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


class _Gphoto:
    """python3-gphoto2's surface as GphotoCamera uses it, for a camera whose shutter speeds are
    the usual third stops: records the shutter speed of every capture."""

    GP_CAPTURE_IMAGE, GP_FILE_TYPE_NORMAL = 0, 1
    SPEEDS = ["1/15", "1/20", "1/25", "1/30", "1/40", "1/50", "1/60", "1/80", "1/100", "1/125"]
    SPEEDS += ["1/160", "1/200", "1/250"]

    class GPhoto2Error(Exception):
        pass

    def __init__(self, jpeg):
        self.settings, self.shots, self.jpeg = {}, [], jpeg
        gp = self

        class Widget:
            def __init__(self, name, choices):
                self.name, self.choices = name, choices

            def count_choices(self):
                return len(self.choices)

            def get_choice(self, i):
                return self.choices[i]

            def set_value(self, v):
                gp.pending[self.name] = v

        class Config:
            def get_child_by_name(self, name):
                choices = {"shutterspeed": gp.SPEEDS, "iso": ["100", "200"], "colortemperature": []}
                return Widget(name, choices[name])

        class File:
            def save(self, path):
                with open(path, "wb") as f:
                    f.write(gp.jpeg)

        class Where:
            folder, name = "/store_00010001/DCIM", "IMG_0001.JPG"

        class Camera:
            def init(self):
                pass

            def get_config(self):
                gp.pending = {}
                return Config()

            def set_config(self, _):
                gp.settings.update(gp.pending)

            def capture(self, _):
                gp.shots.append(gp.settings["shutterspeed"])
                return Where()

            def file_get(self, *_):
                return File()

            def exit(self):
                pass

        self.Camera = Camera


def test_a_dslr_shot_a_stop_darker_gets_half_the_shutter_time(tmp_path):
    from rascal_drivers.archival_camera import GphotoCamera

    _, jpeg = cv2.imencode(".jpg", np.full((30, 40, 3), 128, np.uint8))
    gp = _Gphoto(jpeg.tobytes())
    cfg = read_section({"kind": "gphoto2", "exposure": 1 / 60, "iso": 100}, PREFIX)
    camera = GphotoCamera(gp, cv2, cfg)
    camera.open()
    for ev in (0.0, -1.0, -2.0, 0.0):
        assert camera.capture(str(tmp_path / "a.png"), ev) == (40, 30)
    assert gp.shots == ["1/60", "1/125", "1/250", "1/60"]  # the nearest the camera offers
