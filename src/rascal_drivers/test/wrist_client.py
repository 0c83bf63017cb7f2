#!/usr/bin/python3
"""Test helper for test_wrist_camera_node.py: reads the wrist camera topics as the detector
does, in its own process, and prints one JSON line. Usage: wrist_client.py U V"""

import json
import struct
import sys

import numpy as np
import rospy
from sensor_msgs.msg import CameraInfo, Image, PointCloud2


def main():
    rospy.init_node("wrist_client", anonymous=True)
    u, v = int(sys.argv[1]), int(sys.argv[2])
    cloud_sub_wait = 10.0
    colour = rospy.wait_for_message("/camera/color/image_raw", Image, timeout=10.0)
    depth = rospy.wait_for_message("/camera/aligned_depth_to_color/image_raw", Image, timeout=10.0)
    info = rospy.wait_for_message("/camera/color/camera_info", CameraInfo, timeout=10.0)
    dinfo = rospy.wait_for_message(
        "/camera/aligned_depth_to_color/camera_info", CameraInfo, timeout=10.0
    )
    cloud = rospy.wait_for_message(
        "/camera/depth/color/points", PointCloud2, timeout=cloud_sub_wait
    )
    d = np.frombuffer(depth.data, np.uint16).reshape(depth.height, depth.width)
    c = np.frombuffer(colour.data, np.uint8).reshape(colour.height, colour.width, 3)
    pts = np.frombuffer(cloud.data, np.float32).reshape(-1, 4)
    z = d[v, u] / 1000.0  # the point the cloud must hold for pixel (u, v)
    want = np.array([(u - info.K[2]) * z / info.K[0], (v - info.K[5]) * z / info.K[4], z])
    near = pts[np.argmin(np.linalg.norm(pts[:, :3] - want, axis=1))]
    rgb = struct.unpack("<I", struct.pack("<f", near[3]))[0]
    print(
        json.dumps(
            {
                "encodings": [colour.encoding, depth.encoding],
                "size": [colour.width, colour.height, depth.width, depth.height],
                "frames": [colour.header.frame_id, depth.header.frame_id, cloud.header.frame_id],
                "K": list(info.K),
                "K_depth": list(dinfo.K),
                "depth_at": int(d[v, u]),
                "colour_at": [int(x) for x in c[v, u]],
                "fields": [f.name for f in cloud.fields],
                "points": cloud.width,
                "valid_depth": int((d > 0).sum()),
                "nearest_point": [float(x) for x in near[:3]],
                "nearest_rgb": [(rgb >> 16) & 255, (rgb >> 8) & 255, rgb & 255],
            }
        )
    )


if __name__ == "__main__":
    main()
