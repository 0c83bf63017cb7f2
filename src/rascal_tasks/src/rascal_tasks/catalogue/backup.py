"""Backup and restore of a catalogue with its image archive, as one file (``rascal backup`` /
``rascal restore``).

The backup is an uncompressed tar (the dump and the PNGs are compressed already) holding:

- ``catalogue.dump``: ``pg_dump -Fc`` of the whole database (schema, migrations, sherds,
  events, the audit trail, the catalogue's identity);
- ``archive/<image_path>``: every image a row names and its JSON sidecar;
- ``manifest.json`` (last): format and version, when and from where, the migrations, counts,
  and every other member's size and SHA-256, computed from the bytes written into the tar.

pg_dump runs on the snapshot that the image list was read in (``pg_export_snapshot``), so
the dump and the files agree even while a rig records. An image that is missing or whose
SHA-256 differs from its row is left out and named (``problems``); the backup is still written.

Restore checks the manifest and every member's size and SHA-256 before anything is changed,
refuses a database that holds any table (or type or function) and an archive folder that
holds anything unless ``force``, then runs ``pg_restore`` in one transaction and moves the
checked files into place. The restored catalogue keeps its identity (it is the same catalogue
brought back, so its files keep their names and ``rascal verify`` passes); give it its own
archive folder when the original still runs.

pg_dump and pg_restore are those of the server's major version (Debian's
/usr/lib/postgresql/<major>/bin, else the ones on PATH if at least as new). The password never
reaches a command line: it goes to the tool in PGPASSWORD, the rest of the DSN as a connection
string. Every wait has a deadline (``timeout``, pg_dump's lock wait). No ROS here.
"""

import datetime
import hashlib
import io
import json
import os
import re
import shutil
import subprocess
import tarfile
import tempfile

import psycopg2
import psycopg2.extensions

from .errors import CatalogueError, FieldError

__all__ = [
    "BACKUP_FORMAT",
    "BackupError",
    "create_backup",
    "read_manifest",
    "restore_backup",
    "find_pg_tool",
    "tool_connection",
]

BACKUP_FORMAT = "rascal-backup"
BACKUP_VERSION = 1
DUMP_NAME = "catalogue.dump"
MANIFEST_NAME = "manifest.json"
ARCHIVE_PREFIX = "archive/"
DEFAULT_TIMEOUT = 3600.0  # s: pg_dump / pg_restore of a catalogue takes seconds
_LOCK_WAIT = "30s"  # pg_dump waits this long for a table lock held by a stuck writer
_CHUNK = 1 << 20


class BackupError(CatalogueError):
    """pg_dump or pg_restore failed, or a file could not be written: one line."""


def _first_line(text):
    lines = [ln for ln in str(text).strip().splitlines() if ln.strip()]
    return lines[0] if lines else "no message"


def _mask(dsn):
    dsn = re.sub(r"(://[^:/@]*:)[^@]*@", r"\1***@", dsn)
    return re.sub(r"(password\s*=\s*)\S+", r"\1***", dsn)


# --- the tools ---
def tool_connection(dsn):
    """``(connection string without the password, environment)`` for a libpq tool: the
    password goes into PGPASSWORD, never onto a command line (where ``ps`` shows it)."""
    try:
        params = psycopg2.extensions.parse_dsn(dsn)
    except psycopg2.ProgrammingError as e:
        raise FieldError("DSN %s: not a valid DSN (%s)" % (_mask(dsn), _first_line(e))) from None
    env = dict(os.environ)
    password = params.pop("password", None)
    if password is not None:
        env["PGPASSWORD"] = password
    return psycopg2.extensions.make_dsn(**params), env


def _major(version_text):
    """15 of 'pg_dump (PostgreSQL) 15.20 (Debian 15.20-0+deb12u1)'."""
    m = re.search(r"\(PostgreSQL\)\s+(\d+)", version_text)
    return int(m.group(1)) if m else None


def find_pg_tool(name, server_major):
    """The path of pg_dump or pg_restore for a server of ``server_major``: Debian's
    /usr/lib/postgresql/<major>/bin first, else the one on PATH if its major version is at
    least the server's. BackupError naming the package otherwise."""
    candidates = ["/usr/lib/postgresql/%d/bin/%s" % (server_major, name), shutil.which(name)]
    tried = []
    for path in candidates:
        if not path or not os.access(path, os.X_OK):
            continue
        try:
            out = subprocess.run(
                [path, "--version"], capture_output=True, text=True, timeout=30, check=True
            ).stdout
        except (OSError, subprocess.SubprocessError):
            continue
        major = _major(out)
        tried.append("%s (%s)" % (path, out.strip()))
        if major is not None and major >= server_major:
            return path
    raise BackupError(
        "%s for PostgreSQL %d not found (%s); install postgresql-client-%d"
        % (
            name,
            server_major,
            "; ".join(tried) or "none in /usr/lib/postgresql or on PATH",
            server_major,
        )
    )


