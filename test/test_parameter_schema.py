"""The parameter schema is the one source of truth (issue 12): check_config (Python), the C++
nodes' reading (rascal_workcell::Parameters, through its check_parameters tool) and the README
tables agree with it. Core tier: no master."""

import copy
import glob
import os
import re
import subprocess

import pytest
import yaml

from rascal_tasks.config import ConfigError, config_from_dict
from rascal_workcell import readme_tables, schema

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHIPPED = os.path.join(WORKSPACE, "config", "rascal.yaml")
CHECK = os.path.join(WORKSPACE, "devel", "lib", "rascal_workcell", "check_parameters")
READERS = ("rascal", "sim", "arm_controller", "sherd_detector")


@pytest.fixture(scope="module")
def shipped():
    with open(SHIPPED) as f:
        return yaml.safe_load(f)


def _set(data, dotted, value):
    node = data
    keys = dotted.split(".")
    for k in keys[:-1]:
        node = node[k]
    if value is None:
        del node[keys[-1]]
    else:
        node[keys[-1]] = value


@pytest.mark.parametrize(
    "key,value,nearest",
    [
        ("survey.stepp", 0.1, "survey.step"),
        ("recover", {"max_grasp_attempts": 2}, "recovery"),
        ("arm.gripper.held_margn", 0.002, "arm.gripper.held_margin"),
        ("stations.camera.stand.heigth", 0.6, "stations.camera.stand.height"),
        ("perception.fingertip_offset", 0.004, "perception."),  # from the URDF now, not a parameter
        ("simulator.scenarios", "x.yaml", "simulator.scenario"),
    ],
)
def test_unknown_key_at_any_depth_is_refused_naming_the_nearest_known_key(
    shipped, key, value, nearest
):
    data = copy.deepcopy(shipped)
    _set(data, key, value)
    with pytest.raises(ConfigError) as e:
        config_from_dict(data)
    text = str(e.value)
    assert "%s: unknown key (a typo? did you mean %s" % (key, nearest) in text
    assert "\n" not in text


def test_a_key_of_another_station_type_is_refused(shipped):
    data = copy.deepcopy(shipped)
    data["stations"]["scale"]["wall_height"] = 0.04
    with pytest.raises(
        ConfigError, match="stations.scale.wall_height: not a key of a scale " "station"
    ):
        config_from_dict(data)


def test_a_missing_optional_key_takes_the_schema_default(shipped):
    data = copy.deepcopy(shipped)
    del data["perception"]["frame_wait"]
    del data["arm"]["gripper"]
    cfg = config_from_dict(data)
    assert cfg["perception"]["frame_wait"] == 1.0
    assert cfg["arm"]["gripper"]["held_margin"] == 0.002


def test_joint_values_are_checked_against_the_urdf_limits(shipped):
    data = copy.deepcopy(shipped)
    data["arm"]["named_poses"]["home"] = [0.0, 2.5, 0.0, 0.0, 0.0, 0.0]  # shoulder max 1.99
    with pytest.raises(
        ConfigError, match="arm.named_poses.home: shoulder = 2.5 rad is outside " "its URDF limits"
    ):
        config_from_dict(data)


# ---------------------------------------------------------------- C++ and Python agree
def _concrete(spec, shipped):
    """A key of the shipped file that the schema entry covers (wildcards filled in)."""

    def leaves(node, prefix):
        for k, v in node.items():
            key = prefix + k
            yield key
            if isinstance(v, dict):
                yield from leaves(v, key + ".")

    return next((k for k in leaves(shipped, "") if spec.matches(k)), None)


def _cases(shipped):
    """(key, value, must_fail) probes at and beyond every bound of every number in the schema."""
    cases = []
    for spec in schema.builtin().specs:
        key = _concrete(spec, shipped)
        if key is None or spec.type not in ("number", "integer"):
            continue
        if not set(spec.readers) & set(READERS):
            continue  # read only by the Python drivers, through the same check_config code
        for which, sign in (("min", -1), ("max", 1)):
            bound = getattr(spec, which)
            if not isinstance(bound, (int, float)):
                continue
            step = 1 if spec.type == "integer" else max(abs(bound) * 0.01, 1e-4)
            cases.append((key, bound + sign * step, True))
            if not (which == "min" and spec.exclusive_min):
                cases.append((key, bound, False))
    cases += [
        ("stations.scale.surface_z", 0.005, False),  # a flat scale: the sim refused < 11 mm
        ("simulator.joint_state_period", 0.0005, True),  # below physics_step 0.001
        ("perception.selection_policy", "random", True),
        ("simulator.wrist_camera", "yes", True),
        ("stations.scale.position", "abc", True),
        ("simulator.archival_size", [2000, 1499], True),
    ]
    return cases


