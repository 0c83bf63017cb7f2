"""``State`` and ``CBState``: the leaves of a state machine."""

import sys

from .util import has_smach_interface

__all__ = ["State", "CBState"]


class State:
    """A state declares its outcomes and userdata keys; ``execute(ud)`` returns an outcome.

    Preemption is cooperative: a long ``execute`` polls ``preempt_requested()``, calls
    ``service_preempt()`` and returns an outcome (by convention ``'preempted'``).
    """

    def __init__(self, outcomes=(), input_keys=(), output_keys=(), io_keys=()):
        self._outcomes = set(outcomes)
        self._input_keys = set(input_keys) | set(io_keys)
        self._output_keys = set(output_keys) | set(io_keys)
        self._preempt_requested = False

    def execute(self, ud):
        raise NotImplementedError()

    # --- interface declaration ---
    def register_outcomes(self, new_outcomes):
        self._outcomes = self._outcomes | set(new_outcomes)

    def get_registered_outcomes(self):
        return tuple(self._outcomes)

    def register_io_keys(self, keys):
        self._input_keys = self._input_keys | set(keys)
        self._output_keys = self._output_keys | set(keys)

    def register_input_keys(self, keys):
        self._input_keys = self._input_keys | set(keys)

    def get_registered_input_keys(self):
        return tuple(self._input_keys)

    def register_output_keys(self, keys):
        self._output_keys = self._output_keys | set(keys)

    def get_registered_output_keys(self):
        return tuple(self._output_keys)

    # --- cooperative preemption ---
    def request_preempt(self):
        """Ask the state to stop; it decides when (containers propagate this)."""
        self._preempt_requested = True

    def service_preempt(self):
        """Called by the state when it honours a preempt."""
        self._preempt_requested = False

    def recall_preempt(self):
        """Called by a container to withdraw a preempt the state did not service."""
        self._preempt_requested = False

    def preempt_requested(self):
        return self._preempt_requested


class CBState(State):
    """A state whose ``execute`` is ``cb(ud, *cb_args, **cb_kwargs)``.

    If ``cb`` was decorated with ``cb_interface``, its outcomes and keys are added to the
    ones given here.
    """

    def __init__(
        self, cb, cb_args=(), cb_kwargs=None, outcomes=(), input_keys=(), output_keys=(), io_keys=()
    ):
        State.__init__(self, outcomes, input_keys, output_keys, io_keys)
        if not callable(cb):
            raise sys.modules[__package__].InvalidStateError(
                "CBState: cb must be callable, got %r" % (cb,)
            )
        self._cb = cb
        self._cb_args = list(cb_args)
        self._cb_kwargs = dict(cb_kwargs or {})
        if has_smach_interface(cb):
            self.register_input_keys(cb.get_registered_input_keys())
            self.register_output_keys(cb.get_registered_output_keys())
            self.register_outcomes(cb.get_registered_outcomes())

    def execute(self, ud):
        return self._cb(ud, *self._cb_args, **self._cb_kwargs)
