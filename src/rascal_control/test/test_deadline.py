"""Core tests of rascal_control.deadline (no master): the deadline rule in ROS and wall time,
waits that a stop event interrupts, and service calls with a deadline."""

import threading
import time

import pytest

from rascal_control import deadline as dl


class Clocks:
    """A ROS clock and a wall clock the test moves by hand."""

    def __init__(self, ros=100.0):
        self.ros = ros
        self.wall = 0.0

    def step(self, wall, ros=None):
        self.wall += wall
        self.ros += wall if ros is None else ros

    def deadline(self, seconds):
        return dl.Deadline(seconds, lambda: self.ros, lambda: self.wall)


def test_expires_when_both_ros_and_wall_time_are_over():
    c = Clocks()
    d = c.deadline(5.0)
    c.step(4.9)
    assert not d.expired()
    c.step(0.2)
    assert d.expired()


def test_a_fast_simulator_does_not_shorten_it():
    c = Clocks()
    d = c.deadline(5.0)
    c.step(1.0, ros=30.0)  # 30x real time
    assert not d.expired()
    c.step(4.1, ros=120.0)
    assert d.expired()


def test_a_slow_simulator_lengthens_it():
    c = Clocks()
    d = c.deadline(5.0)
    for _ in range(9):  # 0.5x real time: 9 s of wall time, 4.5 s of ROS time
        c.step(0.5, ros=0.25)
        assert not d.expired()
        c.step(0.5, ros=0.25)
        assert not d.expired()
    c.step(1.1, ros=0.55)
    assert d.expired()


def test_wall_time_alone_counts_while_ros_time_stands_still():
    c = Clocks()
    d = c.deadline(5.0)
    c.step(0.5)
    assert not d.expired()  # waits check every slice; this one saw ROS time move
    for _ in range(9):  # the simulator is gone: no /clock
        c.step(0.5, ros=0.0)
        assert not d.expired()
    c.step(0.5, ros=0.0)
    assert d.expired()
    assert d.wall_elapsed() == pytest.approx(5.5)


def test_wall_time_alone_counts_after_ros_time_went_backwards():
    c = Clocks(ros=300.0)
    d = c.deadline(5.0)
    c.step(2.0)
    c.ros = 0.1  # a restarted simulator's clock
    assert not d.expired()
    c.step(3.1)
    assert d.expired()


def test_the_seconds_may_be_raised_while_waiting():
    c = Clocks()
    d = c.deadline(5.0)
    c.step(6.0)
    d.seconds = 10.0  # the move's planned duration became known
    assert not d.expired()
    c.step(4.1)
    assert d.expired()


def test_wait_for_done_stopped_gone_expired():
    d = dl.Deadline(5.0, time.monotonic)
    assert dl.wait_for(lambda: True, d) == dl.DONE
    stop = threading.Event()
    threading.Timer(0.1, stop.set).start()
    t0 = time.monotonic()
    assert dl.wait_for(lambda: False, d, stop) == dl.STOPPED
    assert time.monotonic() - t0 < 0.1 + 2 * dl.SLICE + 0.05
    t0 = time.monotonic()
    assert dl.wait_for(lambda: False, d, alive=lambda: False) == dl.GONE
    assert time.monotonic() - t0 < dl.ALIVE_PERIOD + 2 * dl.SLICE + 0.05
    assert dl.wait_for(lambda: False, dl.Deadline(0.1, time.monotonic)) == dl.EXPIRED


def test_a_stop_set_before_the_wait_does_not_interrupt_it():
    stop = threading.Event()
    stop.set()
    done = threading.Event()
    threading.Timer(0.2, done.set).start()
    assert dl.wait_for(done.is_set, dl.Deadline(5.0, time.monotonic), stop) == dl.DONE


def test_call_returns_raises_or_gives_up():
    d = dl.Deadline(1.0, time.monotonic)
    assert dl.call(lambda a, b: a + b, 1, 2, deadline=d) == 3

    def fails():
        raise KeyError("service failed")

    with pytest.raises(KeyError):
        dl.call(fails, deadline=d)
    release = threading.Event()
    t0 = time.monotonic()
    with pytest.raises(dl.Unfinished) as info:
        dl.call(release.wait, 10.0, deadline=dl.Deadline(0.2, time.monotonic))
    assert info.value.outcome == dl.EXPIRED and time.monotonic() - t0 < 0.5
    stop = threading.Event()
    threading.Timer(0.1, stop.set).start()
    with pytest.raises(dl.Unfinished) as info:
        dl.call(release.wait, 10.0, deadline=dl.Deadline(5.0, time.monotonic), stop=stop)
    assert info.value.outcome == dl.STOPPED
    release.set()


def test_a_background_call_runs_while_the_caller_works_and_says_when_it_failed():
    go = threading.Event()
    pending = dl.Background(lambda: go.wait(5.0) and "photo")
    assert not pending.finished.is_set() and not pending.failed()  # the caller works meanwhile
    go.set()
    assert pending.result(dl.Deadline(1.0, time.monotonic)) == "photo"

    def refused():
        raise RuntimeError("arm in view")

    failing = dl.Background(refused)
    failing.finished.wait(1.0)
    assert failing.failed()
    with pytest.raises(RuntimeError):
        failing.result(dl.Deadline(1.0, time.monotonic))


def test_controller_timings_from_the_config_and_the_schema():
    cfg = {
        "arm": {"settle_timeout": 1.5, "state_timeout": 0.5, "gripper": {"timeout": 2.0}},
        "rig": {"answer_margin": 4.0},
    }
    t = dl.ControllerTimings.from_config(cfg)
    assert t.move(3.0) == pytest.approx(1.5 + 3.0 + 1.5 + 4.0)
    assert t.gripper() == pytest.approx(1.0 + 2.0 + 4.0)
    assert t.service() == pytest.approx(0.5 + 4.0)
    d = dl.ControllerTimings.defaults()
    assert (d.settle_timeout, d.state_timeout, d.gripper_timeout, d.margin) == (2.0, 1.0, 3.0, 5.0)
