"""``ImageArchive``: archival images on disk, written so that a crash never leaves a partial
file under a final name.

Layout: ``<root>/<context>/<seq>.png`` with ``<seq>.json`` beside it (the sherd's record as
it was when the image was archived, plus the image's SHA-256). Each file is written to a
temporary name in the same directory, flushed and fsync'ed, then renamed into place
(``os.replace`` is atomic on POSIX); the directory is fsync'ed after the rename. Only then
are the path and hash handed to the database.
"""

import datetime
import hashlib
import json
import os
import tempfile

from .context_id import validate_context_id
from .errors import FieldError

__all__ = ["ImageArchive", "PNG_SIGNATURE"]

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_CHUNK = 1 << 20


def _json_default(value):
    if isinstance(value, datetime.datetime):
        return value.astimezone(datetime.timezone.utc).isoformat()
    return str(value)


class ImageArchive:
    """Stores images under ``root`` (created if missing)."""

    def __init__(self, root, fsync=True):
        if not isinstance(root, str) or not root:
            raise FieldError("archive.root %r: must be a directory path" % (root,))
        self.root = os.path.abspath(root)
        self._fsync = fsync

    @staticmethod
    def relpath(context_id, seq):
        """Where a sherd's image lives, relative to the root: ``<context>/<seq>.png``."""
        validate_context_id(context_id)
        if isinstance(seq, bool) or not isinstance(seq, int) or seq < 1:
            raise FieldError(
                "seq %r: must be the sherd's sequence number (an integer >= 1)" % (seq,)
            )
        return "%s/%d.png" % (context_id, seq)

    def path(self, relpath):
        """Absolute path of an archived file; refuses paths that leave the archive."""
        full = os.path.realpath(os.path.join(self.root, relpath))
        if os.path.commonpath([full, os.path.realpath(self.root)]) != os.path.realpath(self.root):
            raise FieldError(
                "image_path '%s': points outside the archive %s" % (relpath, self.root)
            )
        return full

    def store(self, context_id, seq, image, record=None):
        """Write ``image`` (PNG bytes, or the path of a PNG file) and its JSON sidecar.

        Returns ``(relpath, sha256)``; raises FieldError (nothing left behind) for a bad
        context, sequence number or image.
        """
        rel = self.relpath(context_id, seq)
        final = self.path(rel)
        directory = os.path.dirname(final)
        os.makedirs(directory, exist_ok=True)
        sha = self._write_atomic(final, self._chunks(image), check_png=True)
        self.write_sidecar(context_id, seq, dict(record or {}, image_path=rel, image_sha256=sha))
        return rel, sha

    def write_sidecar(self, context_id, seq, record):
        """(Re)write ``<context>/<seq>.json`` atomically with ``record`` (the sherd's row)."""
        rel = self.relpath(context_id, seq)
        final = self.path(rel)[:-4] + ".json"
        os.makedirs(os.path.dirname(final), exist_ok=True)
        side = dict(record, written_at=datetime.datetime.now(datetime.timezone.utc))
        blob = json.dumps(side, default=_json_default, sort_keys=True, indent=1).encode() + b"\n"
        self._write_atomic(final, iter([blob]))
        return final

    def verify(self, relpath, sha256):
        """True if the archived file exists and has this SHA-256."""
        try:
            h = hashlib.sha256()
            with open(self.path(relpath), "rb") as f:
                for block in iter(lambda: f.read(_CHUNK), b""):
                    h.update(block)
        except FileNotFoundError:
            return False
        return h.hexdigest() == sha256

    @staticmethod
    def _chunks(image):
        if isinstance(image, (bytes, bytearray, memoryview)):
            yield bytes(image)
            return
        if isinstance(image, (str, os.PathLike)):
            try:
                f = open(image, "rb")
            except OSError as e:
                raise FieldError("image '%s': cannot be read (%s)" % (image, e.strerror)) from None
            with f:
                yield from iter(lambda: f.read(_CHUNK), b"")
            return
        raise FieldError(
            "image: must be PNG bytes or the path of a PNG file, got %s" % type(image).__name__
        )

    def _write_atomic(self, final, chunks, check_png=False):
        directory = os.path.dirname(final)
        fd, tmp = tempfile.mkstemp(
            prefix="." + os.path.basename(final) + ".", suffix=".tmp", dir=directory
        )
        h = hashlib.sha256()
        try:
            with os.fdopen(fd, "wb") as f:
                total = 0
                for block in chunks:
                    if not block:
                        continue
                    if check_png and total == 0 and not block.startswith(PNG_SIGNATURE):
                        raise FieldError(
                            "image: not a PNG file (the archive keeps lossless "
                            "PNG only; save the capture as PNG)"
                        )
                    h.update(block)
                    f.write(block)
                    total += len(block)
                if check_png and total == 0:
                    raise FieldError("image: empty (the capture returned no data)")
                f.flush()
                if self._fsync:
                    os.fsync(f.fileno())
            os.replace(tmp, final)
        except BaseException:
            try:
                os.unlink(tmp)
            except FileNotFoundError:
                pass
            raise
        if self._fsync:
            dfd = os.open(directory, os.O_RDONLY)
            try:
                os.fsync(dfd)
            finally:
                os.close(dfd)
        return h.hexdigest()
