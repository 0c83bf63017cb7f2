"""The one-station layout (issue 18, item 4; config/layouts/one_station.yaml): the scale under
the archival camera, so a sherd is set down once, weighed, photographed where it lies and
picked up from the scale for the discard box (batch tier, on the in-memory rig)."""

import pytest
import fake_rig
from fake_rig import Recorder, Sherd, World, riding_world, run_batch, shipped_config

from rascal_tasks import workflow
from rascal_tasks.layout_bound import sequence
from rascal_tasks.run_batch import what_is_left
from rascal_tasks.stations import ScaleStation

LAYOUT = "config/layouts/one_station.yaml"


@pytest.fixture
def config():
    return shipped_config(LAYOUT)


def test_each_sherd_is_set_down_once_and_photographed_on_the_scale(config):
    world = World(config, [Sherd("a", 0.10, 0.22), Sherd("b", 0.25, 0.30, mass=0.031)])
    outcome, batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done", 2: "done"}
    assert (rec.sherds[1].mass, rec.sherds[2].mass) == pytest.approx((0.020, 0.031))
    # each photo shows the sherd in progress, and only it, lying where it was weighed
    assert world.in_view_at_shutter == [["a"], ["b"]]
    standby = tuple(config["arm"]["standby"])
    assert all(at[:2] == pytest.approx(standby) for at in world.at_shutter)
    # set down, straight up and out of view: the scale settles with the arm at standby (no
    # hover over it as when a repick follows the weighing)
    scale, travel = config.stations["scale"], config["arm"]["travel_z"]
    k = next(i for i, m in enumerate(world.moves) if m[:2] == pytest.approx(standby))
    over, place, up = world.moves[k - 3 : k]
    assert over[:2] == pytest.approx(scale.place_at) and over[2] == pytest.approx(travel)
    assert place[:2] == pytest.approx(scale.place_at) and place[2] < travel and place[4]
    assert up[:2] == pytest.approx(scale.place_at) and up[2] == pytest.approx(travel) and up[4]
    # no carry from the scale to the camera: no repick at the scale, no placing at the camera
    states = set(batch.state_times)
    assert {"At scale", "At camera", "Repick@camera", "Place@discard"} <= states
    assert not states & {"Repick@scale", "Translate→camera", "Place@camera"}
    # the scale never took the sherd lying on it while photographed for one left behind
    assert not any("stayed on the scale" in n for r in rec.sherds.values() for n in r.notes)


def test_the_way_back_during_the_transfer_reaches_the_sherd_on_the_platform(config):
    world = World(config, [Sherd("a", 0.10, 0.22)])
    outcome, _batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done"}
    scale = config.stations["scale"]
    (over, down, lift) = world.transfer_moves[0]
    assert over[:2] == pytest.approx(scale.place_at) and down[:2] == pytest.approx(scale.place_at)
    # fingers at the sherd's grasp height on the platform, not on the table under the camera
    assert scale.surface_z < down[2] < over[2] < config["arm"]["travel_z"]
    # picked up off the platform while the photo still transfers: waits at travel height
    assert lift[:2] == pytest.approx(scale.place_at) and lift[2] == config["arm"]["travel_z"]


def test_a_restart_with_a_weighed_sherd_on_the_scale_photographs_it_there(config):
    scale = config.stations["scale"]
    lying = Sherd("a", *scale.place_at, station="scale")
    world = World(config, [lying, Sherd("b", 0.25, 0.30)])
    rec = Recorder(unfinished=[(1, "weighed", (0.10, 0.22))])
    rec.sherds[1].mass = 0.020
    outcome, batch, rec = run_batch(config, world, rec)
    assert outcome == "finished" and rec.status() == {1: "done", 2: "done"}
    assert world.in_view_at_shutter[0] == ["a"]  # shot where it lay, not carried first
    assert "Repick@scale" not in batch.state_times


def test_the_machine_goes_from_the_scale_straight_to_the_camera(config):
    world = World(config, [])
    batch = workflow.Batch(config, world.rig(), Recorder(), context="T")
    camera = batch.plugins[1]
    assert camera.stays and camera.lies_at is config.stations["scale"]
    assert [s.name for s in batch.route()] == ["scale", "discard"]


