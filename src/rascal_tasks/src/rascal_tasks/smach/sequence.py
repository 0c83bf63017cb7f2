"""``Sequence``: a StateMachine whose states are linked in the order they are added."""

import sys

from .state_machine import StateMachine

__all__ = ["Sequence"]


class Sequence(StateMachine):
    """Each added state's ``connector_outcome`` leads to the next state added, unless that
    outcome was given an explicit transition. The last state's connector outcome falls
    through, so it must be an outcome of the Sequence."""

    def __init__(self, outcomes, connector_outcome, input_keys=(), output_keys=()):
        StateMachine.__init__(self, outcomes, input_keys, output_keys)
        self._last_added_seq_label = None
        self._connector_outcome = connector_outcome

    @staticmethod
    def add(label, state, transitions=None, remapping=None):
        """Add ``state`` after the previous one (no ``constants``, as in smach)."""
        self = Sequence._currently_opened_container()
        if label in self._states:
            raise sys.modules[__package__].InvalidStateError(
                "Attempting to add state with label '%s' to sequence, but this label is "
                "already being used." % label
            )
        previous = self._last_added_seq_label
        if previous is not None:
            prev_transitions = self._transitions[previous]
            if prev_transitions.get(self._connector_outcome) in (None, ""):
                prev_transitions[self._connector_outcome] = label
        StateMachine.add(label, state, transitions, remapping)
        self._last_added_seq_label = label
        return state
