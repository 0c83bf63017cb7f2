"""An emulated D435 for the tests: librealsense's software_device with a depth and a colour
sensor (the D435's stream layout, intrinsics and depth units), whose frames are recorded with
the SDK's own recorder, so the wrist camera driver plays them through the real pipeline,
rs.align and rs.pointcloud, unchanged. The default scene is what the wrist camera sees over the
pickup mat: a flat mat 0.40 m away with a 10 mm high sherd on it. No ROS here.
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


def record(path: str, frames: Iterable[Tuple[np.ndarray, np.ndarray]], rs, fps: int = 30) -> None:
    """Writes `frames` ((colour, depth) pairs) as a D435 recording the pipeline can play."""
    frames = list(frames)
    height, width = frames[0][1].shape
    device = rs.software_device()
    device.register_info(rs.camera_info.name, "Intel RealSense D435 (emulated)")
    device.register_info(rs.camera_info.serial_number, "000000000435")
    depth_sensor = device.add_sensor("Stereo Module")
    colour_sensor = device.add_sensor("RGB Camera")
    intrinsics = rs.intrinsics()
    intrinsics.width, intrinsics.height = width, height
    intrinsics.fx, intrinsics.fy, intrinsics.ppx, intrinsics.ppy = FX, FY, CX, CY
    intrinsics.model = rs.distortion.brown_conrady
    intrinsics.coeffs = [0.0] * 5

    def stream(kind, fmt, bpp, uid):
        s = rs.video_stream()
        s.type, s.index, s.uid = kind, 0, uid
        s.width, s.height, s.fps, s.bpp, s.fmt = width, height, fps, bpp, fmt
        s.intrinsics = intrinsics
        return s

    depth_profile = depth_sensor.add_video_stream(stream(rs.stream.depth, rs.format.z16, 2, 0))
    colour_profile = colour_sensor.add_video_stream(stream(rs.stream.color, rs.format.rgb8, 3, 1))
    depth_sensor.add_read_only_option(rs.option.depth_units, DEPTH_UNITS)
    extrinsics = rs.extrinsics()
    extrinsics.rotation = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    extrinsics.translation = [COLOUR_OFFSET, 0.0, 0.0]  # p_colour = p_depth + t
    depth_profile.register_extrinsics_to(colour_profile, extrinsics)
    recorder = rs.recorder(path, device)
    rec_depth, rec_colour = recorder.query_sensors()
    sink = rs.frame_queue(len(frames) * 2 + 2)
    rec_depth.open(depth_profile)
    rec_colour.open(colour_profile)
    rec_depth.start(sink)
    rec_colour.start(sink)
    for n, (colour, depth) in enumerate(frames):
        for sensor, profile, pixels, bpp in (
            (depth_sensor, depth_profile, depth, 2),
            (colour_sensor, colour_profile, colour, 3),
        ):
            f = rs.software_video_frame()
            f.pixels = np.ascontiguousarray(pixels)
            f.bpp, f.stride = bpp, width * bpp
            f.timestamp = n * 1000.0 / fps
            f.domain = rs.timestamp_domain.hardware_clock
            f.frame_number = n
            f.profile = profile.as_video_stream_profile()
            sensor.on_video_frame(f)
        time.sleep(1.0 / fps)  # the recorder stamps what it receives in real time
    rec_depth.stop()
    rec_colour.stop()
    rec_depth.close()
    rec_colour.close()
    del recorder  # closes the file
