"""An emulated D435: librealsense's software_device with a depth and a colour sensor (the D435's
stream layout, intrinsics and depth units), so the wrist camera driver gets its frames through
the real SDK path, rs.align and rs.pointcloud, unchanged. Two ways to feed it:

- `LiveD435`: frame by frame as they come (the emulated rig pushes the simulator's wrist camera
  images into it); the driver waits on it as on a camera's pipeline;
- `record()`: frames written with the SDK's own recorder, which the driver plays through its
  pipeline (the tests' fixed scene: a flat mat 0.40 m away with a 10 mm high sherd on it).

No ROS here.
"""

import time
from typing import Iterable, Tuple

import numpy as np

FX = FY = 615.0  # the simulator's wrist camera (rascal_sim README), close to facts §4.3
CX, CY = 320.0, 240.0
DEPTH_UNITS = 0.001  # [m] per depth count: the D435's default
COLOUR_OFFSET = 0.015  # [m] colour imager 15 mm from the depth origin (facts §4.1)
MAT_RGB = (26, 56, 140)  # the simulator's blue mat
SHERD_RGB = (170, 100, 60)


def mat_with_sherd(
    width=640, height=480, mat_z=0.40, sherd_height=0.010
) -> Tuple[np.ndarray, np.ndarray]:
    """(colour RGB, depth in counts): the sherd in the middle of the depth image; the colour
    imager, 15 mm to the left of the depth origin (x = -0.015 m in the optical frame), sees it
    shifted right by fx * 0.015 / z pixels."""
    depth = np.full((height, width), int(round(mat_z / DEPTH_UNITS)), np.uint16)
    u0, u1, v0, v1 = width // 2 - 40, width // 2 + 40, height // 2 - 30, height // 2 + 30
    depth[v0:v1, u0:u1] = int(round((mat_z - sherd_height) / DEPTH_UNITS))
    colour = np.empty((height, width, 3), np.uint8)
    colour[:] = MAT_RGB
    shift = int(round(FX * COLOUR_OFFSET / (mat_z - sherd_height)))
    colour[v0:v1, u0 + shift : u1 + shift] = SHERD_RGB
    return colour, depth


class _SoftwareD435:
    """The device: two sensors, one stream each, the colour imager `colour_offset` metres along
    x from the depth origin (0 when the depth is aligned to colour already, as the simulator's)."""

    def __init__(
        self, rs, width, height, fx, fy, cx, cy, fps=30, colour_offset=COLOUR_OFFSET, matcher=None
    ):
        self.rs, self.width, self.height, self.fps = rs, width, height, fps
        self.device = rs.software_device()
        if matcher is not None:  # before the sensors are added, or the syncer pairs nothing
            self.device.create_matcher(matcher)
        self.device.register_info(rs.camera_info.name, "Intel RealSense D435 (emulated)")
        self.device.register_info(rs.camera_info.serial_number, "000000000435")
        self.depth_sensor = self.device.add_sensor("Stereo Module")
        self.colour_sensor = self.device.add_sensor("RGB Camera")
        intrinsics = rs.intrinsics()
        intrinsics.width, intrinsics.height = width, height
        intrinsics.fx, intrinsics.fy, intrinsics.ppx, intrinsics.ppy = fx, fy, cx, cy
        intrinsics.model = rs.distortion.brown_conrady
        intrinsics.coeffs = [0.0] * 5

        def stream(kind, fmt, bpp, uid):
            s = rs.video_stream()
            s.type, s.index, s.uid = kind, 0, uid
            s.width, s.height, s.fps, s.bpp, s.fmt = width, height, fps, bpp, fmt
            s.intrinsics = intrinsics
            return s

        self.depth_profile = self.depth_sensor.add_video_stream(
            stream(rs.stream.depth, rs.format.z16, 2, 0)
        )
        self.colour_profile = self.colour_sensor.add_video_stream(
            stream(rs.stream.color, rs.format.rgb8, 3, 1)
        )
        self.depth_sensor.add_read_only_option(rs.option.depth_units, DEPTH_UNITS)
        extrinsics = rs.extrinsics()
        extrinsics.rotation = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        extrinsics.translation = [colour_offset, 0.0, 0.0]  # p_colour = p_depth + t
        self.depth_profile.register_extrinsics_to(self.colour_profile, extrinsics)

    def send(self, sensor, profile, pixels: np.ndarray, bpp: int, stamp_ms: float, n: int):
        f = self.rs.software_video_frame()
        f.pixels = np.ascontiguousarray(pixels)
        f.bpp, f.stride = bpp, self.width * bpp
        f.timestamp = stamp_ms
        f.domain = self.rs.timestamp_domain.hardware_clock
        f.frame_number = n
        f.profile = profile.as_video_stream_profile()
        sensor.on_video_frame(f)


