"""``Concurrence``: runs its states at the same time, each in its own thread.

Semantics are smach 2.5.2's (including: a preempted concurrence whose children all serviced
the preempt goes on to its normal outcome selection). Fixed: upstream hangs forever when a
child returns ``None`` or when ``child_termination_cb`` raises; here both end the
concurrence with an error once the siblings have been preempted and joined.
"""

import copy
import sys
import threading
import traceback

from .container import Container
from .state import State
from .user_data import Remapper

__all__ = ["Concurrence"]

_POLL = 0.05  # [s] how often a waiting concurrence checks the shutdown hook


def _smach():
    return sys.modules[__package__]


class Concurrence(Container):
    """All children start together and share the concurrence's userdata.

    The outcome is ``default_outcome``, replaced by the satisfied ``outcome_map`` entry
    with the most constraints (``{container_outcome: {child_label: child_outcome}}``),
    replaced by ``outcome_cb(child_outcomes)`` when that returns a string.
    ``child_termination_cb(child_outcomes)`` is called as each child ends; a truthy return
    preempts every child still running.
    """

    def __init__(
        self,
        outcomes,
        default_outcome,
        input_keys=(),
        output_keys=(),
        outcome_map=None,
        outcome_cb=None,
        child_termination_cb=None,
    ):
        Container.__init__(self, outcomes, input_keys, output_keys)
        outcome_map = {} if outcome_map is None else outcome_map
        if not (default_outcome or outcome_map or outcome_cb):
            raise _smach().InvalidStateError(
                "Concurrence requires an outcome policy: default_outcome, outcome_map or "
                "outcome_cb."
            )
        registered = self.get_registered_outcomes()
        if not isinstance(default_outcome, str) or default_outcome not in registered:
            raise _smach().InvalidStateError(
                "Concurrence default_outcome %r must be one of its outcomes: %s"
                % (default_outcome, list(registered))
            )
        for container_outcome in outcome_map:
            if container_outcome not in registered:
                raise _smach().InvalidStateError(
                    "Outcome map in Concurrence names outcome '%s', which is not one of its "
                    "outcomes: %s" % (container_outcome, list(registered))
                )
        if outcome_cb is not None and not callable(outcome_cb):
            raise _smach().InvalidStateError("Concurrence outcome_cb must be callable.")
        if child_termination_cb is not None and not callable(child_termination_cb):
            raise _smach().InvalidStateError("Concurrence child_termination_cb must be callable.")
        self._default_outcome = default_outcome
        self._outcome_map = outcome_map
        self._outcome_cb = outcome_cb
        self._child_termination_cb = child_termination_cb
        self._states = {}
        self._remappings = {}
        self._threads = {}
        self._child_outcomes = {}
        self._errors = []
        self._done_cond = threading.Condition(threading.RLock())
        self._terminate = False
        self._running = False

    # --- construction ---
    @staticmethod
    def add(label, state, remapping=None):
        """Add a child (a repeated label replaces the earlier child, as in smach)."""
        self = Concurrence._currently_opened_container()
        if label in self._states:
            _smach().logwarn("Concurrence: replacing the state labelled '%s'." % label)
        self._states[label] = state
        self._remappings[label] = dict(remapping) if remapping else {}
        return state

    # --- execution ---
    def execute(self, parent_ud=None):
        if not self._states:
            raise _smach().InvalidStateError("No states was added to concurrence")
        self._copy_input_keys(parent_ud, self.userdata)
        with self._done_cond:
            self._child_outcomes = {label: None for label in self._states}
            self._errors = []
            self._terminate = False
            self._running = True
        try:
            self.call_start_cbs()
            go = threading.Event()
            self._threads = {}
            for label in self._states:
                t = threading.Thread(
                    target=self._state_runner,
                    args=(label, go),
                    name="concurrent_split:" + label,
                    daemon=True,
                )
                self._threads[label] = t
                t.start()
            go.set()

            with self._done_cond:
                while not (
                    self._terminate
                    or self._errors
                    or self._preempt_requested
                    or all(o is not None for o in self._child_outcomes.values())
                ):
                    if _smach().is_shutdown():
                        break
                    self._done_cond.wait(_POLL)
                running = [lb for lb, o in self._child_outcomes.items() if o is None]
            for label in running:
                try:
                    self._states[label].request_preempt()
                except Exception:
                    _smach().logerr(
                        "Failed to preempt concurrent state '%s': %s"
                        % (label, traceback.format_exc())
                    )
            for t in self._threads.values():
                while t.is_alive() and not _smach().is_shutdown():
                    t.join(_POLL)

            if self._errors:
                kind, message = self._errors[0]
                if kind == "user":
                    raise _smach().InvalidUserCodeError(message)
                raise _smach().InvalidStateError(
                    "A concurrent state raised an exception during execution. " + message
                )

            if self._preempt_requested:
                unserviced = [lb for lb, s in self._states.items() if s.preempt_requested()]
                if not unserviced:
                    self.service_preempt()
                else:
                    for label in unserviced:
                        self._states[label].recall_preempt()
                    _smach().logwarn(
                        "Concurrence preempted, but these children did not "
                        "service the preempt: %s" % unserviced
                    )

            outcome = self._select_outcome()
            self.call_termination_cbs(list(self._states), outcome)
            self._copy_output_keys(self.userdata, parent_ud)
            return outcome
        finally:
            with self._done_cond:
                self._running = False

    def _select_outcome(self):
        outcomes = dict(self._child_outcomes)
        outcome = self._default_outcome
        best = 0
        for container_outcome, required in self._outcome_map.items():
            if all(outcomes.get(label) == child for label, child in required.items()):
                if len(required) > best:
                    best = len(required)
                    outcome = container_outcome
        if self._outcome_cb is not None:
            try:
                cb_outcome = self._outcome_cb(copy.copy(outcomes))
            except Exception:
                raise _smach().InvalidUserCodeError(
                    "Could not execute outcome callback '%s': %s"
                    % (self._outcome_cb, traceback.format_exc())
                ) from None
            if isinstance(cb_outcome, str) and cb_outcome:
                outcome = cb_outcome
            elif cb_outcome is None or cb_outcome == "":
                _smach().logwarn("Outcome callback returned None; using outcome '%s'." % outcome)
            else:
                _smach().logerr(
                    "Outcome callback returned a non-string %r; using outcome '%s'."
                    % (cb_outcome, outcome)
                )
        return outcome

    def _state_runner(self, label, go):
        go.wait()
        state = self._states[label]
        self.call_transition_cbs()
        try:
            outcome = state.execute(
                Remapper(
                    self.userdata,
                    state.get_registered_input_keys(),
                    state.get_registered_output_keys(),
                    self._remappings[label],
                )
            )
        except Exception:
            self._fail(
                "state",
                "State '%s' of type '%s' failed: %s" % (label, state, traceback.format_exc()),
            )
            return
        if outcome is None:
            self._fail(
                "state",
                "State '%s' of type '%s' returned None; it must return one of "
                "its registered outcomes %s"
                % (label, state, list(state.get_registered_outcomes())),
            )
            return
        with self._done_cond:
            self._child_outcomes[label] = outcome
        self.call_transition_cbs()
        with self._done_cond:
            terminate = False
            if self._child_termination_cb is not None:
                try:
                    terminate = self._child_termination_cb(self._child_outcomes)
                except Exception:
                    self._fail(
                        "user",
                        "Could not execute child termination callback: %s" % traceback.format_exc(),
                    )
                    return
            if terminate:
                self._terminate = True
            self._done_cond.notify_all()

    def _fail(self, kind, message):
        _smach().logerr(message)
        with self._done_cond:
            self._errors.append((kind, message))
            self._done_cond.notify_all()

    # --- preemption ---
    def request_preempt(self):
        """Ask the concurrence to stop; its children are preempted by the waiting thread."""
        with self._done_cond:
            State.request_preempt(self)
            self._done_cond.notify_all()

    # --- introspection ---
    def get_children(self):
        return self._states

    def __getitem__(self, key):
        if key not in self._states:
            raise KeyError(key)
        return self._states[key]

    def get_initial_states(self):
        return list(self._states)

    def set_initial_state(self, initial_states, userdata=None):
        """All children always start; only ``userdata`` is merged (upstream raises
        TypeError here on Python 3)."""
        if initial_states:
            _smach().logwarn(
                "Attempting to set initial state of a Concurrence; all of its "
                "states start together, so this is ignored."
            )
        if userdata is not None:
            self.userdata.update(userdata)

    def get_active_states(self):
        with self._done_cond:
            if not self._running:
                return []
            return [label for label, o in self._child_outcomes.items() if o is None]

    def get_internal_edges(self):
        edges = []
        for container_outcome, required in self._outcome_map.items():
            for child_label, child_outcome in required.items():
                edges.append((child_outcome, child_label, container_outcome))
        return edges

    def check_consistency(self):
        for container_outcome, required in self._outcome_map.items():
            for child_label, child_outcome in required.items():
                if child_label not in self._states:
                    raise _smach().InvalidTransitionError(
                        "Outcome map of outcome '%s' names state '%s', which is not a child "
                        "of this Concurrence (children: %s)"
                        % (container_outcome, child_label, list(self._states))
                    )
                if child_outcome not in self._states[child_label].get_registered_outcomes():
                    raise _smach().InvalidTransitionError(
                        "Outcome map of outcome '%s' expects outcome '%s' from state '%s', "
                        "which only has outcomes %s"
                        % (
                            container_outcome,
                            child_outcome,
                            child_label,
                            list(self._states[child_label].get_registered_outcomes()),
                        )
                    )
