"""Exception types of the SMACH-compatible core (same names and hierarchy as smach 2.5.2).

Constructing any of them logs one ERROR line ``<ClassName>: <message>`` through the
package's current error logger, as smach does.
"""

import sys

__all__ = [
    "SmachError",
    "InvalidTransitionError",
    "InvalidStateError",
    "InvalidUserCodeError",
    "InvalidConstructionError",
]


class SmachError(Exception):
    """Base class of every error raised by the state-machine core."""

    def __init__(self, message):
        super().__init__(message)
        sys.modules[__package__].logerr("%s: %s" % (type(self).__name__, message))


class InvalidTransitionError(SmachError):
    """A transition names an outcome or target the machine does not have."""


class InvalidStateError(SmachError):
    """A container was built or used in a way its states do not allow."""


class InvalidUserCodeError(SmachError):
    """User code (a state's execute, a callback, a userdata access) failed."""


class InvalidConstructionError(SmachError):
    """A construction method was called while its container was not open."""
