"""What `rascal run` needs of the ROS graph before anything moves, checked with deadlines:

- `check_master(uri)`: a ROS master answers (rospy.init_node would wait for one forever);
- `wait_for_nodes(needs, deadline)`: every service, action and topic the run uses is offered by a
  node that answers; what is still missing at the deadline is named by node, one line each,
  with the command that starts it.

Talks to the master over XML-RPC (rosgraph), so it works before rospy.init_node.
"""

import socket
import time
import xmlrpc.client
from collections import namedtuple
from typing import Callable, List, Optional

import rosgraph

CALLER = "/rascal_run_check"

# kind: service | action | topic (published); node: what offers it; start: what to do
Need = namedtuple("Need", "kind name node start")

ARM = ("arm_controller", "start it with rosrun rascal_control arm_controller")
DETECTOR = ("sherd_detector", "start it with rosrun rascal_perception sherd_detector")
SIM = ("sim", "start it with rosrun rascal_sim sim")
DRIVERS = ("the device drivers", "start the rig's camera, scale and archival camera drivers")


def run_needs(simulated: bool) -> List[Need]:
    """What the task node uses (ros_rig.py). On the field rig the scale, the cameras and the clock
    come from drivers; in simulation (use_sim_time) from `sim`."""
    devices = SIM if simulated else DRIVERS
    needs = [
        Need("action", "/rascal/arm/move", *ARM),
        Need("service", "/rascal/arm/compute_ik", *ARM),
        Need("action", "/rascal/gripper", *ARM),
        Need("topic", "/rascal/gripper/state", *ARM),
        Need("service", "/rascal/perception/detect", *DETECTOR),
        Need("service", "/rascal/perception/calibrate_background", *DETECTOR),
        Need("topic", "/camera/color/image_raw", *devices),
        Need("service", "/scale/tare", *devices),
        Need("topic", "/scale/mass", *devices),
        Need("service", "/archival_camera/capture", *devices),
    ]
    if simulated:
        needs.insert(0, Need("topic", "/clock", *SIM))
    return needs


class GraphError(Exception):
    """The master or nodes are missing; str() is one line per problem."""


class _Timeout:
    """Socket timeout for the XML-RPC calls made inside the block (rosgraph sets none)."""

    def __init__(self, seconds):
        self.seconds = seconds

    def __enter__(self):
        self.old = socket.getdefaulttimeout()
        socket.setdefaulttimeout(self.seconds)

    def __exit__(self, *exc):
        socket.setdefaulttimeout(self.old)


def check_master(uri: Optional[str] = None, timeout: float = 3.0) -> str:
    """The master's URI when it answers within `timeout` seconds; GraphError otherwise."""
    uri = uri or rosgraph.get_master_uri()
    try:
        with _Timeout(timeout):
            rosgraph.Master(CALLER, master_uri=uri).getPid()
    except (OSError, xmlrpc.client.Error, rosgraph.MasterException):
        raise GraphError(
            "no ROS master at %s; start roscore (and the rig's nodes) first" % uri
        ) from None
    return uri


def _alive(master, node: str, cache: dict) -> bool:
    """Registered, and its XML-RPC port open: a killed node stays registered with the master
    until it is started again, but nothing listens on its port any more. A node too busy to
    answer within the socket timeout counts as alive."""
    if node not in cache:
        try:
            uri = master.lookupNode(node)
            xmlrpc.client.ServerProxy(uri).getPid(CALLER)
            cache[node] = True
        except (ConnectionRefusedError, rosgraph.MasterException):
            cache[node] = False
        except (OSError, xmlrpc.client.Error):
            cache[node] = True
    return cache[node]


def missing(master, needs: List[Need]) -> List[Need]:
    """The needs no live node offers now."""
    pubs, _subs, srvs = master.getSystemState()
    offered = {
        "topic": dict(pubs),
        "service": dict(srvs),
    }
    cache = {}
    out = []
    for need in needs:
        if need.kind == "action":  # an action server publishes <name>/status
            nodes = offered["topic"].get(need.name + "/status", [])
        else:
            nodes = offered[need.kind].get(need.name, [])
        if not any(_alive(master, n, cache) for n in nodes):
            out.append(need)
    return out


def describe(gone: List[Need], waited: float) -> str:
    """One line per node: what it should offer, and how to start it."""
    lines = []
    for node in dict.fromkeys(n.node for n in gone):
        mine = [n for n in gone if n.node == node]
        more = " (and %d more)" % (len(mine) - 1) if len(mine) > 1 else ""
        lines.append(
            "%s not running: no %s%s after %.0f s; %s"
            % (node, mine[0].name, more, waited, mine[0].start)
        )
    return "\n".join(lines)


def wait_for_nodes(
    needs: List[Need],
    timeout: float,
    uri: Optional[str] = None,
    stopped: Callable[[], bool] = lambda: False,
    poll: float = 0.25,
) -> bool:
    """Wait up to `timeout` seconds (wall clock) until every need is offered by a live node.
    Returns False if `stopped()` (Ctrl-C); raises GraphError naming what is still missing."""
    master = rosgraph.Master(CALLER, master_uri=uri or rosgraph.get_master_uri())
    start = time.monotonic()
    gone = needs
    while True:
        try:
            with _Timeout(2.0):
                gone = missing(master, needs)
        except (OSError, xmlrpc.client.Error, rosgraph.MasterException):
            raise GraphError(
                "no ROS master at %s any more; start roscore (and the rig's nodes) again"
                % master.master_uri
            ) from None
        if not gone:
            return True
        if stopped():
            return False
        if time.monotonic() - start > timeout:
            raise GraphError(describe(gone, timeout))
        time.sleep(poll)
