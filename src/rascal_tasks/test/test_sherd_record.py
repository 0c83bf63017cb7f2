"""Core tests of SherdRecord: a sherd's catalogue writes and the one path that ends it (done or
lost), which is where completed and lost sherds are counted (no master, no database)."""

import math
import os

import pytest
import yaml
from fake_rig import Recorder, Sherd, World

from rascal_tasks import workflow
from rascal_tasks.config import config_from_dict
from rascal_tasks.rig import Observation
from rascal_tasks.sherd_record import SherdRecord

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))


@pytest.fixture
def config():
    with open(os.path.join(WORKSPACE, "config", "rascal.yaml")) as f:
        return config_from_dict(yaml.safe_load(f))


def _batch(config, recorder=None, sherds=()):
    world = World(config, list(sherds))
    return workflow.Batch(config, world.rig(), recorder or Recorder(), context="T"), world


def _obs(x, y):
    return Observation(x, y, 0.0, 0.05, 0.04, 0.01, x, y, 0.005, 0.3, 0.052)


def test_a_picked_sherd_is_numbered_with_its_dimensions_and_grasp(config):
    b, _ = _batch(config)
    s = SherdRecord.picked(b, _obs(0.1, 0.2), b.pickup, attempts=2)
    assert s.seq == 1 and s.status == "picked"
    assert b.recorder.writes == [("picked", 1), ("dimensions", 1)]
    assert (s.where, s.last_xy, s.picked_xy) == ("pickup", (0.1, 0.2), (0.1, 0.2))
    assert (s.grasp_yaw, s.grasp_height, s.width) == (0.3, 0.005, 0.04)


def test_losing_a_sherd_records_notes_and_counts_it_once(config):
    b, _ = _batch(config)
    s = b.sherd = SherdRecord.picked(b, _obs(0.1, 0.2), b.pickup, attempts=1)
    b.timings.add("grasping", 2.5)
    timings = b.timings
    s.lose("fell off the table")
    row = b.recorder.sherds[1]
    assert (row.status, row.lost_reason) == ("lost", "fell off the table")
    assert row.notes == ["lost: fell off the table"]
    assert (b.completed, b.lost) == (0, 1)
    assert b.sherd is None and b.timings is not timings  # the next sherd's time starts afresh
    with pytest.raises(RuntimeError, match="sherd 1 is lost already"):
        s.lose("again")
    with pytest.raises(RuntimeError, match="sherd 1 is lost already"):
        s.done()
    assert b.lost == 1 and [w for w in b.recorder.writes if w[0] == "lost"] == [("lost", 1)]


def test_a_done_sherd_is_counted_completed(config):
    b, _ = _batch(config)
    s = b.sherd = SherdRecord.picked(b, _obs(0.1, 0.2), b.pickup, attempts=1)
    s.record_mass(0.025, stable=True)
    s.record_photo("/spool/T-1.png")
    s.done()
    assert b.recorder.status() == {1: "done"} and s.status == "done" and s.mass == 0.025
    assert (b.completed, b.lost) == (1, 0) and b.sherd is None


def test_each_stage_is_timed_on_the_rig_clock_from_where_the_last_ended(config):
    b, world = _batch(config)
    world.t = 10.0
    b.timings = type(b.timings)(started=10.0)  # the last sherd ended at 10 s
    world.t = 14.0
    s = b.sherd = SherdRecord.picked(b, _obs(0.1, 0.2), b.pickup, attempts=1)
    world.t = 20.5
    s.record_mass(0.025, stable=True)
    world.t = 23.0
    s.record_photo("/spool/T-1.png")
    world.t = 27.0
    s.done()
    assert b.recorder.sherds[1].seconds == {"pick": 4.0, "weigh": 6.5, "photo": 2.5, "discard": 4.0}
    assert b.timings.started == 27.0  # the next sherd's time starts when this one is done


def test_a_sherd_not_found_after_a_restart_is_lost_through_the_same_path(config):
    # sherd 2 was weighed when the run was killed; nothing lies anywhere now
    rec = Recorder(unfinished=[(2, "weighed", (0.15, 0.22))])
    b, world = _batch(config, rec)
    outcome = workflow.build_machine(b).execute()
    assert outcome == "finished" and world.named == ["sleep"]
    assert rec.sherds[2].lost_reason == "not found after restart (was weighed)"
    assert rec.sherds[2].notes == ["lost: not found after restart (was weighed)"]
    assert (b.completed, b.lost) == (0, 1)


