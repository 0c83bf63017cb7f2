"""One `rascal run` per rig and per context.

- `RigLock`: an exclusive `flock` on a file named after the rig (`rig.name`) and the ROS master
  it runs on, in the temporary folder. The kernel drops it when the process ends, however it
  ends (SIGKILL included). The file holds who holds it (host, pid, start time, context), so a
  second run can name the first.
- `ContextLock`: a session-level PostgreSQL advisory lock on a hash of the context ID, held on
  the catalogue's connection for the run. PostgreSQL drops it when that connection ends (a
  killed run, a terminated backend); after a reconnect it is taken again with `acquire(conn)`.
  The holder's connection carries `application_name` "rascal run <pid>@<host> <rig>", which a
  second run reads from pg_stat_activity.

Both raise `Busy` with one line naming the other run. No ROS here: the master URI and the
psycopg2 connection are passed in.
"""

import datetime
import fcntl
import hashlib
import json
import os
import re
import socket
import struct
import tempfile

# application_name is at most 63 bytes (NAMEDATALEN - 1); PostgreSQL truncates longer ones.
_APP_NAME_MAX = 63


class Busy(Exception):
    """Another run holds the rig or the context; str() is one line naming it."""


def _now_text(ts: float = None) -> str:
    t = datetime.datetime.fromtimestamp(ts, datetime.timezone.utc) if ts else None
    t = t or datetime.datetime.now(datetime.timezone.utc)
    return t.strftime("%Y-%m-%d %H:%M:%S UTC")


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)[:64]


class RigLock:
    """`with RigLock(rig, master_uri, context):` or `acquire()` / `release()`."""

    def __init__(self, rig: str, master_uri: str, context: str, directory: str = None):
        self.rig = rig
        self.context = context
        key = hashlib.sha1(master_uri.encode()).hexdigest()[:8]
        self.path = os.path.join(
            directory or tempfile.gettempdir(), "rascal-rig-%s-%s.lock" % (_safe(rig), key)
        )
        self.master_uri = master_uri
        self._fd = None

    def acquire(self):
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = self._read(fd)
            os.close(fd)
            raise Busy(
                "rig %s is in use by another `rascal run` (%s); wait for it to end or stop "
                "it with Ctrl-C in its terminal (lock file %s)" % (self.rig, holder, self.path)
            ) from None
        info = {
            "host": socket.gethostname(),
            "pid": os.getpid(),
            "started": _now_text(),
            "context": self.context,
            "master": self.master_uri,
        }
        os.ftruncate(fd, 0)
        os.pwrite(fd, (json.dumps(info) + "\n").encode(), 0)
        self._fd = fd
        return self

    @staticmethod
    def _read(fd) -> str:
        try:
            info = json.loads(os.pread(fd, 4096, 0).decode() or "{}")
        except (OSError, ValueError):
            info = {}
        if not info:
            return "it is just starting"
        return "pid %s on host %s since %s, context %s" % (
            info.get("pid", "?"),
            info.get("host", "?"),
            info.get("started", "?"),
            info.get("context", "?"),
        )

    def release(self):
        if self._fd is not None:
            os.close(self._fd)  # closing the descriptor drops the flock
            self._fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()


def context_key(context: str) -> int:
    """The advisory lock key of a context: a signed 64-bit hash, stable across runs and hosts."""
    digest = hashlib.blake2b(("rascal-context:" + context).encode(), digest_size=8).digest()
    return struct.unpack(">q", digest)[0]


class ContextLock:
    """pg_try_advisory_lock(context_key(context)) on a psycopg2 connection, for the run."""

    def __init__(self, context: str, rig: str):
        self.context = context
        self.rig = rig
        self.key = context_key(context)
        self.conn = None
        self.app_name = ("rascal run %d@%s %s" % (os.getpid(), socket.gethostname(), rig))[
            :_APP_NAME_MAX
        ]

    def acquire(self, conn):
        """Take the lock on `conn` (again, after a reconnect); Busy if another session holds it.
        Leaves no transaction open on `conn`."""
        with conn.cursor() as cur:
            try:
                cur.execute("SELECT pg_try_advisory_lock(%s)", (self.key,))
                got = cur.fetchone()[0]
                if got:
                    cur.execute(
                        "SELECT set_config('application_name', %s, false)", (self.app_name,)
                    )
                    holder = None
                else:
                    holder = self._holder(cur)
            finally:
                if not conn.autocommit:
                    conn.commit()
        if not got:
            raise Busy(
                "context %s is being recorded by another `rascal run` (%s); wait for it to end "
                "or stop it with Ctrl-C in its terminal" % (self.context, holder)
            )
        self.conn = conn
        return self

    def _holder(self, cur) -> str:
        """Who holds the lock, from pg_locks and pg_stat_activity."""
        key = self.key & 0xFFFFFFFFFFFFFFFF
        cur.execute(
            "SELECT a.application_name, a.client_addr::text, a.backend_start, a.pid "
            "FROM pg_locks l LEFT JOIN pg_stat_activity a ON a.pid = l.pid "
            "WHERE l.locktype = 'advisory' AND l.granted AND l.objsubid = 1 "
            "AND l.classid::bigint = %s AND l.objid::bigint = %s "
            "AND l.database = (SELECT oid FROM pg_database WHERE datname = current_database())",
            (key >> 32, key & 0xFFFFFFFF),
        )
        row = cur.fetchone()
        if row is None:
            return "it has just ended: run again"
        app, addr, started, pid = row
        m = re.match(r"rascal run (\d+)@(\S+) ?(.*)$", app or "")
        since = started.astimezone(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
        if m:
            return "pid %s on host %s since %s, rig %s" % (
                m.group(1),
                m.group(2),
                since,
                m.group(3) or "?",
            )
        return "database session %s from %s since %s" % (pid, addr or "local socket", since)

    def release(self):
        """Drop the lock (it also goes with the connection)."""
        conn, self.conn = self.conn, None
        if conn is None or conn.closed:
            return
        try:
            with conn.cursor() as cur:
                cur.execute("SELECT pg_advisory_unlock(%s)", (self.key,))
            if not conn.autocommit:
                conn.commit()
        except Exception:  # the connection is going away anyway
            pass
