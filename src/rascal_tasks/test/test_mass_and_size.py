"""The rules of mass against measured size (`mass_and_size.py`) on figures of simulated heaps:
a wall the depth measured where a sherd lay on another it could not tell apart is no wall of
the mass the scale weighs; every generated sherd's own wall is."""

import pytest

from rascal_tasks.mass_and_size import more_than_one_sherd, wall_heavier_than
from rascal_tasks.rig import Observation


def _seen(length, width, wall):
    return Observation(
        0.1, 0.2, 0.0, length, width, wall, 0.1, 0.2, 0.01, 0.0, 0.05, thickness=wall
    )


# heap_20 seed 59 (one station, b2c45c4): rows as recorded, walls measured in the heap
@pytest.mark.parametrize(
    "grams, length_mm, width_mm, wall_mm",
    [
        (26.6, 47.2, 36.5, 35.1),
        (31.0, 48.5, 41.0, 33.3),
        (21.6, 66.4, 46.2, 17.8),
        (40.6, 61.4, 50.2, 20.8),
    ],
)
def test_a_wall_of_two_stacked_sherds_is_no_wall_of_the_mass_weighed(
    grams, length_mm, width_mm, wall_mm
):
    why = wall_heavier_than(_seen(length_mm / 1e3, width_mm / 1e3, wall_mm / 1e3), grams / 1e3)
    assert "%.1f mm wall" % wall_mm in why and "%.1f g" % grams in why


# generated sherds (truth, heap_20 seeds 58-60): the rider and the one under it of seed 59, and
# of the 60 the least and the most mass for their box (1.19, 1.59 g/cm^3)
@pytest.mark.parametrize(
    "grams, length_mm, width_mm, wall_mm",
    [
        (20.9, 68.2, 37.5, 6.2),
        (34.1, 63.9, 38.2, 10.0),
        (14.3, 60.1, 39.1, 5.1),
        (16.6, 43.7, 42.2, 5.7),
    ],
)
def test_one_sherds_own_wall_is(grams, length_mm, width_mm, wall_mm):
    assert (
        wall_heavier_than(_seen(length_mm / 1e3, width_mm / 1e3, wall_mm / 1e3), grams / 1e3) == ""
    )


def test_nothing_is_said_without_a_wall_or_a_mass():
    assert wall_heavier_than(_seen(0.05, 0.04, 0.0), 0.001) == ""
    assert wall_heavier_than(None, 0.02) == ""
    assert wall_heavier_than(_seen(0.05, 0.04, 0.03), 0.0) == ""


def test_more_than_one_sherd_of_a_size_can_weigh_is_two():
    # 45 x 35 mm, 6 mm wall: at most 2.3 g/cm^3 over its box, 10 % for the curve: 23.9 g
    assert more_than_one_sherd(_seen(0.045, 0.035, 0.006), 0.0139) == ""
    assert "two sherds in one grasp?" in more_than_one_sherd(_seen(0.045, 0.035, 0.006), 0.032)
    assert more_than_one_sherd(_seen(0.045, 0.035, 0.0), 1.0) == ""
