"""Loads and validates the site configuration (config/rascal.yaml).

Every key is checked against the parameter schema (rascal_workcell/schema/parameters.yaml: type,
unit, range, default; unknown keys at any depth are refused naming the nearest known key); this
module adds the rules that relate keys to each other and to the arm (reach, overlaps, URDF limits).

Every Python node reads its configuration through `load_config` (from the file) or
`config_from_dict` (from the parameter server, after `rosparam load`). A bad value stops the node
with one line naming the file, the key, the value and what is expected, for example:

    config/rascal.yaml: stations.scale.position: expected [x, y] in metres, got 'abc'

Besides types and ranges it checks the layout as a whole: every station the arm must reach lies
within the wx250s's top-down reach, and no two stations (or a station and the camera stand)
overlap. No ROS in here.
"""

import hashlib
import json
import math
import os
from dataclasses import dataclass, field, replace
from typing import Dict, List, Optional, Tuple

import yaml

from rascal_workcell import schema, urdf_model
from rascal_workcell.fixtures import SCALE_HOUSING_MARGIN

from rascal_tasks.planar import local_of, placed, turned
from rascal_tasks.sorting import Rule, RuleError, parse_rule
from rascal_tasks.stations import STATION_PLUGINS
from rascal_tasks.survey import lawnmower

# --- wx250s geometry for the reach check, from the URDF (rascal_description) ---------------------
_ARM = urdf_model.arm_geometry()
SHOULDER_Z = _ARM.shoulder_z  # shoulder axis above base_link
UPPER_ARM = _ARM.upper_arm  # shoulder axis -> elbow axis
FOREARM = _ARM.forearm  # elbow axis -> wrist_angle axis
WRIST_TO_EE = _ARM.wrist_to_ee  # wrist_angle axis -> ee_gripper_link
# Stretched-out arm is singular and slow; keep 5 % in hand. Over the base the waist spins fast
# for small moves and the forearm hits the base: stay 10 cm out.
MAX_WRIST_DISTANCE = 0.95 * (UPPER_ARM + FOREARM)
MIN_RADIUS = 0.10

# Every station type with a plug-in (stations.py) can appear in the config; these four must.
REQUIRED_STATION_TYPES = ("pickup", "scale", "archival_camera", "discard")
ARM_JOINTS = urdf_model.ARM_JOINTS


class ConfigError(ValueError):
    """A configuration value is wrong; str() is one line naming the file, key and fix."""


def top_down_reachable(x: float, y: float, z: float) -> bool:
    """True when ee_gripper_link can be at (x, y, z) in base_link with the gripper pointing down."""
    r = math.hypot(x, y)
    wrist = math.hypot(r, z + WRIST_TO_EE - SHOULDER_Z)
    return MIN_RADIUS <= r and wrist <= MAX_WRIST_DISTANCE


@dataclass(frozen=True)
class Rect:
    """Rectangle on the table: centre and size [along its own x, along its own y] in metres,
    turned by yaw [rad] about +z (its station's `yaw`; 0 = square to the arm's base)."""

    center: Tuple[float, float]
    size: Tuple[float, float]
    yaw: float = 0.0

    def to_local(self, p) -> Tuple[float, float]:
        """p = (x, y) in base_link, in the rectangle's frame (origin at its centre, axes along
        its sides)."""
        return local_of(self.center, self.yaw, p)

    def to_table(self, local) -> Tuple[float, float]:
        """A point of the rectangle's frame in base_link."""
        return placed(self.center, self.yaw, local)

    def corners(self) -> List[Tuple[float, float]]:
        hx, hy = self.size[0] / 2, self.size[1] / 2
        return [self.to_table(c) for c in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy))]

    def overlaps(self, other: "Rect") -> bool:
        """Whether the two share more than an edge (separating axes: each one's sides)."""
        mine, theirs = self.corners(), other.corners()
        for r in (self, other):
            for ax in (turned((1.0, 0.0), r.yaw), turned((0.0, 1.0), r.yaw)):
                a = [ax[0] * x + ax[1] * y for x, y in mine]
                b = [ax[0] * x + ax[1] * y for x, y in theirs]
                if max(a) <= min(b) + 1e-12 or max(b) <= min(a) + 1e-12:
                    return False
        return True

    def contains(self, other: "Rect") -> bool:
        return all(self.has(c) for c in other.corners())

    def has(self, p) -> bool:
        """Whether the point p = (x, y) lies on the rectangle."""
        lx, ly = self.to_local(p)
        return abs(lx) <= self.size[0] / 2 + 1e-9 and abs(ly) <= self.size[1] / 2 + 1e-9

    def lawnmower(self, step: float) -> List[Tuple[float, float]]:
        """Boustrophedon centres covering the rectangle (`lawnmower` in its own frame)."""
        return [self.to_table(p) for p in lawnmower((0.0, 0.0), self.size, step)]