def test_the_layouts_sequence_has_one_grasp_and_one_carry_fewer(config):
    separate = [s.what for s in sequence(shipped_config(), (0.16, 0.25))]
    one = [s.what for s in sequence(config, (0.16, 0.25))]
    assert separate.count("descend") == one.count("descend") + 1
    assert "place at camera" in separate and "place at camera" not in one
    assert one.count("standby") == 1


def test_a_sherd_left_on_the_scale_is_taken_to_the_mat_before_the_batch_ends(config):
    """With the camera over the scale no later station watches the empty pan with the arm
    free: the pan is looked at again when the mat is found empty, and what stayed on it is
    taken back and recorded as its own sherd, not left on the scale unsaid."""
    big = Sherd("big", 0.14, 0.24, length=0.06, width=0.05, thickness=0.009, mass=0.030)
    rider = Sherd("rider", 0.14, 0.24, length=0.04, width=0.03, mass=0.015)
    world = World(config, [big, rider])
    world.doubles = {"big": "rider"}  # the first grasp of `big` lifts `rider` too
    world.scale_settle = 1.5  # the pan not steady yet when the arm is at the discard box
    outcome, batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done", 2: "done"}
    assert rec.sherds[2].mass == pytest.approx(0.015)  # weighed on its own, later
    assert {s.station for s in world.sherds} == {"discard"}
    assert any(n.startswith("cleared: ") for n in rec.sherds[1].notes)
    # the first row weighed both; it was photographed (done) before the pan was seen: its own
    # mass by difference is said on it
    assert rec.sherds[1].mass == pytest.approx(0.045)
    assert any("its own mass by difference 30.0 g" in n for n in rec.sherds[1].notes)
    # and its photo, shot on the pan, had the rider in it: said on the row, a person to look
    assert any("archival photo was taken with that one" in n for n in rec.sherds[1].notes)
    assert batch.photo_with_another == [1]
    assert "photographed with another sherd" in what_is_left(batch, [])


def test_what_a_thick_sherd_taken_up_high_leaves_on_the_pan_is_weighed_out_of_its_row(config):
    # a 16 mm wall is thicker than a body sherd's (selection.THICK_WALL): two seen as one,
    # perhaps, so it is taken up high on its edge, and the pan is read, waited for, before its
    # row is done: what stayed there comes out of the row by difference (heap_20 seed 59: the
    # one left was weighed over by the next sherd and the row kept both masses)
    big = Sherd("big", 0.14, 0.24, length=0.06, width=0.05, height=0.018, thickness=0.016)
    big.mass = 0.030
    rider = Sherd("rider", 0.14, 0.24, length=0.04, width=0.03, mass=0.015)
    world = World(config, [big, rider])
    world.doubles = {"big": "rider"}
    world.scale_settle = 1.5
    outcome, _batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done", 2: "done"}
    assert (rec.sherds[1].mass, rec.sherds[2].mass) == pytest.approx((0.030, 0.015))
    assert any("its own mass by difference 30.0 g, recorded" in n for n in rec.sherds[1].notes)
    assert not any(n.startswith("pan_loaded") for r in rec.sherds.values() for n in r.notes)
    assert {s.station for s in world.sherds} == {"discard"}


