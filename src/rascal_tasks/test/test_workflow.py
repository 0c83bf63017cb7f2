"""Core tests of the station workflow's structure (no master, no rig): the machine is built
from the config's stations, and a new station type is a class plus a config entry."""
import copy
import os

import pytest
import yaml

from rascal_tasks import rig, stations, workflow
from rascal_tasks.config import config_from_dict
from rascal_tasks.survey import lawnmower

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))


@pytest.fixture
def data():
    with open(os.path.join(WORKSPACE, "config", "rascal.yaml")) as f:
        return yaml.safe_load(f)


class _Clock(rig.Clock):
    def now(self):
        return 0.0


def _batch(cfg):
    r = rig.Rig(rig.Arm(), rig.Gripper(), rig.Perception(), rig.Scale(), rig.ArchivalCamera(),
                _Clock())
    return workflow.Batch(cfg, r, recorder=None, context="T")


def test_machine_visits_the_stations_in_config_order(data):
    sm = workflow.build_machine(_batch(config_from_dict(data)))
    labels = set(sm.get_children())
    assert {"TRANSLATE_0", "PLACE_0", "STATION_0", "REPICK_0", "TRANSLATE_2"} <= labels
    assert "REPICK_2" not in labels  # nothing is picked up from the discard box
    assert isinstance(sm.get_children()["STATION_0"], workflow.AtStation)
    b = sm.get_children()["STATION_0"].batch
    assert [type(p).__name__ for p in b.plugins] == [
        "ScaleStation", "ArchivalCameraStation", "DiscardStation"]


def test_every_state_outcome_is_wired(data):
    sm = workflow.build_machine(_batch(config_from_dict(data)))
    sm.check_consistency()  # raises InvalidTransitionError for a dangling outcome
    for label, state in sm.get_children().items():
        assert set(state.get_registered_outcomes()) <= set(sm._transitions[label]), label


def test_a_new_station_type_is_a_class_and_a_config_entry(data, monkeypatch):
    monkeypatch.setitem(stations.STATION_PLUGINS, "profile_scanner", None)

    @stations.station_type("profile_scanner")
    class ProfileScanner(stations.StationPlugin):
        status = "weighed"

        def after_place(self, sherd):
            return "done"

    d = copy.deepcopy(data)
    order = list(d["stations"].items())
    scanner = {"type": "profile_scanner", "position": [0.38, 0.12], "size": [0.08, 0.08],
               "surface_z": 0.01}
    d["stations"] = dict(order[:2] + [("scanner", scanner)] + order[2:])
    cfg = config_from_dict(d)
    assert cfg.station_order() == ["scale", "scanner", "camera", "discard"]
    b = _batch(cfg)
    assert isinstance(b.plugins[1], ProfileScanner)
    labels = set(workflow.build_machine(b).get_children())
    assert {"TRANSLATE_3", "STATION_1", "REPICK_2"} <= labels


def test_unknown_station_type_is_refused(data):
    d = copy.deepcopy(data)
    d["stations"]["scale"]["type"] = "balance"
    with pytest.raises(ValueError, match="stations.scale.type: expected one of pickup, scale"):
        config_from_dict(d)


def test_opening_is_clamped_to_the_gripper():
    assert workflow.opening_for(0.010, 0.012) == workflow.MIN_OPENING
    assert workflow.opening_for(0.040, 0.012) == pytest.approx(0.052)
    assert workflow.opening_for(0.070, 0.012) == workflow.MAX_OPENING


def test_detections_from_two_survey_poses_are_merged():
    def obs(x, y):
        return rig.Observation(x, y, 0, 0.04, 0.03, 0.01, x, y, 0.01, 0, 0.045)
    merged = workflow._merge([obs(0.10, 0.20)], [obs(0.105, 0.20), obs(0.20, 0.25)])
    assert [(o.x, o.y) for o in merged] == [(0.10, 0.20), (0.20, 0.25)]


def test_lawnmower_covers_the_area_without_backtracking():
    poses = lawnmower((0.16, 0.25), (0.30, 0.16), 0.16)
    assert poses == pytest.approx([(0.085, 0.25), (0.235, 0.25)])
    grid = lawnmower((0.0, 0.0), (0.3, 0.2), 0.1)
    assert len(grid) == 6
    assert [p[1] for p in grid[:2]] == pytest.approx([-0.05, 0.05])
    assert [p[1] for p in grid[2:4]] == pytest.approx([0.05, -0.05])  # boustrophedon
