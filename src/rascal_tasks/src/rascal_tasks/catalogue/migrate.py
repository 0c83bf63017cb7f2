"""Versioned SQL migrations, shipped in ``migrations/NNNN_name.sql`` inside this package.

``migrate(conn)`` applies the missing ones in order, each in its own transaction together
with its row in ``schema_migrations``; a transaction-level advisory lock makes concurrent
migrators wait for each other. Re-running is a no-op. A migration that was edited after it
was applied is refused (its SHA-256 no longer matches).
"""

import hashlib
import logging
import os
import re

from .errors import MigrationError

__all__ = ["MIGRATIONS_DIR", "Migration", "available", "migrate", "status"]

MIGRATIONS_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "migrations")
_NAME = re.compile(r"^(\d{4})_([a-z0-9_]+)\.sql$")
_LOCK_KEY = 0x7261_7363  # 'rasc': pg_advisory_xact_lock key shared by every migrator

_BOOTSTRAP = """
CREATE TABLE IF NOT EXISTS schema_migrations (
    version     integer PRIMARY KEY,
    name        text NOT NULL,
    sha256      text NOT NULL,
    applied_at  timestamptz NOT NULL DEFAULT now()
)"""


class Migration:
    """One migration file: its version, name, SQL text and the SHA-256 of that text."""

    def __init__(self, version, name, path):
        self.version = version
        self.name = name
        self.path = path
        with open(path, "rb") as f:
            raw = f.read()
        self.sql = raw.decode("utf-8")
        self.sha256 = hashlib.sha256(raw).hexdigest()

    @property
    def filename(self):
        return os.path.basename(self.path)


def available(directory=MIGRATIONS_DIR):
    """The migrations shipped with the package, by version."""
    found = []
    for fn in sorted(os.listdir(directory)):
        if not fn.endswith(".sql"):
            continue
        m = _NAME.match(fn)
        if not m:
            raise MigrationError(
                "migration file '%s': name must be NNNN_name.sql "
                "(four digits, lower-case name)" % fn
            )
        found.append(Migration(int(m.group(1)), m.group(2), os.path.join(directory, fn)))
    versions = [m.version for m in found]
    if len(set(versions)) != len(versions):
        raise MigrationError("migrations in %s: two files share a version number" % directory)
    return found


def _applied(cur):
    cur.execute("SELECT to_regclass('schema_migrations') IS NOT NULL")
    if not cur.fetchone()[0]:
        return {}
    cur.execute("SELECT version, name, sha256, applied_at FROM schema_migrations ORDER BY version")
    return {row[0]: row for row in cur.fetchall()}


def migrate(conn, logger=None, directory=MIGRATIONS_DIR):
    """Apply every missing migration; return the list of versions applied now."""
    log = logger or logging.getLogger("rascal.catalogue")
    migrations = available(directory)
    done = []
    with conn:
        with conn.cursor() as cur:
            cur.execute("SELECT pg_advisory_xact_lock(%s)", (_LOCK_KEY,))
            cur.execute(_BOOTSTRAP)
    for mig in migrations:
        with conn:
            with conn.cursor() as cur:
                cur.execute("SELECT pg_advisory_xact_lock(%s)", (_LOCK_KEY,))
                applied = _applied(cur)
                if mig.version in applied:
                    if applied[mig.version][2] != mig.sha256:
                        raise MigrationError(
                            "migration %s was changed after it was applied (sha256 %s in the "
                            "database, %s on disk); restore it and add a new migration instead"
                            % (mig.filename, applied[mig.version][2][:12], mig.sha256[:12])
                        )
                    continue
                cur.execute(mig.sql)
                cur.execute(
                    "INSERT INTO schema_migrations (version, name, sha256) " "VALUES (%s, %s, %s)",
                    (mig.version, mig.name, mig.sha256),
                )
                log.info("applied migration %s" % mig.filename)
                done.append(mig.version)
    return done


def status(conn, directory=MIGRATIONS_DIR):
    """``[(version, name, applied_at or None, state)]`` for every known migration, where
    state is 'applied', 'pending', 'changed' (edited after applying) or 'unknown' (in the
    database but not shipped with this software)."""
    migrations = {m.version: m for m in available(directory)}
    with conn:
        with conn.cursor() as cur:
            applied = _applied(cur)
    rows = []
    for version in sorted(set(migrations) | set(applied)):
        mig, row = migrations.get(version), applied.get(version)
        if row is None:
            rows.append((version, mig.name, None, "pending"))
        elif mig is None:
            rows.append((version, row[1], row[3], "unknown"))
        else:
            rows.append(
                (version, mig.name, row[3], "applied" if row[2] == mig.sha256 else "changed")
            )
    return rows