def test_one_outline_whose_wall_its_mass_rules_out_that_leaves_nothing_is_flagged(config):
    # heap_20 seed 64: a sherd wholly on one of its size is seen as one outline on the pan too,
    # its wall there more than its mass allows for one sherd; the take-up high on its edge
    # lifted both (nothing stayed on the pan): the row stands as weighed, flagged `maybe_two`,
    # and the batch says so; had something stayed, it is weighed out of the row instead
    world = World(config, [Sherd("a", 0.10, 0.22, mass=0.025)])
    outcome, batch, rec = run_batch(config, world)
    assert outcome == "finished" and not batch.maybe_two
    scale = next(p for p in batch.plugins if p.station.name == "scale")
    last = scale._last
    world.t += 10.0  # the pan empty and settled
    last.parted_on, last.wall_doubted_alone = "scale", True
    scale._early_tare = None
    scale.while_away(arm_free=True)
    assert batch.maybe_two == [last.seq]
    assert any(n.startswith("maybe_two: seen as one outline") for n in rec.sherds[last.seq].notes)
    from rascal_tasks.run_batch import what_is_left

    assert "may be two lying as one (`maybe_two`)" in what_is_left(batch, [])
    # a wall its mass allows (not doubted alone), or something left on the pan: no flag
    batch.maybe_two.clear()
    last.parted_on, last.wall_doubted_alone = "scale", False
    scale.while_away(arm_free=True)
    assert not batch.maybe_two
    left = Sherd("left", 0.0, 0.0, mass=0.01)
    world.sherds.append(left)
    world.put(left, *config.stations["scale"].place_at)
    world.t += 10.0
    last.parted_on, last.wall_doubted_alone, last.status = "scale", True, "done"
    scale._early_tare = None  # (the empty pan was tared above)
    scale.while_away(arm_free=True)
    assert not batch.maybe_two and left.station == "pickup"


def test_a_sherd_recorded_lost_on_the_scale_is_left_there(config):
    """What lies on the pan after the scale's last sherd was recorded lost there, or what weighs
    what it weighed (dropped back unseen), is most likely that sherd: it is left for a person,
    not taken to the mat to be picked and recorded a second time. Any other sherd left on the
    pan is taken to the mat."""
    world = World(config, [Sherd("a", 0.10, 0.22, mass=0.025)])
    outcome, batch, rec = run_batch(config, world)
    assert outcome == "finished"
    scale = next(p for p in batch.plugins if p.station.name == "scale")
    left = Sherd("left", 0.0, 0.0, mass=0.02)
    world.sherds.append(left)
    world.put(left, *config.stations["scale"].place_at)
    world.t += 10.0  # settled on the pan for longer than a stable window
    scale._early_tare = None
    scale._last.status = "lost"
    assert scale.while_away(arm_free=True) is False
    assert left.station == "scale"
    scale._last.status = "done"
    scale._last.mass = 0.0201  # within two digits of what lies there: most likely itself
    assert scale.while_away(arm_free=True) is False
    assert left.station == "scale"
    scale._last.mass = 0.025
    assert scale.while_away(arm_free=True) is True
    assert left.station == "pickup"


def test_the_carry_lowers_the_sherd_onto_the_tared_scale_without_a_stop(config):
    """The scale tared while away and holding: the carry goes on down to where the sherd is
    let go (one motion, Batch.move_through), no second descent at the scale."""
    world = World(config, [Sherd("a", 0.10, 0.22)])
    outcome, _batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done"}
    scale = config.stations["scale"]
    travel = config["arm"]["travel_z"]
    at_scale = [m for m in world.moves if m[:2] == tuple(scale.place_at)]
    # carried, lowered to let it go (a step of the same motion), lifted with the way out
    carry = next(c for c in world.chains if c[-1][:2] == tuple(scale.place_at))
    assert [s[2] for s in carry[-2:]] == [travel, at_scale[1][2]] and carry[-1][4] is True
    assert at_scale[0][2] == travel and at_scale[1][2] < travel and at_scale[2][2] == travel
    # straight up from the sherd and on to the camera's standby, one motion
    way_out = [c for c in world.chains if c[-1][:2] == tuple(config["arm"]["standby"])][0]
    assert way_out[0][:3] == (*scale.place_at, travel) and way_out[0][4] is True


