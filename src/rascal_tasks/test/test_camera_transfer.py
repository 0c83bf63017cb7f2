"""The archival station's capture overlapped with the arm (issue 18, item 4): the shutter only
with the arm at standby, the way back over the sherd during the image's transfer, and every
retake or failed transfer taken again from standby (batch tier, on the in-memory rig)."""

import pytest
from fake_rig import Sherd, World, run_batch, shipped_config


@pytest.fixture
def config():
    return shipped_config()


def _poses(config):
    cam = next(s for s in config.stations.values() if s.type == "archival_camera")
    return cam, tuple(config["arm"]["standby"]), config["arm"]["travel_z"]


def _at_standby(at, standby, travel):
    return at[:2] == pytest.approx(standby) and at[2] == pytest.approx(travel)


def test_the_shutter_sees_no_arm_and_the_fingers_are_open_around_the_sherd_by_the_photo(config):
    world = World(config, [Sherd("a", 0.10, 0.22), Sherd("b", 0.25, 0.30)])
    outcome, _batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done", 2: "done"}
    cam, standby, travel = _poses(config)
    assert len(world.at_shutter) == 2
    assert all(_at_standby(at, standby, travel) for at in world.at_shutter)
    # while the image is transferred: over the sherd, straight down to its grasp height, and
    # (only the discard box after it: nothing else works on it there) picked up, straight up
    # to travel height, where it waits for the photo
    for moves in world.transfer_moves:
        over, down, lift = moves
        assert over[:2] == pytest.approx(tuple(cam.place_at)) and not over[4]
        assert down[:2] == pytest.approx(tuple(cam.place_at)) and down[4]
        assert cam.surface_z < down[2] < over[2] < travel
        assert lift[:2] == pytest.approx(tuple(cam.place_at)) and lift[2] == travel and lift[4]
    # once the photo is in, the next move carries it on to the discard box: REPICK did nothing
    box = config.stations["discard"]
    for k, m in enumerate(world.moves):
        if _at_standby(m, standby, travel):
            assert world.moves[k + 4][:2] == pytest.approx(tuple(box.place_at))
    assert {s.station for s in world.sherds} == {"discard"}


def test_a_transfer_that_fails_is_shot_again_from_standby_after_lifting_straight_up(config):
    world = World(config, [Sherd("a", 0.10, 0.22)])
    world.transfer_failures = 1  # the shutter closed, the arm came back; the image was lost
    outcome, _batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done"}
    assert any(n.startswith("capture_failed: attempt 1") for n in rec.sherds[1].notes)
    cam, standby, travel = _poses(config)
    assert len(world.at_shutter) == 2
    assert all(_at_standby(at, standby, travel) for at in world.at_shutter)
    # between the two shutters: over the sherd, straight up (linear) at its spot, to standby
    first = next(k for k, m in enumerate(world.moves) if _at_standby(m, standby, travel))
    second = next(
        k for k, m in enumerate(world.moves) if k > first and _at_standby(m, standby, travel)
    )
    lift = world.moves[second - 1]
    assert lift[:2] == pytest.approx(tuple(cam.place_at)) and lift[2] == travel and lift[4]
    # it had been picked up during the lost transfer: set down again for the second shutter
    down_again = world.moves[second - 2]
    assert down_again[:2] == pytest.approx(tuple(cam.place_at)) and down_again[2] < travel
    assert world.in_view_at_shutter == [["a"], ["a"]]


def test_a_clipped_photo_is_retaken_from_standby_too(config, tmp_path):
    world = World(config, [Sherd("a", 0.10, 0.22), Sherd("b", 0.25, 0.30)])
    world.photo_folder = str(tmp_path)
    world.photo_light = 1.5  # clips at the configured exposure: the first photo is retaken
    outcome, _batch, rec = run_batch(config, world)
    assert outcome == "finished" and rec.status() == {1: "done", 2: "done"}
    assert world.exposures == [0.0, -1.0, -1.0]
    _cam, standby, travel = _poses(config)
    assert len(world.at_shutter) == 3
    assert all(_at_standby(at, standby, travel) for at in world.at_shutter)


def test_a_move_during_a_capture_counts_as_locomotion_only(config):
    world = World(config, [])
    _outcome, batch, _rec = run_batch(config, world)
    batch.timings = type(batch.timings)()
    with batch.phase("data_collection"):
        world.t += 2.0  # the shutter
        batch.move_down(0.2, 0.0, 0.2, 0.0)  # 1 s in the fake world
        world.t += 0.5  # the rest of the transfer
    assert batch.timings.locomotion == pytest.approx(1.0)
    assert batch.timings.data_collection == pytest.approx(2.5)
