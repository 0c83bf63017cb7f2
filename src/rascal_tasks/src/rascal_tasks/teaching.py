"""Teaching a station's place by demonstration (issue 17 item 6). No ROS in here.

The person jogs the gripper, pointing down just above the station's surface, to where a sherd
should be set down and turned as it should lie (for the archival photo: along the scale bar),
and saves: `stations.<name>.taught_place: [x, y, yaw]`, which later batches use (station_states:
PLACE_i and TRANSLATE_i). Every jog is a checked move and the pose saved is the one measured after
it (forward kinematics through TF), never the one asked for.

Commands, one per line (a terminal or a pipe): `x+5` / `y-2.5` (millimetres, base_link axes:
x away from the arm, y to its left), `yaw+15` (degrees, anticlockwise seen from above), `show`,
`save`, `quit`.
"""

import math
import re
from dataclasses import dataclass
from typing import Callable, Iterable, Optional, TextIO, Tuple

from rascal_tasks.rig import RigError
from rascal_tasks.stations import STATION_PLUGINS

# The gripper's tip this high above the station's surface while teaching: low enough to judge
# where the sherd will lie, clear of the surface and of a sherd lying there.
TEACH_HEIGHT = 0.02  # [m]
# The measured pose must be this close to the one asked for (the controller's goal tolerance
# is 0.002 rad per joint: about 1 mm at the gripper).
ARRIVED_XY = 0.002  # [m]
ARRIVED_YAW = math.radians(1.0)  # [rad]
# The controller's answers to a jog that leave the arm where it was: said, and teaching goes on.
REFUSED_MOVES = ("UNREACHABLE", "COLLISION")
_JOG = re.compile(r"^(x|y|yaw)\s*([+-])\s*(\d+(?:\.\d*)?)$")


class TeachError(Exception):
    """One line for the person teaching; the session goes on (or, from the arm, stops)."""


@dataclass(frozen=True)
class Place:
    x: float  # [m]
    y: float  # [m]
    yaw: float  # [rad]

    def text(self) -> str:
        return "(%.4f, %.4f) m, yaw %.1f°" % (
            self.x,
            self.y,
            round(math.degrees(self.yaw), 1) + 0.0,
        )


def wrap(angle: float) -> float:
    """The same direction in [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def jogged(place: Place, command: str, area) -> Place:
    """`place` moved by one jog command; TeachError for a command that is not one or a place off
    the station (`area`: config.Rect)."""
    m = _JOG.match(command.strip().lower())
    if not m:
        raise TeachError(
            "%r: not a command; x+5, y-2.5 (mm), yaw+15 (degrees), show, save or quit" % command
        )
    axis, sign, amount = m.group(1), m.group(2), float(m.group(3))
    step = amount if sign == "+" else -amount
    if axis == "yaw":
        return Place(place.x, place.y, wrap(place.yaw + math.radians(step)))
    dx, dy = (step / 1000, 0.0) if axis == "x" else (0.0, step / 1000)
    new = Place(place.x + dx, place.y + dy, place.yaw)
    if not area.has((new.x, new.y)):
        raise TeachError(
            "%s: would leave the station (corners %s m); the place must lie on it"
            % (command.strip(), ", ".join("(%.3f, %.3f)" % c for c in area.corners()))
        )
    return new


def _yaw_gap(a: float, b: float) -> float:
    """Angle between two gripper yaws; the two fingers are alike, so a half turn is none."""
    d = abs(wrap(a - b)) % math.pi
    return min(d, math.pi - d)


def teach_height(station, travel_z: float) -> float:
    """ee_gripper_link's height while teaching: where the sherd is let go (a box's sherds fall
    from travel height; elsewhere they are set down on the surface)."""
    from_above = station.type == "bin" or STATION_PLUGINS[station.type].release_from_above
    return travel_z if from_above else station.surface_z + TEACH_HEIGHT


def teach(
    station,
    start: Place,
    move: Callable[[Place, float], None],
    measure: Callable[[], Tuple[float, float, float, float]],
    commands: Iterable[str],
    out: TextIO,
    z: float,
) -> Optional[Place]:
    """One teaching session at `station` (config.Station): the gripper to `start` at height `z`,
    then each command. `move(place, z)` puts the gripper there pointing down (a RigError when it
    cannot: a jog the controller refuses, unreachable or colliding, is said and ignored; any other
    ends the session); `measure()` is its pose now, (x, y, z, yaw) in base_link. Returns the
    measured place on `save`, None on `quit` or the end of the commands."""
    wanted = start
    here = _go(move, measure, wanted, z)
    print("at %s; jog with x+5, y-2.5 (mm), yaw+15 (°); then save or quit" % here.text(), file=out)
    for line in commands:
        command = line.strip().lower()
        if not command:
            continue
        if command == "quit":
            return None
        if command == "save":
            return here
        if command == "show":
            print("at %s" % here.text(), file=out)
            continue
        try:
            nxt = jogged(wanted, command, station.area)
        except TeachError as e:
            print("refused: %s" % e, file=out)
            continue
        try:
            here, wanted = _go(move, measure, nxt, z), nxt
        except RigError as e:
            if e.code not in REFUSED_MOVES:
                raise
            print("refused: %s: %s" % (command, e.reason), file=out)
            continue
        print("at %s" % here.text(), file=out)
    return None


def teach_by_hand(
    station,
    limp: Callable[[bool], None],
    measure: Callable[[], Tuple[float, float, float, float]],
    commands: Iterable[str],
    out: TextIO,
) -> Optional[Place]:
    """Teaching on the field rig with the arm's torque off: the person puts the gripper where a
    sherd should be let go, pointing down, and presses Enter (an empty line); the place is read,
    checked against the station and offered: `save`, or Enter again to take another. The torque
    comes back (holding the arm where it was left) before this returns, whatever happened."""
    limp(True)
    try:
        print(
            "the arm is limp: hold it, put the gripper where a sherd should be let go, pointing "
            "down, and press Enter (quit: leave)",
            file=out,
        )
        here = None
        for line in commands:
            command = line.strip().lower()
            if command == "quit":
                return None
            if command == "save":
                if here is not None:
                    return here
                print("refused: nothing read yet; press Enter to read the place", file=out)
                continue
            if command:
                print("refused: %r: press Enter to read the place, then save" % command, file=out)
                continue
            x, y, _, yaw = measure()
            if not station.area.has((x, y)):
                print(
                    "refused: (%.4f, %.4f) m is not on the station; move it there" % (x, y),
                    file=out,
                )
                here = None
                continue
            here = Place(x, y, yaw)
            print("read %s: save, or move it and press Enter again" % here.text(), file=out)
        return None
    finally:
        limp(False)


def _go(move, measure, place: Place, z: float) -> Place:
    """Move, then the place as measured; TeachError when the arm is not where it was sent."""
    move(place, z)
    x, y, _, yaw = measure()
    got = Place(x, y, yaw)
    if math.hypot(x - place.x, y - place.y) > ARRIVED_XY or _yaw_gap(yaw, place.yaw) > ARRIVED_YAW:
        raise TeachError(
            "the gripper is at %s, not at %s where it was sent; nothing saved"
            % (got.text(), place.text())
        )
    # the fingers are alike: a yaw measured half a turn off is the one asked for
    return Place(x, y, yaw if abs(wrap(yaw - place.yaw)) <= math.pi / 2 else wrap(yaw + math.pi))
