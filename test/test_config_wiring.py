"""Wiring tests of the configuration: rosparam load on a real master, read back by a node."""

import os

import yaml

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONFIG = os.path.join(WORKSPACE, "config", "rascal.yaml")


def test_rosparam_load_and_read_back(ros_master):
    ros_master.run(["rosparam", "load", CONFIG])
    out = ros_master.run(["rosparam", "get", "/stations/scale/position"]).stdout
    assert yaml.safe_load(out) == [0.30, 0.0]
    assert ros_master.run(["rosparam", "get", "/survey/step"]).stdout.strip() == "0.16"


def test_node_validates_what_the_master_holds(ros_master):
    ros_master.run(["rosparam", "load", CONFIG])
    ok = ros_master.run(["rosrun", "rascal_tasks", "check_config"], check=False)
    assert ok.returncode == 0, ok.stderr
    assert "configuration OK" in ok.stdout
    ros_master.run(["rosparam", "set", "/stations/scale/position", "abc"])
    bad = ros_master.run(["rosrun", "rascal_tasks", "check_config"], check=False)
    assert bad.returncode == 2
    assert "stations.scale.position: expected [x, y] in metres, got 'abc'" in bad.stderr
    assert len(bad.stderr.strip().splitlines()) == 1


def test_node_without_config_says_how_to_load_it(ros_master):
    res = ros_master.run(["rosrun", "rascal_tasks", "check_config"], check=False)
    assert res.returncode == 2
    assert "rosparam load config/rascal.yaml" in res.stderr
