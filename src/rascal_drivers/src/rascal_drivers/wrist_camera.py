"""The wrist D435 through librealsense (pyrealsense2): colour, depth aligned to colour with the
SDK's own rs.align, the colour stream's intrinsics, and a point cloud from the SDK's own
deprojection (rs.pointcloud), as the simulator gives them to perception.

The source is a live D435 (`usb`, picked by serial number) or a recording the SDK plays back
through the same pipeline (a file written by rs.recorder: the tests' emulated D435, or a
session recorded on the rig). No ROS here; pyrealsense2 is injected by the node.
"""

from dataclasses import dataclass
from typing import Optional

import numpy as np

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
    stamp: float  # [s] the SDK's frame timestamp (ms in librealsense) in seconds
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
    def __init__(self, rs, config: dict):
        self.rs = rs
        self.config = config
        self.pipeline = None
        self.align = rs.align(rs.stream.color)
        self.cloud = rs.pointcloud()
        self.depth_scale_mm = 1.0

    def open(self) -> None:
        rs, c = self.rs, self.config
        width, height = (int(v) for v in c["size"])
        cfg = rs.config()
        source = c["source"]
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

    def frame(self, with_cloud: bool) -> WristFrame:
        try:
            frames = self.pipeline.wait_for_frames(int(self.config["frame_timeout"] * 1000))
        except RuntimeError as e:
            raise CameraError(
                "no frames from the wrist camera for %.1f s (drivers.wrist_camera.frame_timeout; "
                "%s); check its USB cable" % (self.config["frame_timeout"], e)
            ) from e
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
        out = WristFrame(
            stamp=colour_frame.get_timestamp() / 1000.0,
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
        if self.pipeline is not None:
            try:
                self.pipeline.stop()
            except RuntimeError:
                pass
