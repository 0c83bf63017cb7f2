"""`rascal teach STATION`: the place where sherds are set down at a station, taught by jogging
the gripper there (the node wrapper of teaching.py). Commands come one per line from the terminal
(or a pipe); `save` stores the measured place as `stations.<name>.taught_place` in the site file
itself, after the changed file has loaded and checked like any configuration (a copy of the old
one is kept beside it as `.bak`). The arm is parked at the end, whatever happened.
"""

import os
import shutil
import sys

from rascal_tasks import exit_codes, site_file, teaching
from rascal_tasks.config import ConfigError, load_config

TEACHABLE = ("scale", "archival_camera", "discard", "bin")


LIMP_SERVICE = "/arm/limp"  # rascal_drivers arm_driver: the arm's torque off and on
LIMP_WAIT = 3.0  # [s]


def run(config_path: str, station_name: str, commands=None, out=sys.stdout, hand=False) -> int:
    try:
        cfg = load_config(config_path)
    except ConfigError as e:
        return exit_codes.fail(str(e), exit_codes.BAD_INPUT)
    station = cfg.stations.get(station_name)
    if station is None:
        return exit_codes.fail(
            "no station %r in %s; its stations: %s"
            % (station_name, config_path, ", ".join(cfg.stations)),
            exit_codes.BAD_INPUT,
        )
    if station.type not in TEACHABLE:
        return exit_codes.fail(
            "stations.%s: sherds are not set down on a %s station; teach one of %s"
            % (
                station_name,
                station.type,
                ", ".join(n for n, s in cfg.stations.items() if s.type in TEACHABLE),
            ),
            exit_codes.BAD_INPUT,
        )
    from rascal_tasks.rig import RigError
    from rascal_tasks.ros_session import ArmSession, SessionError

    start = teaching.Place(*station.place_at, station.place_yaw or 0.0)
    try:
        with ArmSession(cfg, config_path, "teach") as s:
            if hand:
                place = _by_hand(s, station, commands or sys.stdin, out)
                return _saved_or_not(config_path, station_name, place, out)
            travel_z = cfg["arm"]["travel_z"]
            at = []  # where the gripper was last sent

            def move(place, z):
                if not at:  # from wherever it stands: over the station first, then down
                    s.arm.move_down(place.x, place.y, travel_z, place.yaw)
                if at or abs(z - travel_z) > 1e-6:
                    # a turn on the spot is the wrist's alone: no straight line to follow
                    turn = at and (at[0].x, at[0].y) == (place.x, place.y)
                    s.arm.move_down(place.x, place.y, z, place.yaw, linear=not turn)
                at[:] = [place]

            try:
                z = teaching.teach_height(station, travel_z)
                place = teaching.teach(
                    station, start, move, s.gripper_pose, commands or sys.stdin, out, z
                )
            except RigError as e:
                code = exit_codes.INTERRUPTED if s.stop.is_set() else exit_codes.FAULT
                raise SessionError("%s; nothing saved" % e, code) from None
            except teaching.TeachError as e:
                raise SessionError(str(e), exit_codes.FAULT) from None
            finally:
                if at:  # up out of the box or off the pan before parking
                    try:
                        s.arm.move_down(at[0].x, at[0].y, travel_z, at[0].yaw, linear=True)
                    except RigError as e:
                        print("error: lifting before parking: %s" % e, file=sys.stderr)
    except SessionError as e:
        return exit_codes.fail(str(e), e.code)
    return _saved_or_not(config_path, station_name, place, out)


def _saved_or_not(config_path, station_name, place, out) -> int:
    if place is None:
        print("nothing saved; %s is as it was" % config_path, file=out)
        return exit_codes.INCOMPLETE
    return save(config_path, station_name, place, out)


def _by_hand(s, station, commands, out):
    """teaching.teach_by_hand on the field rig's arm driver (its /arm/limp service)."""
    import rospy
    from std_srvs.srv import SetBool

    from rascal_tasks.ros_session import SessionError

    try:
        rospy.wait_for_service(LIMP_SERVICE, timeout=LIMP_WAIT)
    except rospy.ROSException:
        raise SessionError(
            "%s: no arm driver offers it (the simulator's arm cannot be moved by hand); teach "
            "without --hand, by jogging" % LIMP_SERVICE,
            exit_codes.BAD_INPUT,
        ) from None
    call = rospy.ServiceProxy(LIMP_SERVICE, SetBool)

    def limp(on):
        try:
            res = call(on)
        except rospy.ServiceException as e:
            raise SessionError("%s: %s" % (LIMP_SERVICE, e), exit_codes.FAULT) from None
        if not res.success:
            raise SessionError("%s: %s" % (LIMP_SERVICE, res.message), exit_codes.FAULT)

    return teaching.teach_by_hand(station, limp, s.gripper_pose, commands, out)


def save(config_path: str, station: str, place: teaching.Place, out) -> int:
    with open(config_path, encoding="utf-8") as f:
        text = f.read()
    values = [round(v, 4) + 0.0 for v in (place.x, place.y, place.yaw)]  # + 0.0: never -0.0
    try:
        changed = site_file.set_station_value(text, station, "taught_place", values)
    except ValueError as e:
        return exit_codes.fail("%s; nothing saved" % e, exit_codes.BAD_INPUT)
    tmp = config_path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(changed)
    try:  # the changed file must load like any other and hold the place taught
        got = load_config(tmp)["stations"][station]["taught_place"]
        if got != values:
            raise ConfigError("stations.%s.taught_place: not written (got %r)" % (station, got))
    except ConfigError as e:
        os.unlink(tmp)
        return exit_codes.fail("%s; nothing saved" % e, exit_codes.FAULT)
    shutil.copy2(config_path, config_path + ".bak")
    os.replace(tmp, config_path)
    print(
        "saved stations.%s.taught_place: %s in %s (the old file: %s.bak); `rosparam load` it "
        "and the next `rascal run` sets sherds down there"
        % (station, values, config_path, config_path),
        file=out,
    )
    return exit_codes.COMPLETE
