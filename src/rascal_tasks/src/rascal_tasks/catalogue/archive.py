"""``ImageArchive``: archival images on disk, written so that a crash never leaves a partial
file under a final name.

Layout: ``<root>/<folder>/<seq>-<tag>.png`` with ``<seq>-<tag>.json`` beside it (the sherd's
record, the image's SHA-256 and the writing catalogue's identity). ``<folder>`` is the context
ID made safe as a file name (``context_id.context_folder``: ``TR1/1023`` is ``TR1%2F1023``; an
ID of letters, digits, '-', '_', '.' is its own folder). ``<tag>`` is the first 12 hex
digits of that identity (``Catalogue.identity``), so two catalogues recording the same context
into one folder never overwrite each other. Rows written before the tag keep their
``<context>/<seq>.png``; the sidecar of any image is its path with ``.json`` for ``.png``.

Each file is written to a temporary name in the same directory (``.<name>.<random>.tmp``),
flushed and fsync'ed, then renamed into place (``os.replace`` is atomic on POSIX); the directory
is fsync'ed after the rename. Files get ``file_mode`` (0644) and the folders the archive creates
``dir_mode`` (0755) whatever the umask, so the group can read the archive (archive.file_mode,
archive.dir_mode). Only then are the path and hash handed to the database. A crash
can leave a temporary file behind (never a partial final file): ``repair_archive`` removes it.

Every OS failure is an ``ArchiveError`` whose text is one line naming archive.root and the fix.
"""

import datetime
import errno
import hashlib
import json
import os
import re
import tempfile
import time

from .context_id import context_folder, context_from_folder, validate_context_id
from .errors import ArchiveError, ContextIdError, FieldError

__all__ = [
    "ImageArchive",
    "PNG_SIGNATURE",
    "TAG_LENGTH",
    "owner_tag",
    "sidecar_relpath",
    "sidecar_content",
    "FILE_MODE",
    "DIR_MODE",
    "make_dirs",
]

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
TAG_LENGTH = 12
_CHUNK = 1 << 20
_MB = 1000 * 1000
# <seq>.png|json (before the tag) or <seq>-<tag>.png|json
ARCHIVE_NAME = re.compile(r"^(\d+)(?:-([0-9a-f]{%d}))?\.(png|json)$" % TAG_LENGTH)
TEMP_NAME = re.compile(r"^\..+\.tmp$")
_PROBE_PREFIX = ".rascal-probe-"
FILE_MODE = 0o644  # archive.file_mode: readable by the group and others, written by the owner
DIR_MODE = 0o755  # archive.dir_mode


def _json_default(value):
    if isinstance(value, datetime.datetime):
        return value.astimezone(datetime.timezone.utc).isoformat()
    return str(value)


def owner_tag(owner):
    """The file-name tag of a catalogue identity (a UUID): its first 12 hex digits."""
    tag = str(owner).replace("-", "").lower()[:TAG_LENGTH]
    if not re.fullmatch(r"[0-9a-f]{%d}" % TAG_LENGTH, tag):
        raise FieldError("owner %r: must be the catalogue's UUID (Catalogue.identity())" % (owner,))
    return tag


def sidecar_relpath(image_relpath):
    """The JSON sidecar beside an archived image: the image's path with ``.json``."""
    return os.path.splitext(image_relpath)[0] + ".json"


def sidecar_content(record, owner=None):
    """What the sidecar of ``record`` (a catalogue row) holds, as JSON values, without the
    ``written_at`` stamp: two sidecars of the same row compare equal."""
    side = dict(record)
    side.pop("written_at", None)
    if owner is not None:
        side["catalogue_id"] = str(owner)
    return json.loads(json.dumps(side, default=_json_default, sort_keys=True))


def _user():
    try:
        import pwd

        return pwd.getpwuid(os.geteuid()).pw_name
    except (ImportError, KeyError):
        return "uid %d" % os.geteuid()