class LiveD435(_SoftwareD435):
    """Fed one colour + depth pair at a time (`push`, each stamped by its source in seconds);
    `wait_for_frames` gives the driver the SDK's frameset of the pair, as a camera's pipeline
    would, and `stamp_of` the source's stamp of a frame.

    The device's own clock ticks at its nominal frame rate (pair n at n / fps): the SDK's syncer
    pairs depth and colour only on a steady timestamp sequence starting near zero (with the
    simulator's stamps, which start late and stand still while no one looks, it stopped pairing
    after the first frames)."""

    depth_units = DEPTH_UNITS
    KEEP = 256  # stamps remembered: frames waiting in the syncer and the driver

    def __init__(self, rs, width, height, fx, fy, cx, cy, fps=30, colour_offset=0.0):
        # depth and colour paired by timestamp, as a D435's own matcher does
        super().__init__(rs, width, height, fx, fy, cx, cy, fps, colour_offset, rs.matchers.dlr_c)
        self.syncer = rs.syncer(2)
        self.depth_sensor.open(self.depth_profile)
        self.colour_sensor.open(self.colour_profile)
        self.depth_sensor.start(self.syncer)
        self.colour_sensor.start(self.syncer)
        self.count = 0
        self.stamps = {}

    def _check(self, what: str, pixels: np.ndarray, shape, dtype) -> None:
        if pixels.shape != shape or pixels.dtype != dtype:
            raise ValueError(
                "emulated D435 %s: expected %s %s, got %s %s"
                % (what, shape, np.dtype(dtype).name, pixels.shape, pixels.dtype.name)
            )

    def push(self, rgb: np.ndarray, depth: np.ndarray, stamp: float) -> None:
        """`rgb` (H, W, 3) uint8 and `depth` (H, W) uint16 in counts of `depth_units` (mm),
        aligned as the device's extrinsics say, both taken at `stamp`."""
        self._check("colour", rgb, (self.height, self.width, 3), np.uint8)
        self._check("depth", depth, (self.height, self.width), np.uint16)
        self.count += 1
        n = self.count
        self.stamps[n] = stamp
        self.stamps.pop(n - self.KEEP, None)
        tick_ms = n * 1000.0 / self.fps
        self.send(self.depth_sensor, self.depth_profile, depth, 2, tick_ms, n)
        self.send(self.colour_sensor, self.colour_profile, rgb, 3, tick_ms, n)

    def stamp_of(self, frame_number: int) -> float:
        return self.stamps.get(frame_number, float("nan"))

    def wait_for_frames(self, timeout_ms: int):
        return self.syncer.wait_for_frames(timeout_ms)

    def close(self) -> None:
        for sensor in (self.depth_sensor, self.colour_sensor):
            try:
                sensor.stop()
                sensor.close()
            except RuntimeError:
                pass


class StampPairs:
    """Colour and depth images arrive on two topics; `add` returns the (colour, depth, stamp)
    pair once both of one stamp are in, and forgets what is older (a frame whose partner never
    came)."""

    def __init__(self):
        self.waiting = {}  # stamp -> {"colour": ..., "depth": ...}

    def add(self, kind: str, pixels: np.ndarray, stamp: float):
        got = self.waiting.setdefault(stamp, {})
        got[kind] = pixels
        if len(got) < 2:
            for old in [t for t in self.waiting if t < stamp - 1.0]:
                del self.waiting[old]  # partner lost a second ago: never coming
            return None
        for old in [t for t in self.waiting if t <= stamp]:
            del self.waiting[old]
        return got["colour"], got["depth"], stamp


def record(path: str, frames: Iterable[Tuple[np.ndarray, np.ndarray]], rs, fps: int = 30) -> None:
    """Writes `frames` ((colour, depth) pairs) as a D435 recording the pipeline can play."""
    frames = list(frames)
    height, width = frames[0][1].shape
    d435 = _SoftwareD435(rs, width, height, FX, FY, CX, CY, fps)
    recorder = rs.recorder(path, d435.device)
    rec_depth, rec_colour = recorder.query_sensors()
    sink = rs.frame_queue(len(frames) * 2 + 2)
    rec_depth.open(d435.depth_profile)
    rec_colour.open(d435.colour_profile)
    rec_depth.start(sink)
    rec_colour.start(sink)
    for n, (colour, depth) in enumerate(frames):
        stamp_ms = n * 1000.0 / fps
        d435.send(d435.depth_sensor, d435.depth_profile, depth, 2, stamp_ms, n)
        d435.send(d435.colour_sensor, d435.colour_profile, colour, 3, stamp_ms, n)
        time.sleep(1.0 / fps)  # the recorder stamps what it receives in real time
    rec_depth.stop()
    rec_colour.stop()
    rec_depth.close()
    rec_colour.close()
    del recorder  # closes the file
