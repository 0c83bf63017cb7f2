"""Callback interfaces and the shutdown hook of the SMACH-compatible core."""

import functools
import sys

__all__ = [
    "is_shutdown",
    "set_shutdown_check",
    "has_smach_interface",
    "CBInterface",
    "cb_interface",
]


def is_shutdown():
    """Containers poll this between states; a node replaces it with rospy.is_shutdown."""
    return False


def set_shutdown_check(cb):
    """Replace ``is_shutdown`` for the whole core (smach_ros passes rospy.is_shutdown)."""
    if not callable(cb):
        raise TypeError("set_shutdown_check: the check must be callable, got %r" % (cb,))
    for module in (sys.modules[__package__], sys.modules[__name__]):
        module.is_shutdown = cb


def has_smach_interface(obj):
    """True if ``obj`` declares outcomes and userdata keys like a State or CBInterface."""
    return (
        hasattr(obj, "get_registered_input_keys")
        and hasattr(obj, "get_registered_output_keys")
        and hasattr(obj, "get_registered_outcomes")
    )


class CBInterface:
    """A callable wrapper that declares a callback's outcomes and userdata keys.

    Unlike smach 2.5.2, ``io_keys`` is honoured (upstream silently drops it).
    """

    def __init__(self, cb, outcomes=None, input_keys=None, output_keys=None, io_keys=None):
        self._cb = cb
        io = list(io_keys or [])
        self._outcomes = set(outcomes or [])
        self._input_keys = set(input_keys or []) | set(io)
        self._output_keys = set(output_keys or []) | set(io)
        functools.update_wrapper(self, cb, updated=())

    def __call__(self, *args, **kwargs):
        return self._cb(*args, **kwargs)

    def get_registered_input_keys(self):
        return tuple(self._input_keys)

    def get_registered_output_keys(self):
        return tuple(self._output_keys)

    def get_registered_outcomes(self):
        return tuple(self._outcomes)


def cb_interface(outcomes=None, input_keys=None, output_keys=None):
    """Decorator factory: ``@cb_interface(outcomes=[...], input_keys=[...])``."""

    def decorator(cb):
        return CBInterface(cb, outcomes, input_keys, output_keys)

    return decorator
