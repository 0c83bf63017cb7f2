"""`rascal doctor`: checks every device of the configured field rig and says what to fix.

One `Item` per check, in the order an operator fixes things (cable before baud before IDs):
the U2D2 and each of the nine servos (present, model, firmware, ID, baud, torque, hardware
error), the scale (present, answering in the configured protocol, stable), the archival camera
and the wrist D435 (found, model/firmware, one frame). Nothing is changed on a device: no
torque is switched, no tare is done. Every wait has a deadline from drivers.* of the
configuration. The libraries (dynamixel_sdk, pyserial, OpenCV, gphoto2, pyrealsense2) are
imported only when their device is checked. No ROS here: the drivers must not be running (they
hold the serial lines and the cameras).
"""

import importlib
import os
import time
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional

from rascal_drivers import control_table as ct
from rascal_drivers import workspace_venv
from rascal_drivers.parameters import EMULATED

OK, WARN, FAIL = "ok", "warn", "FAIL"
MODEL_NAMES = {ct.XM430_W350: "XM430-W350", ct.XL430_W250: "XL430-W250"}
DEVICES = ("arm", "scale", "archival_camera", "wrist_camera")
SCALE_STABLE_WITHIN = 5.0  # [s] a scale on a still table with an empty pan settles in 1-3 s
UDEV_RULES = "src/rascal_drivers/udev/99-rascal.rules"


@dataclass
class Item:
    device: str  # arm, scale, archival_camera, wrist_camera
    what: str  # what was checked, e.g. "servo 4 (elbow)"
    status: str  # ok, warn, FAIL
    detail: str  # what was found
    fix: str = ""  # what to do (FAIL and warn only)

    def line(self) -> str:
        text = "%-4s  %-16s %s: %s" % (self.status, self.device, self.what, self.detail)
        return text + ("; fix: " + self.fix if self.fix else "")


def _import(name: str):
    workspace_venv.add()  # dynamixel_sdk and pyrealsense2 live in the workspace's .venv
    return importlib.import_module(name)


# ---------------------------------------------------------------------- arm
def check_arm(section: dict, sdk=None) -> List[Item]:
    from rascal_drivers import arm_bus

    items: List[Item] = []

    def add(what, status, detail, fix=""):
        items.append(Item("arm", what, status, detail, fix))

    try:
        config = arm_bus.config_from_section(section)
    except ValueError as e:
        add("configuration", FAIL, str(e), "correct it in config/rascal.yaml")
        return items
    device = config.device
    if not os.path.exists(device):
        add(
            "U2D2 adapter",
            FAIL,
            "%s does not exist" % device,
            "plug the U2D2's USB cable into the computer and its power supply into the arm; "
            "install %s (makes /dev/ttyDXL), or set drivers.arm.device" % UDEV_RULES,
        )
        return items
    sdk = sdk or _import("dynamixel_sdk")
    port = sdk.PortHandler(device)
    packet = sdk.PacketHandler(2.0)
    try:
        opened = port.openPort() and port.setBaudRate(config.baud)
    except Exception as e:  # pyserial's SerialException, OSError (permissions)
        opened, why = False, str(e)
    else:
        why = "the port did not open"
    if not opened:
        add(
            "U2D2 adapter",
            FAIL,
            "cannot open %s at %d baud (%s)" % (device, config.baud, why),
            "stop arm_driver (it holds the line) or add your user to the dialout group",
        )
        return items
    add("U2D2 adapter", OK, "%s open at %d baud" % (device, config.baud))
    slow = arm_bus.latency_warning(device)
    if slow:
        add("USB latency", WARN, slow.split("; ")[0], "install %s, replug the U2D2" % UDEV_RULES)
    try:
        port.ser.timeout = 0.001
        _check_servos(config, sdk, port, packet, add)
    finally:
        try:
            port.closePort()
        except Exception:
            pass
    return items


def _ping(sdk, port, packet, dxl_id: int, deadline: float) -> Optional[int]:
    while True:
        try:
            port.ser.reset_input_buffer()
            model, result, _ = packet.ping(port, dxl_id)
        except Exception:
            result, model = None, None
        if result == sdk.COMM_SUCCESS:
            return model
        if time.monotonic() > deadline:
            return None
        time.sleep(0.01)


def _read(sdk, port, packet, dxl_id: int, name: str) -> Optional[int]:
    f = ct.field(name)
    reader = {1: packet.read1ByteTxRx, 2: packet.read2ByteTxRx, 4: packet.read4ByteTxRx}[f.size]
    for _ in range(3):
        try:
            port.ser.reset_input_buffer()
            value, result, _ = reader(port, dxl_id, f.address)
        except Exception:
            continue
        if result == sdk.COMM_SUCCESS:
            return value
    return None


