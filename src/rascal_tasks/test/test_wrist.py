"""The wrist's turns along a sherd's way (wrist.py) and the joint-move times they are weighed
by (joint_motion.py); then a whole batch on the fake rig: no turn between the archival camera's
spot and its standby, and every pickup grasp is the detection's, turned by 0 or pi."""

import math
import os
from types import SimpleNamespace

import pytest
import yaml
from fake_rig import Recorder, Sherd, World

from rascal_tasks import workflow
from rascal_tasks.config import config_from_dict
from rascal_tasks.joint_motion import move_time, trapezoid
from rascal_tasks.wrist import (
    leg_time,
    route_yaw,
    same_grasp_yaws,
    standby_yaw,
    station_yaw,
    wrist_angle,
)

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))


@pytest.fixture
def config():
    with open(os.path.join(WORKSPACE, "config", "rascal.yaml")) as f:
        return config_from_dict(yaml.safe_load(f))


def test_trapezoid_at_the_servo_limits():
    # short: triangular, 2 sqrt(d/a); long: cruise at pi rad/s
    assert trapezoid(0.5) == pytest.approx(2 * math.sqrt(0.5 / 5.0))
    assert trapezoid(-3.0) == pytest.approx(3.0 / math.pi + math.pi / 5.0)
    assert trapezoid(0.0) == 0.0
    assert move_time([0, 0, 0], [0.1, -2.0, 0.3]) == pytest.approx(trapezoid(2.0))


def test_the_wrist_angle_is_the_waist_less_the_yaw_as_the_controller_solves_it():
    # joints the arm_controller reported in a bench/throughput run (waist, wrist_rotate)
    assert wrist_angle(0.218, 0.214, -0.89) == pytest.approx(1.67, abs=0.01)
    assert wrist_angle(0.28, -0.30, -0.89) == pytest.approx(0.07, abs=0.01)
    assert wrist_angle(0.02, -0.31, -0.89) == pytest.approx(-0.61, abs=0.01)
    assert -math.pi <= wrist_angle(-0.1, 0.001, -3.0) < math.pi


def test_the_same_grasp_turned_by_pi_stays_within_the_wrists_range():
    assert same_grasp_yaws(0.5) == pytest.approx((0.5, 0.5 - math.pi))
    assert same_grasp_yaws(-3.0) == pytest.approx((-3.0, math.pi - 3.0))
    assert all(-math.pi <= a <= math.pi for a in same_grasp_yaws(math.pi))


def test_a_leg_takes_the_slower_of_the_waists_and_the_wrists_turn():
    # the same yaw across the table: the wrist turns back as far as the waist turns
    assert leg_time((0.02, -0.31, 0.0), (0.22, 0.21, 0.0)) == pytest.approx(
        trapezoid(2.29), abs=0.01
    )
    # beside the camera: the waist turns 0.3 rad, a wrist turned by pi/2 takes longer
    near = leg_time((0.28, -0.30, 0.0), (0.14, -0.30, 0.0))
    turned = leg_time((0.28, -0.30, 0.0), (0.14, -0.30, math.pi / 2))
    assert turned > near + 0.5


def test_under_the_archival_camera_the_sherd_is_set_down_turned_as_at_the_standby(config):
    camera, scale = config.stations["camera"], config.stations["scale"]
    away = standby_yaw(config, camera)
    assert away == pytest.approx(math.pi)  # standby (0.14, -0.30) lies -x of the view's centre
    assert station_yaw(config, camera, 0.3) == away
    assert station_yaw(config, scale, 0.3) == 0.3  # elsewhere: as it is held
    taught = SimpleNamespace(place_yaw=-0.5, type="archival_camera")
    assert station_yaw(config, taught, 0.3) == -0.5  # a taught yaw is kept


def test_the_pickup_grasp_is_turned_by_pi_when_its_way_turns_the_wrist_less(config):
    route = [config.stations[n] for n in ("scale", "camera", "discard")]
    start = (0.02, -0.31, -2.1)  # over the discard box, wrist at 0.59
    for g in (-1.5, -0.89, 0.0, 0.7, 1.5):
        chosen = route_yaw(config, start, (0.218, 0.214), g, route)
        assert math.remainder(chosen - g, math.pi) == pytest.approx(0.0, abs=1e-9)  # same grasp

        def way(yaw):
            here, total = (0.218, 0.214, yaw), leg_time(start, (0.218, 0.214, yaw))
            for st in route:
                there = (*st.place_at, station_yaw(config, st, here[2]))
                total, here = total + leg_time(here, there), there
            return total

        other = math.remainder(chosen + math.pi, 2 * math.pi)
        assert way(chosen) <= way(other) + 1e-9, (g, chosen)
    # one case by hand: from a wrist at -2.7 the grasp at -0.89 turns it 4.4 rad the long way
    # round (its +-pi stop); the same grasp at 2.25 turns it 1.2 rad
    assert route_yaw(config, (0.02, -0.31, 1.2), (0.218, 0.214), -0.89, route[:1]) == pytest.approx(
        -0.89 + math.pi
    )


def test_a_batch_turns_the_wrist_only_on_the_way_to_the_camera_not_to_its_standby(config):
    world = World(config, [Sherd("a", 0.10, 0.22), Sherd("b", 0.25, 0.30)])
    recorder = Recorder()
    batch = workflow.Batch(config, world.rig(), recorder, context="T")
    assert workflow.build_machine(batch).execute() == "finished"
    assert recorder.status() == {1: "done", 2: "done"}
    camera = config.stations["camera"]
    sx, sy = config["arm"]["standby"]
    standby = [i for i, m in enumerate(world.moves) if (m[0], m[1]) == (sx, sy)]
    assert len(standby) == 2
    for i in standby:
        before = world.moves[i - 1]  # lifted from the sherd set down under the camera
        assert (before[0], before[1]) == tuple(camera.place_at)
        assert before[3] == world.moves[i][3] == standby_yaw(config, camera)
