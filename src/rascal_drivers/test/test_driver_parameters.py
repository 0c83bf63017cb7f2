"""Core tests (no master): a driver's section of the parameter server is read through the one
parameter schema, with check_config's messages."""

import pytest

from rascal_drivers.parameters import read_section
from rascal_workcell.schema import SchemaError


def test_defaults_fill_what_the_section_leaves_out():
    got = read_section({"device": "/dev/ttyUSB0"}, "drivers.scale")
    assert got["device"] == "/dev/ttyUSB0" and got["protocol"] == "mt_sics"
    assert got["disconnect_timeout"] == 2.0


@pytest.mark.parametrize(
    "prefix,data,message",
    [
        ("drivers.arm", None, "drivers.arm: not on the parameter server; rosparam load"),
        ("drivers.scale", {"protocl": "mt_sics"}, "did you mean drivers.scale.protocol?"),
        ("drivers.scale", {"protocol": "sartorius"}, "expected one of mt_sics, a_and_d"),
        ("drivers.arm", {"baud": "fast"}, "drivers.arm.baud: expected an integer"),
        ("drivers.wrist_camera", {"size": [640]}, "drivers.wrist_camera.size: expected"),
    ],
)
def test_a_bad_section_is_refused_in_one_line_naming_the_key(prefix, data, message):
    with pytest.raises(SchemaError) as e:
        read_section(data, prefix)
    assert message in str(e.value) and "\n" not in str(e.value)
