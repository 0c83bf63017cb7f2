"""Context and site IDs, and the archive folder a context ID is stored under.

A context ID is written as the excavation writes it: any printable text of 1 to 64 characters
(``TR1/1023``, ``SU 1023``, ``Köln-1``), kept exactly as typed after Unicode NFC normalisation
(a decomposed ``o`` + ``¨`` and a composed ``ö`` are the same context). Refused, with one line:
empty or only spaces, a space at either end, control or invisible characters, and ``.`` or
``..`` as a path part (``../x``, ``a/../b``). IDs always reach SQL as query parameters.

A site ID keeps the small alphabet (ASCII letters, digits, '-', '_', '.'): it is a code the rig
is configured with, never typed per bag. The database repeats both rules as CHECKs.

In the image archive a context lives in the folder ``context_folder(id)``: every character
that is not a letter, a digit, '-' or '_' (or '.' after the first character) is written as
``%XX`` of its UTF-8 bytes, so ``TR1/1023`` is ``TR1%2F1023`` and ``SU 1023`` ``SU%201023``,
while ``Köln-1`` and every ID of the old alphabet keep their own name. The escape is
reversible (``context_from_folder``) and two IDs never share a folder. A name that would
exceed ``MAX_FOLDER_BYTES`` (64 escaped emoji) is cut and ends ``~<16 hex of its SHA-256>``; its
ID is then read from a sidecar in the folder (each holds ``context_id``).
"""

import hashlib
import unicodedata

from .errors import ContextIdError

__all__ = [
    "MAX_ID_LENGTH",
    "MAX_FOLDER_BYTES",
    "validate_context_id",
    "validate_site_id",
    "context_folder",
    "context_from_folder",
]

MAX_ID_LENGTH = 64
MAX_FOLDER_BYTES = 200  # below NAME_MAX (255) of every common filesystem, with room for temps
_SITE_HINT = "(use letters, digits, '-', '_', '.')"
_CONTEXT_HINT = "(any printable text up to %d characters, e.g. TR1/1023, SU 1023, Köln-1)" % (
    MAX_ID_LENGTH
)
_SITE_CHARS = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-")
_HASH_MARK = "~"  # never produced by the escape ('~' is escaped), so hashed names are distinct


def _shown(value):
    """The value as it can be printed on one line (control characters escaped)."""
    return repr(value)[1:-1] if isinstance(value, str) else repr(value)


def _common(kind, value, hint):
    if not isinstance(value, str):
        raise ContextIdError(
            "%s %s: must be a string, got %s %s" % (kind, _shown(value), type(value).__name__, hint)
        )
    where = "%s '%s'" % (kind, _shown(value))
    if value == "":
        raise ContextIdError("%s: must not be empty %s" % (where, hint))
    if len(value) > MAX_ID_LENGTH:
        raise ContextIdError(
            "%s: is %d characters long, at most %d are allowed %s"
            % (where, len(value), MAX_ID_LENGTH, hint)
        )
    for ch in value:
        if unicodedata.category(ch) == "Cc":
            raise ContextIdError(
                "%s: must not contain control characters (found %s) %s" % (where, _shown(ch), hint)
            )
    return where


def validate_context_id(value):
    """The context ID, NFC-normalised, if it is acceptable; else ContextIdError (one line).
    Callers store and look up the returned value."""
    where = _common("context id", value, _CONTEXT_HINT)
    value = unicodedata.normalize("NFC", value)
    if not value.strip():
        raise ContextIdError("%s: must not be only spaces %s" % (where, _CONTEXT_HINT))
    if value != value.strip():
        raise ContextIdError("%s: must not start or end with a space %s" % (where, _CONTEXT_HINT))
    for ch in value:
        if ch != " " and not ch.isprintable():
            raise ContextIdError(
                "%s: must not contain invisible characters (found U+%04X) %s"
                % (where, ord(ch), _CONTEXT_HINT)
            )
    for part in value.replace("\\", "/").split("/"):
        if part in (".", ".."):
            raise ContextIdError(
                "%s: must not contain '%s' as a path part %s" % (where, part, _CONTEXT_HINT)
            )
    return value


def validate_site_id(value):
    """Return ``value`` if it is an acceptable site code, else raise ContextIdError."""
    where = _common("site id", value, _SITE_HINT)
    for sep in ("/", "\\"):
        if sep in value:
            raise ContextIdError("%s: must not contain %r %s" % (where, sep, _SITE_HINT))
    for ch in value:
        if ch not in _SITE_CHARS:
            raise ContextIdError("%s: must not contain %r %s" % (where, ch, _SITE_HINT))
    if value[0] in ".-":
        raise ContextIdError("%s: must not start with %r %s" % (where, value[0], _SITE_HINT))
    return value


def _plain(ch, first):
    if ch in "-_":
        return True
    if ch == ".":
        return not first  # no hidden folders, no '.' or '..'
    return ch.isalnum()


def context_folder(context_id):
    """The archive folder name of a context ID (validated first): see the module's text."""
    value = validate_context_id(context_id)
    out = []
    for i, ch in enumerate(value):
        if _plain(ch, i == 0):
            out.append(ch)
        else:
            out.append("".join("%%%02X" % b for b in ch.encode("utf-8")))
    name = "".join(out)
    if len(name.encode("utf-8")) <= MAX_FOLDER_BYTES:
        return name
    digest = hashlib.sha256(value.encode("utf-8")).hexdigest()[:16]
    keep = MAX_FOLDER_BYTES - len(_HASH_MARK) - len(digest)
    head = name.encode("utf-8")[:keep].decode("utf-8", "ignore")
    head = head[: head.rfind("%")] if "%" in head[-2:] else head  # no cut escape
    return head + _HASH_MARK + digest


def context_from_folder(name):
    """The context ID an archive folder name stands for; None where the name is not one
    ``context_folder`` writes (a hashed long name, the spool, anything else)."""
    if not name or _HASH_MARK in name:
        return None
    raw = bytearray()
    i = 0
    try:
        while i < len(name):
            ch = name[i]
            if ch == "%":
                raw += bytes([int(name[i + 1 : i + 3], 16)])
                i += 3
                continue
            raw += ch.encode("utf-8")
            i += 1
        value = raw.decode("utf-8")
        return value if context_folder(value) == name else None
    except (ValueError, IndexError, ContextIdError):
        return None
