"""Core tests of PICKUP's rule that a grasp on the pickup mat uses a detection made after the
mat last changed (`pickup.look_again`), run against the in-memory rig of `fake_rig.py`."""

import math
from dataclasses import replace

import pytest
from fake_rig import GRASP_ABOVE, Recorder, Sherd, World, run_batch, shipped_config

from rascal_tasks import workflow
from rascal_tasks.config import top_down_reachable
from rascal_tasks.pickup import both_views_diameter, look_from
from rascal_tasks.rig import Observation
from rascal_tasks.survey import CAMERA_OFFSET, gripper_for_camera_over, lawnmower
from rascal_tasks.wrist import route_yaw


@pytest.fixture
def config():
    return shipped_config()


def _run(config, world):
    return run_batch(config, world)


def _when_holding(world, name, change):
    """`change(world)` once, at the first move made while sherd `name` is in the fingers (what
    the grasp did to the mat around it, or a person reaching in)."""
    done = []

    def refuse(x, y, z, yaw, linear):
        if not done and world.held is not None and world.held.name == name:
            done.append(True)
            change(world)
        return None

    return refuse


def _grasp_descents(config, world):
    """(x, y) of every descent to grasp height on the pickup mat."""
    grasp_z = config.stations["pickup"].surface_z + GRASP_ABOVE + 0.01  # a 10 mm tall sherd
    return [(x, y) for x, y, z, _yaw, linear in world.moves if linear and z <= grasp_z + 1e-9]


def test_a_sherd_nudged_since_the_survey_is_grasped_where_it_lies_now(config):
    world = World(config, [Sherd("a", 0.10, 0.22), Sherd("b", 0.25, 0.30)])
    b = world.sherds[1]
    world.refuse = _when_holding(world, "a", lambda w: w.put(b, 0.265, 0.31))
    outcome, _batch, rec = _run(config, world)
    assert outcome == "finished"
    assert rec.status() == {1: "done", 2: "done"}
    descents = _grasp_descents(config, world)
    assert not any(math.hypot(x - 0.25, y - 0.30) < 0.005 for x, y in descents), descents
    assert rec.sherds[2].pickup_xy == pytest.approx((0.265, 0.31))


def test_a_sherd_taken_away_since_the_survey_is_not_grasped_at(config):
    world = World(config, [Sherd("a", 0.10, 0.22), Sherd("b", 0.25, 0.30)])
    b = world.sherds[1]
    world.refuse = _when_holding(world, "a", lambda w: w.put(b, 0.7, 0.7))  # off every station
    outcome, _batch, rec = _run(config, world)
    assert outcome == "finished"
    assert rec.status() == {1: "done"}
    descents = _grasp_descents(config, world)
    assert not any(math.hypot(x - 0.25, y - 0.30) < 0.05 for x, y in descents), descents


def test_only_a_grasp_after_a_change_looks_again(config):
    """The first grasp after a survey takes the survey's detection (nothing changed since);
    the next one, after a grasp on the mat, looks once more first."""
    world = World(config, [Sherd("a", 0.10, 0.22), Sherd("b", 0.25, 0.30)])
    _run(config, world)
    pickup = config.stations["pickup"]
    survey_z = pickup.surface_z + config["survey"]["z"]
    views = len(lawnmower(pickup.area.center, pickup.area.size, config["survey"]["step"]))
    looks = []  # wrist camera views of the mat before each grasp descent
    n = 0
    for x, y, z, _yaw, linear in world.moves:
        if z == pytest.approx(survey_z) and pickup.area.has((x, y)):
            n += 1
        elif linear and z < survey_z and n:
            looks.append(n)
            n = 0
    assert looks[:2] == [views, 1], looks


def _seen_at(x, y, yaw=0.4):
    return Observation(x, y, yaw, 0.05, 0.04, 0.01, x, y, 0.005, yaw, 0.052)


@pytest.mark.parametrize("xy", [(0.08, 0.22), (0.16, 0.25), (0.24, 0.20), (0.05, 0.31)])
def test_a_look_turns_the_gripper_as_its_grasp_will_be_with_the_camera_over_the_sherd(config, xy):
    b = workflow.Batch(config, World(config, []).rig(), Recorder(), context="T")
    b.last_pose = (*config.stations["discard"].place_at, 0.0)
    o = _seen_at(*xy)
    x, y, yaw = look_from(b, o)
    assert (x, y) == xy
    g = route_yaw(config, b.last_pose, xy, o.grasp_yaw, [p.station for p in b.plugins])
    assert math.sin(yaw - g) == pytest.approx(0.0, abs=1e-9)  # the grasp's yaw, or turned by pi
    ex, ey, _ = gripper_for_camera_over(x, y, yaw)
    assert ex + CAMERA_OFFSET * math.cos(yaw) == pytest.approx(x)  # the camera over the sherd
    assert top_down_reachable(ex, ey, config["survey"]["z"])


def test_a_sherd_out_of_reach_at_the_survey_height_is_looked_at_from_the_survey_view(config):
    b = workflow.Batch(config, World(config, []).rig(), Recorder(), context="T")
    b.last_pose = (*config.stations["discard"].place_at, 0.0)
    far = (0.30, 0.32)  # the mat's far corner
    for yaw in (None, 0.0, math.pi / 2, math.pi, -math.pi / 2):
        assert not top_down_reachable(*gripper_for_camera_over(*far, yaw)[:2], 0.25)
    x, y, yaw = look_from(b, _seen_at(*far))
    area = config.stations["pickup"].area
    views = lawnmower(area.center, area.size, config["survey"]["step"])
    assert (x, y) in views and yaw is None
    assert math.hypot(x - far[0], y - far[1]) < 0.11  # within the camera's view of ~0.3 x 0.23 m
    assert top_down_reachable(*gripper_for_camera_over(x, y)[:2], config["survey"]["z"])


def test_the_vessel_diameter_of_two_views_is_their_inverse_variance_mean():
    def seen(diameter, sigma):
        return replace(_seen_at(0.1, 0.2), vessel_diameter=diameter, vessel_diameter_sigma=sigma)

    # alike sigmas in curvature: the mean curvature; the sigma shrinks by about sqrt(2)
    both = both_views_diameter(seen(0.400, 0.020), seen(0.400, 0.020))
    assert both["vessel_diameter"] == pytest.approx(0.400)
    assert both["vessel_diameter_sigma"] == pytest.approx(0.020 / math.sqrt(2))
    both = both_views_diameter(seen(0.360, 0.013), seen(0.440, 0.013 * (0.44 / 0.36) ** 2))
    assert both["vessel_diameter"] == pytest.approx(2.0 / ((2 / 0.36 + 2 / 0.44) / 2))
    # the surer view counts more
    surer = both_views_diameter(seen(0.360, 0.050), seen(0.440, 0.010))["vessel_diameter"]
    assert 0.42 < surer < 0.44
    # a view that told none: the other's
    assert both_views_diameter(seen(0.0, 0.0), seen(0.44, 0.01))["vessel_diameter"] == 0.44
    assert both_views_diameter(seen(0.44, 0.01), seen(0.0, 0.0))["vessel_diameter"] == 0.44
    assert both_views_diameter(seen(0.0, 0.0), seen(0.0, 0.0))["vessel_diameter"] == 0.0
