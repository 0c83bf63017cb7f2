"""Core tests of the scale station's weighing rule (`stations.settled`, `stations.ScaleStation`)
against a scripted scale on the fake clock (no master, no database): a mass is recorded only
from a reading that held within the readability for scale.stable_window on a platform tared
after it settled (the tare checked); otherwise the sherd is read again and then recorded
mass_unstable without a mass. Only a steady reading below the minimum means "not there"."""

import dataclasses
import math
import os

import pytest
import yaml
from fake_rig import Recorder, World

from rascal_tasks import rig, workflow
from rascal_tasks.config import config_from_dict
from rascal_tasks.rig import RigError, ScaleReading
from rascal_tasks.sherd_record import SherdRecord
from rascal_tasks.stations import ScaleStation, reads_zero, settled

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
SHERD = 0.0139  # kg: the sherd of the field report (13.9 g)
SWING = 0.003  # kg: what an unsettled tare catches (the field report: 3 g low)


@pytest.fixture
def config():
    with open(os.path.join(WORKSPACE, "config", "rascal.yaml")) as f:
        return config_from_dict(yaml.safe_load(f))


class ScriptedScale(rig.Scale):
    """A 10 Hz scale of 0.1 g readability on the fake clock. `load(t)` is what the pan carries
    (kg, disturbances included), `flag(t)` the scale's own stable flag. Each of the first
    `unsettled_tares` tares catches the platform swinging SWING high, which dies away over
    2 s (as the simulator's SCALE_UNSETTLED_TARE): zero SWING too high."""

    def __init__(self, world):
        self.w = world
        self.load = lambda t: 0.0
        self.flag = lambda t: True
        self.unsettled_tares = 0
        self.tares = []  # (time, zero, swing start or None)
        self.silent = False

    def tare(self):
        t = self.w.t
        swing = len(self.tares) < self.unsettled_tares
        self.tares.append((t, self.load(t) + (SWING if swing else 0.0), t if swing else None))

    def shown(self, t):
        zero, value = 0.0, self.load(t)
        for at, z, swing in self.tares:
            if at < t:
                zero = z
                if swing is not None and t < swing + 2.0:
                    value += SWING * (1.0 - (t - swing) / 2.0)
        return round((value - zero) / 1e-4) * 1e-4

    def readings(self, since):
        if self.silent:
            return []
        first = math.floor(max(since, self.w.t - 30.0) / 0.1 + 1e-9) + 1
        last = math.floor(self.w.t / 0.1 + 1e-9)
        return [
            ScaleReading(self.shown(k * 0.1), self.flag(k * 0.1), k * 0.1)
            for k in range(first, last + 1)
        ]


def _garbage(t):
    """What a glitching scale shows: jumps of up to +-2 g about 0.5 g (a steady 'empty' never)."""
    return 0.0005 + 0.002 * math.sin(t * 7.3) * math.cos(t * 2.1)


@pytest.fixture
def station(config):
    world = World(config, [])
    world.t = 100.0
    r = world.rig()
    r.scale = ScriptedScale(world)
    recorder = Recorder()
    log = []
    batch = workflow.Batch(config, r, recorder, context="T", log=log.append)
    plugin = batch.plugins[0]
    assert isinstance(plugin, ScaleStation)
    sherd = SherdRecord(batch, recorder.new_sherd((0.1, 0.2)))
    batch.sherd = sherd
    return plugin, sherd, r.scale, world, recorder, log


def _place(world, scale, at_load=SHERD, after=1.0):
    """The sherd lands on the pan `after` s from now; it settles like a real pan (0.3 s)."""
    t0 = world.t + after
    old = scale.load
    scale.load = lambda t: old(t) + (at_load * (1 - math.exp(-(t - t0) / 0.3)) if t >= t0 else 0)
    world.t = t0 + 0.6  # down, open, up to hover: then the station reads


def _row(recorder):
    return recorder.sherds[1]