class ImageArchive:
    """Stores images under ``root`` (created if missing; see ``check``)."""

    def __init__(self, root, fsync=True, file_mode=FILE_MODE, dir_mode=DIR_MODE):
        if not isinstance(root, str) or not root:
            raise FieldError("archive.root %r: must be a directory path" % (root,))
        for key, mode in (("archive.file_mode", file_mode), ("archive.dir_mode", dir_mode)):
            if isinstance(mode, bool) or not isinstance(mode, int) or not 0 <= mode <= 0o777:
                raise FieldError(
                    "%s %r: must be permission bits 0000..0777, e.g. 0644 (octal)" % (key, mode)
                )
        self.root = os.path.abspath(root)
        self._fsync = fsync
        self.file_mode = file_mode
        self.dir_mode = dir_mode
        self.min_free_bytes = 0  # set by check(); store() keeps to it

    # --- the folder itself ---
    def check(self, min_free_bytes=0):
        """Check the archive folder before anything is recorded: it exists or can be created,
        a probe file can really be written, fsync'ed and removed, and more than
        ``min_free_bytes`` are free (also enforced by every later ``store``).

        Returns the free bytes; raises ArchiveError (one line naming archive.root and the
        fix)."""
        if isinstance(min_free_bytes, bool) or not isinstance(min_free_bytes, (int, float)):
            raise FieldError("min_free_bytes %r: must be a number of bytes" % (min_free_bytes,))
        if os.path.exists(self.root) and not os.path.isdir(self.root):
            raise ArchiveError(
                "archive.root %s: exists but is not a folder; set archive.root in "
                "config/rascal.yaml to a folder" % self.root
            )
        try:
            make_dirs(self.root, self.dir_mode)
        except OSError as e:
            raise ArchiveError(
                "archive.root %s: does not exist and cannot be created (%s); create it "
                "writable by %s, or set archive.root in config/rascal.yaml"
                % (self.root, e.strerror, _user())
            ) from None
        try:
            fd, probe = tempfile.mkstemp(prefix=_PROBE_PREFIX, suffix=".tmp", dir=self.root)
            try:
                with os.fdopen(fd, "wb") as f:
                    f.write(b"rascal archive probe\n")
                    f.flush()
                    os.fsync(f.fileno())
            finally:
                os.unlink(probe)
        except OSError as e:
            raise ArchiveError(
                "archive.root %s: not writable (%s); make it writable by %s (chown/chmod, "
                "or remount read-write), or set archive.root in config/rascal.yaml"
                % (self.root, e.strerror, _user())
            ) from None
        self.min_free_bytes = min_free_bytes
        return self._check_space()

    def free_bytes(self):
        st = os.statvfs(self.root)
        return st.f_bavail * st.f_frsize

    def _check_space(self):
        try:
            free = self.free_bytes()
        except OSError as e:
            raise ArchiveError(
                "archive.root %s: cannot be read (%s); check that the disk is mounted"
                % (self.root, e.strerror)
            ) from None
        if free < self.min_free_bytes:
            raise ArchiveError(
                "archive.root %s: %d MB free, below archive.min_free_mb (%d MB); free some "
                "space or move archive.root to a larger disk"
                % (self.root, free // _MB, -(-self.min_free_bytes // _MB))
            )
        return free

    # --- names ---
    @staticmethod
    def relpath(context_id, seq, owner=None):
        """Where a sherd's image lives, relative to the root: ``<folder>/<seq>-<tag>.png``
        with the catalogue's identity ``owner``, ``<folder>/<seq>.png`` without (``<folder>``:
        ``context_folder(context_id)``)."""
        folder = context_folder(context_id)
        if isinstance(seq, bool) or not isinstance(seq, int) or seq < 1:
            raise FieldError(
                "seq %r: must be the sherd's sequence number (an integer >= 1)" % (seq,)
            )
        if owner is None:
            return "%s/%d.png" % (folder, seq)
        return "%s/%d-%s.png" % (folder, seq, owner_tag(owner))

    def path(self, relpath):
        """Absolute path of an archived file; refuses paths that leave the archive."""
        full = os.path.realpath(os.path.join(self.root, relpath))
        if os.path.commonpath([full, os.path.realpath(self.root)]) != os.path.realpath(self.root):
            raise FieldError(
                "image_path '%s': points outside the archive %s" % (relpath, self.root)
            )
        return full

    # --- writing ---
    def store(self, context_id, seq, image, record=None, owner=None):
        """Write ``image`` (PNG bytes, or the path of a PNG file) and its JSON sidecar, named
        for the catalogue ``owner`` (its identity; see ``relpath``).

        Returns ``(relpath, sha256)``; raises FieldError (nothing left behind) for a bad
        context, sequence number or image, ArchiveError when the folder cannot take it."""
        rel = self.relpath(context_id, seq, owner)
        final = self.path(rel)
        self._makedirs(os.path.dirname(final))
        if owner is not None:
            self._refuse_foreign(rel, owner)
        self._check_space()
        sha = self._write_atomic(final, self._chunks(image), check_png=True)
        self.write_sidecar(
            context_id, seq, dict(record or {}, image_path=rel, image_sha256=sha), owner=owner
        )
        return rel, sha

    def write_sidecar(self, context_id, seq, record, owner=None):
        """(Re)write the sidecar of ``record`` (the sherd's row) atomically, beside the image
        the record names (``image_path``), else beside ``relpath(context_id, seq, owner)``."""
        image_rel = record.get("image_path") or self.relpath(context_id, seq, owner)
        final = self.path(sidecar_relpath(image_rel))
        self._makedirs(os.path.dirname(final))
        side = sidecar_content(record, owner)
        side["written_at"] = datetime.datetime.now(datetime.timezone.utc).isoformat()
        blob = json.dumps(side, sort_keys=True, indent=1).encode() + b"\n"
        self._write_atomic(final, iter([blob]))
        return final

    # --- reading ---
    def sha256(self, relpath):
        """SHA-256 of an archived file, or None if it is missing."""
        h = hashlib.sha256()
        try:
            with open(self.path(relpath), "rb") as f:
                for block in iter(lambda: f.read(_CHUNK), b""):
                    h.update(block)
        except FileNotFoundError:
            return None
        except OSError as e:
            raise ArchiveError(
                "archive.root %s: cannot read %s (%s); check the disk and the folder's "
                "permissions" % (self.root, relpath, e.strerror)
            ) from None
        return h.hexdigest()

    def verify(self, relpath, sha256):
        """True if the archived file exists and has this SHA-256."""
        return self.sha256(relpath) == sha256

    def read_sidecar(self, image_relpath):
        """The sidecar of an image as a dict; None if it is missing; ValueError if it is not
        a JSON object."""
        try:
            with open(self.path(sidecar_relpath(image_relpath)), "rb") as f:
                data = json.loads(f.read().decode("utf-8"))
        except FileNotFoundError:
            return None
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
            raise ValueError(str(e)) from None
        if not isinstance(data, dict):
            raise ValueError("not a JSON object")
        return data

    def context_dirs(self):
        """The context IDs whose folders are under the root (a cut long name: the ID its
        sidecars name)."""
        try:
            names = sorted(os.listdir(self.root))
        except FileNotFoundError:
            return []
        out = []
        for name in names:
            if not os.path.isdir(os.path.join(self.root, name)):
                continue
            context = context_from_folder(name) or self._context_of_cut_folder(name)
            if context is not None:
                out.append(context)
        return out

    def _context_of_cut_folder(self, name):
        try:
            sidecars = sorted(os.listdir(os.path.join(self.root, name)))
        except OSError:
            return None
        for n in sidecars:
            if ARCHIVE_NAME.match(n) and n.endswith(".json"):
                try:
                    side = self.read_sidecar("%s/%s" % (name, n[:-5] + ".png"))
                    context = validate_context_id((side or {}).get("context_id"))
                except (ValueError, ContextIdError):
                    continue
                if context_folder(context) == name:
                    return context
        return None

    def files(self, context_id):
        """Names of the plain files directly in a context's folder (subfolders, such as the
        report, are not the archive's)."""
        folder = os.path.join(self.root, context_folder(context_id))
        try:
            names = sorted(os.listdir(folder))
        except FileNotFoundError:
            return []
        return [n for n in names if os.path.isfile(os.path.join(folder, n))]

    def temp_files(self, context_id=None, older_than=0.0, now=None):
        """Relative paths of temporary files an interrupted write left behind (in the
        context's folder, or in every context folder, and the root's probe files), last
        modified more than ``older_than`` seconds before ``now``: younger ones may belong to
        a write in progress."""
        contexts = [context_id] if context_id is not None else self.context_dirs()
        found = [
            "%s/%s" % (context_folder(c), n)
            for c in contexts
            for n in self.files(c)
            if TEMP_NAME.match(n)
        ]
        try:
            found += [
                n
                for n in sorted(os.listdir(self.root))
                if n.startswith(_PROBE_PREFIX) and TEMP_NAME.match(n)
            ]
        except FileNotFoundError:
            pass
        if older_than > 0:
            now = time.time() if now is None else now
            found = [r for r in found if self._age(r, now) > older_than]
        return found

    def _age(self, relpath, now):
        try:
            return now - os.stat(os.path.join(self.root, relpath)).st_mtime
        except FileNotFoundError:
            return -1.0

    def remove(self, relpath):
        """Remove one file of the archive (a temporary file left by a crash)."""
        try:
            os.unlink(self.path(relpath))
        except FileNotFoundError:
            pass
        except OSError as e:
            raise ArchiveError(
                "archive.root %s: cannot remove %s (%s); make the folder writable by %s"
                % (self.root, relpath, e.strerror, _user())
            ) from None

    # --- internals ---
    def _refuse_foreign(self, rel, owner):
        """Never replace a file that another catalogue's sidecar claims."""
        try:
            side = self.read_sidecar(rel)
        except ValueError:
            side = None
        theirs = (side or {}).get("catalogue_id")
        if theirs and str(theirs) != str(owner):
            raise ArchiveError(
                "archive.root %s: %s belongs to catalogue %s, not this one (%s); give each "
                "catalogue its own archive.root" % (self.root, rel, theirs, owner)
            )

    def _makedirs(self, directory):
        try:
            make_dirs(directory, self.dir_mode)
        except OSError as e:
            raise self._write_error(directory, e) from None

    def _write_error(self, what, e):
        why = e.strerror or str(e)
        hint = (
            "free some space or move archive.root to a larger disk"
            if e.errno in (errno.ENOSPC, errno.EDQUOT)
            else "make it writable by %s and check the disk" % _user()
        )
        return ArchiveError(
            "archive.root %s: cannot write %s (%s); %s, then run again to resume"
            % (self.root, os.path.relpath(what, self.root), why, hint)
        )

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
        try:
            fd, tmp = tempfile.mkstemp(
                prefix="." + os.path.basename(final) + ".", suffix=".tmp", dir=directory
            )
        except OSError as e:
            raise self._write_error(final, e) from None
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
                os.fchmod(f.fileno(), self.file_mode)  # mkstemp made it 0600
                if self._fsync:
                    os.fsync(f.fileno())
            os.replace(tmp, final)
            if self._fsync:
                dfd = os.open(directory, os.O_RDONLY)
                try:
                    os.fsync(dfd)
                finally:
                    os.close(dfd)
        except BaseException as e:
            try:
                os.unlink(tmp)
            except OSError:
                pass
            if isinstance(e, OSError):
                raise self._write_error(final, e) from None
            raise
        return h.hexdigest()


def make_dirs(directory, mode=DIR_MODE):
    """``os.makedirs`` whose new folders get exactly ``mode`` (not mode & ~umask); folders that
    already exist keep theirs."""
    directory = os.path.abspath(directory)
    missing = []
    while not os.path.isdir(directory):
        missing.append(directory)
        parent = os.path.dirname(directory)
        if parent == directory:
            break
        directory = parent
    for d in reversed(missing):
        try:
            os.mkdir(d, mode)
        except FileExistsError:
            if not os.path.isdir(d):
                raise
            continue
        os.chmod(d, mode)
