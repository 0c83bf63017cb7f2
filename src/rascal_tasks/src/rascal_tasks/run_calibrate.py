"""`rascal calibrate`: the wrist camera measures where each station stands, from its ArUco
markers, and a corrected layout is written (the node wrapper of marker_calibration.py).

For each station with markers, the arm puts the wrist camera over each marker where the site file
says it lies, takes a frame taken after the arm came to rest, finds the marker's corners and
casts them onto the table through the camera's pose in base_link (TF at the frame's stamp). The
arm is parked at the end, also after a failure or Ctrl-C. Nothing is written over the site file:
the corrected layout goes to its own file, checked by loading it like any configuration.
"""

import math
import os
import re
import sys

import numpy as np

from rascal_tasks import exit_codes, site_file
from rascal_tasks import marker_calibration as mc
from rascal_tasks.config import ConfigError, load_config
from rascal_tasks.survey import gripper_for_camera_over

IMAGE_TOPIC = "/camera/color/image_raw"
INFO_TOPIC = "/camera/color/camera_info"


def default_output(config_path: str) -> str:
    return os.path.join(os.path.dirname(os.path.abspath(config_path)), "rascal.calibrated.yaml")


class Calibration:
    def __init__(self, config_path: str, output: str):
        self.config_path = config_path
        self.output = output or default_output(config_path)
        self.session = None

    def main(self) -> int:
        try:
            cfg = load_config(self.config_path)
        except ConfigError as e:
            return exit_codes.fail(str(e), exit_codes.BAD_INPUT)
        specs = mc.stations_with_markers(cfg)
        if not specs:
            return exit_codes.fail(
                "%s: no station has calibration markers; add stations.<name>.marker_ids and "
                "marker_positions (README, Calibrating the layout)" % self.config_path,
                exit_codes.BAD_INPUT,
            )
        from rascal_tasks.ros_graph import Need
        from rascal_tasks.ros_session import ArmSession, SessionError

        camera = ("the wrist camera", "start the simulator or rascal_drivers wrist_camera_driver")
        needs = [Need("topic", IMAGE_TOPIC, *camera), Need("topic", INFO_TOPIC, *camera)]
        try:
            with ArmSession(cfg, self.config_path, "calibrate", needs) as self.session:
                poses, problems = self.measure(cfg, specs)
        except SessionError as e:
            return exit_codes.fail("%s; nothing written" % e, e.code)
        self.report(poses)
        if problems:
            for p in problems:
                print("error: %s" % p, file=sys.stderr)
            return exit_codes.fail("nothing written", exit_codes.INCOMPLETE)
        moved = {p.station: p for p in poses if not p.confirmed()}
        if not moved:
            print(
                "layout confirmed: every station within %.0f mm and %.1f° of %s; nothing written"
                % (mc.POSITION_TOLERANCE * 1e3, math.degrees(mc.TURN_TOLERANCE), self.config_path)
            )
            return exit_codes.COMPLETE
        return self.write(poses, moved)

    def measure(self, cfg, specs):
        """(the stations' poses, one line per refused station); SessionError on a fault."""
        from rascal_tasks.rig import RigError
        from rascal_tasks.ros_session import SessionError

        poses, problems = [], []
        try:
            for spec in specs:
                seen = {}
                for i, marker in enumerate(spec.markers):
                    seen.update(self.look_at(cfg, marker.id, spec.marker_position(i)))
                try:
                    pose = mc.station_pose(spec, seen)
                    poses.append(pose)
                    mc.check_pose(pose)
                except mc.CalibrationError as e:
                    problems.append(str(e))
        except RigError as e:
            stopped = self.session.stop.is_set()
            code = exit_codes.INTERRUPTED if stopped else exit_codes.FAULT
            raise SessionError(str(e), code) from None
        except mc.CalibrationError as e:
            raise SessionError(str(e), exit_codes.FAULT) from None
        return poses, problems

    def look_at(self, cfg, marker_id, xy):
        """{marker_id: its corners on the table} seen from above `xy`, or {} when not seen."""
        import rospy
        from cv_bridge import CvBridge
        from sensor_msgs.msg import CameraInfo, Image

        from rascal_tasks.ros_session import rotation

        ex, ey, yaw = gripper_for_camera_over(*xy)
        self.session.arm.move_down(ex, ey, cfg["survey"]["z"], yaw)
        self.session.clock.sleep(cfg["survey"]["settle_time"])
        at_rest = rospy.Time.now()
        wait = cfg["perception"]["frame_wait"] + 1.0
        deadline = rospy.get_time() + wait
        while True:  # a frame exposed after the arm stopped
            left = deadline - rospy.get_time()
            if left <= 0 or self.session.stop.is_set():
                raise mc.CalibrationError(
                    "%s: no frame after the arm stopped within %.1f s" % (IMAGE_TOPIC, wait)
                )
            try:
                img = rospy.wait_for_message(IMAGE_TOPIC, Image, timeout=max(left, 0.1))
            except rospy.ROSException:
                continue
            if img.header.stamp >= at_rest:
                break
        try:
            info = rospy.wait_for_message(INFO_TOPIC, CameraInfo, timeout=wait)
        except rospy.ROSException:
            raise mc.CalibrationError("%s: none within %.1f s" % (INFO_TOPIC, wait)) from None
        t = self.session.transform(img.header.frame_id, img.header.stamp)
        bgr = CvBridge().imgmsg_to_cv2(img, "bgr8")
        corners = mc.detect_markers(bgr).get(marker_id)
        if corners is None:
            return {}
        tr = t.transform.translation
        on_table = mc.pixels_to_table(
            corners,
            np.array(info.K).reshape(3, 3),
            np.array(info.D) if info.D else None,
            np.array(rotation(t.transform.rotation)),
            np.array([tr.x, tr.y, tr.z]),
        )
        return {marker_id: on_table}

    # one row of report(): station (configured x, y) (measured x, y) shift mm turn° (residual)
    _ROW = re.compile(r"^(\w+)\s+\(%s,%s\)\s+\(%s,%s\)%s mm%s°" % ((r"\s*([-\d.]+)",) * 6), re.M)

    @classmethod
    def parse_report(cls, out: str) -> dict:
        """station -> (measured x [m], measured y [m], turn [rad]) from what report() printed
        (benches and end-to-end tests read the command's output so)."""
        return {
            m.group(1): (float(m.group(4)), float(m.group(5)), math.radians(float(m.group(7))))
            for m in cls._ROW.finditer(out)
        }

    def report(self, poses):
        print(
            "%-10s %-18s %-18s %8s %8s %9s"
            % ("station", "configured [m]", "measured [m]", "shift", "turn", "residual")
        )
        for p in poses:
            print(
                "%-10s (%6.3f, %6.3f)   (%7.4f, %7.4f) %5.1f mm %6.2f° %6.2f mm"
                % (
                    p.station,
                    p.configured[0],
                    p.configured[1],
                    p.measured[0],
                    p.measured[1],
                    p.shift_norm * 1e3,
                    math.degrees(p.turn),
                    p.residual * 1e3,
                )
            )

    def write(self, poses, moved) -> int:
        """The site file with each station of `moved` (name -> StationPose) moved and turned to
        where it was measured, written to self.output once it loads and holds them."""
        with open(self.config_path, encoding="utf-8") as f:
            text = f.read()
        # a turn within the tolerance is the measurement's noise: the station keeps its yaw
        turns = {
            n: p.turned if abs(p.turned) > mc.TURN_TOLERANCE else 0.0 for n, p in moved.items()
        }
        corrected = site_file.move_stations(
            text, {n: (p.configured, p.measured, turns[n]) for n, p in moved.items()}
        )
        for n, p in moved.items():
            if turns[n]:
                corrected = site_file.set_station_value(corrected, n, "yaw", round(p.turn, 4))
        tmp = self.output + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(corrected)
        try:  # the written layout must load like any other and hold what was measured
            written = load_config(tmp)
            for p in poses:
                got = written["stations"][p.station]
                if p.station not in moved:
                    continue
                if math.dist(got["position"], p.measured) > 1e-4:
                    raise ConfigError("stations.%s.position: not rewritten" % p.station)
                if turns[p.station] and abs(got.get("yaw", 0.0) - p.turn) > 1e-3:
                    raise ConfigError("stations.%s.yaw: not rewritten" % p.station)
        except ConfigError as e:
            os.unlink(tmp)
            return exit_codes.fail(
                "the corrected layout is refused: %s; nothing written" % e, exit_codes.FAULT
            )
        os.replace(tmp, self.output)
        print(
            "wrote %s: %s moved; compare it with %s, copy it over, `rosparam load` it and "
            "restart the nodes" % (self.output, ", ".join(sorted(moved)), self.config_path)
        )
        return exit_codes.COMPLETE


def write_sheet(config_path: str, path: str, out=sys.stdout) -> int:
    """The configured markers on one page to print (marker_calibration.marker_sheet)."""
    import cv2

    try:
        specs = mc.stations_with_markers(load_config(config_path))
        if not specs:
            raise ConfigError("%s: no station has calibration markers" % config_path)
        page = mc.marker_sheet(specs)
    except (ConfigError, mc.CalibrationError) as e:
        return exit_codes.fail(str(e), exit_codes.BAD_INPUT)
    if not cv2.imwrite(path, page):
        return exit_codes.fail(
            "%s: cannot be written (a .png path in a folder that exists)" % path, exit_codes.FAULT
        )
    print(
        "wrote %s: %d markers; print at 100 %% (300 dpi), each 40 mm across between its black edges"
        % (path, sum(len(s.markers) for s in specs)),
        file=out,
    )
    return exit_codes.COMPLETE


def run(config_path: str, output: str = None) -> int:
    return Calibration(config_path, output).main()
