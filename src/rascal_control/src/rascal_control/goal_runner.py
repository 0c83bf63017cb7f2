"""One action goal at a time, without SimpleActionClient's send_goal race, and never waiting
without a deadline.

actionlib's SimpleActionClient stores the new goal handle only after send_goal() returns; a
transition that arrives before that (a goal the controller refuses in a few milliseconds, such as
an unreachable pose) is dropped with "Got a transition callback on a goal handle that we're not
tracking" (ros/actionlib#206), and wait_for_result() may then never return. GoalRunner uses the
plain ActionClient and a per-goal event set from the transition callback itself, so no
transition can be lost.

Goals are stamped with WALL time. actionlib's SimpleActionServer cancels, unrun, every goal
stamped earlier than the last one it took (a goal stamped 0 gets the server's ROS time), and
answers it with an empty result: code 0, OK, in 0.0 s. After ROS time went backwards (a
restarted simulator: its /clock starts again at 0) every goal would "succeed" without the arm
moving. Wall time keeps the order in which goals were sent (the newest still preempts the one
running). The clients also take success only from a goal the server SUCCEEDED (`terminal()`).

Its waits follow `deadline.py`: a deadline in ROS and wall time (raised once the goal's feedback
says how long it takes), a stop event, and a liveness check of the server's node over XML-RPC
every half second, so a killed controller is noticed at once (its topics stay registered with
the master, and actionlib's own wait_for_server measures ROS time, which stands still when the
simulator is gone).
"""

import threading
import time
import xmlrpc.client
from typing import Callable, Optional

from rascal_control.deadline import ALIVE_PERIOD, Deadline, wait_for

CALLER = "/rascal_control_client"


class _TimeoutTransport(xmlrpc.client.Transport):
    def __init__(self, timeout: float):
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host):
        conn = super().make_connection(host)
        conn.timeout = self._timeout
        return conn


def node_answers(node: str, master_uri: str, timeout: float = ALIVE_PERIOD) -> Optional[bool]:
    """Whether the ROS node `node` runs: True when it answers on its XML-RPC port within
    `timeout` seconds, False when it is not registered with the master or refuses the
    connection (a killed node stays registered until it is started again), None when the
    master or the node did not answer in time (a loaded machine: ask again)."""
    try:
        master = xmlrpc.client.ServerProxy(master_uri, transport=_TimeoutTransport(timeout))
        code, _msg, uri = master.lookupNode(CALLER, node)
        if code != 1:
            return False
        api = xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport(timeout))
        return api.getPid(CALLER)[0] == 1
    except TimeoutError:
        return None
    except (OSError, xmlrpc.client.Error):
        return False


def _publishers(subscriber) -> list:
    """The nodes a rospy subscriber is connected to (rospy names a connection's publisher
    "unknown" until its header is read)."""
    names = (getattr(conn, "callerid_pub", None) for conn in subscriber.impl.connections)
    return [name for name in names if name and name != "unknown"]


