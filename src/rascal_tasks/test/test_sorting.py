"""Core tests of sorting (rascal_tasks.sorting, a bin's rule and the choice among bins), of the
configuration of sorting bins, and of whole batches that sort (the in-memory rig of
fake_rig.py; no master, no database)."""

import copy
import os

import pytest
import yaml
from fake_rig import Recorder, Sherd, World

from rascal_tasks import workflow
from rascal_tasks.config import ConfigError, config_from_dict
from rascal_tasks.sorting import RuleError, SherdValues, choose_bin, parse_rule

WORKSPACE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
BIG = SherdValues(length=0.072, width=0.05, thickness=0.008, mass=0.031, munsell="5YR 6/4")
SMALL = SherdValues(length=0.024, width=0.018, mass=0.0031, munsell="10YR 4/2")
NO_MASS = SherdValues(length=0.05, width=0.04, flags=frozenset({"mass_unstable"}))


@pytest.fixture
def data():
    with open(os.path.join(WORKSPACE, "config", "rascal.yaml")) as f:
        return yaml.safe_load(f)


def with_bins(data, **rules):
    """The shipped config with sorting bins (name=rule) in free places beside the arm."""
    d = copy.deepcopy(data)
    spots = [[0.14, -0.13], [-0.12, -0.20], [-0.12, 0.20]]
    for (name, rule), xy in zip(rules.items(), spots, strict=False):
        d["stations"][name] = {
            "type": "bin",
            "position": xy,
            "size": [0.10, 0.08],
            "surface_z": 0.0,
            "wall_height": 0.04,
            "rule": rule,
        }
    return d


# -- the rule ----------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "rule, big, small",
    [
        ("length >= 60 mm", True, False),
        ("length >= 6cm", True, False),
        ("length >= 0.06", True, False),
        ("mass < 5 g", False, True),
        ("mass < 0.005 kg", False, True),
        ("munsell_hue = 5yr", True, False),
        ("munsell_hue in [10YR, 7.5YR]", False, True),
        ("munsell_value <= 4", False, True),
        ("munsell_chroma >= 4 and length > 50 mm", True, False),
        ("length > 100 mm or munsell_value < 5", False, True),
        ("width >= 18 mm and width <= 18 mm", False, True),
    ],
)
def test_a_rule_reads_as_written_in_the_units_written(rule, big, small):
    r = parse_rule(rule)
    assert r.holds(BIG)[0] is big
    assert r.holds(SMALL)[0] is small


def test_and_binds_tighter_than_or():
    r = parse_rule("mass < 1 g and length > 1 m or munsell_value >= 6")
    assert r.holds(BIG)[0]  # the second clause
    assert not r.holds(SMALL)[0]


def test_a_value_not_measured_never_satisfies_a_condition():
    assert not parse_rule("mass < 5 g").holds(NO_MASS)[0]
    assert not parse_rule("mass >= 5 g").holds(NO_MASS)[0]
    assert "mass not measured" in parse_rule("mass < 5 g").holds(NO_MASS)[1]
    assert not parse_rule("munsell_value <= 9").holds(NO_MASS)[0]
    assert parse_rule("flag mass_unstable").holds(NO_MASS)[0]
    assert not parse_rule("flag mass_unstable").holds(BIG)[0]


def test_neutral_munsell_has_hue_n_and_its_value():
    grey = SherdValues(munsell="N5")
    assert parse_rule("munsell_hue = N and munsell_value < 6").holds(grey)[0]


def test_only_colour_rules_wait_for_the_photo():
    assert not parse_rule("length > 5 cm or flag dropped").needs_colour
    assert parse_rule("mass > 1 g and munsell_hue = 5YR").needs_colour
    assert parse_rule("flag no_colour").needs_colour


