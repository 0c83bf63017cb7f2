"""The layout's physical bound (layout_bound.py) on its own: trapezoids at the servo limits, the
scale's settling, and the bound of the site's layout with a stand-in IK (a top-down arm in
cylindrical coordinates: the waist turns to the spot, the other joints follow reach and height)."""

import copy
import math
import os

import pytest
import yaml

from rascal_tasks import layout_bound as lb
from rascal_tasks.config import config_from_dict, merged

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))


@pytest.fixture
def data():
    with open(os.path.join(WORKSPACE, "config", "rascal.yaml")) as f:
        return yaml.safe_load(f)


def ik(x, y, z, seed):
    r = math.hypot(x, y)
    return [math.atan2(y, x), 4.0 * (r - 0.3), -4.0 * (r - 0.3) + 3.0 * z, 0.0, 3.0 * z, 0.0]


def test_the_scale_settles_later_for_heavier_sherds_and_longer_windows():
    light = lb.scale_settle(0.005, 1.0, 1e-4)
    heavy = lb.scale_settle(0.060, 1.0, 1e-4)
    assert 1.0 < light < heavy < 4.0
    assert lb.scale_settle(0.02, 0.5, 1e-4) < lb.scale_settle(0.02, 1.0, 1e-4)


def test_the_bound_is_below_the_serial_sequence_and_grows_with_the_layout(data):
    near = lb.bound_of(config_from_dict(data), ik)
    assert 0 < near["bound"] < near["serial"]
    # the transfer, less the way back over the sherd made meanwhile
    assert 0 < near["serial"] - near["bound"] < lb.TRANSFER
    far = copy.deepcopy(data)
    far["stations"]["discard"]["position"] = [-0.05, -0.38]  # the box farther round
    assert lb.bound_of(config_from_dict(far), ik)["motion"] > near["motion"]


def test_every_pick_but_a_surveys_first_pays_for_a_look_at_the_sherd(data):
    cfg = config_from_dict(data)
    spot = cfg.stations["pickup"].area.center
    looked = lb.sequence(cfg, spot)
    assert looked[0].what == "look at the sherd"
    assert looked[1:] == lb.sequence(cfg, spot, look=False)
    # one sherd per survey: no look; ten: nine of ten pay for one
    assert lb.bound_of(cfg, ik, 1)["motion"] < lb.bound_of(cfg, ik, 10)["motion"]


def test_a_wait_that_overlaps_the_next_move_costs_only_what_the_move_leaves_of_it():
    def ik1(x, y, z, seed):  # the waist alone turns to x (rad)
        return [x, 0.0, 0.0, 0.0, 0.0, 0.0]

    def serial(wait):
        steps = [lb.Step("a", (0.0, 0, 0), serial_wait=wait, overlaps_next=True)]
        steps.append(lb.Step("b", (1.0, 0, 0)))
        return lb.timed(steps, ik1, [0.0] * 6)[2]

    move = lb.move_time([0.0] * 6, [1.0] + [0.0] * 5)
    assert serial(move + 0.5) == pytest.approx(0.5)
    assert serial(move / 2) == 0.0
    last = [lb.Step("a", (0.0, 0, 0), serial_wait=1.0, overlaps_next=True)]
    assert lb.timed(last, ik1, [0.0] * 6)[2] == 1.0  # no move after it: all of it


def test_a_wait_run_on_during_the_next_moves_is_waited_only_past_them():
    def ik1(x, y, z, seed):  # the waist alone turns to x (rad)
        return [x, 0.0, 0.0, 0.0, 0.0, 0.0]

    def waits(wait):  # the scale settling while the arm goes up and to standby (2 moves)
        steps = [
            lb.Step("settles", (0.0, 0, 0), wait=wait, wait_during=2),
            lb.Step("up", (0.5, 0, 0)),
            lb.Step("standby", (1.0, 0, 0), wait=0.2),
        ]
        return lb.timed(steps, ik1, [0.0] * 6)[1]

    moves = 2 * lb.move_time([0.0] * 6, [0.5] + [0.0] * 5)
    assert waits(moves + 0.7) == pytest.approx(0.7 + 0.2)
    assert waits(moves / 2) == pytest.approx(0.2)

    def through_the_shutter(wait):  # on through the shutter and the way back down
        steps = [
            lb.Step("settles", (0.0, 0, 0), wait=wait, wait_during=3),
            lb.Step("standby", (0.5, 0, 0), wait=0.2),
            lb.Step("back", (0.0, 0, 0)),
            lb.Step("down", (0.5, 0, 0), wait=0.1),  # the close: after it has settled
        ]
        return lb.timed(steps, ik1, [0.0] * 6)[1]

    three = 3 * lb.move_time([0.0] * 6, [0.5] + [0.0] * 5)
    assert through_the_shutter(three + 0.2 + 0.4) == pytest.approx(0.2 + 0.4 + 0.1)
    assert through_the_shutter(three / 2) == pytest.approx(0.2 + 0.1)


