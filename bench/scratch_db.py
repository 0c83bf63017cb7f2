"""A throw-away catalogue database for one benchmark batch (bench/throughput, bench/heap): made
on the server of RASCAL_TEST_PG_DSN (default: the local one `make test` sets up), dropped after,
with any connection still open to it. Imported by the bench scripts beside it."""

import contextlib
import os

import psycopg2
import psycopg2.extras

from rascal_tasks.catalogue import scratch

ADMIN = os.environ.get("RASCAL_TEST_PG_DSN", "postgresql://rascal:rascal@127.0.0.1:5432/rascal")


@contextlib.contextmanager
def scratch_database():
    """Yields the DSN of a new, empty database; drops it on the way out."""
    with scratch.scratch_database(ADMIN, "rascal_bench_") as dsn:
        yield dsn


def sherd_rows(dsn):
    """Every row of its sherds table, by number."""
    conn = psycopg2.connect(dsn)
    try:
        with conn.cursor(cursor_factory=psycopg2.extras.RealDictCursor) as cur:
            cur.execute("SELECT * FROM sherds ORDER BY seq")
            return cur.fetchall()
    finally:
        conn.close()
