"""Core tests of the site configuration loader (no ROS master)."""

import copy
import os

import pytest
import yaml

from rascal_workcell.fixtures import SCALE_HOUSING_MARGIN

from rascal_tasks.config import (
    ConfigError,
    config_from_dict,
    load_config,
    merged,
    top_down_reachable,
)

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHIPPED = os.path.join(WORKSPACE, "config", "rascal.yaml")


@pytest.fixture(scope="module")
def shipped():
    with open(SHIPPED) as f:
        return yaml.safe_load(f)


def test_shipped_config_passes():
    cfg = load_config(SHIPPED)
    assert set(cfg.stations) == {"pickup", "scale", "camera", "discard"}
    assert cfg.station_order() == ["scale", "camera", "discard"]
    assert cfg.stations["camera"].place_at == (0.28, -0.30)
    assert cfg.resolve(cfg["archive"]["root"]) == os.path.join(WORKSPACE, "var", "archive")
    assert len(cfg.hash) == 16


def test_config_hash_changes_with_content(shipped):
    a = config_from_dict(copy.deepcopy(shipped))
    changed = copy.deepcopy(shipped)
    changed["survey"]["settle_time"] = 0.2
    assert config_from_dict(changed).hash != a.hash


def _set(data, dotted, value):
    keys = dotted.split(".")
    node = data
    for k in keys[:-1]:
        node = node[k]
    if value is _DELETE:
        del node[keys[-1]]
    else:
        node[keys[-1]] = value


_DELETE = object()

# (dotted key, bad value, text the one-line error must contain)
BAD = [
    (
        "stations.scale.position",
        "abc",
        "stations.scale.position: expected [x, y] in metres, got 'abc'",
    ),
    ("stations.scale.position", [0.3], "stations.scale.position: expected [x, y]"),
    ("stations.pickup.size", [0.3, -0.1], "stations.pickup.size: expected [length along x"),
    ("stations.scale.surface_z", "high", "stations.scale.surface_z: expected a number"),
    ("stations.scale.type", "balance", "stations.scale.type: expected one of pickup, scale"),
    ("stations.discard.position", [0.9, -0.5], "stations.discard.position: station corner"),
    ("stations.scale.position", [0.16, 0.25], "overlaps station pickup"),
    ("stations.camera.place_at", [0.0, -0.30], "stations.camera.place_at: must lie inside"),
    (
        "stations.camera.colour_chart.position",
        [0.6, -0.1],
        "stations.camera.colour_chart: must lie",
    ),
    ("arm.travel_z", 0.03, "arm.travel_z: expected a number in metres in [0.05, 0.45], got 0.03"),
    ("arm.standby", [0.30, -0.30], "arm.standby: inside the archival camera's view"),
    ("arm.named_poses.home", [0, 0, 0], "arm.named_poses.home: expected 6 joint angles"),
    ("arm.named_poses.sleep", _DELETE, "arm.named_poses.sleep: missing"),
    ("arm.travel_z", 0.26, "survey.z: expected at least arm.travel_z (0.26 m)"),
    ("survey.z", 0.45, "survey.z: too high to reach the survey pose"),
    ("survey.step", 0, "survey.step: expected a number in metres in [0.02, 0.5], got 0"),
    (
        "perception.selection_policy",
        "random",
        "perception.selection_policy: expected one of nearest",
    ),
    ("perception.background_clusters", 2.5, "perception.background_clusters: expected an integer"),
    ("perception.max_sherd_size", 0.01, "perception.max_sherd_size: expected a number"),
    ("perception.depth_min", True, "perception.depth_min: expected a number"),
    ("database.dsn", "localhost", "database.dsn: expected a libpq URI"),
    ("database", _DELETE, "database: missing"),
    ("archive.root", "", "archive.root: expected a non-empty one-line string"),
    ("rig.name", "a\nb", "rig.name: expected a non-empty one-line string"),
    ("recovery.max_grasp_attempts", 0, "recovery.max_grasp_attempts: expected an integer"),
    ("simulator.mat_colour", [0, 0, 2], "simulator.mat_colour: expected [r, g, b]"),
    ("simulator.scale_colours", [[0, 0, 0]], "simulator.scale_colours: expected two"),
    (
        "simulator.archival_size",
        [640, 480],
        "simulator.archival_size: expected [width, height] of at least",
    ),
    ("simulator.wrist_camera", "yes", "simulator.wrist_camera: expected true or false"),
    ("survey.stepp", 0.1, "survey.stepp: unknown key"),
]


