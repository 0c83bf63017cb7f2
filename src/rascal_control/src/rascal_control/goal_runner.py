"""One action goal at a time, without SimpleActionClient's send_goal race.

actionlib's SimpleActionClient stores the new goal handle only after send_goal() returns; a
transition that arrives before that (a goal the controller refuses in a few milliseconds, such as
an unreachable pose) is dropped with "Got a transition callback on a goal handle that we're not
tracking" (ros/actionlib#206), and wait_for_result() may then never return. GoalRunner uses the
plain ActionClient and a per-goal event set from the transition callback itself, so no
transition can be lost. It offers the SimpleActionClient methods the clients use.
"""

import threading
import time


class GoalRunner:
    def __init__(self, name: str, action_type):
        import actionlib

        self._actionlib = actionlib
        self._client = actionlib.ActionClient(name, action_type)
        self._gh = None
        self._done = threading.Event()

    def wait_for_server(self, timeout) -> bool:
        """Waits up to `timeout` (rospy.Duration or seconds) of WALL time. actionlib measures its
        own timeout in ROS time, which under use_sim_time starts at 0 and then jumps to the
        simulator's clock (or races ahead of the wall clock), so it can give up at once."""
        import rospy

        seconds = timeout.to_sec() if hasattr(timeout, "to_sec") else float(timeout)
        deadline = time.monotonic() + seconds
        while not rospy.is_shutdown():
            if self._client.wait_for_server(rospy.Duration(0.02)):
                return True
            if time.monotonic() > deadline:
                return False
            time.sleep(0.01)
        return False

    def send_goal(self, goal):
        done = threading.Event()
        finished = (self._actionlib.CommState.DONE, self._actionlib.CommState.LOST)

        def on_transition(gh):
            if gh.get_comm_state() in finished:
                done.set()

        self._done = done
        self._gh = self._client.send_goal(goal, transition_cb=on_transition)

    def wait_for_result(self, timeout) -> bool:
        """True when the goal finished; `timeout` (rospy.Duration) 0 = no limit."""
        import rospy

        seconds = timeout.to_sec()
        start = None  # ROS time is 0 until a simulator's first /clock arrives
        while not rospy.is_shutdown():
            if self._done.wait(0.05):
                return True
            now = rospy.get_time()
            if seconds > 0.0 and now > 0.0:
                start = now if start is None else start
                if now - start > seconds:
                    return False
        return self._done.is_set()

    def get_result(self):
        return self._gh.get_result() if self._gh is not None else None

    def cancel_goal(self):
        if self._gh is not None:
            self._gh.cancel()

    def cancel_all_goals(self):
        self._client.cancel_all_goals()
