"""An emulated DSLR at python3-gphoto2's boundary, for the emulated rig and the tests.

`EmulatedGphoto2` stands where the `gphoto2` module stands for GphotoCamera: `Camera()` with
init, get_config / set_config (widgets with the camera's own choice lists), capture, file_get
and exit; `GPhoto2Error` with libgphoto2's codes and messages; the capture and file-type
constants. Each capture is taken by a `shoot(path, exposure_ev)` callable (in the emulated rig
the simulator's archival camera), at the exposure the chosen shutter speed and ISO give relative
to the reference settings, and saved on the "card" as a JPEG, as a DSLR set to JPEG does.

libgphoto2's own virtual camera ("Directory Browse") cannot capture, so the boundary is the
Python binding. No ROS here; cv2 is injected.
"""

import math
import os
from typing import Callable

from rascal_drivers.archival_camera import shutter_seconds

# libgphoto2's result codes and texts (gphoto2-result.h, gphoto2-port-result.h)
GP_ERROR = -1
GP_ERROR_BAD_PARAMETERS = -2
GP_ERROR_IO = -7
GP_ERROR_MODEL_NOT_FOUND = -105
GP_ERROR_FILE_NOT_FOUND = -108
MESSAGES = {
    GP_ERROR: "Unspecified error",
    GP_ERROR_BAD_PARAMETERS: "Bad parameters",
    GP_ERROR_IO: "I/O problem",
    GP_ERROR_MODEL_NOT_FOUND: "Unknown model",
    GP_ERROR_FILE_NOT_FOUND: "File not found",
}

# a DSLR's third-stop shutter speeds from 30 s to 1/4000 s, and its ISO steps
SHUTTER_SPEEDS = ["30", "25", "20", "15", "13", "10", "8", "6", "5", "4", "3.2", "2.5", "2"]
SHUTTER_SPEEDS += ["1.6", "1.3", "1", "0.8", "0.6", "0.5", "0.4", "0.3"]
SHUTTER_SPEEDS += ["1/%d" % d for d in (4, 5, 6, 8, 10, 13, 15, 20, 25, 30, 40, 50, 60, 80, 100)]
SHUTTER_SPEEDS += ["1/%d" % d for d in (125, 160, 200, 250, 320, 400, 500, 640, 800, 1000)]
SHUTTER_SPEEDS += ["1/%d" % d for d in (1250, 1600, 2000, 2500, 3200, 4000)]
ISO_SPEEDS = ["100", "200", "400", "800", "1600", "3200", "6400"]
COLOUR_TEMPERATURE = (2500, 10000)  # [K] the range the body accepts
JPEG_QUALITY = 95  # a DSLR's "fine" JPEG


class GPhoto2Error(Exception):
    """As python3-gphoto2's: `code`, and str() '[code] message'."""

    def __init__(self, code: int, detail: str = ""):
        self.code = code
        text = "[%d] %s" % (code, MESSAGES.get(code, "Unspecified error"))
        super().__init__(text + (" (%s)" % detail if detail else ""))


class _Widget:
    def __init__(self, name: str, choices, check):
        self.name, self.choices, self.check = name, choices, check
        self.value = None

    def count_choices(self) -> int:
        return len(self.choices)

    def get_choice(self, i: int) -> str:
        if not 0 <= i < len(self.choices):
            raise GPhoto2Error(GP_ERROR_BAD_PARAMETERS)
        return self.choices[i]

    def set_value(self, value: str) -> None:
        if not self.check(value):
            raise GPhoto2Error(GP_ERROR_BAD_PARAMETERS, "%s cannot be %r" % (self.name, value))
        self.value = value


def _colour_temperature_ok(value: str) -> bool:
    try:
        return COLOUR_TEMPERATURE[0] <= int(value) <= COLOUR_TEMPERATURE[1]
    except ValueError:
        return False


class _Config:
    def __init__(self, settings: dict):
        self.widgets = {
            "shutterspeed": _Widget("shutterspeed", SHUTTER_SPEEDS, SHUTTER_SPEEDS.__contains__),
            "iso": _Widget("iso", ISO_SPEEDS, ISO_SPEEDS.__contains__),
            "colortemperature": _Widget("colortemperature", [], _colour_temperature_ok),
        }
        for name, value in settings.items():
            self.widgets[name].value = value

    def get_child_by_name(self, name: str) -> _Widget:
        if name not in self.widgets:
            raise GPhoto2Error(GP_ERROR_BAD_PARAMETERS, "no setting %r" % name)
        return self.widgets[name]


