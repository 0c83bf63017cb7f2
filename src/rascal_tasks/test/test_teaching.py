"""Unit tests of teaching by demonstration (no ROS): jog commands and their bounds, a session
saving the measured place (never the one asked for), the site file changed in one line only,
the configuration's checks of a taught place, and a whole fake batch setting sherds down there.
"""

import copy
import io
import math
import os

import pytest
import yaml
from fake_rig import Recorder, Sherd, World

from rascal_tasks import site_file, teaching, workflow
from rascal_tasks.rig import RigError
from rascal_tasks.config import ConfigError, config_from_dict, load_config

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
SHIPPED = os.path.join(WORKSPACE, "config", "rascal.yaml")


@pytest.fixture
def data():
    with open(SHIPPED, encoding="utf-8") as f:
        return yaml.safe_load(f)


def test_jogs_move_in_millimetres_and_degrees_and_stay_on_the_station(data):
    scale = config_from_dict(data).stations["scale"]
    p = teaching.Place(0.30, 0.0, 0.0)
    assert teaching.jogged(p, "x+5", scale.area).x == pytest.approx(0.305)
    assert teaching.jogged(p, "Y - 2.5", scale.area).y == pytest.approx(-0.0025)
    assert teaching.jogged(p, "yaw+200", scale.area).yaw == pytest.approx(math.radians(-160))
    leaves = r"x\+70: would leave the station \(corners \(0\.235"
    with pytest.raises(teaching.TeachError, match=leaves):
        teaching.jogged(p, "x+70", scale.area)
    with pytest.raises(teaching.TeachError, match="not a command"):
        teaching.jogged(p, "left 5", scale.area)


class _Arm:
    """Goes where it is sent, 0.4 mm short in x and with the yaw read half a turn off (the
    fingers are alike: the same grip)."""

    def __init__(self):
        self.at = None

    def move(self, place, z):
        self.at = (place.x - 0.0004, place.y, z, teaching.wrap(place.yaw + math.pi))

    def measure(self):
        return self.at


def test_a_session_saves_the_measured_place(data):
    scale = config_from_dict(data).stations["scale"]
    arm, out = _Arm(), io.StringIO()
    commands = ["x+10", "x+500", "bogus", "y-5", "yaw+30", "show", "save", "x+1"]
    z = teaching.teach_height(scale, travel_z=0.10)
    got = teaching.teach(
        scale, teaching.Place(0.30, 0.0, 0.0), arm.move, arm.measure, commands, out, z
    )
    assert (got.x, got.y, got.yaw) == pytest.approx((0.3096, -0.005, math.radians(30)))
    assert arm.at[2] == pytest.approx(scale.surface_z + teaching.TEACH_HEIGHT)
    assert out.getvalue().count("refused:") == 2
    assert teaching.teach(scale, got, arm.move, arm.measure, ["x+1", "quit"], out, z) is None
    assert teaching.teach(scale, got, arm.move, arm.measure, iter([]), out, z) is None


def test_a_jog_the_controller_refuses_is_said_and_teaching_goes_on(data):
    cfg = config_from_dict(data)
    discard, arm, out = cfg.stations["discard"], _Arm(), io.StringIO()
    z = teaching.teach_height(discard, cfg["arm"]["travel_z"])
    assert z == cfg["arm"]["travel_z"]  # a box's sherds are let go from travel height
    plain = arm.move

    def move(place, z):
        if place.y < -0.33:
            raise RigError("arm", "COLLISION", "right_finger_link would hit the wall")
        plain(place, z)

    start = teaching.Place(0.02, -0.31, 0.0)
    got = teaching.teach(discard, start, move, arm.measure, ["y-30", "x+10", "save"], out, z)
    assert "refused: y-30: right_finger_link would hit the wall" in out.getvalue()
    assert (got.x, got.y) == pytest.approx((0.0296, -0.31))

    def broken(place, z):
        raise RigError("arm", "TIMEOUT", "did not arrive")

    with pytest.raises(RigError, match="TIMEOUT"):
        teaching.teach(discard, start, broken, arm.measure, ["save"], out, z)


