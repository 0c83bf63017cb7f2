"""``Iterator``: runs one contained state once per item of an iterable."""

import sys
import traceback

from .container import Container
from .state import State

__all__ = ["Iterator"]


def _smach():
    return sys.modules[__package__]


class Iterator(Container):
    """Puts each item in ``userdata[it_label]`` and runs the contained state on it.

    The contained state gets the Iterator's own userdata (no Remapper), as in smach. The
    loop ends with ``exhausted_outcome`` when the items run out, or with the state's
    outcome when that is a break outcome or when the Iterator is preempted.
    """

    def __init__(
        self,
        outcomes,
        input_keys,
        output_keys,
        it=(),
        it_label="it_data",
        exhausted_outcome="exhausted",
    ):
        outcomes = list(outcomes)
        if exhausted_outcome not in outcomes:
            outcomes.append(exhausted_outcome)
        Container.__init__(self, outcomes, input_keys, output_keys)
        self._items = it
        self._items_label = it_label
        self._exhausted_outcome = exhausted_outcome
        self._state_label = None
        self._state = None
        self._loop_outcomes = []
        self._break_outcomes = []
        self._final_outcome_map = {}
        self._is_running = False

    # --- construction ---
    @staticmethod
    def set_iteritems(it, it_label="it_data"):
        """Set the items (an iterable, or a callable returning one per execution)."""
        self = Iterator._currently_opened_container()
        self._items = it
        self._items_label = it_label

    @staticmethod
    def set_contained_state(
        label, state, loop_outcomes=(), break_outcomes=(), final_outcome_map=None
    ):
        """Set the state to iterate. With ``break_outcomes`` every other outcome loops;
        otherwise every outcome not in ``loop_outcomes`` breaks."""
        self = Iterator._currently_opened_container()
        outcomes = state.get_registered_outcomes()
        if break_outcomes:
            if loop_outcomes:
                _smach().logwarn(
                    "Iterator: both loop_outcomes and break_outcomes were given; "
                    "break_outcomes wins."
                )
            self._break_outcomes = list(break_outcomes)
            self._loop_outcomes = [o for o in outcomes if o not in break_outcomes]
        else:
            self._loop_outcomes = list(loop_outcomes)
            self._break_outcomes = [o for o in outcomes if o not in loop_outcomes]
        self._state_label = label
        self._state = state
        self._final_outcome_map = dict(final_outcome_map or {})

    # --- execution ---
    def execute(self, parent_ud=None):
        if self._state is None:
            raise _smach().InvalidStateError(
                "Iterator has no contained state: call " 'set_contained_state inside "with it:".'
            )
        self._is_running = True
        try:
            self._copy_input_keys(parent_ud, self.userdata)
            self.call_start_cbs()
            items = self._items() if callable(self._items) else self._items
            try:
                iterator = iter(items)
            except Exception:
                iterator = iter(())
            outcome = self._exhausted_outcome
            while not _smach().is_shutdown():
                try:
                    item = next(iterator)
                except Exception:
                    outcome = self._exhausted_outcome
                    break
                self.userdata[self._items_label] = item
                try:
                    state_outcome = self._state.execute(self.userdata)
                except _smach().InvalidUserCodeError:
                    raise
                except Exception:
                    raise _smach().InvalidUserCodeError(
                        "Could not execute Iterator state '%s' of type '%s': %s"
                        % (self._state_label, self._state, traceback.format_exc())
                    ) from None
                if self._preempt_requested:
                    self.service_preempt()
                    outcome = state_outcome
                    break
                if state_outcome in self._break_outcomes or (
                    self._loop_outcomes and state_outcome not in self._loop_outcomes
                ):
                    outcome = state_outcome
                    break
                self.call_transition_cbs()
            outcome = self._final_outcome_map.get(outcome, outcome)
            self._copy_output_keys(self.userdata, parent_ud)
            self.call_termination_cbs(self._state_label, outcome)
            return outcome
        finally:
            self._is_running = False

    # --- preemption ---
    def request_preempt(self):
        State.request_preempt(self)
        if self._is_running and self._state is not None:
            self._state.request_preempt()

    # --- introspection ---
    def get_children(self):
        return {self._state_label: self._state} if self._state is not None else {}

    def __getitem__(self, key):
        if self._state is None or key != self._state_label:
            _smach().logwarn(
                "Iterator has no state labelled '%s' (it contains '%s')." % (key, self._state_label)
            )
            raise KeyError(key)
        return self._state

    def set_initial_state(self, initial_states, userdata=None):
        if isinstance(initial_states, str):
            initial_states = [initial_states]
        for label in initial_states or []:
            if label != self._state_label:
                _smach().logwarn(
                    "Iterator cannot start at '%s': its only state is '%s'."
                    % (label, self._state_label)
                )
                raise KeyError(label)
        if userdata is not None:
            self.userdata.update(userdata)

    def get_initial_states(self):
        return [self._state_label]

    def get_active_states(self):
        return [self._state_label] if self._is_running else []

    def get_internal_edges(self):
        edges = [[o, self._state_label, self._state_label] for o in self._loop_outcomes]
        edges += [
            (o, self._state_label, self._final_outcome_map.get(o)) for o in self._break_outcomes
        ]
        return edges

    def check_consistency(self):
        pass
