"""WristFrame -> the simulator's wrist camera messages (sensor_msgs value types only, no rospy):
rgb8 colour, 16UC1 aligned depth in mm, CameraInfo (plumb_bob, K/P from the colour intrinsics)
and a PointCloud2 of valid points with x y z rgb float32 fields, all in
camera_color_optical_frame, the layout rascal_sim publishes."""

import numpy as np
from sensor_msgs.msg import CameraInfo, Image, PointCloud2, PointField

FRAME = "camera_color_optical_frame"


def image(array: np.ndarray, encoding: str, stamp) -> Image:
    msg = Image(height=array.shape[0], width=array.shape[1], encoding=encoding, is_bigendian=0)
    msg.header.stamp, msg.header.frame_id = stamp, FRAME
    msg.step = array.strides[0]
    msg.data = np.ascontiguousarray(array).tobytes()
    return msg


def camera_info(intrinsics, stamp) -> CameraInfo:
    i = intrinsics
    msg = CameraInfo(width=i.width, height=i.height, distortion_model="plumb_bob")
    msg.header.stamp, msg.header.frame_id = stamp, FRAME
    msg.D = list(i.coeffs[:5]) + [0.0] * (5 - len(i.coeffs[:5]))
    msg.K = [i.fx, 0.0, i.cx, 0.0, i.fy, i.cy, 0.0, 0.0, 1.0]
    msg.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    msg.P = [i.fx, 0.0, i.cx, 0.0, 0.0, i.fy, i.cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    return msg


def point_cloud(points: np.ndarray, colours: np.ndarray, stamp) -> PointCloud2:
    n = len(points)
    packed = np.zeros((n, 4), np.float32)
    packed[:, :3] = points
    rgb = (
        (colours[:, 0].astype(np.uint32) << 16)
        | (colours[:, 1].astype(np.uint32) << 8)
        | colours[:, 2].astype(np.uint32)
    )
    packed[:, 3] = rgb.view(np.float32)  # PCL's float rgb: 0x00RRGGBB
    msg = PointCloud2(height=1, width=n, is_bigendian=False, is_dense=True, point_step=16)
    msg.header.stamp, msg.header.frame_id = stamp, FRAME
    msg.fields = [
        PointField(name=name, offset=4 * k, datatype=PointField.FLOAT32, count=1)
        for k, name in enumerate(("x", "y", "z", "rgb"))
    ]
    msg.row_step = 16 * n
    msg.data = packed.tobytes()
    return msg