def test_an_arm_that_does_not_get_there_stops_the_session(data):
    scale = config_from_dict(data).stations["scale"]
    arm = _Arm()
    arm.measure = lambda: (0.31, 0.0, 0.045, 0.0)
    with pytest.raises(teaching.TeachError, match="not at .* where it was sent; nothing saved"):
        teaching.teach(
            scale,
            teaching.Place(0.30, 0.0, 0.0),
            arm.move,
            arm.measure,
            ["save"],
            io.StringIO(),
            0.045,
        )


def test_the_site_file_changes_in_one_line_and_loads(tmp_path):
    with open(SHIPPED, encoding="utf-8") as f:
        text = f.read()
    once = site_file.set_station_value(text, "scale", "taught_place", [0.31, -0.01, 1.5708])
    assert len(once.splitlines()) == len(text.splitlines()) + 1
    twice = site_file.set_station_value(once, "scale", "taught_place", [0.29, 0.01, 0.0])
    assert len(twice.splitlines()) == len(once.splitlines())
    path = tmp_path / "rascal.yaml"
    path.write_text(twice)
    cfg = load_config(str(path))
    assert cfg.stations["scale"].place_at == (0.29, 0.01)
    assert cfg.stations["scale"].place_yaw == 0.0
    assert yaml.safe_load(twice)["stations"]["camera"] == yaml.safe_load(text)["stations"]["camera"]
    # a later calibration moves a taught place with its station
    moved = yaml.safe_load(site_file.shift_stations(twice, {"scale": (0.01, 0.0)}))
    assert moved["stations"]["scale"]["taught_place"] == pytest.approx([0.30, 0.01, 0.0])
    with pytest.raises(ValueError, match="stations.nowhere"):
        site_file.set_station_value(text, "nowhere", "taught_place", [0, 0, 0])


@pytest.mark.parametrize(
    "place, message",
    [
        ([0.40, 0.0, 0.0], r"stations\.scale\.taught_place: must lie on the station"),
        ([0.30, 0.0, 3.3], r"stations\.scale\.taught_place"),
        ([0.30, 0.0], r"stations\.scale\.taught_place"),
    ],
)
def test_a_bad_taught_place_is_refused_naming_the_key(data, place, message):
    data["stations"]["scale"]["taught_place"] = place
    with pytest.raises(ConfigError, match=message):
        config_from_dict(data)


def test_a_batch_sets_sherds_down_where_and_as_taught(data):
    taught = copy.deepcopy(data)
    taught["stations"]["scale"]["taught_place"] = [0.32, 0.02, 1.2]
    cfg = config_from_dict(taught)
    world = World(cfg, [Sherd("a", 0.10, 0.22), Sherd("b", 0.20, 0.27)])
    batch = workflow.Batch(cfg, world.rig(), Recorder(), context="T", log=print)
    assert workflow.build_machine(batch).execute() == "finished"
    low = cfg.stations["scale"].surface_z + 0.03
    at_scale = [
        m for m in world.moves if m[2] < low and math.hypot(m[0] - 0.32, m[1] - 0.02) < 1e-9
    ]
    assert len(at_scale) >= 4, world.moves  # set down and picked up again, each sherd
    assert all(m[3] == pytest.approx(1.2) for m in at_scale)
    assert not [m for m in world.moves if m[2] < low and math.hypot(m[0] - 0.30, m[1]) < 0.01]


def test_taught_by_hand_the_place_read_is_saved_and_the_torque_always_comes_back(data):
    scale = config_from_dict(data).stations["scale"]
    torque, out = [], io.StringIO()
    poses = iter([(0.50, 0.0, 0.05, 0.0), (0.31, 0.012, 0.05, 0.4)])
    got = teaching.teach_by_hand(
        scale, torque.append, lambda: next(poses), ["save", "wiggle", "", "", "save"], out
    )
    assert (got.x, got.y, got.yaw) == (0.31, 0.012, 0.4)
    assert torque == [True, False]
    text = out.getvalue()
    assert "is not on the station" in text and "refused: 'wiggle'" in text
    assert "nothing read yet" in text

    def broken():
        raise RigError("tf", "LOOKUP", "no transform")

    torque.clear()
    with pytest.raises(RigError):
        teaching.teach_by_hand(scale, torque.append, broken, [""], out)
    assert torque == [True, False]
    assert teaching.teach_by_hand(scale, torque.append, broken, ["quit"], out) is None
