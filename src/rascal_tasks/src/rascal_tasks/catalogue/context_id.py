"""Validation of context and site IDs.

An ID becomes a directory name in the image archive and a key in the database, so it is held
to a small alphabet: ASCII letters, digits, '-', '_' and '.', 1 to 64 characters, not starting
with '.' or '-'. The same rule is a CHECK in the database. IDs always reach SQL as query
parameters, never formatted into the statement.
"""

import re

from .errors import ContextIdError

__all__ = ["MAX_ID_LENGTH", "validate_context_id", "validate_site_id"]

MAX_ID_LENGTH = 64
_ALLOWED = re.compile(r"[A-Za-z0-9._-]")
_HINT = "(use letters, digits, '-', '_', '.')"


def _shown(value):
    """The value as it can be printed on one line (control characters escaped)."""
    return repr(value)[1:-1] if isinstance(value, str) else repr(value)


def _check(kind, value):
    if not isinstance(value, str):
        raise ContextIdError(
            "%s %s: must be a string, got %s %s"
            % (kind, _shown(value), type(value).__name__, _HINT)
        )
    where = "%s '%s'" % (kind, _shown(value))
    if value == "":
        raise ContextIdError("%s: must not be empty %s" % (where, _HINT))
    if len(value) > MAX_ID_LENGTH:
        raise ContextIdError(
            "%s: is %d characters long, at most %d are allowed %s"
            % (where, len(value), MAX_ID_LENGTH, _HINT)
        )
    for sep in ("/", "\\"):
        if sep in value:
            raise ContextIdError("%s: must not contain %r %s" % (where, sep, _HINT))
    for ch in value:
        if ord(ch) < 32 or ord(ch) == 127:
            raise ContextIdError(
                "%s: must not contain control characters (found %s) %s" % (where, _shown(ch), _HINT)
            )
    for ch in value:
        if not _ALLOWED.fullmatch(ch):
            raise ContextIdError("%s: must not contain %r %s" % (where, ch, _HINT))
    if value[0] in ".-":
        raise ContextIdError("%s: must not start with %r %s" % (where, value[0], _HINT))
    return value


def validate_context_id(value):
    """Return ``value`` if it is an acceptable context ID, else raise ContextIdError."""
    return _check("context id", value)


def validate_site_id(value):
    """Return ``value`` if it is an acceptable site code, else raise ContextIdError."""
    return _check("site id", value)