@dataclass(frozen=True)
class Fixture:
    area: Rect
    height: float = 0.0


@dataclass(frozen=True)
class Station:
    name: str
    type: str
    area: Rect
    surface_z: float
    place_at: Tuple[float, float]  # where a sherd is put (the centre unless the config says)
    wall_height: float = 0.0  # discard box and sorting bin walls
    camera_height: float = 0.0  # archival camera lens above the surface
    colour_chart: Optional[Fixture] = None
    scale_bar: Optional[Fixture] = None
    stand: Optional[Fixture] = None
    rule: Optional[Rule] = None  # a sorting bin's (sorting.py)
    place_yaw: Optional[float] = None  # [rad] gripper yaw of a taught place (else as picked up)
    over_scale: bool = False  # an archival camera that photographs the sherd on the scale


@dataclass(frozen=True)
class Config:
    """The validated site configuration. `data` is the checked dictionary as loaded."""

    source: str
    workspace: str
    data: dict
    stations: Dict[str, Station] = field(default_factory=dict)

    def __getitem__(self, key):
        return self.data[key]

    def station_order(self) -> List[str]:
        """Stations a sherd visits after pickup, in config order (a sorting bin only when its
        rule takes the sherd, in place of the discard box)."""
        return [n for n, s in self.stations.items() if s.type not in ("pickup", "bin")]

    def route(self) -> List[str]:
        """The stations a sherd is carried to and set down at, in order: station_order without
        a camera over the scale (`over_scale`), which works where the scale has the sherd."""
        return [n for n in self.station_order() if not self.stations[n].over_scale]

    def bins(self) -> List[Tuple[str, Rule]]:
        """The sorting bins (name, rule) in the order their rules are tried."""
        return [(n, s.rule) for n, s in self.stations.items() if s.type == "bin"]

    def resolve(self, path: str) -> str:
        """A path from the config, relative paths taken from the workspace root."""
        path = os.path.expanduser(path)
        return path if os.path.isabs(path) else os.path.join(self.workspace, path)

    @property
    def hash(self) -> str:
        """Short SHA-256 of the checked configuration, recorded with every sherd."""
        blob = json.dumps(self.data, sort_keys=True, separators=(",", ":")).encode()
        return hashlib.sha256(blob).hexdigest()[:16]


def _fail(source: str, key: str, message: str, got=None, show_got=True):
    raise ConfigError(
        "%s: %s: %s%s" % (source, key, message, ", got %r" % (got,) if show_got else "")
    )


def load_config(path: str, workspace: Optional[str] = None, over=()) -> Config:
    """Read and validate a config file, with the files `over` (a layout's keys, e.g.
    config/layouts/one_station.yaml) merged over it as `rosparam load` merges them. `workspace`
    defaults to the parent of its folder."""
    data = _read_yaml(path)
    for layer in over:
        data = merged(data, _read_yaml(layer))
    if workspace is None:
        workspace = os.path.dirname(os.path.dirname(os.path.abspath(path)))
    return config_from_dict(data, source=path, workspace=workspace)


def merged(base, over):
    """`base` with `over` merged in: mappings key by key at every depth, anything else replaced
    (what `rosparam load` does to the parameter server)."""
    if not isinstance(base, dict) or not isinstance(over, dict):
        return over
    out = dict(base)
    for k, v in over.items():
        out[k] = merged(base.get(k), v)
    return out


def _read_yaml(path: str):
    try:
        with open(path, encoding="utf-8") as f:
            return yaml.safe_load(f)
    except FileNotFoundError:
        raise ConfigError(
            "%s: file not found; pass the path of config/rascal.yaml" % path
        ) from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = " (line %d)" % (mark.line + 1) if mark else ""
        raise ConfigError(
            "%s: not valid YAML%s: %s" % (path, where, getattr(e, "problem", None) or e)
        ) from None