def test_a_pan_disturbed_during_the_carry_is_tared_with_the_sherd_clear_of_it(config):
    """Ready when the carry started, not at the arrival (something landed on the pan): the
    arm goes back up above the scale before the tare, then down to let the sherd go."""
    world = World(config, [Sherd("a", 0.10, 0.22)])
    scale = config.stations["scale"]
    grain = Sherd("grain", 0.0, 0.0, mass=0.002)

    def refuse(x, y, z, yaw, linear):
        if world.held is not None and (x, y) == tuple(scale.place_at) and grain not in world.sherds:
            if z < config["arm"]["travel_z"]:
                world.sherds.append(grain)
                world.put(grain, x + 0.05, y)  # on the pan, beside where the sherd goes
        return None

    world.refuse = refuse
    outcome, _batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done"}
    at_scale = [m for m in world.moves if m[:2] == tuple(scale.place_at)]
    travel = config["arm"]["travel_z"]
    # down with the carry, back up (linear) for the tare, down again
    zs = [m[2] for m in at_scale]
    first_low = next(i for i, z in enumerate(zs) if z < travel)
    assert zs[first_low + 1] == travel and at_scale[first_low + 1][4] is True
    assert zs[first_low + 2] < travel
    assert rec.sherds[1].mass == pytest.approx(0.02, abs=1e-6)  # the grain tared away


def test_parking_with_the_fingers_low_around_a_sherd_goes_straight_up_first(config):
    """A failure between setting a sherd down and the move that lifts away (Batch.lift_later)
    parks the arm: straight up from the sherd before the way to the sleep pose."""
    world = World(config, [])
    batch = workflow.Batch(config, world.rig(), Recorder(), context="T")
    batch.lift_later(0.23, -0.28, 0.5)
    workflow.park(batch)
    assert world.moves[-1] == (0.23, -0.28, config["arm"]["travel_z"], 0.5, True)
    assert world.named == ["sleep"] and batch.lift_pending is None


def _spy_shutters(monkeypatch, rec):
    """Each capture's sherd masses (seq -> kg or None) as its shutter fires."""
    shots = []
    real = fake_rig._Camera.capture_while

    def spy(camera, path, exposure_ev, during):
        shots.append({seq: r.mass for seq, r in rec.sherds.items()})
        return real(camera, path, exposure_ev, during)

    monkeypatch.setattr(fake_rig._Camera, "capture_while", spy)
    return shots


def test_the_photo_is_shot_while_the_scale_settles_and_the_sherd_taken_up_once_weighed(
    config, monkeypatch
):
    """The camera over the scale fires as soon as the arm is at standby, before the pan's
    reading has held for a window: the fingers go round the sherd and it is weighed during the
    transfer, then taken up."""
    world = World(config, [Sherd("a", 0.10, 0.22)])
    world.scale_settle = 1.5  # readings unsteady this long after the sherd lands
    rec = Recorder()
    shots = _spy_shutters(monkeypatch, rec)
    weighs = []  # the arm's moves made by the time the weighing starts
    weigh = ScaleStation._weigh
    monkeypatch.setattr(
        ScaleStation,
        "_weigh",
        lambda station, sherd, since: (
            weighs.append(list(world.moves)),
            weigh(station, sherd, since),
        )[1],
    )
    outcome, _batch, rec = run_batch(config, world, rec)
    assert outcome == "finished" and rec.status() == {1: "done"}
    assert shots == [{1: None}]  # no mass yet at the shutter
    over, down, _lift = world.transfer_moves[0]
    assert weighs[0][-2:] == [over, down]  # the fingers round it while the pan settles
    assert rec.sherds[1].mass == pytest.approx(0.02) and rec.sherds[1].image
    _over, _down, lift = world.transfer_moves[0]  # weighed, then taken up in the transfer
    assert lift[2] == config["arm"]["travel_z"]


def test_two_on_the_pan_keep_no_photo_and_are_not_taken_up_during_the_transfer(config, monkeypatch):
    """Two sherds lifted as one weigh too much: the photo shot meanwhile is not theirs to
    keep, the arm does not take them up during the transfer, and both are put back (PutBack)."""
    world = World(
        config,
        [Sherd("a", 0.10, 0.22), Sherd("b", 0.25, 0.29), Sherd("c", 0.20, 0.21, mass=0.015)],
    )
    world.doubles = {"a": "b"}
    rec = Recorder()
    shots = _spy_shutters(monkeypatch, rec)
    outcome, _batch, rec = run_batch(config, world, rec)
    assert outcome == "finished" and rec.status() == {1: "done", 2: "done", 3: "done"}
    assert sorted(round(r.mass, 4) for r in rec.sherds.values()) == [0.015, 0.02, 0.02]
    assert len(shots) == 4  # the pair's, then one for each sherd
    # the pair's transfer: the fingers went round them while the pan settled, then straight
    # up without closing (PUT_BACK picks them up)
    over, down, up = world.transfer_moves[0]
    assert down[2] < over[2] and up[:2] == down[:2] and up[2] == config["arm"]["travel_z"]
    assert up[4]