class _CameraFilePath:
    def __init__(self, folder: str, name: str):
        self.folder, self.name = folder, name


class _CameraFile:
    def __init__(self, data: bytes):
        self.data = data

    def save(self, path: str) -> None:
        with open(path, "wb") as f:
            f.write(self.data)


class EmulatedGphoto2:
    """The module surface. `shoot(path, exposure_ev)` writes an image to `path` (any format
    cv2 reads) or raises RuntimeError with a one-line reason; `reference` is the shutter time
    [s] and ISO at which the source's own light is 0 EV. `plugged = False` is a camera off or
    unplugged; `shots` lists each capture's (shutter speed, ISO, exposure_ev)."""

    GP_CAPTURE_IMAGE = 0
    GP_FILE_TYPE_NORMAL = 1
    GPhoto2Error = GPhoto2Error
    FOLDER = "/store_00020001/DCIM/100EMULA"
    CARD_KEEPS = 8  # images left on the card; older ones are deleted

    def __init__(
        self,
        cv2,
        shoot: Callable[[str, float], None],
        card_dir: str,
        reference=(0.01, 100),
    ):
        self.cv2, self.shoot, self.card_dir = cv2, shoot, card_dir
        self.reference_shutter, self.reference_iso = reference
        self.plugged = True
        self.settings = {"shutterspeed": "1/100", "iso": "100", "colortemperature": "5500"}
        self.shots = []
        self.files = {}  # name -> path on the card
        self.count = 0
        os.makedirs(card_dir, exist_ok=True)
        emulator = self

        class Camera:
            def __init__(self):
                self.ready = False

            def init(self, context=None):
                if not emulator.plugged:
                    raise GPhoto2Error(GP_ERROR_MODEL_NOT_FOUND)
                self.ready = True

            def _need(self):
                if not self.ready or not emulator.plugged:
                    raise GPhoto2Error(GP_ERROR_IO if self.ready else GP_ERROR)

            def get_config(self, context=None):
                self._need()
                return _Config(emulator.settings)

            def set_config(self, config, context=None):
                self._need()
                for name, widget in config.widgets.items():
                    if widget.value is not None:
                        emulator.settings[name] = widget.value

            def capture(self, kind, context=None):
                self._need()
                if kind != EmulatedGphoto2.GP_CAPTURE_IMAGE:
                    raise GPhoto2Error(GP_ERROR_BAD_PARAMETERS)
                return emulator._capture()

            def file_get(self, folder, name, kind, context=None):
                self._need()
                if folder != EmulatedGphoto2.FOLDER or name not in emulator.files:
                    raise GPhoto2Error(GP_ERROR_FILE_NOT_FOUND)
                with open(emulator.files[name], "rb") as f:
                    return _CameraFile(f.read())

            def exit(self, context=None):
                self.ready = False

        self.Camera = Camera

    def exposure_ev(self) -> float:
        """Stops of light the current settings give more than the reference ones."""
        shutter = shutter_seconds(self.settings["shutterspeed"])
        iso = float(self.settings["iso"])
        return math.log2(shutter / self.reference_shutter) + math.log2(iso / self.reference_iso)

    def _capture(self) -> _CameraFilePath:
        self.count += 1
        n = self.count
        name = "IMG_%04d.JPG" % n
        raw = os.path.join(self.card_dir, "capture_%04d.png" % n)
        ev = self.exposure_ev()
        try:
            self.shoot(raw, ev)
            image = self.cv2.imread(raw, self.cv2.IMREAD_COLOR)
        except RuntimeError as e:
            raise GPhoto2Error(GP_ERROR_IO, "emulated: %s" % e) from e
        finally:
            if os.path.exists(raw):
                os.unlink(raw)
        if image is None:
            raise GPhoto2Error(GP_ERROR_IO, "emulated: the source gave no image")
        path = os.path.join(self.card_dir, name)
        self.cv2.imwrite(path, image, [self.cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
        self.files[name] = path
        for old in sorted(self.files)[: -self.CARD_KEEPS]:  # a long batch fills no disk
            os.unlink(self.files.pop(old))
        self.shots.append((self.settings["shutterspeed"], self.settings["iso"], ev))
        return _CameraFilePath(self.FOLDER, name)
