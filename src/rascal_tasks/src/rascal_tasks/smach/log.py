"""Logging hooks of the SMACH-compatible core.

The core never imports a logging framework. By default it prints to stdout with smach's
prefixes; ``set_loggers`` injects other functions (a node passes rospy's loggers). The core
always calls the package attributes (``smach.loginfo`` ...) at call time, so replacing them
takes effect everywhere at once.
"""

import sys

__all__ = ["loginfo", "logwarn", "logdebug", "logerr", "set_loggers"]


def loginfo(msg):
    print("[  INFO ] : " + str(msg))


def logwarn(msg):
    print("[  WARN ] : " + str(msg))


def logdebug(msg):
    print("[ DEBUG ] : " + str(msg))


def logerr(msg):
    print("[ ERROR ] : " + str(msg))


def set_loggers(info, warn, debug, error):
    """Replace the four loggers. Argument order is smach's: info, warn, debug, error."""
    pkg = sys.modules[__package__]
    module = sys.modules[__name__]
    for name, fn in (("loginfo", info), ("logwarn", warn), ("logdebug", debug), ("logerr", error)):
        if not callable(fn):
            raise TypeError("set_loggers: %s must be callable, got %r" % (name, fn))
        setattr(pkg, name, fn)
        setattr(module, name, fn)


# the defaults, so a caller (or a test) can put them back with set_loggers
_default_info, _default_warn, _default_debug, _default_error = loginfo, logwarn, logdebug, logerr