def test_a_sherd_the_take_up_missed_is_looked_for_before_it_is_grasped_again(config, monkeypatch):
    """The camera's take-up during the transfer (REPICK's blind grasp, grasp_where_set_down)
    closes on nothing: REPICK then looks first, instead of the same blind grasp again."""
    world = World(config, [Sherd("a", 0.10, 0.22)])
    scale = config.stations["scale"]
    events = []
    close, detect, put = fake_rig._Gripper.close, fake_rig._Perception.detect, world.put

    def logged_close(gripper):
        if world.station_at(*world.at[:2]) is scale:
            events.append("grasp")
        return close(gripper)

    def logged_detect(perception, station):
        if station == "scale":
            events.append("look")
        return detect(perception, station)

    def put_and_miss(s, x, y):
        put(s, x, y)
        if s.station == "scale" and not events:
            world.bad_holds[s.name] = 1  # set down: the next grasp closes on nothing

    monkeypatch.setattr(fake_rig._Gripper, "close", logged_close)
    monkeypatch.setattr(fake_rig._Perception, "detect", logged_detect)
    world.put = put_and_miss
    outcome, batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done"}
    assert events[:3] == ["grasp", "look", "grasp"], events


def test_a_rider_within_the_mass_bound_is_seen_on_the_pan_after_the_shutter(config, monkeypatch):
    """A 5 g sherd lying on `a`'s edge rides along on its grasp (25 g: within the mass bound of a
    50 x 40 mm sherd). `a` was picked with it lying on it, so the wrist camera looks at the pan
    on the way up from it: two there, no photo kept, both put back apart, a row each. The
    photos show the arm at standby only."""
    world = riding_world(config)
    rec = Recorder()
    shots = _spy_shutters(monkeypatch, rec)
    outcome, _batch, rec = run_batch(config, world, rec)
    assert outcome == "finished" and rec.status() == {1: "done", 2: "done", 3: "done"}
    assert sorted(round(r.mass, 4) for r in rec.sherds.values()) == [0.005, 0.02, 0.02]
    notes = [n for r in rec.sherds.values() for n in r.notes]
    assert any(n.startswith("two_in_one: ") and "sees 2 sherds on the scale" in n for n in notes)
    assert len(shots) == 4  # the pair's (not kept), then one for each sherd
    standby = tuple(config["arm"]["standby"])
    assert all(at[:2] == pytest.approx(standby) for at in world.at_shutter)


def test_the_look_for_a_second_sherd_is_made_on_the_way_up_before_the_photo(config):
    """`a` had a sherd lying on it (which did not ride along): the pan is looked at on the way
    up from it, before standby and the shutter; the transfer then only reaches back (a look
    from standby during it and back cost 2.4 s, heap_20 seed 45)."""
    world = World(
        config,
        [Sherd("a", 0.10, 0.22), Sherd("b", 0.13, 0.22, mass=0.005, support=0.01)],
    )
    outcome, _batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done", 2: "done"}
    scale = config.stations["scale"]
    survey_z = scale.surface_z + config["survey"]["z"]
    sx, sy = scale.place_at
    looks = [
        i
        for i, m in enumerate(world.moves)
        if m[2] == pytest.approx(survey_z) and abs(m[0] - sx) + abs(m[1] - sy) < 0.15
    ]
    standby = tuple(config["arm"]["standby"])
    first_standby = next(i for i, m in enumerate(world.moves) if m[:2] == pytest.approx(standby))
    assert looks and looks[0] < first_standby, (looks, first_standby)
    assert not any(m[2] == pytest.approx(survey_z) for m in world.transfer_moves[0])
    assert all(at[:2] == pytest.approx(standby) for at in world.at_shutter)