def _notes(recorder, kind):
    return [n for n in _row(recorder).notes if n.startswith(kind + ":")]


# -- the rule ------------------------------------------------------------------------------------
def _series(values, stable=True, start=10.0):
    return [ScaleReading(v, stable, start + 0.1 * i) for i, v in enumerate(values)]


def test_settled_needs_a_whole_window_within_the_readability():
    steady = _series([0.0139, 0.0140, 0.0139] * 4)  # 1.1 s flickering by one digit
    r = settled(steady, 1.0, 1e-4)
    assert r.stable and r.stamp == steady[-1].stamp
    assert r.mass == pytest.approx((4 * 0.0140 + 7 * 0.0139) / 11, abs=1e-7)  # 11 readings: 1 s
    assert settled(steady[:10], 1.0, 1e-4) is None  # 0.9 s watched: not a whole window yet
    jump = steady[:6] + [ScaleReading(0.0141, True, 10.6)] + steady[7:]
    assert settled(jump, 1.0, 1e-4) is None  # 0.2 g apart inside the window
    assert settled(jump[:6] + _series([0.014] * 11, start=10.6), 1.0, 1e-4) is not None
    assert settled(_series([0.0139] * 12, stable=False), 1.0, 1e-4) is None  # the scale says no
    # the scale's own flag is not enough: it says stable while the reading creeps 0.3 g
    creep = _series([0.0139 + 0.00003 * i for i in range(12)])
    assert settled(creep, 1.0, 1e-4) is None
    assert settled([], 1.0, 1e-4) is None


def test_reads_zero_allows_the_last_digit_either_way_for_a_whole_window():
    flicker = _series([0.0, 1e-4, 0.0, -1e-4, 0.0, 0.0, 1e-4, 0.0, -1e-4, 0.0, 0.0])  # 1.0 s
    assert settled(flicker, 1.0, 1e-4) is None  # 0.2 g apart: too loose for a mass
    assert reads_zero(flicker, 1.0, 1e-4)  # but zero within the readability throughout
    assert not reads_zero(flicker[:10], 1.0, 1e-4)  # 0.9 s: not a whole window
    assert not reads_zero(flicker[:5] + _series([2e-4] * 6, start=10.5), 1.0, 1e-4)  # off zero
    assert not reads_zero(_series([0.0] * 11, stable=False), 1.0, 1e-4)  # the scale says no
    assert not reads_zero([], 1.0, 1e-4)


# -- weighing ------------------------------------------------------------------------------------
def test_a_steady_sherd_is_weighed_on_a_checked_tare(station):
    plugin, sherd, scale, world, recorder, _ = station
    plugin.before_place(sherd)
    assert len(scale.tares) == 1
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).status == "weighed"
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)
    assert sherd.status == "weighed"


def test_more_mass_than_one_sherd_of_its_size_can_have_is_two_sherds_put_back_once(station):
    # 45 x 35 mm with a 6 mm wall: 13.9 g (1.47 g/cm^3 of its box) is one sherd; 2.3 times that
    # is no single sherd of that size (at most 2.3 g/cm^3 over the box, 10 % for the curve)
    plugin, sherd, scale, world, recorder, log = station
    sherd.observation = rig.Observation(
        0.1, 0.2, 0, 0.045, 0.035, 0.012, 0.1, 0.2, 0.01, 0, 0.05, thickness=0.006
    )
    plugin.before_place(sherd)
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"  # one sherd: weighed
    assert not [n for n in _row(recorder).notes if "mass checked" in n]
    plugin.before_place(sherd)
    _place(world, scale, at_load=2.3 * SHERD)
    assert plugin.after_place(sherd) == "double"  # two: no mass, put back (PutBack)
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)  # what was recorded stands
    # the same number weighed as heavy again after it was put back: one heavy sherd, noted
    plugin.before_place(sherd)
    _place(world, scale, at_load=2.3 * SHERD)
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).mass == pytest.approx(2.3 * SHERD, abs=5e-5)
    assert [n for n in _row(recorder).notes if n.startswith("mass checked: two sherds")]