def _check_servos(config, sdk, port, packet, add: Callable) -> None:
    from rascal_drivers import arm_bus

    deadline = time.monotonic() + config.connect_timeout
    present: Dict[str, int] = {}
    missing: List[str] = []
    for role in arm_bus.ROLES:
        dxl_id = config.ids[role]
        model = _ping(sdk, port, packet, dxl_id, deadline)
        if model is None:
            missing.append(role)
        else:
            present[role] = model
            deadline = max(deadline, time.monotonic() + 0.2)  # the bus answers: short waits now
    if not present:
        add(
            "servos",
            FAIL,
            "none of IDs %s answers on %s at %d baud within %.1f s"
            % (
                ",".join(str(config.ids[r]) for r in arm_bus.ROLES),
                config.device,
                config.baud,
                config.connect_timeout,
            ),
            "switch on the arm's 12 V supply (the servos' LEDs blink once), check the cable "
            "from the U2D2 to the arm's base, and that drivers.arm.baud is the servos' rate "
            "(the wx250s ships at 1000000)",
        )
        return
    others = _broadcast_ping(sdk, port, packet) if missing else {}
    strangers = sorted(set(others) - set(config.ids.values()))
    for role in arm_bus.ROLES:
        dxl_id = config.ids[role]
        where = "servo %d (%s)" % (dxl_id, role)
        want = arm_bus.MODEL[role]
        if role in missing:
            hint = (
                "; a servo answers as ID %s: set its ID to %d with Dynamixel Wizard or put %s in "
                "drivers.arm.ids" % (",".join(str(i) for i in strangers), dxl_id, strangers[0])
                if strangers
                else ""
            )
            add(
                where,
                FAIL,
                "does not answer a ping",
                "check the 3-pin cable into this servo and the one before it in the chain%s" % hint,
            )
            continue
        model = present[role]
        firmware = _read(sdk, port, packet, dxl_id, "firmware_version")
        if model != want:
            add(
                where,
                FAIL,
                "is a %s (model %d), expected %s"
                % (MODEL_NAMES.get(model, "servo"), model, MODEL_NAMES[want]),
                "drivers.arm.ids lists the servos in the order waist, shoulder, shoulder shadow, "
                "elbow, elbow shadow, forearm roll, wrist angle, wrist rotate, gripper",
            )
            continue
        torque = _read(sdk, port, packet, dxl_id, "torque_enable")
        error = _read(sdk, port, packet, dxl_id, "hardware_error_status")
        facts = "%s, firmware %s, torque %s" % (
            MODEL_NAMES[want],
            "?" if firmware is None else "v%d" % firmware,
            {None: "?", 0: "off"}.get(torque, "on"),
        )
        if error:
            add(
                where,
                FAIL,
                "%s, hardware error: %s" % (facts, ct.describe_hardware_error(error)),
                "remove what blocks the arm, switch the arm's power off for 5 s and on again",
            )
        elif torque is None or error is None:
            add(where, FAIL, facts + ", does not answer reads", "check its cable")
        else:
            add(where, OK, facts)
    if present and not missing:
        add(
            "servo bus",
            OK,
            "all 9 servos answer at %d baud (IDs %s)"
            % (config.baud, ",".join(str(config.ids[r]) for r in arm_bus.ROLES)),
        )


def _broadcast_ping(sdk, port, packet) -> Dict[int, list]:
    try:
        port.ser.reset_input_buffer()
        data, result = packet.broadcastPing(port)
    except Exception:
        return {}
    return dict(data) if result == sdk.COMM_SUCCESS else {}