@pytest.mark.parametrize("key,value,message", BAD, ids=[b[0] + ":" + repr(b[1])[:20] for b in BAD])
def test_bad_value_is_rejected_with_one_line_naming_the_key(shipped, key, value, message):
    data = copy.deepcopy(shipped)
    _set(data, key, value)
    with pytest.raises(ConfigError) as e:
        config_from_dict(data, source="config/rascal.yaml")
    text = str(e.value)
    assert text.startswith("config/rascal.yaml: ")
    assert message in text
    assert "\n" not in text


def test_station_overlapping_camera_stand_is_rejected(shipped):
    data = copy.deepcopy(shipped)
    data["stations"]["camera"]["stand"]["position"] = [0.30, 0.0]
    with pytest.raises(ConfigError, match="stations.scale: overlaps the archival camera stand"):
        config_from_dict(data)


def test_missing_station_type_is_rejected(shipped):
    data = copy.deepcopy(shipped)
    del data["stations"]["discard"]
    with pytest.raises(ConfigError, match="stations: expected exactly one station of type discard"):
        config_from_dict(data)


def test_missing_file_and_bad_yaml(tmp_path):
    with pytest.raises(ConfigError, match="file not found"):
        load_config(str(tmp_path / "nope.yaml"))
    bad = tmp_path / "bad.yaml"
    bad.write_text("stations: [unclosed\n")
    with pytest.raises(ConfigError, match=r"bad.yaml: not valid YAML \(line"):
        load_config(str(bad))
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    with pytest.raises(ConfigError, match="expected a mapping"):
        load_config(str(empty))


def test_top_down_reach_matches_the_arm_geometry():
    assert top_down_reachable(0.30, 0.0, 0.0)
    assert top_down_reachable(0.45, 0.0, 0.0)
    assert not top_down_reachable(0.55, 0.0, 0.0)  # stretched arm is 0.505 m at the wrist
    assert not top_down_reachable(0.05, 0.0, 0.1)  # over the base
    assert not top_down_reachable(0.40, 0.0, 0.45)  # too high that far out


# ------------------------------------------------------------------ the one-station layout
ONE_STATION = os.path.join(WORKSPACE, "config", "layouts", "one_station.yaml")


@pytest.fixture()
def one_station(shipped):
    with open(ONE_STATION) as f:
        return merged(copy.deepcopy(shipped), yaml.safe_load(f))


def test_one_station_layout_passes_and_sets_the_sherd_down_once():
    cfg = load_config(SHIPPED, over=[ONE_STATION])
    scale, camera = cfg.stations["scale"], cfg.stations["camera"]
    assert camera.over_scale and not scale.over_scale
    # the scale sets the sherd down where the camera shoots it
    assert scale.place_at == camera.place_at
    assert camera.area.contains(scale.area)
    assert not load_config(SHIPPED).stations["camera"].over_scale


def test_merged_is_what_rosparam_load_does():
    base = {"a": {"b": 1, "c": [1, 2]}, "d": 2}
    assert merged(base, {"a": {"c": [3]}, "e": 5}) == {"a": {"b": 1, "c": [3]}, "d": 2, "e": 5}
    assert base == {"a": {"b": 1, "c": [1, 2]}, "d": 2}  # not changed


ONE_STATION_BAD = [
    (
        "stations.scale.position",
        [0.16, -0.10],
        "stations.scale.position: with stations.camera.over_scale: true the scale's platform "
        "must lie inside",
    ),
    (
        "stations.camera.scale_bar.position",
        [0.30, -0.355],
        "stations.camera.scale_bar: lies on the scale or its housing",
    ),
    (
        "stations.camera.place_at",
        [0.32, -0.26],
        "stations.camera.place_at: with stations.camera.over_scale: true the sherd is "
        "photographed where it is weighed",
    ),
    (
        "stations.scale.taught_place",
        [0.23, -0.28, 0.0],
        "stations.scale.taught_place: with stations.camera.over_scale: true the sherd is set "
        "down at the camera's place",
    ),
]