@pytest.mark.parametrize(
    "rule, message",
    [
        ("", "empty"),
        ("lenght > 5 cm", "unknown quantity 'lenght'"),
        ("length > 5 g", "unit 'g' not known"),
        ("mass > five", "expected a number"),
        ("length 5 cm", "expected <, <=, >, >= or ="),
        ("length > 5 cm mass < 2 g", "expected and / or"),
        ("munsell_hue in [5YR, 7.5XX]", "not a Munsell hue"),
        ("munsell_hue in [5YR", "ends where"),
        ("flag broken", "unknown flag 'broken'"),
        ("munsell_value > 4 mm", "it has no unit"),
    ],
)
def test_a_rule_that_cannot_be_read_says_where(rule, message):
    with pytest.raises(RuleError, match=message):
        parse_rule(rule)


def test_the_first_bin_whose_rule_holds_takes_it_else_the_default():
    bins = [("large", parse_rule("length >= 60 mm")), ("light", parse_rule("mass < 5 g"))]
    assert choose_bin(bins, "discard", BIG).bin == "large"
    assert choose_bin(bins, "discard", SMALL).bin == "light"
    d = choose_bin(bins, "discard", NO_MASS)
    assert d.bin == "discard"
    assert "no bin's rule held" in d.reason and "mass not measured" in d.reason
    assert "(72 mm)" in choose_bin(bins, "discard", BIG).reason


def test_values_from_a_catalogue_row_are_si_and_flag_what_is_missing():
    v = SherdValues.from_row(
        {"length_mm": 41.0, "width_mm": 30.0, "mass_g": None, "drops": 1, "colour_munsell": None}
    )
    assert v.length == pytest.approx(0.041) and v.mass is None
    assert {"mass_unstable", "dropped", "no_colour", "no_thickness"} <= v.flags


# -- configuration -------------------------------------------------------------------------------
def test_bins_are_not_visited_by_every_sherd_and_keep_their_order(data):
    cfg = config_from_dict(with_bins(data, small="length < 3 cm", heavy="mass > 40 g"))
    assert cfg.station_order() == ["scale", "camera", "discard"]
    assert [n for n, _ in cfg.bins()] == ["small", "heavy"]
    assert cfg.stations["small"].wall_height == 0.04


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda d: d["stations"]["b"].update(rule="mass >> 3"), "stations.b.rule: "),
        (lambda d: d["stations"]["b"].pop("rule"), "stations.b.rule: missing"),
        (lambda d: d["stations"]["b"].update(position=[0.30, 0.0]), "overlaps station scale"),
        (lambda d: d["stations"]["b"].update(position=[0.9, 0.0]), "outside the arm's top-down"),
        (lambda d: d["stations"]["scale"].update(rule="mass > 3 g"), "not a key of a scale"),
    ],
)
def test_a_bad_bin_is_refused_with_one_line_naming_the_key(data, change, message):
    d = with_bins(data, b="length < 3 cm")
    change(d)
    with pytest.raises(ConfigError, match=message) as e:
        config_from_dict(d)
    assert "\n" not in str(e.value)


# -- whole batches -------------------------------------------------------------------------------
def test_every_sherd_goes_into_the_bin_its_rule_names(data):
    cfg = config_from_dict(with_bins(data, small="length < 30 mm", heavy="mass >= 40 g"))
    cfg["arm"]["gripper"]["fingertip_pads"] = 0.0075  # a 25 mm sherd needs pads to be held
    world = World(
        cfg,
        [
            Sherd("a", 0.08, 0.22, length=0.025, width=0.02, mass=0.004),
            Sherd("b", 0.16, 0.25, length=0.07, width=0.05, mass=0.045),
            Sherd("c", 0.24, 0.28, length=0.05, width=0.04, mass=0.020),
        ],
    )
    recorder = Recorder()
    batch = workflow.Batch(cfg, world.rig(), recorder, context="T", log=print)
    assert workflow.build_machine(batch).execute() == "finished"
    where = {s.name: s.station for s in world.sherds}
    assert where == {"a": "small", "b": "heavy", "c": "discard"}
    assert sorted(r.bin for r in recorder.sherds.values()) == ["discard", "heavy", "small"]
    assert all(r.status == "done" for r in recorder.sherds.values())