def config_from_dict(data, source="config/rascal.yaml", workspace=".") -> Config:
    """Validate an already-loaded configuration (e.g. from the ROS parameter server): every key
    against the parameter schema (rascal_workcell/schema/parameters.yaml), then the layout."""
    try:
        checked = schema.validate(data)
    except schema.SchemaError as e:
        raise ConfigError("%s: %s" % (source, e)) from None
    stations = _read_stations(source, checked["stations"])
    _check_arm(source, checked["arm"], stations)
    _check_survey(source, checked, stations)
    dsn = checked["database"]["dsn"]
    if not (dsn.startswith(("postgresql://", "postgres://")) or "=" in dsn):
        _fail(
            source,
            "database.dsn",
            "expected a libpq URI (postgresql://user:password@host:"
            "port/dbname) or key=value string",
            dsn,
        )
    sim = checked["simulator"]
    _check_joints(source, "simulator.initial_joints", sim["initial_joints"])
    lo, hi = urdf_model.finger_limits()
    if not lo <= sim["initial_finger"] <= hi:
        _fail(
            source,
            "simulator.initial_finger",
            "expected a number in metres in [%g, %g] (the " "URDF's finger limits)" % (lo, hi),
            sim["initial_finger"],
        )
    return Config(source=source, workspace=workspace, data=checked, stations=stations)


def _check_joints(source: str, key: str, q):
    for name, v, (lo, hi) in zip(ARM_JOINTS, q, urdf_model.arm_joint_limits(), strict=False):
        if not lo <= v <= hi:
            _fail(
                source,
                key,
                "%s = %g rad is outside its URDF limits [%g, %g]" % (name, v, lo, hi),
                list(q),
            )


def _check_survey(source: str, cfg: dict, stations: Dict[str, Station]):
    survey_z, step = cfg["survey"]["z"], cfg["survey"]["step"]
    if survey_z < cfg["arm"]["travel_z"]:
        _fail(
            source,
            "survey.z",
            "expected at least arm.travel_z (%g m): the camera surveys "
            "from above the travel height" % cfg["arm"]["travel_z"],
            survey_z,
        )
    pickup = next(s for s in stations.values() if s.type == "pickup")
    for cx, cy in pickup.area.lawnmower(step):
        if not top_down_reachable(cx, cy, survey_z):
            _fail(
                source,
                "survey.z",
                "too high to reach the survey pose (%.3f, %.3f) m over the "
                "pickup area; lower it or move the pickup area closer" % (cx, cy),
                survey_z,
            )


def _only(source: str, stations, type_) -> str:
    names = [n for n, s in stations.items() if s.type == type_]
    if len(names) != 1:
        _fail(
            source,
            "stations",
            "expected exactly one station of type %s" % type_,
            names,
            show_got=bool(names),
        )
    return names[0]


def _rect(section: dict, yaw: float = 0.0) -> Rect:
    return Rect(tuple(section["position"]), tuple(section["size"]), float(yaw))


def _read_stations(source: str, sec: dict) -> Dict[str, Station]:
    stations: Dict[str, Station] = {}
    types = ("pickup",) + tuple(STATION_PLUGINS) + ("bin",)
    for name, st in sec.items():
        key = "stations." + name
        type_ = st["type"]
        if type_ not in types:
            _fail(source, key + ".type", "expected one of %s" % ", ".join(types), type_)
        yaw = st.get("yaw", 0.0)  # everything on the station turns with it
        area = _rect(st, yaw)
        surface_z = st["surface_z"]
        extra = {}
        if type_ == "archival_camera":
            place_at = tuple(st["place_at"])
            extra["camera_height"] = st["camera_height"]
            extra["colour_chart"] = Fixture(_rect(st["colour_chart"], yaw))
            extra["scale_bar"] = Fixture(_rect(st["scale_bar"], yaw))
            extra["stand"] = Fixture(_rect(st["stand"], yaw), st["stand"]["height"])
            extra["over_scale"] = bool(st.get("over_scale", False))
            for part in ("colour_chart", "scale_bar"):
                if not area.contains(extra[part].area):
                    _fail(
                        source,
                        "%s.%s" % (key, part),
                        "must lie inside the camera's field of " "view %s" % _fmt_rect(area),
                        _fmt_rect(extra[part].area),
                    )
            if not area.has(place_at):
                _fail(
                    source,
                    key + ".place_at",
                    "must lie inside the camera's field of view %s" % _fmt_rect(area),
                    list(place_at),
                )
            if not top_down_reachable(place_at[0], place_at[1], surface_z):
                _fail(
                    source,
                    key + ".place_at",
                    "outside the arm's top-down reach (%.2f m from "
                    "the base); move it closer" % math.hypot(*place_at),
                    list(place_at),
                )
        else:
            place_at = area.center
            if type_ in ("discard", "bin"):
                extra["wall_height"] = st["wall_height"]
            if type_ == "bin":
                try:
                    extra["rule"] = parse_rule(st["rule"])
                except RuleError as e:
                    _fail(source, key + ".rule", str(e), st["rule"])
            for cx, cy in area.corners():
                if not top_down_reachable(cx, cy, surface_z):
                    _fail(
                        source,
                        key + ".position",
                        "station corner (%.3f, %.3f) is outside "
                        "the arm's top-down reach (%.2f..%.2f m from the base); move or shrink "
                        "the station" % (cx, cy, MIN_RADIUS, _max_radius(surface_z)),
                        list(area.center),
                    )
        if st.get("taught_place") is not None:
            place_at, extra["place_yaw"] = _taught_place(source, key, st, area, surface_z)
        stations[name] = Station(name, type_, area, surface_z, place_at, **extra)

    for type_ in REQUIRED_STATION_TYPES:
        _only(source, stations, type_)
    cam = stations[_only(source, stations, "archival_camera")]
    one_station = _scale_under_camera(source, sec, stations, cam) if cam.over_scale else ()
    names = list(stations)
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            if {a, b} == set(one_station):
                continue
            if stations[a].area.overlaps(stations[b].area):
                _fail(
                    source,
                    "stations." + b,
                    "overlaps station %s %s; move one of them" % (a, _fmt_rect(stations[a].area)),
                    _fmt_rect(stations[b].area),
                )
    for name, s in stations.items():
        if s is not cam and s.area.overlaps(cam.stand.area):
            _fail(
                source,
                "stations." + name,
                "overlaps the archival camera stand %s" % _fmt_rect(cam.stand.area),
                _fmt_rect(s.area),
            )
    _check_markers(source, sec, stations, cam)
    return stations


