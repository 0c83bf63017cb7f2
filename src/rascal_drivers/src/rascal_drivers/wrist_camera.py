"""The wrist D435 through librealsense (pyrealsense2): colour, depth aligned to colour with the
SDK's own rs.align, the colour stream's intrinsics, and a point cloud from the SDK's own
deprojection (rs.pointcloud), as the simulator gives them to perception.

The source is a live D435 (`usb`, picked by serial number), a recording the SDK plays back
through the same pipeline (a file written by rs.recorder: the tests' emulated D435, or a
session recorded on the rig), or an emulated D435 fed live (`emulated:NS`, d435_emulator's
LiveD435: the SDK's software device, fed by the node with the simulator's images). No ROS here;
pyrealsense2 and the live feed are injected by the node.
"""

import time
from dataclasses import dataclass
from typing import Optional

import numpy as np

from rascal_drivers.parameters import EMULATED

FRAME_RATES = (6, 15, 30, 60)  # colour + depth modes both D435 streams offer (Intel)


class CameraError(RuntimeError):
    """One line: what failed and what to do."""


@dataclass
class Intrinsics:
    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    coeffs: list


@dataclass
class WristFrame:
    stamp: float  # [s] the SDK's frame timestamp (ms in librealsense) in seconds; live
    # emulated: the stamp of the simulator's image
    colour: np.ndarray  # (H, W, 3) uint8 RGB
    depth_mm: np.ndarray  # (H, W) uint16, depth in mm aligned to colour, 0 = none
    intrinsics: Intrinsics  # of the colour stream (the aligned depth shares them)
    points: Optional[np.ndarray] = None  # (N, 3) float32 in the colour optical frame [m]
    point_colours: Optional[np.ndarray] = None  # (N, 3) uint8 RGB


def check_config(config: dict) -> None:
    if config["rate"] not in FRAME_RATES:
        raise ValueError(
            "drivers.wrist_camera.rate: expected one of %s (the D435's modes), got %r"
            % (", ".join(str(r) for r in FRAME_RATES), config["rate"])
        )


class RealSenseCamera:
    def __init__(self, rs, config: dict, feed=None):
        self.rs = rs
        self.config = config
        self.feed = feed  # a LiveD435 for source emulated:NS
        self.pipeline = None
        self.align = rs.align(rs.stream.color)
        self.cloud = rs.pointcloud()
        self.depth_scale_mm = 1.0

    def open(self) -> None:
        rs, c = self.rs, self.config
        width, height = (int(v) for v in c["size"])
        source = c["source"]
        if source.startswith(EMULATED):
            if (self.feed.width, self.feed.height) != (width, height):
                raise CameraError(
                    "drivers.wrist_camera.size: the emulated camera gives %d x %d, not %d x %d; "
                    "set it to [%d, %d]"
                    % (
                        self.feed.width,
                        self.feed.height,
                        width,
                        height,
                        self.feed.width,
                        self.feed.height,
                    )
                )
            self.depth_scale_mm = self.feed.depth_units * 1000.0
            return
        cfg = rs.config()
        if source != "usb":
            cfg.enable_device_from_file(source, True)  # repeat: a recording stands in for a camera
        elif c["serial"] != "any":
            cfg.enable_device(c["serial"])
        cfg.enable_stream(rs.stream.color, width, height, rs.format.rgb8, int(c["rate"]))
        cfg.enable_stream(rs.stream.depth, width, height, rs.format.z16, int(c["rate"]))
        if source == "usb" and len(rs.context().query_devices()) == 0:
            # pipeline.start would wait for a device to appear; there is none on the bus now
            raise CameraError(
                "no RealSense D435 found on USB; plug it into a USB 3 port (lsusb shows "
                "'Intel Corp. RealSense'), or check drivers.wrist_camera.source"
            )
        self.pipeline = rs.pipeline()
        try:
            profile = self.pipeline.start(cfg)
        except RuntimeError as e:
            self.pipeline = None
            where = (
                "drivers.wrist_camera.source: cannot play %s" % source
                if source != "usb"
                else "no RealSense D435%s found"
                % ("" if c["serial"] == "any" else " with serial %s" % c["serial"])
            )
            raise CameraError(
                "%s (%s); plug it into a USB 3 port, or check drivers.wrist_camera.serial/size/rate"
                % (where, e)
            ) from e
        depth_sensor = profile.get_device().first_depth_sensor()
        units = depth_sensor.get_option(rs.option.depth_units)  # [m] per depth count
        self.depth_scale_mm = units * 1000.0

    def _frameset(self):
        """The next frameset with both colour and depth (the syncer gives the very first frame
        of each stream alone)."""
        timeout = self.config["frame_timeout"]
        source = self.feed if self.feed is not None else self.pipeline
        end = time.monotonic() + timeout
        while True:
            left_ms = max(1, int((end - time.monotonic()) * 1000))
            try:
                frames = source.wait_for_frames(left_ms)
            except RuntimeError as e:
                raise CameraError(
                    "no frames from the wrist camera for %.1f s (drivers.wrist_camera."
                    "frame_timeout; %s); check its USB cable" % (timeout, e)
                ) from e
            if frames.get_color_frame() and frames.get_depth_frame():
                return frames
            if time.monotonic() > end:
                raise CameraError(
                    "the wrist camera delivered no frame set with both colour and depth for "
                    "%.1f s (drivers.wrist_camera.frame_timeout)" % timeout
                )

    def frame(self, with_cloud: bool) -> WristFrame:
        frames = self._frameset()
        aligned = self.align.process(frames)
        colour_frame = aligned.get_color_frame()
        depth_frame = aligned.get_depth_frame()
        if not colour_frame or not depth_frame:
            raise CameraError("the wrist camera delivered a frame set without colour or depth")
        colour = np.asanyarray(colour_frame.get_data()).copy()
        raw = np.asanyarray(depth_frame.get_data())
        if abs(self.depth_scale_mm - 1.0) < 1e-6:
            depth_mm = raw.copy()
        else:
            depth_mm = np.clip(np.rint(raw * self.depth_scale_mm), 0, 65535).astype(np.uint16)
        i = colour_frame.profile.as_video_stream_profile().intrinsics
        stamp = colour_frame.get_timestamp() / 1000.0
        if self.feed is not None:
            stamp = self.feed.stamp_of(colour_frame.get_frame_number())
        out = WristFrame(
            stamp=stamp,
            colour=colour,
            depth_mm=depth_mm,
            intrinsics=Intrinsics(i.width, i.height, i.fx, i.fy, i.ppx, i.ppy, list(i.coeffs)),
        )
        if with_cloud:
            self.cloud.map_to(colour_frame)
            points = self.cloud.calculate(depth_frame)
            xyz = np.asanyarray(points.get_vertices()).view(np.float32).reshape(-1, 3)
            valid = xyz[:, 2] > 0
            out.points = xyz[valid].copy()
            out.point_colours = colour.reshape(-1, 3)[valid]  # aligned: vertex i is pixel i
        return out

    def close(self) -> None:
        if self.feed is not None:
            self.feed.close()
        if self.pipeline is not None:
            try:
                self.pipeline.stop()
            except RuntimeError:
                pass