# ---------------------------------------------------------------------- scale
def check_scale(section: dict, serial=None) -> List[Item]:
    from rascal_drivers.scale_link import ScaleFault, ScaleLink
    from rascal_drivers.scale_protocols import PROTOCOLS

    items: List[Item] = []

    def add(what, status, detail, fix=""):
        items.append(Item("scale", what, status, detail, fix))

    device = section["device"]
    if not os.path.exists(device):
        add(
            "serial line",
            FAIL,
            "%s does not exist" % device,
            "plug in the scale's serial (USB) cable and switch the scale on; put its adapter's "
            "IDs in %s (makes /dev/ttyScale), or set drivers.scale.device" % UDEV_RULES,
        )
        return items
    serial = serial or _import("serial")
    try:
        port = serial.Serial(device, section["baud"], timeout=section["reply_timeout"])
    except (serial.SerialException, OSError) as e:
        add(
            "serial line",
            FAIL,
            "cannot open %s (%s)" % (device, e),
            "stop scale_driver (it holds the line) or add your user to the dialout group",
        )
        return items
    add("serial line", OK, "%s open at %d baud 8N1" % (device, section["baud"]))
    link = ScaleLink(port, PROTOCOLS[section["protocol"]](), device, section["disconnect_timeout"])
    try:
        reading, why, start = None, "", time.monotonic()
        while reading is None:
            try:
                reading, why = link.poll()
            except ScaleFault as e:
                add(
                    "answering",
                    FAIL,
                    str(e).split("; ")[0],
                    "set drivers.scale.protocol to the scale's (mt_sics or a_and_d) and "
                    "drivers.scale.baud to the rate in the scale's interface menu; switch it on",
                )
                return items
            if reading is None:
                time.sleep(section["poll_period"])
        add(
            "answering",
            OK,
            "%s, %.1f g on the pan after %.1f s"
            % (section["protocol"], reading.mass * 1000.0, time.monotonic() - start),
        )
        deadline = time.monotonic() + SCALE_STABLE_WITHIN
        while not reading.stable and time.monotonic() < deadline:
            time.sleep(section["poll_period"])
            try:
                got, why = link.poll()
            except ScaleFault as e:
                add("stable", FAIL, str(e).split("; ")[0], "check the scale's cable and power")
                return items
            reading = got or reading
        if reading.stable:
            add("stable", OK, "stable at %.1f g" % (reading.mass * 1000.0))
        else:
            add(
                "stable",
                FAIL,
                "not stable within %.0f s (%.1f g)" % (SCALE_STABLE_WITHIN, reading.mass * 1e3),
                "close the draught shield, take everything off the pan, put the scale on a "
                "still table away from the arm's base, and level it (bubble in the circle)",
            )
    finally:
        port.close()
    return items


# ---------------------------------------------------------------------- cameras
def check_archival_camera(section: dict, cv2=None, gp=None) -> List[Item]:
    from rascal_drivers.archival_camera import CaptureError, GphotoCamera, OpenCvCamera

    items: List[Item] = []

    def add(what, status, detail, fix=""):
        items.append(Item("archival_camera", what, status, detail, fix))

    cv2 = cv2 or _import("cv2")
    if section["kind"] == "opencv":
        device = section["device"]
        if device.startswith("/dev/") and not os.path.exists(device):
            add(
                "USB camera",
                FAIL,
                "%s does not exist" % device,
                "plug the camera in (v4l2-ctl --list-devices names its /dev/videoN) and set "
                "drivers.archival_camera.device",
            )
            return items
        camera = OpenCvCamera(cv2, section)
        try:
            camera.open()
            ok, image = camera.capture_.read()
        except CaptureError as e:
            add("USB camera", FAIL, str(e).split("; ")[0], "plug the camera in or set the path")
            return items
        finally:
            camera.close()
        if not ok or image is None:
            add("USB camera", FAIL, "%s opens but gives no frame" % device, "replug the camera")
        else:
            add("USB camera", OK, "%s answers, %dx%d px" % (device, image.shape[1], image.shape[0]))
        return items
    if section["device"].startswith(EMULATED):
        add(
            "DSLR",
            WARN,
            "emulated (%s: the simulator takes the pictures)" % section["device"],
            "on the rig, set drivers.archival_camera.device back to /dev/video0 (rig --emulated "
            "sets it itself)",
        )
        return items
    try:
        gp = gp or _import("gphoto2")
    except ImportError:
        add("DSLR", FAIL, "libgphoto2 is not installed", "run scripts/setup.sh (python3-gphoto2)")
        return items
    camera = GphotoCamera(gp, cv2, section)
    try:
        camera.open()  # also sets exposure, ISO and white balance, as the driver does
        model = camera.camera.get_abilities().model
    except CaptureError as e:
        add(
            "DSLR",
            FAIL,
            str(e).split("; ")[0],
            "connect it by USB, switch it on, set it to PTP and JPEG, or set "
            "drivers.archival_camera.kind: opencv",
        )
        return items
    except Exception as e:  # gphoto2 errors reading the abilities
        add("DSLR", FAIL, "answers but not its model (%s)" % e, "switch it off and on again")
        return items
    finally:
        camera.close()
    add("DSLR", OK, "%s answers; exposure, ISO, white balance set" % model)
    return items


