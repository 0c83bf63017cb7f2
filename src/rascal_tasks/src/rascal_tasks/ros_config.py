"""Node side of the configuration: read config/rascal.yaml's keys from the parameter server.

`rosparam load config/rascal.yaml` puts the file's top-level sections at the root namespace;
every Python node calls `load_from_param_server()` before it advertises anything and exits with
the validator's one-line message when something is wrong.
"""

import os

import rospkg
import rospy

from rascal_workcell import schema

from rascal_tasks.config import Config, ConfigError, config_from_dict

# The top-level sections of config/rascal.yaml, as the parameter schema lists them.
SECTIONS = tuple(schema.builtin().sections(""))


def workspace_root() -> str:
    """The workspace holding src/rascal_tasks (relative config paths are taken from here)."""
    pkg = rospkg.RosPack().get_path("rascal_tasks")
    return os.path.dirname(os.path.dirname(os.path.realpath(pkg)))


def load_from_param_server(source="parameter server (rosparam load config/rascal.yaml)") -> Config:
    data = {}
    for key in SECTIONS:
        if rospy.has_param("/" + key):
            data[key] = rospy.get_param("/" + key)
    if not data:
        raise ConfigError(
            "%s: no RASCAL configuration found; run `rosparam load "
            "config/rascal.yaml` first" % source
        )
    return config_from_dict(data, source=source, workspace=workspace_root())
