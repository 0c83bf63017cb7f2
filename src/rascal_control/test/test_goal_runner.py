"""Core tests of goal_runner.node_answers, the liveness check of an action server's node (no ROS
master: a fake master and fake nodes on XML-RPC)."""

import socket
import threading
from xmlrpc.server import SimpleXMLRPCServer

import pytest

from rascal_control.goal_runner import node_answers


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
