"""Wiring tests of scale_driver (master on a free port): the node, started with rosrun, reads
the scale emulator on a pseudo-terminal through pyserial, in both dialects."""

import json
import os
import subprocess

import pytest

from rascal_drivers.scale_emulator import ScaleEmulator
from rascal_tasks.sim_rig import stop

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
CONFIG = os.path.join(WORKSPACE, "config", "rascal.yaml")
CLIENT = os.path.join(HERE, "scale_client.py")


def start(master, rosrun, scale, protocol, load=True):
    if load:
        master.run(["rosparam", "load", CONFIG])
    master.run(["rosparam", "set", "/drivers/scale/device", scale.link])
    master.run(["rosparam", "set", "/drivers/scale/protocol", protocol])
    return rosrun("rascal_drivers", "scale_driver")


def client(master, *args):
    res = master.run(["/usr/bin/python3", CLIENT, *args], timeout=40)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("protocol", ["mt_sics", "a_and_d"])
def test_mass_settles_stable_and_tares(ros_master, rosrun, tmp_path, protocol):
    scale = ScaleEmulator(protocol, link=str(tmp_path / "ttyScale")).start()
    try:
        node = start(ros_master, rosrun, scale, protocol)
        scale.put(0.0252)  # the simulator's 5 x 4 x 0.7 cm sherd
        got = client(ros_master, "settle", "0.0252", "tare")
        assert got["stable"] and abs(got["mass"] - 0.0252) <= 2e-4, got
        assert got["frame"] == "scale_link"
        assert got["tare"]["success"], got
        after = got["after_tare"]
        assert after["stable"] and abs(after["mass"]) <= 2e-4, got
        stop(node)
        assert node.returncode == 0, node.stdout.read()
    finally:
        scale.stop()


def test_an_unplugged_scale_gives_one_line_and_exit_1(ros_master, rosrun, tmp_path):
    scale = ScaleEmulator("mt_sics", link=str(tmp_path / "ttyScale")).start()
    node = start(ros_master, rosrun, scale, "mt_sics")
    client(ros_master, "settle", "0.0")
    scale.unplug()
    node.wait(timeout=20)
    text = node.stdout.read()
    assert node.returncode == 1, text
    lines = [ln for ln in text.splitlines() if ln.startswith("scale_driver: ")]
    assert len(lines) == 1 and "/ttyScale" in lines[0], text


def test_a_silent_scale_is_reported_disconnected_after_the_deadline(ros_master, rosrun, tmp_path):
    scale = ScaleEmulator("mt_sics", link=str(tmp_path / "ttyScale")).start()
    try:
        ros_master.run(["rosparam", "load", CONFIG])
        ros_master.run(["rosparam", "set", "/drivers/scale/disconnect_timeout", "0.5"])
        node = start(ros_master, rosrun, scale, "mt_sics", load=False)
        client(ros_master, "settle", "0.0")
        scale.silent = True  # powered off, cable still in
        node.wait(timeout=20)
        text = node.stdout.read()
        assert node.returncode == 1, text
        assert "no valid reply from the scale" in text and "disconnect_timeout" in text, text
    finally:
        scale.stop()


def test_the_wrong_protocol_is_named_in_one_line(ros_master, rosrun, tmp_path):
    scale = ScaleEmulator("a_and_d", link=str(tmp_path / "ttyScale")).start()
    try:
        node = start(ros_master, rosrun, scale, "mt_sics")  # an A&D scale configured as MT-SICS
        node.wait(timeout=20)
        text = node.stdout.read()
        assert node.returncode == 1, text
        assert "drivers.scale.protocol" in text, text
    finally:
        scale.stop()


def test_a_missing_device_is_named_in_one_line(ros_master):
    ros_master.run(["rosparam", "load", CONFIG])
    ros_master.run(["rosparam", "set", "/drivers/scale/device", "/dev/no_such_scale"])
    res = subprocess.run(
        ["rosrun", "rascal_drivers", "scale_driver"],
        env=ros_master.env,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert res.returncode == 1
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "drivers.scale.device: cannot open /dev/no_such_scale" in lines[0]
