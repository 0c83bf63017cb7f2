"""Throw-away catalogue databases for tests and benchmarks: made on a PostgreSQL server through
an admin connection under a generated name, dropped afterwards even while a client (a node
killed mid-commit, a test's leftover connection) is still connected.

Only client backends are terminated before the drop: an autovacuum worker may be working on the
database (it belongs to the superuser, so terminating it fails for the test role), and DROP
DATABASE stops it itself.
"""

import contextlib
import uuid


def dsn_of(admin_dsn: str, name: str) -> str:
    """The DSN of database `name` on the server and with the role of `admin_dsn`."""
    return admin_dsn.rsplit("/", 1)[0] + "/" + name


def create_database(admin, prefix: str = "rascal_test_", template: str = "") -> str:
    """A new database named `prefix` + 12 hex digits (a copy of `template` if given, itself a
    generated name); its name. `admin`: an autocommit psycopg2 connection."""
    name = prefix + uuid.uuid4().hex[:12]
    with admin.cursor() as cur:  # generated names only, never user input
        cur.execute("CREATE DATABASE " + name + (" TEMPLATE " + template if template else ""))
    return name


def drop_database(admin, name: str) -> None:
    """Ends the client connections to database `name` and drops it (nothing if it is gone)."""
    with admin.cursor() as cur:
        cur.execute(
            "SELECT pg_terminate_backend(pid) FROM pg_stat_activity WHERE datname = %s"
            " AND backend_type = 'client backend' AND pid <> pg_backend_pid()",
            (name,),
        )
        cur.execute("DROP DATABASE IF EXISTS " + name)


@contextlib.contextmanager
def scratch_database(admin_dsn: str, prefix: str = "rascal_test_"):
    """Yields the DSN of a new, empty database on the server of `admin_dsn`; drops it on the way
    out."""
    import psycopg2

    admin = psycopg2.connect(admin_dsn)
    admin.autocommit = True
    try:
        name = create_database(admin, prefix)
        try:
            yield dsn_of(admin_dsn, name)
        finally:
            drop_database(admin, name)
    finally:
        admin.close()
