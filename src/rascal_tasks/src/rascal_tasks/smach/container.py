"""``Container``: the base of StateMachine, Concurrence and Iterator.

Construction goes through a class-level stack: ``with sm:`` opens the container, and the
static ``add`` methods add to whatever container is open on top. Unlike smach 2.5.2, an
exception inside the ``with`` block closes the container before it propagates, so the
construction lock is never left held (upstream leaves it held and every other thread that
opens a container then blocks forever).
"""

import contextlib
import sys
import threading
import traceback

from .state import State
from .user_data import UserData

__all__ = ["Container"]


def _smach():
    return sys.modules[__package__]


class Container(State):
    """A state made of states, with its own userdata scope and three callback lists."""

    _construction_stack = []
    _construction_lock = threading.RLock()
    _context_kwargs = []

    def __init__(self, outcomes=(), input_keys=(), output_keys=()):
        State.__init__(self, outcomes, input_keys, output_keys)
        self.userdata = UserData()
        self._start_cbs = []
        self._transition_cbs = []
        self._termination_cbs = []

    # --- the interface each container implements ---
    def __getitem__(self, key):
        raise NotImplementedError()

    def get_children(self):
        raise NotImplementedError()

    def set_initial_state(self, initial_states, userdata=None):
        raise NotImplementedError()

    def get_initial_states(self):
        raise NotImplementedError()

    def get_active_states(self):
        raise NotImplementedError()

    def get_internal_edges(self):
        raise NotImplementedError()

    def check_consistency(self):
        raise NotImplementedError()

    # --- userdata copying between scopes ---
    def _copy_input_keys(self, parent_ud, ud):
        if parent_ud is None:
            return
        for key in self.get_registered_input_keys():
            try:
                ud[key] = parent_ud[key]
            except KeyError:
                _smach().logwarn(
                    "Attempting to copy input key '%s', but this key does not " "exist." % key
                )

    def _copy_output_keys(self, ud, parent_ud):
        if parent_ud is None:
            return
        for key in self.get_registered_output_keys():
            if key in ud:
                parent_ud[key] = ud[key]
            else:
                _smach().logwarn(
                    "Attempting to copy output key '%s', but this key does not " "exist." % key
                )

    # --- callbacks ---
    def register_start_cb(self, start_cb, cb_args=()):
        """``start_cb(userdata, initial_states, *cb_args)`` when execution starts."""
        self._start_cbs.append((start_cb, list(cb_args)))

    def register_transition_cb(self, transition_cb, cb_args=()):
        """``transition_cb(userdata, active_states, *cb_args)`` on every transition."""
        self._transition_cbs.append((transition_cb, list(cb_args)))

    def register_termination_cb(self, termination_cb, cb_args=()):
        """``termination_cb(userdata, terminal_states, outcome, *cb_args)`` at the end."""
        self._termination_cbs.append((termination_cb, list(cb_args)))

    def _call_cbs(self, kind, cbs, args):
        # as in smach: the first failing callback is logged and the rest of that list skipped
        try:
            for cb, cb_args in cbs:
                cb(self.userdata, *(list(args) + cb_args))
        except Exception:
            _smach().logerr("Could not execute %s callback: %s" % (kind, traceback.format_exc()))

    def call_start_cbs(self):
        self._call_cbs("start", self._start_cbs, [self.get_initial_states()])

    def call_transition_cbs(self):
        self._call_cbs("transition", self._transition_cbs, [self.get_active_states()])

    def call_termination_cbs(self, terminal_states, outcome):
        self._call_cbs("termination", self._termination_cbs, [terminal_states, outcome])

    # --- construction context ---
    def open(self):
        """Make this the container that the static ``add`` methods add to."""
        Container._construction_lock.acquire()
        Container._construction_stack.append(self)
        Container._context_kwargs.append({})

    def close(self):
        """Close the container and check it (a failed check is logged, as in smach)."""
        if not Container._construction_stack or Container._construction_stack[-1] is not self:
            raise _smach().InvalidStateError(
                "Attempting to close a container that is not currently open."
            )
        self._pop_construction()
        try:
            self.check_consistency()
        except (_smach().InvalidStateError, _smach().InvalidTransitionError):
            _smach().logerr("Container consistency check failed.")

    def _pop_construction(self):
        Container._construction_stack.pop()
        Container._context_kwargs.pop()
        Container._construction_lock.release()

    def is_opened(self):
        return bool(Container._construction_stack) and Container._construction_stack[-1] is self

    def assert_opened(self, msg=""):
        if not self.is_opened():
            raise _smach().InvalidConstructionError(msg or "The container is not open.")

    def __enter__(self):
        return self.open()  # None, as in smach: the idiom is `with sm:`

    def __exit__(self, exc_type, exc_val, exc_tb):
        if exc_type is None:
            self.close()
            return False
        if Container._construction_stack and Container._construction_stack[-1] is self:
            self._pop_construction()
        if not issubclass(exc_type, (_smach().InvalidStateError, _smach().InvalidTransitionError)):
            _smach().logerr(
                "Error raised during SMACH container construction: %s"
                % "".join(traceback.format_exception(exc_type, exc_val, exc_tb))
            )
        return False

    @contextlib.contextmanager
    def opened(self, **kwargs):
        """``with sm.opened():`` -- like ``with sm:`` but yields the container."""
        self.open()
        Container._context_kwargs[-1] = kwargs
        try:
            yield self
        except BaseException:
            if self.is_opened():
                self._pop_construction()
            raise
        self.close()

    @classmethod
    def _currently_opened_container(cls):
        if not Container._construction_stack:
            raise _smach().InvalidStateError(
                "Attempting to access the currently opened container, but no container is "
                "open (use 'with sm:' around the add calls)."
            )
        top = Container._construction_stack[-1]
        if not isinstance(top, cls):
            raise _smach().InvalidStateError(
                "Attempting to call a %s construction method while a %s is open."
                % (cls.__name__, type(top).__name__)
            )
        return top
