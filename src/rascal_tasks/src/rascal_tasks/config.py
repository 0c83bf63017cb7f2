"""Loads and validates the site configuration (config/rascal.yaml).

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
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

import yaml

from rascal_tasks.stations import STATION_PLUGINS
from rascal_tasks.survey import lawnmower

# --- wx250s geometry for the reach check (shared/facts/widowx250_d435.md §1.1, §1.5) -------------
SHOULDER_Z = 0.11065  # shoulder axis above base_link: 0.072 + 0.03865
UPPER_ARM = math.hypot(0.25, 0.04975)  # shoulder axis -> elbow axis, 0.25490
FOREARM = 0.175 + 0.075  # elbow axis -> wrist_angle axis
WRIST_TO_EE = 0.065 + 0.043 + 0.023 + 0.027575  # wrist_angle axis -> ee_gripper_link, 0.158575
# Stretched-out arm is singular and slow; keep 5 % in hand. Over the base the waist spins fast
# for small moves and the forearm hits the base: stay 10 cm out.
MAX_WRIST_DISTANCE = 0.95 * (UPPER_ARM + FOREARM)
MIN_RADIUS = 0.10

# Every station type with a plug-in (stations.py) can appear in the config; these four must.
REQUIRED_STATION_TYPES = ("pickup", "scale", "archival_camera", "discard")
SELECTION_POLICIES = ("nearest", "largest", "most_isolated")
ARM_JOINTS = ("waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate")


class ConfigError(ValueError):
    """A configuration value is wrong; str() is one line naming the file, key and fix."""


def top_down_reachable(x: float, y: float, z: float) -> bool:
    """True when ee_gripper_link can be at (x, y, z) in base_link with the gripper pointing down."""
    r = math.hypot(x, y)
    wrist = math.hypot(r, z + WRIST_TO_EE - SHOULDER_Z)
    return MIN_RADIUS <= r and wrist <= MAX_WRIST_DISTANCE


@dataclass(frozen=True)
class Rect:
    """Axis-aligned rectangle on the table: centre and size [along x, along y] in metres."""

    center: Tuple[float, float]
    size: Tuple[float, float]

    def corners(self) -> List[Tuple[float, float]]:
        cx, cy = self.center
        hx, hy = self.size[0] / 2, self.size[1] / 2
        return [(cx - hx, cy - hy), (cx + hx, cy - hy), (cx + hx, cy + hy), (cx - hx, cy + hy)]

    def overlaps(self, other: "Rect") -> bool:
        return (abs(self.center[0] - other.center[0]) * 2 < self.size[0] + other.size[0]
                and abs(self.center[1] - other.center[1]) * 2 < self.size[1] + other.size[1])

    def contains(self, other: "Rect") -> bool:
        return all(self.has(c) for c in other.corners())

    def has(self, p) -> bool:
        """Whether the point p = (x, y) lies on the rectangle."""
        return (abs(p[0] - self.center[0]) <= self.size[0] / 2 + 1e-9
                and abs(p[1] - self.center[1]) <= self.size[1] / 2 + 1e-9)


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
    wall_height: float = 0.0  # discard box walls
    camera_height: float = 0.0  # archival camera lens above the surface
    colour_chart: Optional[Fixture] = None
    scale_bar: Optional[Fixture] = None
    stand: Optional[Fixture] = None


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
        """Stations a sherd visits after pickup, in config order."""
        return [n for n, s in self.stations.items() if s.type != "pickup"]

    def resolve(self, path: str) -> str:
        """A path from the config, relative paths taken from the workspace root."""
        path = os.path.expanduser(path)
        return path if os.path.isabs(path) else os.path.join(self.workspace, path)

    @property
    def hash(self) -> str:
        """Short SHA-256 of the checked configuration, recorded with every sherd."""
        blob = json.dumps(self.data, sort_keys=True, separators=(",", ":")).encode()
        return hashlib.sha256(blob).hexdigest()[:16]


class _Reader:
    """Reads one mapping of the YAML, naming `prefix.key` in every error."""

    def __init__(self, source: str, data, prefix: str = ""):
        self.source = source
        self.prefix = prefix
        if not isinstance(data, dict):
            self.fail(None, "expected a mapping of keys", data)
        self.data = data
        self.used = set()

    def key(self, key) -> str:
        return "%s.%s" % (self.prefix, key) if self.prefix and key is not None else (
            key if key is not None else self.prefix or "(top level)")

    def fail(self, key, expected, got, show_got=True):
        msg = "%s: %s: %s" % (self.source, self.key(key), expected)
        if show_got:
            msg += ", got %r" % (got,)
        raise ConfigError(msg)

    def raw(self, key, required=True, default=None):
        self.used.add(key)
        if key not in self.data or self.data[key] is None:
            if required:
                self.fail(key, "missing; add it (see the shipped config/rascal.yaml)", None,
                          show_got=False)
            return default
        return self.data[key]

    def section(self, key) -> "_Reader":
        return _Reader(self.source, self.raw(key), self.key(key))

    def number(self, key, lo=-math.inf, hi=math.inf, unit="", required=True, default=None,
               integer=False):
        v = self.raw(key, required, default)
        if v is None:
            return None
        kind = "an integer" if integer else "a number"
        what = "expected %s%s in [%g, %g]" % (kind, " in " + unit if unit else "", lo, hi)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or (integer and
                                                                       not isinstance(v, int)):
            self.fail(key, what, v)
        if not math.isfinite(v) or not lo <= v <= hi:
            self.fail(key, what, v)
        return int(v) if integer else float(v)

    def vector(self, key, n, lo=-math.inf, hi=math.inf, what="", required=True):
        v = self.raw(key, required)
        if v is None:
            return None
        ok = (isinstance(v, list) and len(v) == n
              and all(isinstance(e, (int, float)) and not isinstance(e, bool)
                      and math.isfinite(e) and lo <= e <= hi for e in v))
        if not ok:
            self.fail(key, "expected %s" % what, v)
        return tuple(float(e) for e in v)

    def xy(self, key, required=True):
        return self.vector(key, 2, -2.0, 2.0, "[x, y] in metres", required)

    def size(self, key):
        return self.vector(key, 2, 0.001, 2.0, "[length along x, width along y] in metres (> 0)")

    def colour(self, key):
        return self.vector(key, 3, 0.0, 1.0, "[r, g, b] with each in [0, 1]")

    def string(self, key, required=True, default=None, choices=None, max_len=500):
        v = self.raw(key, required, default)
        if v is None:
            return None
        if choices is not None:
            if v not in choices:
                self.fail(key, "expected one of %s" % ", ".join(choices), v)
            return v
        if not isinstance(v, str) or not v.strip() or len(v) > max_len or any(
                ord(c) < 32 for c in v):
            self.fail(key, "expected a non-empty one-line string", v)
        return v

    def done(self):
        """Reject keys nobody read: a typo must not silently fall back to a default."""
        for k in self.data:
            if k not in self.used:
                self.fail(k, "unknown key (a typo? known keys: %s)" % ", ".join(
                    sorted(map(str, self.used))), self.data[k], show_got=False)


def load_config(path: str, workspace: Optional[str] = None) -> Config:
    """Read and validate a config file. `workspace` defaults to the parent of its folder."""
    try:
        with open(path, encoding="utf-8") as f:
            data = yaml.safe_load(f)
    except FileNotFoundError:
        raise ConfigError("%s: file not found; pass the path of config/rascal.yaml"
                          % path) from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = " (line %d)" % (mark.line + 1) if mark else ""
        raise ConfigError("%s: not valid YAML%s: %s" % (
            path, where, getattr(e, "problem", None) or e)) from None
    if workspace is None:
        workspace = os.path.dirname(os.path.dirname(os.path.abspath(path)))
    return config_from_dict(data, source=path, workspace=workspace)


def config_from_dict(data, source="config/rascal.yaml", workspace=".") -> Config:
    """Validate an already-loaded configuration (e.g. from the ROS parameter server)."""
    top = _Reader(source, data)
    rig = top.section("rig")
    rig.string("name", max_len=64)
    rig.string("site", max_len=64)
    rig.done()

    stations = _read_stations(top.section("stations"))
    arm = _read_arm(top.section("arm"), stations)

    survey = top.section("survey")
    survey_z = survey.number("z", 0.10, 0.50, "metres")
    step = survey.number("step", 0.02, 0.50, "metres")
    survey.number("settle_time", 0.0, 5.0, "seconds")
    survey.done()
    if survey_z < arm["travel_z"]:
        survey.fail("z", "expected at least arm.travel_z (%g m): the camera surveys from above the "
                    "travel height" % arm["travel_z"], survey_z)
    pickup = stations[_only(stations, "pickup", top)]
    for cx, cy in lawnmower(pickup.area.center, pickup.area.size, step):
        if not top_down_reachable(cx, cy, survey_z):
            survey.fail("z", "too high to reach the survey pose (%.3f, %.3f) m over the pickup "
                        "area; lower it or move the pickup area closer" % (cx, cy), survey_z)

    per = top.section("perception")
    per.number("background_clusters", 1, 8, integer=True)
    per.number("hue_tolerance", 0.0, 0.5, "hue units (full circle = 1)")
    per.number("saturation_tolerance", 0.0, 1.0)
    per.number("min_value", 0.0, 1.0)
    per.number("fixture_dilation", 0.0, 0.05, "metres")
    lo = per.number("min_sherd_size", 0.005, 0.2, "metres")
    per.number("max_sherd_size", lo, 0.5, "metres (>= perception.min_sherd_size)")
    per.number("border_margin", 0, 100, "pixels", integer=True)
    per.string("selection_policy", choices=SELECTION_POLICIES)
    dmin = per.number("depth_min", 0.05, 2.0, "metres")
    per.number("depth_max", dmin, 10.0, "metres (> perception.depth_min)")
    per.number("min_sherd_height", 0.0, 0.02, "metres")
    per.number("split_min_neck", 0.1, 1.0)
    per.number("grasp_height_fraction", 0.1, 1.0)
    per.number("grasp_tip_clearance", 0.0, 0.05, "metres")
    per.number("frame_wait", 0.05, 10.0, "seconds")
    per.number("refresh_period", 0.0, 3600.0, "seconds (0 = never)")
    per.done()

    scale = top.section("scale")
    scale.number("stable_timeout", 0.5, 60.0, "seconds")
    scale.number("rereads", 0, 10, integer=True)
    scale.done()

    rec = top.section("recovery")
    rec.number("max_grasp_attempts", 1, 10, integer=True)
    rec.number("search_radius", 0.0, 0.3, "metres")
    rec.number("max_searches", 0, 10, integer=True)
    rec.number("max_empty_surveys", 1, 10, integer=True)
    rec.done()

    db = top.section("database")
    dsn = db.string("dsn")
    if not (dsn.startswith(("postgresql://", "postgres://")) or "=" in dsn):
        db.fail("dsn", "expected a libpq URI (postgresql://user:password@host:port/dbname) or "
                "key=value string", dsn)
    db.number("connect_timeout", 0.5, 120.0, "seconds")
    db.done()

    archive = top.section("archive")
    archive.string("root")
    archive.done()

    sim = top.section("simulator")
    sim.string("scenario")
    sim.number("real_time_factor", 0.0, 100.0, "(0 = as fast as possible)")
    sim.colour("table_colour")
    sim.colour("mat_colour")
    tones = sim.raw("scale_colours")
    if not (isinstance(tones, list) and len(tones) == 2):
        sim.fail("scale_colours", "expected two [r, g, b] colours (the two-tone platform)", tones)
    for i, tone in enumerate(tones):
        _Reader(source, {i: tone}, sim.key("scale_colours")).colour(i)
    sim.number("physics_step", 0.0002, 0.002, "seconds")
    sim.number("clock_period", 0.0002, 0.1, "seconds")
    sim.number("joint_state_period", 0.001, 0.01, "seconds (>= 100 Hz)")
    sim.raw("wrist_camera")
    if not isinstance(sim.data["wrist_camera"], bool):
        sim.fail("wrist_camera", "expected true or false", sim.data["wrist_camera"])
    sim.number("wrist_rate", 1.0, 30.0, "Hz")
    sim.raw("point_cloud")
    if not isinstance(sim.data["point_cloud"], bool):
        sim.fail("point_cloud", "expected true or false", sim.data["point_cloud"])
    sim.vector("initial_joints", 6, -math.pi, math.pi, "6 joint angles in radians")
    sim.number("initial_finger", 0.015, 0.037, "metres")
    size = sim.vector("archival_size", 2, 100, 20000, "[width, height] in pixels")
    if size[0] < 2000 or size[1] < 1500:
        sim.fail("archival_size", "expected at least [2000, 1500] pixels", list(size))
    sim.string("spool_dir")
    sim.done()
    top.done()
    return Config(source=source, workspace=workspace, data=data, stations=stations)


def _only(stations, type_, reader) -> str:
    names = [n for n, s in stations.items() if s.type == type_]
    if len(names) != 1:
        reader.fail("stations", "expected exactly one station of type %s" % type_,
                    names, show_got=bool(names))
    return names[0]


def _read_fixture(st: _Reader, key, with_height=False) -> Fixture:
    fx = st.section(key)
    area = Rect(fx.xy("position"), fx.size("size"))
    height = fx.number("height", 0.05, 3.0, "metres") if with_height else 0.0
    fx.done()
    return Fixture(area, height)


def _read_stations(sec: _Reader) -> Dict[str, Station]:
    stations: Dict[str, Station] = {}
    if not sec.data:
        sec.fail(None, "expected at least the pickup, scale, archival camera and discard stations",
                 sec.data)
    for name in sec.data:
        if not isinstance(name, str) or not name.replace("_", "").isalnum():
            sec.fail(name, "station names are snake_case words", name, show_got=False)
        st = sec.section(name)
        type_ = st.string("type", choices=("pickup",) + tuple(STATION_PLUGINS))
        area = Rect(st.xy("position"), st.size("size"))
        surface_z = st.number("surface_z", 0.0, 0.2, "metres above the table")
        extra = {}
        if type_ == "archival_camera":
            place_at = st.xy("place_at")
            extra["camera_height"] = st.number("camera_height", 0.2, 2.0, "metres")
            extra["colour_chart"] = _read_fixture(st, "colour_chart")
            extra["scale_bar"] = _read_fixture(st, "scale_bar")
            extra["stand"] = _read_fixture(st, "stand", with_height=True)
            for part in ("colour_chart", "scale_bar"):
                if not area.contains(extra[part].area):
                    st.fail(part, "must lie inside the camera's field of view %s" % (
                        _fmt_rect(area),), _fmt_rect(extra[part].area))
            if not area.has(place_at):
                st.fail("place_at", "must lie inside the camera's field of view %s" % (
                    _fmt_rect(area),), list(place_at))
            if not top_down_reachable(place_at[0], place_at[1], surface_z):
                st.fail("place_at", "outside the arm's top-down reach (%.2f m from the base); "
                        "move it closer" % math.hypot(*place_at), list(place_at))
        else:
            place_at = area.center
            if type_ == "discard":
                extra["wall_height"] = st.number("wall_height", 0.0, 0.15, "metres")
            for cx, cy in area.corners():
                if not top_down_reachable(cx, cy, surface_z):
                    st.fail("position", "station corner (%.3f, %.3f) is outside the arm's top-down "
                            "reach (%.2f..%.2f m from the base); move or shrink the station" % (
                                cx, cy, MIN_RADIUS, _max_radius(surface_z)), list(area.center))
        st.done()
        stations[name] = Station(name, type_, area, surface_z, place_at, **extra)

    for type_ in REQUIRED_STATION_TYPES:
        _only(stations, type_, sec)
    names = list(stations)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if stations[a].area.overlaps(stations[b].area):
                sec.fail(b, "overlaps station %s %s; move one of them" % (
                    a, _fmt_rect(stations[a].area)), _fmt_rect(stations[b].area))
    cam = stations[_only(stations, "archival_camera", sec)]
    for name, s in stations.items():
        if s is not cam and s.area.overlaps(cam.stand.area):
            sec.fail(name, "overlaps the archival camera stand %s" % _fmt_rect(cam.stand.area),
                     _fmt_rect(s.area))
    return stations


def _read_arm(arm: _Reader, stations: Dict[str, Station]) -> dict:
    highest = max(s.surface_z for s in stations.values())
    walls = max(s.wall_height for s in stations.values())
    travel_z = arm.number("travel_z", 0.05, 0.45, "metres")
    if travel_z < max(highest, walls) + 0.05:
        arm.fail("travel_z", "expected at least 0.05 m above the highest station surface or wall "
                 "(%.3f m)" % max(highest, walls), travel_z)
    arm.number("approach_offset", 0.0, 0.15, "metres")
    arm.number("place_clearance", 0.0, 0.05, "metres")
    arm.number("grasp_margin", 0.0, 0.03, "metres")
    standby = arm.xy("standby")
    if not top_down_reachable(standby[0], standby[1], travel_z):
        arm.fail("standby", "outside the arm's top-down reach at travel_z", list(standby))
    cam = next(s for s in stations.values() if s.type == "archival_camera")
    if cam.area.has(standby):
        arm.fail("standby", "inside the archival camera's view %s; the arm must park out of "
                 "view" % _fmt_rect(cam.area), list(standby))
    arm.number("speed_scale", 0.01, 1.0)
    arm.number("acceleration_share", 0.1, 1.0)
    arm.number("command_period", 0.001, 0.2, "seconds")
    arm.number("goal_tolerance", 0.0001, 0.1, "radians")
    arm.number("settle_timeout", 0.1, 30.0, "seconds")
    arm.number("state_timeout", 0.1, 30.0, "seconds")
    if not isinstance(arm.raw("publish_tf"), bool):
        arm.fail("publish_tf", "expected true or false", arm.data["publish_tf"])
    grip = arm.section("gripper")
    grip.number("timeout", 0.1, 30.0, "seconds")
    grip.number("stroke_time", 0.5, 10.0, "seconds (the servo needs at least 0.5)")
    grip.number("held_margin", 0.0, 0.02, "metres")
    grip.done()
    poses = arm.section("named_poses")
    for name in poses.data:
        poses.vector(name, 6, -math.pi, math.pi, "6 joint angles in radians (%s)" % ", ".join(
            ARM_JOINTS))
    for required in ("home", "sleep"):
        poses.raw(required)
    poses.done()
    arm.done()
    return {"travel_z": travel_z}


def _max_radius(z: float) -> float:
    dz = z + WRIST_TO_EE - SHOULDER_Z
    return math.sqrt(max(MAX_WRIST_DISTANCE ** 2 - dz * dz, 0.0))


def _fmt_rect(r: Rect) -> str:
    return "centre [%.3f, %.3f] size [%.3f, %.3f]" % (r.center + r.size)
