"""A throw-away catalogue database for one benchmark batch (bench/throughput, bench/heap): made
on the server of RASCAL_TEST_PG_DSN (default: the local one `make test` sets up), dropped after,
with any connection still open to it. Imported by the bench scripts beside it."""

import contextlib
import os

import psycopg2
import psycopg2.extensions
import psycopg2.extras

from rascal_tasks.catalogue import scratch

ADMIN = os.environ.get("RASCAL_TEST_PG_DSN", "postgresql://rascal:rascal@127.0.0.1:5432/rascal")


@contextlib.contextmanager
def scratch_database():
    """Yields the DSN of a new, empty database; drops it on the way out. A server not reachable
    ends the bench with one line that says how to start it."""
    try:
        psycopg2.connect(ADMIN, connect_timeout=10).close()
    except psycopg2.OperationalError as e:
        where = psycopg2.extensions.parse_dsn(ADMIN)
        raise SystemExit(
            "bench: no catalogue server at %s:%s (RASCAL_TEST_PG_DSN): %s; start it with "
            "`pg_ctlcluster --skip-systemctl-redirect 15 main start` (or run `make test` once)"
            % (where.get("host", "localhost"), where.get("port", "5432"), str(e).splitlines()[0])
        ) from None
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
