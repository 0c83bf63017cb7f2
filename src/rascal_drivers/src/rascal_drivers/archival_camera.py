"""The archival camera of the field rig: a DSLR through libgphoto2, or a USB camera through
OpenCV (V4L2), each taking one still on request and leaving a checked PNG where it was asked.

Both fix exposure and white balance from the configuration, so every sherd of a batch is shot
under the same settings (the colour chart in view is only comparable that way); a capture may ask
for whole stops less (or more) light than configured, which the shutter time gives (the task
layer steps down when highlights clip; the chart in view corrects the photo either way). Every
stored image is read back and decoded before it is reported: an empty or undecodable file is an
error, never a catalogue row. No ROS here; cv2 and gphoto2 are injected by the node.
"""

import os
import tempfile
from typing import Tuple


class CaptureError(RuntimeError):
    """One line: what failed and what to do."""


def store_png(cv2, image, path: str) -> Tuple[int, int]:
    """Writes `image` to `path` as PNG (complete or not at all), reads it back; (width, height)."""
    if image is None or getattr(image, "size", 0) == 0:
        raise CaptureError("the camera delivered an empty image")
    folder = os.path.dirname(path) or "."
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".png", dir=folder)
    os.close(fd)
    try:
        if not cv2.imwrite(tmp, image):
            raise CaptureError("cannot write %s (disk full? permissions?)" % path)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return check_image(cv2, path)


def check_image(cv2, path: str) -> Tuple[int, int]:
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        raise CaptureError("%s is missing or empty after the capture" % path)
    image = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if image is None or image.size == 0:
        raise CaptureError("%s does not decode as an image" % path)
    return int(image.shape[1]), int(image.shape[0])


class OpenCvCamera:
    """A V4L2 camera (/dev/videoN), or any source OpenCV opens (a video file, an image
    sequence such as frames/%03d.png: what the tests use, as no camera is attached there)."""

    FLUSH_FRAMES = 4  # V4L2 keeps a few frames queued; the still must be taken after the call

    def __init__(self, cv2, config: dict):
        self.cv2 = cv2
        self.config = config
        self.device = config["device"]
        self.v4l2 = self.device.startswith("/dev/video")
        self.capture_ = None
        self.exposure_ev = 0.0

    def open(self) -> None:
        cv2, c = self.cv2, self.config
        api = cv2.CAP_V4L2 if self.v4l2 else cv2.CAP_ANY
        self.capture_ = cv2.VideoCapture(self.device, api)
        if not self.capture_.isOpened():
            raise CaptureError(
                "drivers.archival_camera.device: OpenCV cannot open %s; plug the camera in or set "
                "the path" % self.device
            )
        if self.v4l2:
            width, height = c["size"]
            self.capture_.set(cv2.CAP_PROP_FRAME_WIDTH, width)
            self.capture_.set(cv2.CAP_PROP_FRAME_HEIGHT, height)
            self.capture_.set(cv2.CAP_PROP_AUTO_EXPOSURE, 1)  # V4L2: 1 = manual exposure
            self._set_exposure(0.0)
            self.capture_.set(cv2.CAP_PROP_AUTO_WB, 0)
            self.capture_.set(cv2.CAP_PROP_WB_TEMPERATURE, c["white_balance"])

    def _set_exposure(self, exposure_ev: float) -> None:
        seconds = self.config["exposure"] * 2.0**exposure_ev
        self.capture_.set(self.cv2.CAP_PROP_EXPOSURE, seconds * 1e4)  # V4L2: 100 us units
        self.exposure_ev = exposure_ev

    def capture(self, path: str, exposure_ev: float = 0.0, exposed=None) -> Tuple[int, int]:
        """A still at `exposure_ev` stops from the configured exposure (a file or an image
        sequence has no exposure: there it is the source's own); `exposed()` is called once
        the frame is taken, before it is stored."""
        if self.v4l2 and exposure_ev != self.exposure_ev:
            self._set_exposure(exposure_ev)
        if self.v4l2:
            for _ in range(self.FLUSH_FRAMES):
                self.capture_.grab()
        ok, image = self.capture_.read()
        if not ok:
            raise CaptureError("no frame from %s; is the camera still connected?" % self.device)
        if exposed is not None:
            exposed()
        return store_png(self.cv2, image, path)

    def close(self) -> None:
        if self.capture_ is not None:
            self.capture_.release()


