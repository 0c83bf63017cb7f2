"""Errors of the catalogue and the image archive. Messages are one line that names the field
(or the record) and says what to do."""

__all__ = [
    "CatalogueError",
    "FieldError",
    "ContextIdError",
    "StatusError",
    "MigrationError",
    "ConnectionLostError",
    "ArchiveError",
]


class CatalogueError(Exception):
    """Base class of every catalogue error."""


class FieldError(CatalogueError, ValueError):
    """A value offered for a field is not acceptable; nothing was written."""


class ContextIdError(FieldError):
    """A context or site ID is not acceptable; nothing was written."""


class StatusError(CatalogueError):
    """A sherd cannot move to the requested state from the one it is in."""


class MigrationError(CatalogueError):
    """The database schema cannot be brought up to date."""


class ConnectionLostError(CatalogueError):
    """The database cannot be reached (lost mid-call, or not reachable when connecting). The
    transaction in progress was rolled back, or, when the commit itself went unanswered, is
    checked on the next call: after ``Catalogue.reconnect_with_retry`` the same call may be made
    again and is never committed twice. ``reason`` is the driver's own first line."""

    def __init__(self, message, reason=None):
        super().__init__(message)
        self.reason = reason


class ArchiveError(CatalogueError):
    """The image archive folder (archive.root) cannot be used: missing and not creatable, not
    writable, too little free space, or a file that belongs to another catalogue."""