def check_wrist_camera(section: dict, rs=None) -> List[Item]:
    from rascal_drivers.wrist_camera import CameraError, RealSenseCamera, check_config

    items: List[Item] = []

    def add(what, status, detail, fix=""):
        items.append(Item("wrist_camera", what, status, detail, fix))

    try:
        check_config(section)
    except ValueError as e:
        add("configuration", FAIL, str(e), "correct it in config/rascal.yaml")
        return items
    source = section["source"]
    if source.startswith(EMULATED):
        add(
            "D435",
            WARN,
            "emulated (%s: the simulator's images through librealsense's software device)" % source,
            "on the rig, set drivers.wrist_camera.source: usb (rig --emulated sets it itself)",
        )
        return items
    rs = rs or _import("pyrealsense2")
    if source == "usb":
        devices = list(rs.context().query_devices())
        if not devices:
            add(
                "D435",
                FAIL,
                "no RealSense camera on USB",
                "plug the wrist camera's cable into a blue USB 3 port (lsusb shows 'Intel Corp. "
                "RealSense')",
            )
            return items
        for dev in devices:
            name = dev.get_info(rs.camera_info.name)
            serial = dev.get_info(rs.camera_info.serial_number)
            firmware = dev.get_info(rs.camera_info.firmware_version)
            usb = (
                dev.get_info(rs.camera_info.usb_type_descriptor)
                if dev.supports(rs.camera_info.usb_type_descriptor)
                else "?"
            )
            wanted = section["serial"] in ("any", serial)
            status = OK if "D435" in name and wanted else WARN
            fix = ""
            if "D435" not in name:
                fix = "the wrist camera must be a D435"
            elif not wanted:
                fix = "not drivers.wrist_camera.serial (%s)" % section["serial"]
            if usb.startswith("2"):
                status, fix = WARN, "plug it into a USB 3 port (blue): USB %s is too slow" % usb
            add(
                "D435",
                status,
                "%s serial %s, firmware %s, USB %s" % (name, serial, firmware, usb),
                fix,
            )
    elif not os.path.isfile(source):
        add(
            "recording",
            FAIL,
            "%s does not exist" % source,
            "set drivers.wrist_camera.source: usb, or the path of a recording",
        )
        return items
    camera = RealSenseCamera(rs, section)
    try:
        camera.open()
        frame = camera.frame(with_cloud=False)
    except CameraError as e:
        add(
            "frames",
            FAIL,
            str(e).split("; ")[0],
            "replug the camera; check drivers.wrist_camera.serial/size/rate",
        )
        return items
    finally:
        camera.close()
    valid = float((frame.depth_mm > 0).mean())
    add(
        "frames",
        OK if valid > 0.5 else WARN,
        "colour %dx%d and depth (%.0f %% valid) at %d Hz"
        % (frame.colour.shape[1], frame.colour.shape[0], 100 * valid, section["rate"]),
        "" if valid > 0.5 else "clean the lenses; the camera must see the mat from above",
    )
    return items


CHECKS = {
    "arm": check_arm,
    "scale": check_scale,
    "archival_camera": check_archival_camera,
    "wrist_camera": check_wrist_camera,
}


def check_rig(drivers: dict, only=DEVICES) -> List[Item]:
    """Every check of the devices in `only`, given the validated drivers section of the config
    (rascal_tasks.config fills its defaults). An exception out of a library is one FAIL item."""
    items: List[Item] = []
    for device in only:
        try:
            items += CHECKS[device](drivers[device])
        except Exception as e:  # a library failing in a way not foreseen: still one line
            if os.environ.get("RASCAL_DEBUG"):
                raise
            first = (str(e).strip().splitlines() or [type(e).__name__])[0]
            items.append(
                Item(
                    device,
                    "check",
                    FAIL,
                    "%s: %s" % (type(e).__name__, first),
                    "run again with RASCAL_DEBUG=1 and report the traceback",
                )
            )
    return items


def report(items: List[Item], out) -> bool:
    """The checklist on `out`, one line per item and a last line; True when nothing FAILed."""
    for item in items:
        print(item.line(), file=out)
    failed = sum(item.status == FAIL for item in items)
    warned = sum(item.status == WARN for item in items)
    if failed:
        print(
            "doctor: %d of %d checks failed; fix the FAIL lines from the top (a missing cable "
            "explains the lines below it), then run rascal doctor again" % (failed, len(items)),
            file=out,
        )
    else:
        print(
            "doctor: every device answers (%d checks%s); start the rig"
            % (len(items), ", %d warnings" % warned if warned else ""),
            file=out,
        )
    return not failed