def _scale_under_camera(source: str, sec: dict, stations: Dict[str, Station], cam: Station):
    """The one-station layout (`over_scale`): the scale's platform lies in the camera's view,
    clear of the chart and the bar (its housing too), the camera right after the scale in the
    station order, and the sherd set down once, at the camera's place_at on the platform (the
    scale's place becomes it). Returns the pair of station names whose areas may overlap."""
    key = "stations.%s.over_scale" % cam.name
    scale = stations[_only(source, stations, "scale")]
    order = [n for n, s in stations.items() if s.type not in ("pickup", "bin")]
    if order.index(cam.name) != order.index(scale.name) + 1:
        _fail(
            source,
            key,
            "the camera must come right after the scale %s in the station list (the sherd is "
            "photographed where it was weighed); move its section" % scale.name,
            True,
        )
    if not cam.area.contains(scale.area):
        _fail(
            source,
            "stations.%s.position" % scale.name,
            "with %s: true the scale's platform must lie inside the camera's field of view %s"
            % (key, _fmt_rect(cam.area)),
            _fmt_rect(scale.area),
        )
    housing = Rect(
        scale.area.center,
        tuple(v + 2 * SCALE_HOUSING_MARGIN for v in scale.area.size),
        scale.area.yaw,
    )
    for part in ("colour_chart", "scale_bar"):
        fixture = getattr(cam, part).area
        if fixture.overlaps(housing):
            _fail(
                source,
                "stations.%s.%s" % (cam.name, part),
                "lies on the scale or its housing %s; put it beside the scale" % _fmt_rect(housing),
                _fmt_rect(fixture),
            )
    if not scale.area.has(cam.place_at):
        _fail(
            source,
            "stations.%s.place_at" % cam.name,
            "with %s: true the sherd is photographed where it is weighed: put place_at on the "
            "scale's platform %s" % (key, _fmt_rect(scale.area)),
            list(cam.place_at),
        )
    if sec[scale.name].get("taught_place") is not None:
        _fail(
            source,
            "stations.%s.taught_place" % scale.name,
            "with %s: true the sherd is set down at the camera's place; remove it and teach "
            "the camera station (`rascal teach %s`)" % (key, cam.name),
            sec[scale.name]["taught_place"],
        )
    stations[scale.name] = replace(scale, place_at=cam.place_at, place_yaw=cam.place_yaw)
    return scale.name, cam.name