def _run_tool(argv, env, what, timeout):
    try:
        r = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        raise BackupError("%s: not finished after %.0f s; stopped" % (what, timeout)) from None
    except OSError as e:
        raise BackupError("%s: cannot start %s (%s)" % (what, argv[0], e.strerror)) from None
    if r.returncode != 0:
        raise BackupError(
            "%s failed (exit %d): %s" % (what, r.returncode, _first_line(r.stderr or r.stdout))
        )
    return r


def _connect(dsn, connect_timeout):
    try:
        return psycopg2.connect(
            dsn, connect_timeout=max(1, int(round(connect_timeout))), application_name="rascal-cli"
        )
    except psycopg2.OperationalError as e:
        raise CatalogueError(
            "database %s: cannot connect (%s)" % (_mask(dsn), _first_line(e))
        ) from None


# --- writing the backup ---
class _HashingReader:
    """A file read through once, its SHA-256 taken on the way into the tar."""

    def __init__(self, f):
        self._f = f
        self.sha = hashlib.sha256()

    def read(self, n=-1):
        block = self._f.read(n)
        self.sha.update(block)
        return block


def _add_file(tar, name, path, files):
    with open(path, "rb") as f:
        st = os.fstat(f.fileno())
        info = tarfile.TarInfo(name)
        info.size = st.st_size
        info.mtime = int(st.st_mtime)
        info.mode = 0o644
        reader = _HashingReader(f)
        tar.addfile(info, reader)
    files.append({"name": name, "size": info.size, "sha256": reader.sha.hexdigest()})


def create_backup(dsn, output, archive_root, connect_timeout=5.0, timeout=DEFAULT_TIMEOUT):
    """Write the backup of the catalogue at ``dsn`` and of its images under ``archive_root``
    to ``output`` (a new file, written to a temporary name and renamed when complete).

    Returns the manifest with ``problems`` (one line per image left out). Raises FieldError
    when ``output`` exists, BackupError / CatalogueError (one line) on a fault."""
    output = os.path.abspath(output)
    if os.path.exists(output):
        raise FieldError(
            "--output %s: exists; a backup never replaces another, choose a new name" % output
        )
    directory = os.path.dirname(output)
    if not os.path.isdir(directory):
        raise FieldError("--output %s: folder %s does not exist" % (output, directory))
    from .archive import ImageArchive

    archive = ImageArchive(archive_root)
    conn = _connect(dsn, connect_timeout)
    try:
        conn.set_session(
            isolation_level=psycopg2.extensions.ISOLATION_LEVEL_REPEATABLE_READ, readonly=True
        )
        with conn.cursor() as cur:
            cur.execute("SELECT pg_export_snapshot(), current_setting('server_version_num')::int")
            snapshot, version_num = cur.fetchone()
            manifest = _describe(cur, dsn, version_num)
            cur.execute(
                "SELECT context_id || '-' || seq, image_path, image_sha256 FROM sherds "
                "WHERE image_path IS NOT NULL ORDER BY context_id, seq"
            )
            images = cur.fetchall()
            server_major = version_num // 10000
            pg_dump = find_pg_tool("pg_dump", server_major)
            conninfo, env = tool_connection(dsn)
            with tempfile.TemporaryDirectory(prefix=".rascal-backup-", dir=directory) as tmp:
                dump = os.path.join(tmp, DUMP_NAME)
                _run_tool(
                    [
                        pg_dump,
                        "--format=custom",
                        "--snapshot=" + snapshot,
                        "--lock-wait-timeout=" + _LOCK_WAIT,
                        "--file=" + dump,
                        "--dbname=" + conninfo,
                    ],
                    env,
                    "pg_dump of %s" % _mask(dsn),
                    timeout,
                )
                conn.rollback()  # the snapshot is no longer needed
                manifest["pg_dump"] = _run_tool([pg_dump, "--version"], env, "pg_dump", 30).stdout
                manifest["pg_dump"] = manifest["pg_dump"].strip()
                _write_tar(output, dump, archive, images, manifest)
    finally:
        conn.close()
    return manifest


