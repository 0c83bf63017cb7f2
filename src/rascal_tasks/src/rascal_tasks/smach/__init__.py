"""A SMACH-compatible state-machine core (the public names and semantics of smach 2.5.2).

Task code does::

    try:
        import smach
    except ImportError:
        from rascal_tasks import smach

so it runs unchanged on a rig that has the real smach. Nothing here imports ROS: a node
injects rospy's loggers with ``set_loggers`` and its shutdown test with
``set_shutdown_check``. Deviations from upstream (hangs, deadlocks and crashes fixed) are
listed in the rascal_tasks README.
"""

from . import (
    concurrence,
    container,
    exceptions,
    iterator,
    log,
    sequence,
    state,
    state_machine,
    user_data,
    util,
)
from .concurrence import Concurrence
from .container import Container
from .exceptions import (
    InvalidConstructionError,
    InvalidStateError,
    InvalidTransitionError,
    InvalidUserCodeError,
)
from .iterator import Iterator
from .log import logdebug, logerr, loginfo, logwarn, set_loggers
from .sequence import Sequence
from .state import CBState, State
from .state_machine import StateMachine
from .user_data import Remapper, UserData
from .util import CBInterface, cb_interface, has_smach_interface, is_shutdown, set_shutdown_check

__version__ = "2.5.2"

# smach has no __all__, so `from smach import *` gives every public name and the submodules;
# this list keeps exactly that.
__all__ = [
    "CBInterface",
    "CBState",
    "Concurrence",
    "Container",
    "InvalidConstructionError",
    "InvalidStateError",
    "InvalidTransitionError",
    "InvalidUserCodeError",
    "Iterator",
    "Remapper",
    "Sequence",
    "State",
    "StateMachine",
    "UserData",
    "cb_interface",
    "has_smach_interface",
    "is_shutdown",
    "set_shutdown_check",
    "set_loggers",
    "loginfo",
    "logwarn",
    "logerr",
    "logdebug",
    "concurrence",
    "container",
    "exceptions",
    "iterator",
    "log",
    "sequence",
    "state",
    "state_machine",
    "user_data",
    "util",
]
