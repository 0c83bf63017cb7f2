"""A throw-away catalogue database for one benchmark batch (bench/throughput, bench/heap): made
on the server of RASCAL_TEST_PG_DSN (default: the local one `make test` sets up), dropped after,
with any connection still open to it. Imported by the bench scripts beside it."""

import contextlib
import os
import uuid

import psycopg2
import psycopg2.extras

ADMIN = os.environ.get("RASCAL_TEST_PG_DSN", "postgresql://rascal:rascal@127.0.0.1:5432/rascal")


@contextlib.contextmanager
def scratch_database():
    """Yields the DSN of a new, empty database; drops it on the way out."""
    name = "rascal_bench_" + uuid.uuid4().hex[:8]
    admin = psycopg2.connect(ADMIN)
    admin.autocommit = True
    admin.cursor().execute("CREATE DATABASE " + name)
    try:
        yield ADMIN.rsplit("/", 1)[0] + "/" + name
    finally:
        with admin.cursor() as cur:
            cur.execute(
                "SELECT pg_terminate_backend(pid) FROM pg_stat_activity WHERE datname = %s"
                " AND backend_type = 'client backend'",
                (name,),
            )
            cur.execute("DROP DATABASE IF EXISTS " + name)
        admin.close()


def sherd_rows(dsn):
    """Every row of its sherds table, by number."""
    conn = psycopg2.connect(dsn)
    try:
        with conn.cursor(cursor_factory=psycopg2.extras.RealDictCursor) as cur:
            cur.execute("SELECT * FROM sherds ORDER BY seq")
            return cur.fetchall()
    finally:
        conn.close()