def _describe(cur, dsn, version_num):
    cur.execute("SHOW server_version")
    server_version = cur.fetchone()[0]
    cur.execute("SELECT to_regclass('schema_migrations') IS NOT NULL")
    migrations = []
    if cur.fetchone()[0]:
        cur.execute("SELECT version, name, sha256 FROM schema_migrations ORDER BY version")
        migrations = [{"version": v, "name": n, "sha256": s} for v, n, s in cur.fetchall()]
    if not migrations:
        raise FieldError(
            "database %s: holds no RASCAL catalogue (no migrations applied); check --dsn"
            % _mask(dsn)
        )
    counts = {}
    for table in ("contexts", "sherds", "events", "sherd_edits"):
        cur.execute("SELECT to_regclass(%s) IS NOT NULL", (table,))
        if cur.fetchone()[0]:
            cur.execute("SELECT count(*) FROM " + table)  # table names: the constants above
            counts[table] = cur.fetchone()[0]
    identity = None
    cur.execute("SELECT to_regclass('catalogue_identity') IS NOT NULL")
    if cur.fetchone()[0]:
        cur.execute("SELECT catalogue_id::text FROM catalogue_identity")
        row = cur.fetchone()
        identity = row[0] if row else None
    return {
        "format": BACKUP_FORMAT,
        "version": BACKUP_VERSION,
        "created_at": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "database": _mask(dsn),
        "server_version": server_version,
        "server_version_num": version_num,
        "catalogue_id": identity,
        "migrations": migrations,
        "counts": counts,
    }


def _write_tar(output, dump, archive, images, manifest):
    directory = os.path.dirname(output)
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(output) + ".", dir=directory)
    files, problems = [], []
    try:
        with os.fdopen(fd, "wb") as raw:
            with tarfile.open(fileobj=raw, mode="w", format=tarfile.PAX_FORMAT) as tar:
                _add_file(tar, DUMP_NAME, dump, files)
                for find_id, rel, sha in images:
                    try:
                        path = archive.path(rel)
                    except FieldError as e:
                        problems.append("%s: %s; left out" % (find_id, e))
                        continue
                    if not os.path.isfile(path):
                        problems.append(
                            "%s: image %s is missing from the archive %s; left out"
                            % (find_id, rel, archive.root)
                        )
                    else:
                        _add_file(tar, ARCHIVE_PREFIX + rel, path, files)
                        if files[-1]["sha256"] != sha:
                            problems.append(
                                "%s: image %s has SHA-256 %s, the catalogue says %s; backed up "
                                "as it is (`rascal verify` names it)"
                                % (find_id, rel, files[-1]["sha256"][:12], sha[:12])
                            )
                    side = os.path.splitext(path)[0] + ".json"
                    if os.path.isfile(side):
                        _add_file(
                            tar, ARCHIVE_PREFIX + os.path.splitext(rel)[0] + ".json", side, files
                        )
                manifest["files"] = files
                manifest["problems"] = problems
                blob = json.dumps(manifest, indent=1, sort_keys=True).encode() + b"\n"
                info = tarfile.TarInfo(MANIFEST_NAME)
                info.size = len(blob)
                info.mtime = int(datetime.datetime.now().timestamp())
                info.mode = 0o644
                tar.addfile(info, io.BytesIO(blob))
            raw.flush()
            os.fsync(raw.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, output)
        _fsync_dir(directory)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return manifest


def _fsync_dir(directory):
    fd = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


# --- reading and restoring ---
def _safe_member(name):
    """Whether a member name stays inside the folder it is extracted to."""
    if not name or "\x00" in name or "\\" in name or name.startswith("/"):
        return False
    return all(part not in ("", ".", "..") for part in name.split("/"))


