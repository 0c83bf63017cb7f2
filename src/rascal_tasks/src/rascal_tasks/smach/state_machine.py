"""``StateMachine``: states joined by outcome -> label transitions.

Semantics are smach 2.5.2's, plus the ``constants`` argument of noetic-devel. One fix: the
transitioning lock is re-entrant, so ``request_preempt()`` from one of the machine's own
start/transition/termination callbacks no longer deadlocks.
"""

import sys
import threading
import traceback

from .container import Container
from .state import State
from .user_data import Remapper

__all__ = ["StateMachine"]


def _smach():
    return sys.modules[__package__]


class StateMachine(Container):
    """Runs one state at a time; each outcome names the next state or a machine outcome.

    A transition target of ``None`` (the default for an outcome with no transition) or
    ``''`` ends the machine with the outcome of the same name.
    """

    def __init__(self, outcomes, input_keys=(), output_keys=()):
        Container.__init__(self, outcomes, input_keys, output_keys)
        self._state_transitioning_lock = threading.RLock()
        self._states = {}
        self._transitions = {}
        self._remappings = {}
        self._constants = {}
        self._initial_state_label = None
        self._current_label = None
        self._current_state = None
        self._current_transitions = None
        self._current_outcome = None
        self._preempted_label = None
        self._preempted_state = None
        self._is_running = False
        self._last_added_label = None
        self._connector_outcomes = []

    # --- construction (static: they add to the currently open machine) ---
    @staticmethod
    def add(label, state, transitions=None, remapping=None, constants=None):
        """Add ``state`` under ``label``; the first state added is the initial state.

        ``transitions`` maps the state's outcomes to labels or machine outcomes;
        ``remapping`` maps state-local userdata names to the machine's keys;
        ``constants`` (noetic-devel) are written to the machine's userdata just before the
        state runs. Returns ``state``.
        """
        self = StateMachine._currently_opened_container()
        if label in self._states:
            raise _smach().InvalidStateError(
                "Attempting to add state with label '%s' to state machine, but this label is "
                "already being used." % label
            )
        if not isinstance(state, State) and not hasattr(state, "get_registered_outcomes"):
            raise _smach().InvalidStateError(
                "Attempting to add state '%s' of type %s, which is not a smach State."
                % (label, type(state).__name__)
            )
        _smach().logdebug("Adding state (%s, %s, %s)" % (label, repr(state), transitions))
        if transitions is None:
            transitions = {}
        if remapping is None:
            remapping = {}
        if constants is None:
            constants = {}
        # a pending add_auto connection of the previous state points here (it wins, as in smach)
        if self._last_added_label is not None and self._connector_outcomes:
            for connector in self._connector_outcomes:
                self._transitions[self._last_added_label][connector] = label
        self._connector_outcomes = []
        self.check_state_spec(label, state, transitions)
        for outcome in state.get_registered_outcomes():
            if outcome not in transitions:
                transitions[outcome] = None
        self._states[label] = state
        self._transitions[label] = transitions
        self._remappings[label] = remapping
        self._constants[label] = constants
        if self._initial_state_label is None:
            self._initial_state_label = label
        self._last_added_label = label
        return state

    @staticmethod
    def add_auto(
        label, state, connector_outcomes, transitions=None, remapping=None, constants=None
    ):
        """Add ``state`` and connect its ``connector_outcomes`` to the next state added."""
        self = StateMachine._currently_opened_container()
        StateMachine.add(label, state, transitions, remapping, constants)
        registered = state.get_registered_outcomes()
        missing = [c for c in connector_outcomes if c not in registered]
        if missing:
            raise _smach().InvalidStateError(
                "Attempting to auto-connect states with outcomes %s, but state '%s' only has "
                "registered outcomes: %s" % (missing, label, list(registered))
            )
        self._connector_outcomes = list(connector_outcomes)
        return state

    def check_state_spec(self, label, state, transitions):
        registered = state.get_registered_outcomes()
        for outcome in transitions:
            if outcome not in registered:
                raise _smach().InvalidTransitionError(
                    "Specified outcome '%s' on state '%s', which only has available registered "
                    "outcomes: %s" % (outcome, label, list(registered))
                )

    # --- execution ---
    def execute(self, parent_ud=None):
        """Run from the initial state; return the outcome (None if the machine is invalid
        or shutdown was signalled)."""
        with self._state_transitioning_lock:
            try:
                self.check_consistency()
            except (_smach().InvalidStateError, _smach().InvalidTransitionError):
                _smach().logerr("Container consistency check failed.")
                return None
            self._is_running = True
            self._preempted_label = None
            self._preempted_state = None
            self._set_current_state(self._initial_state_label)
            self._copy_input_keys(parent_ud, self.userdata)
            _smach().loginfo(
                "State machine starting in initial state '%s' with userdata: "
                "\n\t%s" % (self._current_label, list(self.userdata.keys()))
            )
            container_outcome = None
            try:
                self.call_start_cbs()
                while container_outcome is None and self._is_running and not _smach().is_shutdown():
                    container_outcome = self._update_once()
                self._copy_output_keys(self.userdata, parent_ud)
            finally:
                self._is_running = False
                self._current_label = None
                self._current_state = None
                self._current_transitions = None
            return container_outcome

    def _set_current_state(self, label):
        if label is None:
            self._current_label = None
            self._current_state = None
            self._current_transitions = None
        else:
            self._current_label = label
            self._current_state = self._states[label]
            self._current_transitions = self._transitions[label]

    def _preempt_current_state(self):
        self._preempted_label = self._current_label
        self._preempted_state = self._current_state
        try:
            self._current_state.request_preempt()
        except Exception:
            _smach().logerr(
                "Failed to preempt contained state '%s': %s"
                % (self._preempted_label, traceback.format_exc())
            )

    def _update_once(self):
        # preemption bookkeeping (the lock is held here)
        if self._preempt_requested:
            if self._preempted_state is not None:
                if self._preempted_state.preempt_requested():
                    _smach().loginfo(
                        "Last state '%s' did not service preempt. Preempting next "
                        "state '%s' before executing..."
                        % (self._preempted_label, self._current_label)
                    )
                    self._preempt_current_state()
                else:
                    # the child serviced it: the machine carries on
                    self._preempt_requested = False
                    self._preempted_state = None
                    self._preempted_label = None
            else:
                self._preempt_current_state()

        label = self._current_label
        state = self._current_state
        transitions = self._current_transitions
        remapping = self._remappings[label]
        constants = self._constants.get(label) or {}

        self._state_transitioning_lock.release()
        try:
            for key, value in constants.items():
                self.userdata[key] = value
            outcome = state.execute(
                Remapper(
                    self.userdata,
                    state.get_registered_input_keys(),
                    state.get_registered_output_keys(),
                    remapping,
                )
            )
        except _smach().InvalidUserCodeError:
            raise
        except Exception:
            raise _smach().InvalidUserCodeError(
                "Could not execute state '%s' of type '%s': %s"
                % (label, state, traceback.format_exc())
            ) from None
        finally:
            self._state_transitioning_lock.acquire()

        if outcome not in state.get_registered_outcomes():
            raise _smach().InvalidTransitionError(
                "Attempted to return outcome '%s' from state '%s' of type '%s' which only has "
                "registered outcomes: %s"
                % (outcome, label, state, list(state.get_registered_outcomes()))
            )
        self._current_outcome = outcome
        target = transitions.get(outcome)

        if target in self._states:
            self._set_current_state(target)
            _smach().loginfo(
                "State machine transitioning '%s':'%s'-->'%s'" % (label, outcome, target)
            )
            self.call_transition_cbs()
            return None

        if (
            self._preempt_requested
            and self._preempted_state is not None
            and not self._current_state.preempt_requested()
        ):
            self.service_preempt()
        if target not in self._outcomes:
            target = outcome  # fall through: the state's outcome becomes the machine's
        if target in self._outcomes:
            self._set_current_state(None)
            _smach().loginfo("State machine terminating '%s':'%s':'%s'" % (label, outcome, target))
            self.call_termination_cbs([label], target)
            return target
        raise _smach().InvalidTransitionError(
            "Outcome '%s' of state '%s' with transition target '%s' is neither a registered "
            "state nor a registered container outcome." % (outcome, label, target)
        )

    # --- preemption ---
    def request_preempt(self):
        """Ask the machine (and its running state) to stop. Safe from any thread and from
        the machine's own callbacks."""
        with self._state_transitioning_lock:
            State.request_preempt(self)
            if self._is_running and self._current_state is not None:
                self._preempt_current_state()

    # --- introspection ---
    def get_children(self):
        return self._states

    def __getitem__(self, key):
        if key not in self._states:
            _smach().logerr(
                "Attempting to get state '%s' from StateMachine container. The only "
                "available states are: %s" % (key, list(self._states))
            )
            raise KeyError(key)
        return self._states[key]

    def set_initial_state(self, initial_states, userdata=None):
        """Start the next execution at ``initial_states[0]`` and merge ``userdata``."""
        if isinstance(initial_states, str):
            initial_states = [initial_states]
        if len(initial_states) > 1:
            _smach().logwarn(
                "Attempting to set initial state to include more than one state, "
                "but the StateMachine container can only have one initial state."
            )
        if initial_states:
            self._initial_state_label = initial_states[0]
        if userdata is not None:
            self.userdata.update(userdata)

    def get_initial_states(self):
        return [str(self._initial_state_label)]

    def get_active_states(self):
        return [str(self._current_label)]

    def get_internal_edges(self):
        edges = []
        for from_label, transitions in self._transitions.items():
            for outcome, to_label in transitions.items():
                edges.append((outcome, from_label, to_label))
        return edges

    def check_consistency(self):
        """Raise InvalidStateError/InvalidTransitionError if the machine cannot run."""
        if not self._states:
            raise _smach().InvalidStateError("The state machine has no states.")
        if self._initial_state_label is None:
            raise _smach().InvalidStateError("The state machine has no initial state.")
        if self._initial_state_label not in self._states:
            raise _smach().InvalidStateError(
                "The initial state '%s' is not a state of this machine (states: %s)."
                % (self._initial_state_label, list(self._states))
            )
        errors = []
        for label, transitions in self._transitions.items():
            for outcome, target in transitions.items():
                if target is None or target == "":
                    if outcome not in self._outcomes:
                        errors.append(
                            "state '%s' outcome '%s' has no transition and is not an "
                            "outcome of the machine" % (label, outcome)
                        )
                elif target not in self._states and target not in self._outcomes:
                    errors.append(
                        "state '%s' outcome '%s' goes to '%s', which is neither a "
                        "state nor an outcome of the machine" % (label, outcome, target)
                    )
        if errors:
            raise _smach().InvalidTransitionError(
                "State machine failed consistency check: "
                + "; ".join(errors)
                + ". Available states: %s; machine outcomes: %s"
                % (list(self._states), sorted(self._outcomes))
            )

    def is_running(self):
        return self._is_running

    # --- pickling (the lock is not state) ---
    def __getstate__(self):
        state = dict(self.__dict__)
        del state["_state_transitioning_lock"]
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._state_transitioning_lock = threading.RLock()