class GoalRunner:
    SILENT_CHECKS = 4  # liveness checks in a row without an answer: the node is hung
    SUCCEEDED, LOST = 3, 9  # actionlib_msgs/GoalStatus

    def __init__(self, name: str, action_type):
        import actionlib
        import rospy

        self.name = name
        self._actionlib = actionlib
        self._client = actionlib.ActionClient(name, action_type)
        publish = self._client.pub_goal.publish

        def send_wall_stamped(action_goal):  # see the module's docstring
            action_goal.goal_id.stamp = rospy.Time.from_sec(time.time())
            publish(action_goal)

        self._client.manager.register_send_goal_fn(send_wall_stamped)
        self._gh = None
        self._done = threading.Event()
        self.feedback = None  # the current goal's latest feedback
        self._silent = 0  # liveness checks in a row the server's node did not answer

    def server_node(self) -> Optional[str]:
        """The node serving the action: the sender of its status messages, or before the first
        one the node whose status topic this client is connected to. (The server publishes its
        status on a timer in ROS time; a /clock that starts late or stalls under use_sim_time
        held actionlib's test, which waits for a status message, for as long: `rascal teach`
        once gave up after 30 s with the controller up. A goal needs only the connections.)
        None while neither is there."""
        msg = self._client.last_status_msg
        header = getattr(msg, "_connection_header", None) or {}
        node = header.get("callerid")
        if node:
            return node
        return next(iter(_publishers(self._client.status_sub)), None)

    def server_alive(self) -> bool:
        """False once the server's node is gone, or has not answered SILENT_CHECKS times."""
        import rosgraph

        node = self.server_node()
        if node is None:
            return True
        answer = node_answers(node, rosgraph.get_master_uri())
        self._silent = self._silent + 1 if answer is None else 0
        return answer is not False and self._silent < self.SILENT_CHECKS

    def missing(self) -> list:
        """What keeps the server from being ready: the action's topics not (yet) connected to
        its node, by name ([] when ready; ["status"] while no server is seen at all)."""
        c = self._client
        server = self.server_node()
        if server is None:
            return ["status"]
        missing = [
            name
            for name, pub in (("goal", c.pub_goal), ("cancel", c.pub_cancel))
            if not pub.impl.has_connection(server)
        ]
        missing += [
            name
            for name, sub in (("result", c.result_sub), ("feedback", c.feedback_sub))
            if server not in _publishers(sub)
        ]
        return missing

    def _server_ready(self) -> bool:
        """actionlib's wait_for_server test, once, but for the status message: every topic of
        the action connected to the server's node."""
        return not self.missing()

    def wait_for_server(self, timeout, stop: Optional[threading.Event] = None) -> bool:
        """Waits up to `timeout` (rospy.Duration or seconds) of WALL time. (actionlib measures its
        own timeout in ROS time, which under use_sim_time starts at 0, jumps to the simulator's
        clock, races ahead of the wall clock, or stands still while the simulator is down.)"""
        import rospy

        seconds = timeout.to_sec() if hasattr(timeout, "to_sec") else float(timeout)
        deadline = time.monotonic() + seconds
        while not rospy.is_shutdown():
            if self._server_ready():
                return True
            if time.monotonic() > deadline or (stop is not None and stop.is_set()):
                return False
            time.sleep(0.01)
        return False

    def send_goal(self, goal):
        done = threading.Event()
        finished = (self._actionlib.CommState.DONE, self._actionlib.CommState.LOST)

        def on_transition(gh):
            if gh.get_comm_state() in finished:
                done.set()

        def on_feedback(_gh, feedback):
            self.feedback = feedback

        self._done = done
        self.feedback = None
        self._gh = self._client.send_goal(
            goal, transition_cb=on_transition, feedback_cb=on_feedback
        )

    def wait_for_result(
        self,
        deadline: Deadline,
        stop: Optional[threading.Event] = None,
        budget: Optional[Callable[[object], float]] = None,
    ) -> str:
        """Until the goal is done: deadline.DONE, STOPPED, GONE (the server's node does not
        answer) or EXPIRED. `budget(feedback)` raises the deadline's seconds as feedback comes
        (a move's planned duration)."""
        import rospy

        def done():
            if budget is not None and self.feedback is not None:
                deadline.seconds = max(deadline.seconds, budget(self.feedback))
            return self._done.is_set() or rospy.is_shutdown()

        return wait_for(done, deadline, stop, self.server_alive, sleep=self._done.wait)

    def acknowledged(self) -> bool:
        """Whether the server's status has listed the goal. (A goal cancelled before that is
        marked LOST by actionlib when the next status lacks it, and its result is dropped.)"""
        if self._gh is None:
            return False
        return self._gh.get_comm_state() not in (
            self._actionlib.CommState.WAITING_FOR_GOAL_ACK,
            self._actionlib.CommState.WAITING_FOR_CANCEL_ACK,
        )

    def get_result(self):
        return self._gh.get_result() if self._gh is not None else None

    def terminal(self):
        """(actionlib_msgs/GoalStatus code, the server's text) of the finished goal."""
        if self._gh is None:
            return self.LOST, "no goal sent"
        return self._gh.get_goal_status(), self._gh.get_goal_status_text()

    def cancel_goal(self):
        if self._gh is not None:
            self._gh.cancel()

    def cancel_all_goals(self):
        self._client.cancel_all_goals()