def read_manifest(path):
    """``(tar, manifest)`` of a backup file, the manifest and the member list checked against
    each other (sizes and names; SHA-256 is checked on extraction). FieldError (one line) for
    a file that is not a RASCAL backup or does not match its manifest."""
    try:
        tar = tarfile.open(path, mode="r:")
    except FileNotFoundError:
        raise FieldError("backup %s: no such file" % path) from None
    except (tarfile.TarError, OSError) as e:
        raise FieldError("backup %s: not a RASCAL backup (%s)" % (path, e)) from None
    try:
        members = {m.name: m for m in tar.getmembers()}
        if MANIFEST_NAME not in members:
            raise FieldError("backup %s: no %s; not a RASCAL backup" % (path, MANIFEST_NAME))
        manifest = json.loads(tar.extractfile(members[MANIFEST_NAME]).read().decode("utf-8"))
        if not isinstance(manifest, dict) or manifest.get("format") != BACKUP_FORMAT:
            raise FieldError("backup %s: %s is not a RASCAL backup's" % (path, MANIFEST_NAME))
        if manifest.get("version") != BACKUP_VERSION:
            raise FieldError(
                "backup %s: format version %r, this software reads %d; restore it with the "
                "RASCAL version that wrote it" % (path, manifest.get("version"), BACKUP_VERSION)
            )
        listed = {}
        for f in manifest.get("files") or []:
            name = f.get("name") if isinstance(f, dict) else None
            if (
                not isinstance(name, str)
                or not _safe_member(name)
                or not (name == DUMP_NAME or name.startswith(ARCHIVE_PREFIX))
            ):
                raise FieldError("backup %s: the manifest names %r; refused" % (path, name))
            listed[name] = f
        if DUMP_NAME not in listed:
            raise FieldError("backup %s: the manifest lists no %s" % (path, DUMP_NAME))
        for name, member in members.items():
            if name == MANIFEST_NAME:
                continue
            if name not in listed:
                raise FieldError(
                    "backup %s: %s is not in the manifest; the backup was changed" % (path, name)
                )
            if not member.isfile():
                raise FieldError("backup %s: %s is not a plain file; refused" % (path, name))
        for name, f in listed.items():
            if name not in members:
                raise FieldError("backup %s: %s is missing; the backup is damaged" % (path, name))
            if members[name].size != f.get("size"):
                raise FieldError(
                    "backup %s: %s has %d bytes, the manifest says %r; the backup is damaged"
                    % (path, name, members[name].size, f.get("size"))
                )
    except FieldError:
        tar.close()
        raise
    except (tarfile.TarError, OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        tar.close()
        raise FieldError("backup %s: unreadable (%s)" % (path, e)) from None
    manifest["_members"] = listed
    return tar, manifest


def _extract_checked(tar, path, name, entry, dest, file_mode):
    """Copy one member to ``dest``, checking its SHA-256 against the manifest."""
    h = hashlib.sha256()
    os.makedirs(os.path.dirname(dest), exist_ok=True)
    with tar.extractfile(name) as src, open(dest, "wb") as out:
        for block in iter(lambda: src.read(_CHUNK), b""):
            h.update(block)
            out.write(block)
        out.flush()
        os.fchmod(out.fileno(), file_mode)
        os.fsync(out.fileno())
    if h.hexdigest() != entry.get("sha256"):
        raise FieldError(
            "backup %s: %s has SHA-256 %s, the manifest says %s; the backup is damaged, "
            "nothing was restored" % (path, name, h.hexdigest()[:12], str(entry.get("sha256"))[:12])
        )


def _database_contents(cur):
    """``(tables, other objects, sherd count or None)`` of the user schemas."""
    user = (
        "n.nspname NOT IN ('pg_catalog', 'information_schema') "
        "AND n.nspname NOT LIKE 'pg\\_toast%%' AND n.nspname NOT LIKE 'pg\\_temp%%'"
    )
    cur.execute(
        "SELECT count(*) FROM pg_class c JOIN pg_namespace n ON n.oid = c.relnamespace "
        "WHERE c.relkind IN ('r', 'p', 'v', 'm', 'f') AND " + user
    )
    tables = cur.fetchone()[0]
    cur.execute(
        "SELECT (SELECT count(*) FROM pg_type t JOIN pg_namespace n ON n.oid = t.typnamespace "
        "WHERE t.typtype IN ('d', 'e') AND " + user + ") + "
        "(SELECT count(*) FROM pg_proc p JOIN pg_namespace n ON n.oid = p.pronamespace "
        "WHERE " + user + ")"
    )
    others = cur.fetchone()[0]
    sherds = None
    cur.execute("SELECT to_regclass('sherds') IS NOT NULL")
    if cur.fetchone()[0]:
        cur.execute("SELECT count(*) FROM sherds")
        sherds = cur.fetchone()[0]
    return tables, others, sherds


def restore_backup(
    path,
    dsn,
    archive_root,
    force=False,
    connect_timeout=5.0,
    timeout=DEFAULT_TIMEOUT,
    file_mode=0o644,
    dir_mode=0o755,
):
    """Restore the backup at ``path`` into the database ``dsn`` and the folder
    ``archive_root``. Both must be empty unless ``force`` (then the catalogue's objects are
    dropped and restored, and files of the same name replaced; other files stay). Files get
    ``file_mode``, the folders made ``dir_mode`` (archive.file_mode, archive.dir_mode).

    Returns the manifest. Raises FieldError (nothing changed) for a damaged backup or a
    non-empty target, BackupError / CatalogueError (one line) on a fault."""
    path = os.path.abspath(path)
    tar, manifest = read_manifest(path)
    members = manifest.pop("_members")
    archive_root = os.path.abspath(archive_root)
    try:
        conn = _connect(dsn, connect_timeout)
        try:
            conn.autocommit = True
            with conn.cursor() as cur:
                cur.execute("SELECT current_setting('server_version_num')::int")
                server_major = cur.fetchone()[0] // 10000
                tables, others, sherds = _database_contents(cur)
            if (tables or others) and not force:
                raise FieldError(
                    "database %s is not empty (%d tables%s%s); restore into a new empty "
                    "database (createdb) or pass --force to replace the catalogue in it"
                    % (
                        _mask(dsn),
                        tables,
                        ", %d types and functions" % others if others else "",
                        ", among them sherds with %d rows" % sherds if sherds is not None else "",
                    )
                )
            if os.path.isdir(archive_root) and os.listdir(archive_root) and not force:
                raise FieldError(
                    "--archive %s is not empty; restore into a new or empty folder, or pass "
                    "--force to add the backup's files to it" % archive_root
                )
            if os.path.exists(archive_root) and not os.path.isdir(archive_root):
                raise FieldError("--archive %s: exists but is not a folder" % archive_root)
            pg_restore = find_pg_tool("pg_restore", server_major)
            made_root = not os.path.exists(archive_root)
            os.makedirs(archive_root, exist_ok=True)
            if made_root:
                os.chmod(archive_root, dir_mode)
            staging = tempfile.mkdtemp(prefix=".rascal-restore-", dir=archive_root)
            restored_all = False
            try:
                for name, entry in members.items():
                    _extract_checked(tar, path, name, entry, os.path.join(staging, name), file_mode)
                conninfo, env = tool_connection(dsn)
                argv = [
                    pg_restore,
                    "--single-transaction",
                    "--exit-on-error",
                    "--no-owner",
                    "--no-privileges",
                ]
                if force:
                    argv += ["--clean", "--if-exists"]
                _run_tool(
                    argv + ["--dbname=" + conninfo, os.path.join(staging, DUMP_NAME)],
                    env,
                    "pg_restore into %s" % _mask(dsn),
                    timeout,
                )
                with conn.cursor() as cur:
                    _keep_identity(cur)
                    cur.execute("SELECT count(*) FROM sherds")
                    restored = cur.fetchone()[0]
                expected = (manifest.get("counts") or {}).get("sherds")
                if expected is not None and restored != expected:
                    raise BackupError(
                        "restored %d sherds, the backup holds %d; the database changed during "
                        "the restore" % (restored, expected)
                    )
                _move_into(staging, archive_root, dir_mode)
                restored_all = True
            finally:
                shutil.rmtree(staging, ignore_errors=True)
                if made_root and not restored_all and not os.listdir(archive_root):
                    os.rmdir(archive_root)  # refused: leave no trace, not even the folder
        finally:
            conn.close()
    finally:
        tar.close()
    return manifest


def _keep_identity(cur):
    """The restored catalogue is the one backed up: it keeps its catalogue_id, its record of
    where it lives made to name this database (``Catalogue.identity`` fills in the server)."""
    cur.execute("SELECT to_regclass('catalogue_identity') IS NOT NULL")
    if cur.fetchone()[0]:
        cur.execute(
            "UPDATE catalogue_identity SET database_name = current_database(), "
            "system_identifier = NULL"
        )


def _move_into(staging, archive_root, dir_mode):
    """Move the checked files of ``staging/archive`` into the archive (renames on one disk)."""
    top = os.path.join(staging, ARCHIVE_PREFIX.rstrip("/"))
    for folder, _, names in os.walk(top):
        rel = os.path.relpath(folder, top)
        target = archive_root if rel == "." else os.path.join(archive_root, rel)
        if not os.path.isdir(target):
            os.makedirs(target)
            os.chmod(target, dir_mode)  # not the umask's
        for name in names:
            os.replace(os.path.join(folder, name), os.path.join(target, name))
        _fsync_dir(target)