def test_a_wall_thicker_than_its_mass_allows_is_taken_out_of_the_row_with_the_figure(station):
    # measured in a heap where it lay on a sherd seen as part of it (heap_20 seed 59: 26.6 g,
    # 47 x 37 mm recorded with a 35.1 mm wall): the row keeps no wall, the note the figure
    plugin, sherd, scale, world, recorder, _ = station
    heaped = rig.Observation(
        0.1, 0.2, 0, 0.045, 0.035, 0.032, 0.1, 0.2, 0.01, 0, 0.05, thickness=0.030
    )
    sherd.record_dimensions(heaped)
    assert _row(recorder).size[2] == pytest.approx(0.030)
    plugin.before_place(sherd)
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)
    assert _row(recorder).size[:2] == pytest.approx((0.045, 0.035))
    assert _row(recorder).size[2] is None
    (note,) = _notes(recorder, "wall_not_recorded")
    assert "30.0 mm wall" in note and "13.9 g" in note
    # its own 6 mm wall at 13.9 g (1.47 g/cm^3 of its box) is one wall: kept
    sherd.record_dimensions(dataclasses.replace(heaped, thickness=0.006))
    plugin.before_place(sherd)
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).size[2] == pytest.approx(0.006)
    assert len(_notes(recorder, "wall_not_recorded")) == 1


def test_a_pan_already_loaded_is_tared_over_and_the_row_says_so(station):
    # a sherd left on the scale that the wrist camera did not see: the next sherd is weighed
    # right (tared over it) and its row says the pan was not empty
    plugin, sherd, scale, world, recorder, _ = station
    scale.load = lambda t: 0.0207
    plugin.before_place(sherd)
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)
    (note,) = _notes(recorder, "pan_loaded")
    assert "the empty pan read 20.7 g before the tare" in note, note
    # the next sherd, on a pan emptied since (it reads below the tare): nothing said
    scale.load = lambda t: 0.0
    plugin.before_place(SherdRecord(plugin.batch, recorder.new_sherd((0.1, 0.2))))
    assert not [n for n in recorder.sherds[2].notes if n.startswith("pan_loaded")]


def test_unstable_longer_than_every_reread_is_mass_unstable_with_no_mass(station, config):
    plugin, sherd, scale, world, recorder, log = station
    plugin.before_place(sherd)
    _place(world, scale)
    glitch_from = world.t
    scale.load = lambda t, base=scale.load: _garbage(t) if t < glitch_from + 20 else base(t)
    scale.flag = lambda t: not glitch_from <= t < glitch_from + 20
    start = world.t
    assert plugin.after_place(sherd) == "done"  # not "missing": the sherd goes on
    cfg = config["scale"]
    assert world.t - start == pytest.approx((1 + cfg["rereads"]) * cfg["stable_timeout"], abs=0.2)
    row = _row(recorder)
    assert (row.status, row.mass) == ("mass_unstable", None)
    assert "did not hold within 0.1 g for 1.0 s in 3 attempts" in row.mass_missing_reason
    assert len(_notes(recorder, "scale_unstable")) == 1 + cfg["rereads"]
    assert not _notes(recorder, "scale_empty") and row.drops == 0
    assert sherd.status == "mass_unstable" and sherd.mass is None
    assert any("mass_unstable" in line for line in log)
    recorder.photo(1, "/spool/T-1.png")  # and it goes on: photographed, then done
    recorder.done(1)
    assert (row.status, row.mass) == ("done", None)


def test_a_sherd_that_settles_late_gets_its_correct_mass(station):
    plugin, sherd, scale, world, recorder, _ = station
    plugin.before_place(sherd)
    _place(world, scale)
    until = world.t + 6.0  # unsteady through the first read, steady in the second
    scale.load = lambda t, base=scale.load: base(t) + (_garbage(t) if t < until else 0.0)
    scale.flag = lambda t: t >= until
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).status == "weighed"
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)
    assert len(_notes(recorder, "scale_unstable")) == 1