def _cpp_error(tmp_path, data):
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(data))
    res = subprocess.run([CHECK, str(path), *READERS], capture_output=True, text=True, timeout=30)
    assert res.returncode in (0, 1), res.stderr
    return None if res.returncode == 0 else res.stdout.strip()


def test_the_nodes_accept_every_value_check_config_accepts_and_refuse_the_same_keys(
    shipped, tmp_path
):
    assert os.path.exists(CHECK), "build rascal_workcell first (make test does)"
    disagree = []
    for key, value, must_fail in _cases(shipped):
        data = copy.deepcopy(shipped)
        _set(data, key, value)
        try:
            config_from_dict(data)
            py = None
        except ConfigError as e:
            py = str(e)
        cpp = _cpp_error(tmp_path, data)
        if must_fail and (py is None or cpp is None or key not in cpp):
            disagree.append("%s=%r: python %r, nodes %r (both must refuse)" % (key, value, py, cpp))
        if py is None and cpp is not None:
            disagree.append(
                "%s=%r passes check_config but a node refuses it: %s" % (key, value, cpp)
            )
    assert not disagree, "\n".join(disagree)


# ---------------------------------------------------------------- README tables
NODE_READMES = {
    "rascal_control": "arm_controller",
    "rascal_sim": "sim",
    "rascal_perception": "sherd_detector",
    "rascal_tasks": "rascal",
}


@pytest.mark.parametrize("package,reader", sorted(NODE_READMES.items()))
def test_every_node_readme_lists_exactly_the_schema_keys_it_reads(package, reader):
    path = os.path.join(WORKSPACE, "src", package, "README.md")
    with open(path) as f:
        text = f.read()
    assert "<!-- BEGIN parameters %s -->" % reader in text, (
        "%s: add the marker lines and run `rosrun rascal_workcell parameter_tables`" % path
    )
    assert readme_tables.render(text) == text, (
        "%s: parameter table is stale; run `rosrun rascal_workcell parameter_tables`" % path
    )
    block = next(m.group(3) for m in readme_tables.MARKER.finditer(text) if m.group(2) == reader)
    listed = re.findall(r"^\| `([^`]+)` \|", block, re.M)
    assert listed == [s.key for s in schema.builtin().for_reader(reader)]


def test_no_readme_has_a_table_for_an_unknown_reader():
    for path in glob.glob(os.path.join(WORKSPACE, "src", "*", "README.md")):
        with open(path) as f:
            for reader in readme_tables.MARKER.findall(f.read()):
                assert reader[1] in READERS, path


def test_the_task_layer_reads_only_keys_the_schema_lists_for_it():
    """Static check of `config["section"]["key"]` reads in rascal_tasks against reader rascal."""
    specs = schema.builtin().for_reader("rascal")
    declared = {s.key for s in specs}
    sections = {k.split(".")[0] for k in declared}
    pattern = re.compile(r"""(?:config|cfg)\["(\w+)"\]\["(\w+)"\](?:\["(\w+)"\])?""")
    src = os.path.join(WORKSPACE, "src", "rascal_tasks", "src", "rascal_tasks")
    wrong = []
    for path in glob.glob(os.path.join(src, "**", "*.py"), recursive=True):
        if path.endswith("config.py"):
            continue  # the validator reads everything
        with open(path) as f:
            for m in pattern.finditer(f.read()):
                key = ".".join(p for p in m.groups() if p)
                if (
                    m.group(1) in sections
                    and not any(spec.matches(key) for spec in specs)  # `*`: a chosen name
                    and not any(d.startswith(key + ".") for d in declared)
                ):
                    wrong.append("%s: %s" % (os.path.relpath(path, WORKSPACE), key))
    assert not wrong, "reads not declared for reader rascal in the schema: %s" % wrong
