"""Node side of the configuration: read config/rascal.yaml's keys from the parameter server.

`rosparam load config/rascal.yaml` puts the file's top-level sections at the root namespace;
every Python node calls `load_from_param_server()` before it advertises anything and exits with
the validator's one-line message when something is wrong. `rascal run --config FILE` uses
`load_for_run`: the file, checked against what the running nodes read.
"""

import os

import rospkg
import rospy

from rascal_workcell import schema

from rascal_tasks.config import Config, ConfigError, config_from_dict, load_config

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


def _leaves(node, prefix=""):
    """(dotted key, value) of every leaf of a nested mapping."""
    if isinstance(node, dict) and node:
        for k, v in node.items():
            yield from _leaves(v, "%s.%s" % (prefix, k) if prefix else str(k))
    else:
        yield prefix, node


def _readers(key: str):
    """The nodes that read `key` (from its own or its nearest parent's schema entry)."""
    parts = key.split(".")
    for n in range(len(parts), 0, -1):
        spec = schema.builtin().find(".".join(parts[:n]))
        if spec is not None:
            return spec.readers
    return []


def _same(a, b) -> bool:
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return a == b


def load_for_run(config_path=None) -> Config:
    """The configuration of `rascal run`: the parameter server's (what the running nodes read);
    or the file given with --config / $RASCAL_CONFIG, which must then agree with the parameter
    server on every key another node reads (the run's own keys, e.g. database.dsn and
    archive.root, may differ). ConfigError with one line otherwise."""
    if not config_path:
        return load_from_param_server()
    cfg = load_config(config_path)
    try:
        server = load_from_param_server()
    except ConfigError:
        return cfg  # nothing (valid) loaded: the nodes could not have started from it
    mine, theirs = dict(_leaves(cfg.data)), dict(_leaves(server.data))
    for key in list(mine) + [k for k in theirs if k not in mine]:
        others = [r for r in _readers(key) if r != "rascal"]
        if others and not _same(mine.get(key), theirs.get(key)):
            raise ConfigError(
                "%s: %s is %r, but the parameter server (read by %s) has %r; `rosparam load "
                "%s` and restart the nodes, or leave out --config"
                % (config_path, key, mine.get(key), ", ".join(others), theirs.get(key), config_path)
            )
    return cfg