def test_a_restart_carries_on_and_numbers_the_next_sherd_after_it(config):
    # sherd 2 lies weighed on the scale; a new sherd lies in the pickup area
    rec = Recorder(unfinished=[(2, "weighed", (0.15, 0.22))])
    scale = config.stations["scale"]
    b, world = _batch(
        config, rec, [Sherd("old", *scale.place_at, station="scale"), Sherd("new", 0.10, 0.22)]
    )
    assert workflow.build_machine(b).execute() == "finished"
    assert rec.status() == {2: "done", 3: "done"}
    assert (b.completed, b.lost) == (2, 0)


def test_an_unstable_reading_is_never_a_mass(config):
    b, _ = _batch(config)
    s = SherdRecord.picked(b, _obs(0.1, 0.2), b.pickup, attempts=1)
    with pytest.raises(ValueError, match="record_mass: sherd 1: an unstable reading"):
        s.record_mass(0.0017, stable=False)
    s.record_mass_unstable("the reading did not hold")
    row = b.recorder.sherds[1]
    assert (row.status, row.mass, row.mass_missing_reason) == (
        "mass_unstable",
        None,
        "the reading did not hold",
    )
    assert (s.status, s.mass) == ("mass_unstable", None)
    s.record_mass(0.0139)  # weighed again, settled
    assert (row.status, row.mass, row.mass_missing_reason) == ("weighed", 0.0139, None)


def test_a_grasp_turned_off_the_minor_axis_on_the_mat_is_turned_back_at_the_station(config):
    # On the mat neighbours made perception turn the grasp 30 degrees off the sherd's minor axis
    # (yaw 0.2: its major axis; grasp yaw 0.2 + 30 deg); set down at the scale by a gripper at
    # yaw 1.0, the sherd's minor axis lies at 1.0 - 30 deg: it is taken up again across it.
    b, _ = _batch(config)
    turn = math.pi / 6
    turned = Observation(0.1, 0.2, 0.2, 0.06, 0.04, 0.01, 0.1, 0.2, 0.005, 0.2 + turn, 0.06)
    s = SherdRecord.picked(b, turned, b.pickup, attempts=1)
    s.placed(config.stations["scale"], 1.0)
    assert math.isclose(s.grasp_yaw, 1.0 - turn)
    # held so, and set down again at another yaw: it is not turned a second time
    s.placed(config.stations["camera"], 1.5)
    assert math.isclose(s.grasp_yaw, 1.5)
    # a grasp across the minor axis (the fingers alike: yaw and yaw + pi) stays as it was held
    across = Observation(0.1, 0.2, 0.0, 0.05, 0.04, 0.01, 0.1, 0.2, 0.005, math.pi, 0.052)
    s = SherdRecord.picked(b, across, b.pickup, attempts=1)
    s.placed(config.stations["scale"], 2.5)
    assert math.isclose(s.grasp_yaw, 2.5)


@pytest.mark.parametrize(
    "pads, width, kept",
    [(0.0, 0.031, True), (0.0, 0.034, False), (0.0075, 0.0165, True), (0.0075, 0.019, False)],
)
def test_a_sherd_too_narrow_across_to_hold_is_taken_up_by_the_chord_it_was_held_by(
    config, pads, width, kept
):
    # held turned 80 degrees (along a longer chord: across its minor axis the fingers would stop
    # within held_margin of closed, 30 mm stock, 15 mm between 7.5 mm pads), it is taken up again
    # as it was held, not turned back across
    config["arm"]["gripper"]["fingertip_pads"] = pads
    b, _ = _batch(config)
    turn = math.radians(80)
    o = Observation(0.1, 0.2, 0.2, 0.045, width, 0.01, 0.1, 0.2, 0.005, 0.2 + turn, 0.06)
    s = SherdRecord.picked(b, o, b.pickup, attempts=1)
    s.placed(config.stations["scale"], 1.0)
    assert math.isclose(s.grasp_yaw, 1.0 if kept else 1.0 - turn)
