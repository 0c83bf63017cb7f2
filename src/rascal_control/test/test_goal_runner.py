"""Core tests of goal_runner (no ROS master): node_answers, the liveness check of an action
server's node, against a fake master and fake nodes on XML-RPC; and when a server counts as
ready, against a client's topics and their connections."""

import socket
import threading
from xmlrpc.server import SimpleXMLRPCServer

import pytest

from rascal_control.goal_runner import GoalRunner, node_answers


def serve(functions):
    server = SimpleXMLRPCServer(("127.0.0.1", 0), logRequests=False, allow_none=True)
    for name, fn in functions.items():
        server.register_function(fn, name)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, "http://127.0.0.1:%d/" % server.server_address[1]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def graph():
    """A master knowing `alive` (answers), `killed` (port closed) and `hung` (never answers)."""
    node, node_uri = serve({"getPid": lambda caller: [1, "", 4242]})
    hung = socket.socket()
    hung.bind(("127.0.0.1", 0))
    hung.listen(1)  # accepts the connection, never answers
    nodes = {
        "/alive": node_uri,
        "/killed": "http://127.0.0.1:%d/" % free_port(),
        "/hung": "http://127.0.0.1:%d/" % hung.getsockname()[1],
    }

    def lookup(caller, name):
        return [1, "", nodes[name]] if name in nodes else [-1, "unknown node", ""]

    master, master_uri = serve({"lookupNode": lookup})
    yield master_uri
    for s in (node, master):
        s.shutdown()
    hung.close()


def test_a_running_node_answers(graph):
    assert node_answers("/alive", graph) is True


def test_a_killed_or_unknown_node_is_gone(graph):
    assert node_answers("/killed", graph) is False
    assert node_answers("/never_started", graph) is False


def test_a_hung_node_or_master_is_asked_again(graph):
    assert node_answers("/hung", graph, timeout=0.2) is None
    assert node_answers("/alive", "http://127.0.0.1:%d/" % free_port()) is False  # no master


class _Conn:
    def __init__(self, callerid_pub):
        self.callerid_pub = callerid_pub


class _Topic:
    """A rospy publisher or subscriber as GoalRunner reads it: .impl's connections."""

    def __init__(self, *nodes):
        self.impl = self
        self.connections = [_Conn(n) for n in nodes]

    def has_connection(self, node):
        return any(c.callerid_pub == node for c in self.connections)


class _Client:
    def __init__(self, status=(), goal=(), cancel=(), result=(), feedback=()):
        self.last_status_msg = None
        self.status_sub, self.result_sub = _Topic(*status), _Topic(*result)
        self.feedback_sub = _Topic(*feedback)
        self.pub_goal, self.pub_cancel = _Topic(*goal), _Topic(*cancel)


def runner(client):
    r = object.__new__(GoalRunner)  # no ROS: only the client's topics are read
    r._client = client
    return r


def test_a_server_whose_topics_are_connected_is_ready_before_its_first_status():
    ctl = "/arm_controller"
    r = runner(_Client(status=[ctl], goal=[ctl], cancel=[ctl], result=[ctl], feedback=[ctl]))
    assert r.server_node() == ctl
    assert r.missing() == [] and r._server_ready()


def test_what_is_not_connected_yet_is_named():
    ctl = "/arm_controller"
    assert runner(_Client()).missing() == ["status"]
    # rospy names a connection's publisher "unknown" until its header is read
    assert runner(_Client(status=["unknown"])).missing() == ["status"]
    r = runner(_Client(status=[ctl], goal=[ctl], cancel=[ctl], feedback=[ctl]))
    assert r.missing() == ["result"] and not r._server_ready()
