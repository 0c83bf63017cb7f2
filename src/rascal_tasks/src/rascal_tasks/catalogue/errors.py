"""Errors of the catalogue and the image archive. Messages are one line that names the field
(or the record) and says what to do."""

__all__ = ["CatalogueError", "FieldError", "ContextIdError", "StatusError", "MigrationError"]


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