def test_only_a_steady_empty_reading_means_the_sherd_is_not_there(station):
    plugin, sherd, scale, world, recorder, _ = station
    plugin.before_place(sherd)
    world.t += 2.0  # nothing landed: it slipped away on the way
    assert plugin.after_place(sherd) == "missing"
    assert _row(recorder).status == "picked" and _notes(recorder, "scale_empty")


def test_a_failed_reweigh_keeps_the_mass_recorded_before(station):
    plugin, sherd, scale, world, recorder, _ = station
    plugin.before_place(sherd)
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"
    plugin.before_place(sherd)  # weighed again (it cannot happen today; defended anyway)
    scale.flag = lambda t: False
    assert plugin.after_place(sherd) == "done"
    assert (_row(recorder).status, _row(recorder).mass) == ("weighed", pytest.approx(SHERD, 5e-3))
    assert any("the mass recorded before stands" in n for n in _row(recorder).notes)


# -- the tare ------------------------------------------------------------------------------------
def test_a_tare_that_caught_the_platform_swinging_is_redone(station):
    plugin, sherd, scale, world, recorder, _ = station
    scale.unsettled_tares = 1
    plugin.before_place(sherd)
    assert len(scale.tares) == 2
    assert _notes(recorder, "tare_failed") == [
        "tare_failed: attempt 1: the empty platform reads -3.0 g after the tare"
    ]
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)  # not 3 g low


def test_the_tare_waits_for_the_empty_platform_to_settle(station, config):
    plugin, sherd, scale, world, recorder, _ = station
    quiet_from = world.t + 2.0  # the pan still swings (the scale calls it stable all along)
    scale.load = lambda t: 0.002 * math.sin(5.0 * t) if t < quiet_from else 0.0
    plugin.before_place(sherd)
    assert len(scale.tares) == 1
    assert scale.tares[0][0] >= quiet_from + config["scale"]["stable_window"] - 1e-6
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)


def test_a_scale_that_cannot_be_tared_records_mass_unstable_and_does_not_weigh(station, config):
    plugin, sherd, scale, world, recorder, _ = station
    scale.load = _garbage
    scale.flag = lambda t: False
    plugin.before_place(sherd)
    assert scale.tares == []  # never tared on an unsettled platform
    assert len(_notes(recorder, "tare_failed")) == 1 + config["scale"]["rereads"]
    row = _row(recorder)
    assert row.status == "mass_unstable" and row.mass is None
    assert row.mass_missing_reason.startswith("the scale could not be tared (empty platform not")
    _place(world, scale)
    t = world.t
    assert plugin.after_place(sherd) == "done" and world.t == t  # not weighed on a bad zero
    assert row.status == "mass_unstable"


def test_a_silent_scale_stops_the_batch(station):
    plugin, sherd, scale, world, recorder, _ = station
    scale.silent = True
    with pytest.raises(RigError) as err:
        plugin.before_place(sherd)
    assert err.value.code == "TIMEOUT" and "no scale reading" in err.value.reason


# -- after a restart -----------------------------------------------------------------------------
def test_after_a_restart_a_sherd_lying_on_the_scale(station):
    plugin, sherd, scale, world, recorder, _ = station
    scale.tare()  # the killed run tared (and checked) before placing it
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"  # picked: weighed, the unchecked tare noted
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)
    assert _notes(recorder, "tare_unchecked")
    other = SherdRecord.resumed(plugin.batch, recorder.new_sherd((0.1, 0.2)), "picked")
    recorder.mass_unstable(other.seq, "the scale could not be tared (x)")
    other.status = "mass_unstable"  # as the catalogue handed it back
    t = world.t
    assert plugin.after_place(other) == "done" and world.t == t  # not weighed on that zero
    assert recorder.sherds[other.seq].status == "mass_unstable"


