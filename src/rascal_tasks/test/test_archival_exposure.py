"""The archival photo's exposure: shot again darker while its highlights clip (unit tier: the
rule on synthetic photos; batch tier: the camera station on the in-memory rig)."""

import os

import cv2
import numpy as np
import pytest
import yaml
from fake_rig import Recorder, Sherd, World

from rascal_tasks import workflow
from rascal_tasks.archival import exposure
from rascal_tasks.archival.exposure import Brightness, Exposure
from rascal_tasks.config import config_from_dict

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))


def photo(tmp_path, top, share):
    """A mid-grey 400 x 300 photo whose brightest `share` of pixels are at code `top`."""
    img = np.full((300, 400, 3), 100, np.uint8)
    n = int(round(share * img.shape[0] * img.shape[1]))
    img.reshape(-1, 3)[:n, 0] = top  # one channel is enough to clip
    path = str(tmp_path / ("p_%d_%g.png" % (top, share)))
    cv2.imwrite(path, img)
    return path


def test_near_clipping_is_measured_on_the_highest_channel(tmp_path):
    seen = exposure.measure(photo(tmp_path, 252, 0.01))
    assert seen.near_clip_share == pytest.approx(0.01, abs=1e-4) and seen.top_code == 252
    dim = exposure.measure(photo(tmp_path, 200, 0.01))
    assert dim.near_clip_share == 0.0 and dim.top_code == 200
    assert exposure.measure(str(tmp_path / "missing.png")) is None


def test_a_clipped_photo_is_shot_again_a_stop_darker_down_to_two_stops():
    e = Exposure()
    clipped = Brightness(0.02, 255)
    assert e.retake(clipped) == -1.0 and e.ev == -1.0
    assert e.retake(clipped) == -2.0
    assert e.retake(clipped) is None and e.ev == -2.0  # darkest: it stands (the analysis flags it)
    assert e.retake(Brightness(exposure.RETAKE_SHARE / 2, 255)) is None  # a glint is no reason
    assert e.retake(None) is None  # unreadable: the analysis says why


def test_the_exposure_steps_back_up_only_with_a_stop_of_headroom():
    e = Exposure()
    e.retake(Brightness(0.02, 255))
    e.settle(Brightness(0.0, 230))  # below clipping but not a stop below: stays
    assert e.ev == -1.0
    e.settle(Brightness(0.0, 120))
    assert e.ev == 0.0
    e.settle(Brightness(0.0, 50))
    assert e.ev == 0.0  # never brighter than the site configured


@pytest.fixture
def config():
    with open(os.path.join(WORKSPACE, "config", "rascal.yaml")) as f:
        return config_from_dict(yaml.safe_load(f))


def test_the_station_retakes_a_clipped_photo_and_keeps_the_darker_exposure(config, tmp_path):
    world = World(config, [Sherd("a", 0.10, 0.22), Sherd("b", 0.25, 0.30), Sherd("c", 0.2, 0.2)])
    world.photo_folder = str(tmp_path)
    world.photo_light = 1.5  # the chart's white clips at the configured exposure, not a stop down
    rec = Recorder()
    batch = workflow.Batch(config, world.rig(), rec, context="T", log=print)
    assert workflow.build_machine(batch).execute() == "finished"
    assert rec.status() == {1: "done", 2: "done", 3: "done"}
    assert world.exposures == [0.0, -1.0, -1.0, -1.0]  # one retake; the next sherds start darker
    notes = {
        seq: [n for n in r.notes if n.startswith("exposure: ")] for seq, r in rec.sherds.items()
    }
    assert len(notes[1]) == 1 and "shot again at -1 EV" in notes[1][0]
    assert notes[2] == notes[3] == []
    # the photo recorded is the darker one
    assert cv2.imread(rec.sherds[1].image)[0, 0, 0] == round(1.5 * 255 / 2)


def test_a_darker_photo_that_fails_leaves_the_first_standing(config, tmp_path):
    world = World(config, [Sherd("a", 0.10, 0.22)])
    world.photo_folder = str(tmp_path)
    world.photo_light = 1.5
    world.camera_refuses = lambda ev: ev < 0  # every darker capture fails
    rec = Recorder()
    batch = workflow.Batch(config, world.rig(), rec, context="T", log=print)
    assert workflow.build_machine(batch).execute() == "finished"
    assert rec.status() == {1: "done"}
    assert cv2.imread(rec.sherds[1].image)[0, 0, 0] == 255  # the clipped photo, not none
    assert any("failed: it stands" in n for n in rec.sherds[1].notes)


def test_the_photo_shot_again_goes_beside_and_the_first_is_removed(config, tmp_path):
    world = World(config, [Sherd("a", 0.10, 0.22)])
    world.photo_folder = str(tmp_path)
    world.photo_light = 1.5
    rec = Recorder()
    batch = workflow.Batch(config, world.rig(), rec, context="T", log=print)
    assert workflow.build_machine(batch).execute() == "finished"
    assert sorted(os.listdir(tmp_path)) == ["T-1_ev-1.png"]
    assert rec.sherds[1].image == str(tmp_path / "T-1_ev-1.png")