@pytest.mark.parametrize("key,value,message", ONE_STATION_BAD, ids=[b[0] for b in ONE_STATION_BAD])
def test_one_station_layout_errors_name_the_key(one_station, key, value, message):
    _set(one_station, key, value)
    with pytest.raises(ConfigError) as e:
        config_from_dict(one_station)
    assert message in str(e.value) and "\n" not in str(e.value)


def test_one_station_camera_must_follow_the_scale(one_station):
    st = one_station["stations"]
    one_station["stations"] = {k: st[k] for k in ["pickup", "camera", "scale", "discard"]}
    with pytest.raises(
        ConfigError, match="stations.camera.over_scale: the camera must come right after the scale"
    ):
        config_from_dict(one_station)


def test_scale_housing_margin_is_the_workcells():
    import re

    header = os.path.join(
        WORKSPACE, "src", "rascal_workcell", "include", "rascal_workcell", "Workcell.hpp"
    )
    with open(header) as f:
        value = re.search(r"kScaleHousingMargin = ([0-9.]+);", f.read()).group(1)
    assert float(value) == SCALE_HOUSING_MARGIN


def test_the_fingertip_pads_layout_passes_with_the_shipped_one_station_layout_too():
    pads = os.path.join(WORKSPACE, "config", "layouts", "fingertip_pads.yaml")
    for over in ([pads], [ONE_STATION, pads]):
        cfg = load_config(SHIPPED, over=over)
        assert cfg["arm"]["gripper"]["fingertip_pads"] == 0.0075
    assert load_config(SHIPPED)["arm"]["gripper"]["fingertip_pads"] == 0.0


def test_the_turned_stations_layout_passes_alone_and_over_the_one_station_layout():
    """config/layouts/turned_stations.yaml (bench/heap's askew table): every station turned, no
    overlap, every marker on the bare table, the scale's platform under the turned camera."""
    turned = os.path.join(WORKSPACE, "config", "layouts", "turned_stations.yaml")
    for over in ([turned], [ONE_STATION, turned]):
        stations = load_config(SHIPPED, over=over).stations
        assert all(s.area.yaw != 0.0 for s in stations.values())
    camera = stations["camera"]
    assert camera.over_scale and camera.area.contains(stations["scale"].area)


def test_a_turned_station_turns_its_area_and_what_stands_on_it(shipped):
    """`stations.<name>.yaw`: the pickup mat turned 5° keeps its centre; its corners, what lies
    on it and the survey's views turn with it, and its markers' offsets are in its frame."""
    import math

    from rascal_tasks.config import Rect

    data = copy.deepcopy(shipped)
    yaw = math.radians(5.0)
    data["stations"]["pickup"]["yaw"] = yaw
    mat = config_from_dict(data).stations["pickup"].area
    square = config_from_dict(shipped).stations["pickup"].area
    assert mat.center == square.center and mat.yaw == pytest.approx(yaw)
    hx, hy = square.size[0] / 2, square.size[1] / 2
    corner = (square.center[0] + hx - 0.002, square.center[1] + hy - 0.002)
    assert square.has(corner) and not mat.has(corner)  # off the turned mat
    assert mat.has(mat.to_table((hx - 0.002, hy - 0.002)))
    assert all(mat.has(v) for v in mat.lawnmower(data["survey"]["step"]))
    assert Rect((0.0, 0.0), (0.1, 0.1), math.radians(45)).overlaps(Rect((0.075, 0.0), (0.02, 0.02)))
    assert not Rect((0.0, 0.0), (0.1, 0.1)).overlaps(Rect((0.075, 0.0), (0.02, 0.1)))
    data["stations"]["pickup"]["yaw"] = 1.0
    with pytest.raises(ConfigError, match=r"stations\.pickup\.yaw"):
        config_from_dict(data)
