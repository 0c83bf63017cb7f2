#!/usr/bin/python3
"""The README's rviz picture: detections over the pickup area, rviz under Xvfb (docs only).

  source devel/setup.bash && src/rascal_perception/scripts/rviz_screenshot.py [out.png]

Starts a master on a free port, the simulator (demo scenario), robot_state_publisher and
sherd_detector; moves the arm over the pickup mat, calibrates the empty mat, spawns the demo
sherds, detects, opens rviz (config/detections.rviz) on a virtual display and grabs the screen
through libX11 (no screenshot tool needed).
"""

import ctypes
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
PKG = os.path.dirname(HERE)
WS = os.path.abspath(os.path.join(PKG, "..", ".."))
SURVEY = [0.8340, -0.1250, -0.0507, 0.0, 1.7465, -0.8340]  # see test/test_sherd_detector.py
ARM = ["waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate"]
W, H = 1280, 800


class XImage(ctypes.Structure):
    _fields_ = [
        ("width", ctypes.c_int),
        ("height", ctypes.c_int),
        ("xoffset", ctypes.c_int),
        ("format", ctypes.c_int),
        ("data", ctypes.c_void_p),
        ("byte_order", ctypes.c_int),
        ("bitmap_unit", ctypes.c_int),
        ("bitmap_bit_order", ctypes.c_int),
        ("bitmap_pad", ctypes.c_int),
        ("depth", ctypes.c_int),
        ("bytes_per_line", ctypes.c_int),
        ("bits_per_pixel", ctypes.c_int),
        ("red_mask", ctypes.c_ulong),
        ("green_mask", ctypes.c_ulong),
        ("blue_mask", ctypes.c_ulong),
    ]


def grab(display):
    x11 = ctypes.cdll.LoadLibrary("libX11.so.6")
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XDefaultRootWindow.restype = ctypes.c_ulong
    x11.XDefaultRootWindow.argtypes = [ctypes.c_void_p]
    x11.XGetImage.restype = ctypes.POINTER(XImage)
    x11.XGetImage.argtypes = [
        ctypes.c_void_p,
        ctypes.c_ulong,
        ctypes.c_int,
        ctypes.c_int,
        ctypes.c_uint,
        ctypes.c_uint,
        ctypes.c_ulong,
        ctypes.c_int,
    ]
    d = x11.XOpenDisplay(display.encode())
    if not d:
        raise RuntimeError("cannot open display " + display)
    img = x11.XGetImage(d, x11.XDefaultRootWindow(d), 0, 0, W, H, 0xFFFFFFFF, 2).contents
    raw = ctypes.string_at(img.data, img.bytes_per_line * img.height)
    a = np.frombuffer(raw, np.uint8).reshape(img.height, img.bytes_per_line // 4, 4)[
        :, : img.width, :3
    ]
    return a.copy()


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(PKG, "docs", "rviz_detections.png")
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    log = tempfile.mkdtemp(prefix="rascal_rviz_")
    env = dict(
        os.environ,
        ROS_MASTER_URI="http://127.0.0.1:%d" % port,
        ROS_HOSTNAME="127.0.0.1",
        ROS_LOG_DIR=log,
        ROS_HOME=log,
        DISPLAY=":97",
        LIBGL_ALWAYS_SOFTWARE="1",
    )
    procs = []

    def start(cmd):
        p = subprocess.Popen(
            cmd,
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        procs.append(p)
        return p

    def run(cmd):
        return subprocess.run(
            cmd, env=env, capture_output=True, text=True, check=True, timeout=120
        ).stdout

    try:
        start(["roscore", "-p", str(port)])
        start(["Xvfb", ":97", "-screen", "0", "%dx%dx24" % (W, H)])
        for _ in range(100):
            if (
                subprocess.run(
                    ["rosparam", "get", "/run_id"], env=env, capture_output=True
                ).returncode
                == 0
            ):
                break
            time.sleep(0.2)
        run(["rosparam", "load", os.path.join(WS, "config", "rascal.yaml")])
        run(["rosparam", "set", "/use_sim_time", "true"])
        run(["rosparam", "set", "/simulator/real_time_factor", "1.0"])
        run(
            [
                "rosparam",
                "set",
                "--textfile",
                os.path.join(WS, "src", "rascal_description", "urdf", "wx250s.urdf"),
                "/robot_description",
            ]
        )
        start(["rosrun", "rascal_sim", "sim"])
        start(["rosrun", "robot_state_publisher", "robot_state_publisher"])
        start(["rosrun", "rascal_perception", "sherd_detector"])
        time.sleep(5)  # the nodes come up
        run(
            [
                "rosservice",
                "call",
                "/sim/spawn",
                "{scenario_file: '', scenario_yaml: 'name: empty'}",
            ]
        )
        traj = "{joint_names: [%s], points: [{positions: [%s], time_from_start: {secs: 2}}]}" % (
            ", ".join(ARM),
            ", ".join(str(q) for q in SURVEY),
        )
        run(
            [
                "rostopic",
                "pub",
                "-1",
                "/arm/joint_trajectory",
                "trajectory_msgs/JointTrajectory",
                traj,
            ]
        )
        time.sleep(4)
        print(
            run(
                [
                    "rosservice",
                    "call",
                    "/rascal/perception/calibrate_background",
                    "{station: pickup}",
                ]
            )
        )
        demo = os.path.join(WS, "config", "scenarios", "demo_10.yaml")
        run(["rosservice", "call", "/sim/spawn", "{scenario_file: '%s', scenario_yaml: ''}" % demo])
        time.sleep(1)
        det = run(["rosservice", "call", "/rascal/perception/detect", "{station: pickup}"])
        print(det.splitlines()[0:2])
        start(["rviz", "-d", os.path.join(PKG, "config", "detections.rviz")])
        time.sleep(25)
        cv2.imwrite(out, grab(":97"))
        print("wrote", out)
    finally:
        for p in reversed(procs):
            try:
                os.killpg(p.pid, signal.SIGINT)
            except ProcessLookupError:
                pass
        time.sleep(2)
        for p in reversed(procs):
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


if __name__ == "__main__":
    main()