# -- the tare done while the arm is away ---------------------------------------------------------
def _weighed_on_the_early_tare(plugin, sherd, scale, world, recorder):
    """The next sherd placed on the tare made while away: no tare, no wait above the scale."""
    t = world.t
    plugin.before_place(sherd)
    assert len(scale.tares) == 1 and world.t == t
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)


def test_a_pan_tared_while_the_arm_was_away_is_not_tared_again_nor_waited_for(station):
    plugin, sherd, scale, world, recorder, _ = station
    plugin.while_away()  # the arm at the camera: the pan has read 0 steadily
    plugin.while_away()  # and at the discard box: once is enough
    assert len(scale.tares) == 1
    world.t += 6.0  # the next sherd is picked up and carried over the scale
    _weighed_on_the_early_tare(plugin, sherd, scale, world, recorder)
    assert not _notes(recorder, "pan_loaded")
    # the next sherd needs a tare of its own
    plugin.before_place(sherd)
    assert len(scale.tares) == 2


def test_an_early_tare_holds_on_a_pan_flickering_one_digit_either_way(station):
    """An empty pan's noise flips its last digit both ways within a window (-0.1 and +0.1 g):
    it is tared while the arm is away, and after the tare it reads zero within the readability,
    so that tare holds (the bench at 3b5372f tared 3 of seed 10's 10 sherds again above the
    scale, 2.5 s each)."""
    plugin, sherd, scale, world, recorder, _ = station
    tared = world.t
    flicks = {-6: 1e-4, -2: -1e-4, 3: 1e-4, 7: -1e-4, 12: 1e-4, 16: -1e-4, 21: -1e-4, 25: 1e-4}
    scale.load = lambda t: flicks.get(round((t - tared) / 0.1), 0.0)
    assert settled(scale.readings(tared - 1.1), 1.0, 1e-4) is None  # empty, 0.2 g apart
    plugin.while_away()  # steady enough to tare: the check after it allows no more
    assert [t for t, _zero, _swing in scale.tares] == [tared]
    world.t = tared + 3.0  # the next sherd carried over the scale
    assert settled(scale.readings(tared), 1.0, 1e-4) is None  # the last window 0.2 g apart
    assert plugin.ready_for_place(sherd)
    _weighed_on_the_early_tare(plugin, sherd, scale, world, recorder)


def test_a_pan_still_swinging_is_not_tared_while_the_arm_is_away(station):
    plugin, sherd, scale, world, recorder, _ = station
    quiet_from = world.t + 2.0
    scale.load = lambda t: 0.002 * math.sin(5.0 * t) if t < quiet_from else 0.0
    plugin.while_away()
    assert scale.tares == []
    world.t += 6.0
    plugin.before_place(sherd)  # tared above the scale, as before
    assert len(scale.tares) == 1 and scale.tares[0][0] >= quiet_from


def test_an_early_tare_that_no_longer_reads_zero_is_done_again_above_the_scale(station):
    # something landed on the pan after the early tare (a sherd that slipped over it), or the
    # early tare caught the platform swinging: the pan is tared again with the sherd above it
    plugin, sherd, scale, world, recorder, _ = station
    plugin.while_away()
    world.t += 3.0
    landed = world.t
    scale.load = lambda t: 0.0207 if t >= landed else 0.0
    world.t += 3.0
    plugin.before_place(sherd)
    assert len(scale.tares) == 2
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)
    (note,) = _notes(recorder, "pan_loaded")  # said, as for any pan found loaded
    assert "the empty pan read 20.7 g before the tare" in note, note


def test_an_early_tare_that_caught_the_platform_swinging_is_redone(station):
    plugin, sherd, scale, world, recorder, _ = station
    scale.unsettled_tares = 1
    plugin.while_away()
    world.t += 6.0
    plugin.before_place(sherd)
    assert len(scale.tares) == 2
    _place(world, scale)
    assert plugin.after_place(sherd) == "done"
    assert _row(recorder).mass == pytest.approx(SHERD, abs=5e-5)  # not 3 g low