def _taught_place(source: str, key: str, st: dict, area: Rect, surface_z: float):
    """A taught place ([x, y, yaw]): on the station and in the arm's reach."""
    x, y, yaw = st["taught_place"]
    if not area.has((x, y)):
        _fail(
            source,
            key + ".taught_place",
            "must lie on the station %s; teach it again with "
            "`rascal teach %s`" % (_fmt_rect(area), key.split(".")[1]),
            st["taught_place"],
        )
    if not top_down_reachable(x, y, surface_z):
        _fail(source, key + ".taught_place", "outside the arm's top-down reach", st["taught_place"])
    if abs(yaw) > math.pi:
        _fail(source, key + ".taught_place", "yaw must be in [-pi, pi] rad", st["taught_place"])
    return (x, y), yaw


def _check_markers(source: str, sec: dict, stations: Dict[str, Station], cam: Station):
    """Calibration markers (marker_calibration.py): both keys or neither, one ID once on the
    rig, each printed square (with its white margin) on the bare table beside the stations, where
    no sherd, mat or chart hides it and the camera can be put over it."""
    from rascal_tasks.marker_calibration import MARKER_SIZE

    seen = {}
    for name, st in sec.items():
        key = "stations.%s." % name
        ids, positions = st.get("marker_ids"), st.get("marker_positions")
        if (ids is None) != (positions is None):
            missing = "marker_positions" if positions is None else "marker_ids"
            _fail(
                source,
                key + missing,
                "missing; a station with markers needs both " "marker_ids and marker_positions",
                None,
                show_got=False,
            )
        if ids is None:
            continue
        for i in ids:
            if i != int(i):
                _fail(source, key + "marker_ids", "expected whole marker IDs", ids)
            if int(i) in seen:
                _fail(
                    source,
                    key + "marker_ids",
                    "marker %d is already on station %s; print " "another ID" % (i, seen[int(i)]),
                    ids,
                )
            seen[int(i)] = name
        area = stations[name].area
        for offset in positions:
            xy = area.to_table(offset)  # offsets are in the station's frame
            square = Rect(xy, (MARKER_SIZE * 4 / 3,) * 2, area.yaw)  # with the margin
            for other in list(stations.values()) + [
                Station("stand", "stand", cam.stand.area, 0.0, xy)
            ]:
                if square.overlaps(other.area):
                    _fail(
                        source,
                        key + "marker_positions",
                        "the marker at (%.3f, %.3f) lies on "
                        "station %s %s; stick it on the bare table beside the station"
                        % (xy[0], xy[1], other.name, _fmt_rect(other.area)),
                        list(offset),
                    )
            if not top_down_reachable(xy[0], xy[1], 0.0):
                _fail(
                    source,
                    key + "marker_positions",
                    "the marker at (%.3f, %.3f) is outside "
                    "the arm's top-down reach; stick it nearer the arm" % xy,
                    list(offset),
                )


def _check_arm(source: str, arm: dict, stations: Dict[str, Station]):
    highest = max(s.surface_z for s in stations.values())
    walls = max(s.wall_height for s in stations.values())
    travel_z = arm["travel_z"]
    if travel_z < max(highest, walls) + 0.05:
        _fail(
            source,
            "arm.travel_z",
            "expected at least 0.05 m above the highest station "
            "surface or wall (%.3f m)" % max(highest, walls),
            travel_z,
        )
    blend_z = arm["blend_z"]
    if blend_z > 0 and not max(highest, walls) + 0.02 <= blend_z <= travel_z:
        _fail(
            source,
            "arm.blend_z",
            "expected between 0.02 m above the highest station surface or wall (%.3f m) and "
            "arm.travel_z (%.3f m), or 0 for no blending" % (max(highest, walls), travel_z),
            blend_z,
        )
    standby = tuple(arm["standby"])
    if not top_down_reachable(standby[0], standby[1], travel_z):
        _fail(source, "arm.standby", "outside the arm's top-down reach at travel_z", list(standby))
    cam = next(s for s in stations.values() if s.type == "archival_camera")
    if cam.area.has(standby):
        _fail(
            source,
            "arm.standby",
            "inside the archival camera's view %s; the arm must park "
            "out of view" % _fmt_rect(cam.area),
            list(standby),
        )
    for name, q in arm["named_poses"].items():
        _check_joints(source, "arm.named_poses." + name, q)


def _max_radius(z: float) -> float:
    dz = z + WRIST_TO_EE - SHOULDER_Z
    return math.sqrt(max(MAX_WRIST_DISTANCE**2 - dz * dz, 0.0))


def _fmt_rect(r: Rect) -> str:
    turned = " yaw %.3f" % r.yaw if r.yaw else ""
    return "centre [%.3f, %.3f] size [%.3f, %.3f]%s" % (r.center + r.size + (turned,))
