"""Reads one section of the parameter server (e.g. drivers.arm) through the parameter schema.

The schema (rascal_workcell/schema/parameters.yaml) is the single definition of every key;
this applies its checks (types, units, ranges, unknown keys with the nearest known one) and
fills its defaults for one section, so a driver validates exactly what check_config validates.
No ROS here: the node passes what rospy.get_param returned.
"""

from typing import Optional

from rascal_workcell import schema

# A camera's source/device `emulated:NS`: the simulator's camera under namespace NS stands in
# for the device (rig --emulated sets it)
EMULATED = "emulated:"


def read_section(data: Optional[dict], prefix: str) -> dict:
    """The section checked and with its defaults; raises schema.SchemaError naming the key.
    None (nothing on the parameter server) is refused: a node must not run on defaults alone
    because the configuration was never loaded."""
    if data is None:
        raise schema.SchemaError(
            prefix, "not on the parameter server; rosparam load config/rascal.yaml first"
        )
    nested: dict = data
    for part in reversed(prefix.split(".")):
        nested = {part: nested}
    # _Validator.walk checks one mapping at a given depth; validate() would demand the whole file
    validator = schema._Validator(schema.builtin(), nested)
    return validator.walk(data, prefix)