def test_a_transfer_is_made_during_the_next_moves_and_their_waits():
    def ik1(x, y, z, seed):
        return [x, 0.0, 0.0, 0.0, 0.0, 0.0]

    def serial(transfer):  # standby, then back over the sherd, down (a close), up
        steps = [
            lb.Step("standby", (0.0, 0, 0), wait=0.2, serial_wait=transfer, overlaps_next=3),
            lb.Step("back over", (0.5, 0, 0)),
            lb.Step("down", (1.0, 0, 0), wait=0.1),
            lb.Step("up", (0.5, 0, 0)),
            lb.Step("on", (0.0, 0, 0)),
        ]
        return lb.timed(steps, ik1, [0.0] * 6)[2]

    three = 3 * lb.move_time([0.0] * 6, [0.5] + [0.0] * 5)
    assert serial(three + 0.1 + 0.4) == pytest.approx(0.4)  # only its excess is waited
    assert serial(three / 2) == pytest.approx(0.0)


def test_the_batch_start_and_end_are_shared_by_its_sherds(data):
    """The measured seconds per sherd count the batch's own moves (from the sleep pose, the
    stations' backgrounds, the first survey, the surveys that find the mat empty, the park):
    the bound counts them too, shared by the batch's sherds; `cycle` leaves them out."""
    cfg = config_from_dict(data)
    ten, twenty = lb.bound_of(cfg, ik, 10), lb.bound_of(cfg, ik, 20)
    assert ten["batch"] == pytest.approx(2 * twenty["batch"])
    # more than the one survey the cycle alone shares: the start and the closing surveys
    assert ten["batch"] > 2 * ten["survey"] > 0
    assert ten["bound"] - ten["cycle"] == pytest.approx(ten["batch"] - ten["survey"])
    # one more closing survey costs its moves over the mat (not the way there and back)
    more = copy.deepcopy(data)
    more["recovery"]["max_empty_surveys"] += 1
    extra = lb.bound_of(config_from_dict(more), ik, 10)["batch"] - ten["batch"]
    assert 0 < extra < ten["survey"]


def test_one_station_bound_is_below_the_separate_stations(data):
    with open(os.path.join(WORKSPACE, "config", "layouts", "one_station.yaml")) as f:
        one = config_from_dict(merged(data, yaml.safe_load(f)))
    separate = lb.bound_of(config_from_dict(data), ik)
    together = lb.bound_of(one, ik)
    assert together["bound"] < separate["bound"] and together["motion"] < separate["motion"]


def test_moves_made_as_one_motion_are_timed_as_one_move(data):
    def ik1(x, y, z, seed):  # the waist alone turns to x (rad)
        return [x, 0.0, 0.0, 0.0, 0.0, 0.0]

    steps = [lb.Step("up", (0.5, 0, 0)), lb.Step("over", (1.0, 0, 0), wait=0.3, blends=True)]
    motion, waits, _serial, _q = lb.timed(steps, ik1, [0.0] * 6)
    assert motion == pytest.approx(lb.move_time([0.0] * 6, [1.0] + [0.0] * 5))
    assert waits == pytest.approx(0.3)
    stop_and_go = copy.deepcopy(data)
    stop_and_go["arm"]["blend_z"] = 0.0
    blended = lb.bound_of(config_from_dict(data), ik)
    assert blended["motion"] < lb.bound_of(config_from_dict(stop_and_go), ik)["motion"]
