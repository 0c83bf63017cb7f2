"""Core tests of letting go of a sherd (`manipulation.release`): the fingers open wider than
they hold it, and that they got there is checked. Against the in-memory rig of `fake_rig.py`,
whose gripper, like a position-commanded one, presses on when sent narrower than it holds.
"""

from types import SimpleNamespace

import pytest
from fake_rig import Sherd, World, run_batch, shipped_config

from rascal_tasks import rig
from rascal_tasks.manipulation import MAX_OPENING, MIN_OPENING, release


@pytest.fixture
def config():
    return shipped_config()


def test_a_sherd_held_wider_than_seen_is_let_go_at_every_station(config):
    """Seen 35 mm wide from above, held across a 55 mm chord (a grasp turned to clear its
    neighbours): an open to 35 + margin would press the fingers on it at the scale, and it
    would ride along, unweighed, unphotographed, to be let go wherever the fingers next open."""
    a = Sherd("a", 0.12, 0.24, width=0.035, held_width=0.055, mass=0.027)
    world = World(config, [a, Sherd("b", 0.25, 0.30, mass=0.019)])
    outcome, _batch, rec = run_batch(config, world)
    assert outcome == "finished"
    assert rec.status() == {1: "done", 2: "done"}
    assert rec.sherds[1].mass == pytest.approx(0.027)
    assert rec.sherds[2].mass == pytest.approx(0.019)
    assert {s.station for s in world.sherds} == {"discard"}


class _StuckGripper(rig.Gripper):
    """Fingers that stop at 50 mm whatever they are sent to."""

    def __init__(self):
        self.sent = []

    def open(self, width=None):
        self.sent.append(width)
        return 0.5

    def width(self):
        return 0.050


def test_fingers_that_do_not_open_are_tried_fully_open_then_said(config):
    gripper = _StuckGripper()
    b = SimpleNamespace(config=config, rig=SimpleNamespace(gripper=gripper))
    with pytest.raises(rig.RigError) as e:
        release(b, 0.030)
    assert e.value.code == "NOT_RELEASED"
    assert "50.0 mm" in str(e.value) and "free the fingers" in str(e.value)
    assert gripper.sent == [pytest.approx(0.062), None]  # 50 mm held + 12 mm margin; then fully


def test_fingers_sent_wider_than_they_held_it_report_that_width(config):
    class _Gripper(_StuckGripper):
        def __init__(self):
            super().__init__()
            self.at = 0.045

        def open(self, width=None):
            self.at = MAX_OPENING if width is None else width
            return super().open(width)

        def width(self):
            return self.at

    gripper = _Gripper()
    b = SimpleNamespace(config=config, rig=SimpleNamespace(gripper=gripper))
    assert release(b, 0.030) == pytest.approx(0.045)  # the chord it was held across
    assert gripper.sent == [pytest.approx(0.057)]
    # fingers that had closed on nothing (30 mm) say nothing of a 20 mm sherd's width
    gripper.at = MIN_OPENING
    assert release(b, 0.020) == pytest.approx(0.020)