def _nearest_choice(widget, value: float, parse) -> str:
    choices = [widget.get_choice(i) for i in range(widget.count_choices())]
    scored = []
    for choice in choices:
        try:
            scored.append((abs(parse(choice) - value), choice))
        except (ValueError, ZeroDivisionError):
            continue
    if not scored:
        raise ValueError("no numeric choice among %s" % choices)
    return min(scored)[1]


def shutter_seconds(text: str) -> float:
    """A shutter-speed choice ('1/125', '0.5', '2s') in seconds."""
    text = text.strip().rstrip("s")
    if "/" in text:
        num, den = text.split("/", 1)
        return float(num) / float(den)
    return float(text)


class GphotoCamera:
    """A DSLR on USB through libgphoto2 (python3-gphoto2): fixed shutter speed, ISO and colour
    temperature; the camera saves JPEG (set its image quality to JPEG), which is downloaded,
    decoded and stored as PNG."""

    def __init__(self, gp, cv2, config: dict):
        self.gp = gp
        self.cv2 = cv2
        self.config = config
        self.camera = None
        self.exposure_ev = 0.0

    def open(self) -> None:
        gp = self.gp
        try:
            self.camera = gp.Camera()
            self.camera.init()
        except gp.GPhoto2Error as e:
            self.camera = None
            raise CaptureError(
                "no DSLR found by libgphoto2 (%s); connect it by USB, switch it on (PTP mode), "
                "or set drivers.archival_camera.kind: opencv" % e
            ) from e
        self._configure()

    def _configure(self, exposure_ev: float = 0.0) -> None:
        c = self.config
        config = self.camera.get_config()
        shutter = c["exposure"] * 2.0**exposure_ev  # the nearest the camera offers
        settings = (
            ("shutterspeed", "drivers.archival_camera.exposure", shutter, shutter_seconds),
            ("iso", "drivers.archival_camera.iso", c["iso"], float),
        )
        for name, key, value, parse in settings:
            try:
                widget = config.get_child_by_name(name)
                widget.set_value(_nearest_choice(widget, value, parse))
            except (self.gp.GPhoto2Error, ValueError) as e:
                raise CaptureError(
                    "%s: this camera cannot be set to %s (%s)" % (key, value, e)
                ) from e
        try:  # colour temperature in kelvin; names differ between makers
            widget = config.get_child_by_name("colortemperature")
            widget.set_value(str(int(c["white_balance"])))
        except self.gp.GPhoto2Error as e:
            raise CaptureError(
                "drivers.archival_camera.white_balance: this camera offers no colour temperature "
                "setting through libgphoto2 (%s); set %d K on the camera itself"
                % (e, c["white_balance"])
            ) from e
        self.camera.set_config(config)
        self.exposure_ev = exposure_ev

    def capture(self, path: str, exposure_ev: float = 0.0, exposed=None) -> Tuple[int, int]:
        """A still at `exposure_ev` stops from the configured shutter time; `exposed()` is
        called once the shutter has closed (the image is on the camera), before the download."""
        gp = self.gp
        if exposure_ev != self.exposure_ev:
            self._configure(exposure_ev)
        try:
            where = self.camera.capture(gp.GP_CAPTURE_IMAGE)
            if exposed is not None:
                exposed()
            camera_file = self.camera.file_get(where.folder, where.name, gp.GP_FILE_TYPE_NORMAL)
            fd, tmp = tempfile.mkstemp(suffix=os.path.splitext(where.name)[1])
            os.close(fd)
            camera_file.save(tmp)
        except gp.GPhoto2Error as e:
            raise CaptureError("the DSLR did not capture or download (%s)" % e) from e
        try:
            image = self.cv2.imread(tmp, self.cv2.IMREAD_COLOR)
            if image is None:
                raise CaptureError(
                    "the DSLR's file %s does not decode (RAW?); set the camera to JPEG" % where.name
                )
            return store_png(self.cv2, image, path)
        finally:
            os.unlink(tmp)

    def close(self) -> None:
        if self.camera is not None:
            try:
                self.camera.exit()
            except self.gp.GPhoto2Error:
                pass
