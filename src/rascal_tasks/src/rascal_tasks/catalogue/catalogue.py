"""``Catalogue``: what the robot recorded, one committed transaction per measurement.

A sherd's row moves through picked -> weighed -> photographed -> done (or lost from any
unfinished state); mass_unstable stands for weighed when the scale gave no trustworthy mass
(no mass; mass_missing_reason says why). Each ``record_*`` call validates its input (a
FieldError names the field and the fix; nothing is written), updates the row, appends to the
event log and commits before it returns, so a crash loses at most the measurement in progress.

Sequence numbers are gap-free per context and safe under concurrent writers: the number is
taken as MAX(seq)+1 inside the inserting transaction while the context's row is locked
(SELECT ... FOR UPDATE), and UNIQUE (context_id, seq) backs it up. Nothing is counted in
Python. A context taken over from another rig (central.py) numbers on after that rig's last
number (context_claims.seq_floor); keys (sherd_id, event_id) come from the rig's own block.
After a crash, ``resume(context_id)`` hands back the unfinished rows so the restarted run
continues them instead of recording the same sherd twice.

A database failure never escapes as a psycopg2 exception: the transaction is rolled back and
the call raises a one-line CatalogueError; a lost connection raises ConnectionLostError.
``reconnect_with_retry`` then waits for the database (exponential backoff, capped). Every
writing call carries a token in its event row; the same call made again after a reconnect
looks that token up first, so a commit whose answer was lost is never committed twice.

The connection, logger and clock are injected; nothing here imports ROS.
"""

import contextlib
import datetime
import json
import logging
import re
import threading
import time
import uuid

import psycopg2
import psycopg2.errors
import psycopg2.extras
from psycopg2 import sql

from .migrate import status as _migration_status
from .context_id import validate_context_id, validate_site_id
from .errors import CatalogueError, ConnectionLostError, FieldError, StatusError
from .fields import (
    check_count,
    check_munsell,
    check_number,
    check_sha256,
    check_text,
    check_timings,
)

__all__ = ["Catalogue", "SOFTWARE_VERSION", "wait_for_database"]

SOFTWARE_VERSION = "rascal_tasks 0.1.0"
UNFINISHED = ("picked", "mass_unstable", "weighed", "photographed")
# What the scale step ends in: a mass (weighed), or none that can be trusted (mass_unstable, with
# mass_missing_reason); either may be photographed.
WEIGHED = ("mass_unstable", "weighed")
_STATE_AT = {"mass_unstable": "weighed_at"}  # the timestamp column of a state, if not <state>_at
_SEQ_RETRIES = 5

_SHERD_COLUMNS = (
    "sherd_id, s.context_id, c.site_id, seq, status::text AS status, mass_g, mass_missing_reason, "
    "length_mm, width_mm, thickness_mm, vessel_diameter_mm, vessel_diameter_sigma_mm, "
    "colour_munsell, colour_l, colour_a, colour_b, chart_delta_e00, "
    "px_per_cm, image_path, image_sha256, drops, grasp_attempts, pickup_x_m, pickup_y_m, "
    "t_pick_s, t_weigh_s, t_photo_s, t_discard_s, t_locomotion_s, t_grasping_s, "
    "t_data_collection_s, t_perception_s, lost_reason, bin, notes, rig, software_version, "
    "config_hash, picked_at, weighed_at, photographed_at, done_at, lost_at, updated_at"
)


def _first_line(exc):
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0]


def _find_id(context_id, seq):
    return "%s-%d" % (context_id, seq)


# Every wait on the database has a deadline: connect_timeout for connecting, TCP keepalives and
# tcp_user_timeout for a server that vanished without closing the socket, lock_timeout for a
# row lock held by a stuck writer.
_LOCK_TIMEOUT_MS = 30000
_TCP_USER_TIMEOUT_MS = 10000


def _open(dsn, connect_timeout, application_name):
    """A new connection (autocommit off), or a one-line ConnectionLostError / CatalogueError."""
    try:
        conn = psycopg2.connect(
            dsn,
            connect_timeout=max(1, int(round(connect_timeout))),
            application_name=application_name,
            keepalives=1,
            keepalives_idle=10,
            keepalives_interval=3,
            keepalives_count=3,
            tcp_user_timeout=_TCP_USER_TIMEOUT_MS,
        )
    except psycopg2.OperationalError as e:
        raise ConnectionLostError(
            "database.dsn: cannot connect (%s); is PostgreSQL running and the DSN right?"
            % _first_line(e),
            reason=_first_line(e),
        ) from None
    except psycopg2.Error as e:
        raise CatalogueError(
            "database.dsn: not a valid DSN (%s); write a libpq URI "
            "postgresql://user:password@host:port/dbname" % _first_line(e)
        ) from None
    try:
        conn.autocommit = False
        with conn, conn.cursor() as cur:
            cur.execute(
                "SELECT set_config('lock_timeout', %s, false)", ("%dms" % _LOCK_TIMEOUT_MS,)
            )
    except psycopg2.Error as e:
        conn.close()
        raise ConnectionLostError(
            "database.dsn: connection dropped while setting it up (%s); is PostgreSQL "
            "running?" % _first_line(e),
            reason=_first_line(e),
        ) from None
    return conn


def wait_for_database(
    connect,
    retry_for,
    log=None,
    sleep=time.sleep,
    clock=time.monotonic,
    first_delay=0.5,
    max_delay=10.0,
):
    """Call ``connect(timeout)`` until it returns, for at most ``retry_for`` seconds
    (database.retry_for); returns what it returned.

    ``connect`` raises ConnectionLostError while the database is unreachable; it is tried at
    once, then after ``first_delay`` s, doubling up to ``max_delay`` s between attempts, and
    ``timeout`` is the time left (for its own connect timeout). ``log(line)`` gets one line
    per failed attempt and one when it succeeds after failing. When the time is up it raises
    ConnectionLostError, one line naming database.dsn and database.retry_for. Any other
    CatalogueError (a bad DSN, a schema not up to date) is raised at once."""
    if isinstance(retry_for, bool) or not isinstance(retry_for, (int, float)) or retry_for < 0:
        raise FieldError("database.retry_for %r: must be seconds >= 0" % (retry_for,))
    log = log or (lambda line: None)
    start = clock()
    delay = first_delay
    attempt = 0
    while True:
        attempt += 1
        left = retry_for - (clock() - start)
        try:
            result = connect(max(1.0, left))
        except ConnectionLostError as e:
            reason = e.reason or str(e)
            waited = clock() - start
            left = retry_for - waited
            if left <= 0:
                raise ConnectionLostError(
                    "database: still unreachable after %.0f s and %d attempts (%s); start "
                    "PostgreSQL or fix database.dsn, then run again to resume "
                    "(database.retry_for sets how long to wait)" % (waited, attempt, reason),
                    reason=reason,
                ) from None
            pause = min(delay, left)
            log(
                "database: attempt %d failed (%s); next in %.1f s, giving up in %.0f s"
                % (attempt, reason, pause, left)
            )
            sleep(pause)
            delay = min(delay * 2.0, max_delay)
            continue
        if attempt > 1:
            log("database: reachable again after %d attempts (%.1f s)" % (attempt, clock() - start))
        return result


def _colour_fields(colour_munsell, colour_lab, chart_delta_e00, px_per_cm):
    """The archival analysis's columns, checked (record_photo, record_archival)."""
    f = {
        "colour_munsell": check_munsell("colour_munsell", colour_munsell),
        "chart_delta_e00": check_number("chart_delta_e00", chart_delta_e00, 0.0, 200.0),
        "px_per_cm": check_number("px_per_cm", px_per_cm, 0.0, 1e5, "px/cm", lo_open=True),
    }
    if colour_lab is not None:
        if not isinstance(colour_lab, (list, tuple)) or len(colour_lab) != 3:
            raise FieldError("colour_lab %r: must be [L*, a*, b*] (D50)" % (colour_lab,))
        f["colour_l"] = check_number("colour_lab[0] (L*)", colour_lab[0], 0.0, 100.0)
        f["colour_a"] = check_number("colour_lab[1] (a*)", colour_lab[1], -200.0, 200.0)
        f["colour_b"] = check_number("colour_lab[2] (b*)", colour_lab[2], -200.0, 200.0)
    return f


class Catalogue:
    """The sherd catalogue over one psycopg2 connection.

    ``rig`` and ``config_hash`` are stored with every sherd; ``clock()`` returns POSIX
    seconds for the record's timestamps; ``logger`` has ``info``/``warning`` methods.
    """

    def __init__(
        self,
        conn,
        rig,
        config_hash,
        logger=None,
        clock=time.time,
        software_version=SOFTWARE_VERSION,
    ):
        self._conn = conn
        if conn.autocommit:
            conn.autocommit = False
        self._rig = check_text("rig", rig, 64, allow_none=False)
        self._config_hash = check_text("config_hash", config_hash, 128, allow_none=False)
        self._software_version = check_text(
            "software_version", software_version, 64, allow_none=False
        )
        self._log = logger or logging.getLogger("rascal.catalogue")
        self._clock = clock
        self._lock = threading.RLock()  # one transaction at a time on the shared connection
        self._dsn = None
        self._connect_timeout = 5.0
        self._application_name = "rascal"
        self._identity = None  # catalogue_identity.catalogue_id, read once
        self._op = None  # token of the writing call in progress (goes into its event)
        self._in_doubt = None  # (call, token) of a writing call cut off by a lost connection

    @classmethod
    def connect(
        cls, dsn, rig, config_hash, connect_timeout=5.0, application_name="rascal", **kwargs
    ):
        """Open a connection and check that the schema is up to date. Raises
        ConnectionLostError (one line) when the database cannot be reached."""
        conn = _open(dsn, connect_timeout, application_name)
        try:
            cat = cls(conn, rig, config_hash, **kwargs)
            cat._dsn, cat._connect_timeout = dsn, connect_timeout
            cat._application_name = application_name
            cat.check_schema()
        except BaseException:
            conn.close()
            raise
        return cat

    @classmethod
    def connect_with_retry(
        cls,
        dsn,
        rig,
        config_hash,
        retry_for,
        connect_timeout=5.0,
        log=None,
        sleep=time.sleep,
        clock=time.monotonic,
        **kwargs,
    ):
        """``connect``, waiting up to ``retry_for`` seconds for the database to come up
        (see ``wait_for_database``)."""
        return wait_for_database(
            lambda left: cls.connect(
                dsn, rig, config_hash, connect_timeout=min(connect_timeout, left), **kwargs
            ),
            retry_for,
            log=log,
            sleep=sleep,
            clock=clock,
        )

    def reconnect(self, connect_timeout=None):
        """Open a new connection with the DSN given to ``connect`` (after the database was
        restarted), once. Raises ConnectionLostError if it cannot be reached; see
        ``reconnect_with_retry``. Session state (advisory locks) went with the old
        connection: take it again on ``connection``."""
        if self._dsn is None:
            raise CatalogueError(
                "reconnect: this catalogue was built on a connection, not a "
                "DSN; use Catalogue.connect(dsn, ...)"
            )
        timeout = self._connect_timeout if connect_timeout is None else connect_timeout
        with self._lock:
            try:
                self._conn.close()
            except psycopg2.Error:
                pass
            self._conn = _open(
                self._dsn, min(timeout, self._connect_timeout), self._application_name
            )

    def reconnect_with_retry(
        self,
        retry_for,
        log=None,
        sleep=time.sleep,
        clock=time.monotonic,
        first_delay=0.5,
        max_delay=10.0,
    ):
        """After a ConnectionLostError: reconnect, waiting for the database with exponential
        backoff (``first_delay`` s doubling up to ``max_delay`` s) for at most ``retry_for``
        seconds (database.retry_for), and check the schema. ``log(line)`` gets one line per
        attempt (default: the catalogue's logger). Returns the number of attempts; raises
        ConnectionLostError (one line) when the time is up.

        Afterwards the same call that failed may be made again: it is committed once. The
        arm should be parked while this waits (it can take ``retry_for`` seconds)."""

        attempts = []

        def attempt(left):
            attempts.append(left)
            self.reconnect(connect_timeout=left)
            self.check_schema()

        wait_for_database(
            attempt,
            retry_for,
            log=log or self._log.warning,
            sleep=sleep,
            clock=clock,
            first_delay=first_delay,
            max_delay=max_delay,
        )
        return len(attempts)

    @property
    def connection(self):
        return self._conn

    def close(self):
        self._conn.close()

    def check_schema(self):
        """Raise CatalogueError unless every shipped migration has been applied."""
        with self._lock:
            try:
                rows = _migration_status(self._conn)
            except psycopg2.Error as e:
                self._raise_db_error(e, "checking the schema", False)
        pending = [r for r in rows if r[3] != "applied"]
        if pending:
            raise CatalogueError(
                "database schema is not up to date (%s); run `rascal db migrate`"
                % ", ".join("%04d_%s: %s" % (v, n, st) for v, n, _, st in pending)
            )

    # --- helpers ---
    def _now(self):
        return datetime.datetime.fromtimestamp(self._clock(), tz=datetime.timezone.utc)

    @contextlib.contextmanager
    def _tx(self, what, pass_unique=False):
        """One transaction: commit on success, roll back on any error. Database failures
        become one-line CatalogueErrors, a lost connection a ConnectionLostError (a
        UniqueViolation is left to new_sherd with ``pass_unique``)."""
        with self._lock:
            body_done = False
            try:
                with (
                    self._conn,
                    self._conn.cursor(cursor_factory=psycopg2.extras.RealDictCursor) as cur,
                ):
                    yield cur
                    body_done = True
            except psycopg2.errors.UniqueViolation as e:
                if pass_unique:
                    raise
                self._raise_db_error(e, what, False)
            except psycopg2.Error as e:
                self._raise_db_error(e, what, body_done)

    def _raise_db_error(self, e, what, at_commit):
        """Turn a psycopg2 error into one line: ConnectionLostError when the connection is
        gone, else CatalogueError (the transaction was rolled back)."""
        if isinstance(e, psycopg2.InterfaceError) or self._conn.closed:
            if at_commit:
                raise ConnectionLostError(
                    "database: connection lost while committing %s (%s); whether it was "
                    "saved is checked when the same call is made after reconnecting; check "
                    "that PostgreSQL is running and reachable (database.dsn)"
                    % (what, _first_line(e)),
                    reason=_first_line(e),
                ) from None
            raise ConnectionLostError(
                "database: connection lost while %s (%s); rolled back, nothing of it saved; "
                "check that PostgreSQL is running and reachable (database.dsn)"
                % (what, _first_line(e)),
                reason=_first_line(e),
            ) from None
        raise CatalogueError(
            "database refused %s: %s (rolled back, nothing of it saved)" % (what, _first_line(e))
        ) from None

    def _once(self, call, run, replay):
        """Run ``run()``, one writing call, so that making the same ``call`` again after a
        lost connection never commits it twice: its events carry a token, and when the call
        is repeated after a ConnectionLostError, the token is looked up first; if it was
        committed, ``replay(event)`` gives the result without writing again."""
        with self._lock:
            pending = self._in_doubt
            op = None
            if pending is not None and pending[0] == call:
                op = pending[1]
                # (lost again here: the call stays in doubt)
                with self._tx("checking an interrupted write") as cur:
                    cur.execute(
                        "SELECT event_id, context_id, sherd_id, kind, detail FROM events "
                        "WHERE detail->>'op' = %s ORDER BY event_id LIMIT 1",
                        (op,),
                    )
                    found = cur.fetchone()
                if found is not None:
                    result = replay(found)
                    self._in_doubt = None
                    self._log.info(
                        "database: '%s' was committed before the connection was lost; "
                        "not recorded again" % found["kind"]
                    )
                    return result
            self._in_doubt = None  # not committed, or the caller moved on to another call
            self._op = op or uuid.uuid4().hex
            try:
                return run()
            except ConnectionLostError:
                self._in_doubt = (call, self._op)
                raise
            finally:
                self._op = None

    def _event(self, cur, kind, context_id=None, sherd_id=None, detail=None, at=None):
        detail = dict(detail or {})
        if self._op is not None:
            detail["op"] = self._op
        cur.execute(
            "INSERT INTO events (at, context_id, sherd_id, kind, rig, detail) "
            "VALUES (%s, %s, %s, %s, %s, %s)",
            (
                at or self._now(),
                context_id,
                sherd_id,
                kind,
                self._rig,
                json.dumps(detail, sort_keys=True),
            ),
        )

    # --- sites and contexts ---
    def open_context(self, context_id, site_id, description=None):
        """Create the context (and its site) if new; re-opening is harmless. Returns
        ``{'context_id', 'site_id', 'created': bool, 'sherds': n, 'unfinished': n}``."""
        validate_context_id(context_id)
        validate_site_id(site_id)
        check_text("description", description, 500)
        self.claim_context(context_id)
        with self._tx("opening the context") as cur:
            cur.execute(
                "INSERT INTO sites (site_id) VALUES (%s) ON CONFLICT DO NOTHING", (site_id,)
            )
            cur.execute(
                "INSERT INTO contexts (context_id, site_id, description) "
                "VALUES (%s, %s, %s) ON CONFLICT DO NOTHING RETURNING context_id",
                (context_id, site_id, description),
            )
            created = cur.fetchone() is not None
            cur.execute("SELECT site_id FROM contexts WHERE context_id = %s", (context_id,))
            owner = cur.fetchone()["site_id"]
            if owner != site_id:
                raise FieldError(
                    "context id '%s': already belongs to site '%s', not '%s' "
                    "(check rig.site or the context id)" % (context_id, owner, site_id)
                )
            if created:
                self._event(cur, "context_opened", context_id, detail={"site_id": site_id})
            cur.execute(
                "SELECT count(*) AS n, count(*) FILTER (WHERE status IN "
                "('picked', 'mass_unstable', 'weighed', 'photographed')) AS open "
                "FROM sherds WHERE context_id = %s",
                (context_id,),
            )
            counts = cur.fetchone()
        self._log.info(
            "context '%s' (site '%s'): %s, %d sherds, %d unfinished"
            % (
                context_id,
                site_id,
                "created" if created else "reopened",
                counts["n"],
                counts["open"],
            )
        )
        return {
            "context_id": context_id,
            "site_id": site_id,
            "created": created,
            "sherds": counts["n"],
            "unfinished": counts["open"],
        }

    def claim_context(self, context_id):
        """On a rig joined to a central server (``rascal central add-rig``): claim the
        context there so that no other rig records it at the same time (ContextClaimed, one
        line naming the rig that holds it); offline, a provisional claim (see central.py).
        Nothing on a standalone catalogue. Returns the claim's state, or None."""
        from .central import claim_context

        return claim_context(self, context_id)

    # --- one sherd ---
    def new_sherd(self, context_id, pickup_xy=None, grasp_attempts=1, t_pick_s=None):
        """Record a newly picked sherd; returns its record with the next ``seq``. Made again
        after a ConnectionLostError, it returns the sherd it had committed, if it had."""
        call = ("new_sherd", context_id, repr(pickup_xy), repr(grasp_attempts), repr(t_pick_s))
        return self._once(
            call,
            lambda: self._new_sherd(context_id, pickup_xy, grasp_attempts, t_pick_s),
            self._replay_new_sherd,
        )

    def _replay_new_sherd(self, event):
        seq = event["detail"]["seq"]
        return {
            "sherd_id": event["sherd_id"],
            "context_id": event["context_id"],
            "seq": seq,
            "find_id": _find_id(event["context_id"], seq),
            "status": "picked",
        }

    def _new_sherd(self, context_id, pickup_xy, grasp_attempts, t_pick_s):
        validate_context_id(context_id)
        px = py = None
        if pickup_xy is not None:
            if not isinstance(pickup_xy, (list, tuple)) or len(pickup_xy) != 2:
                raise FieldError(
                    "pickup_xy %r: must be [x, y] in metres (base_link)" % (pickup_xy,)
                )
            px = check_number("pickup_xy[0]", pickup_xy[0], -2.0, 2.0, "m")
            py = check_number("pickup_xy[1]", pickup_xy[1], -2.0, 2.0, "m")
        check_count("grasp_attempts", grasp_attempts)
        t_pick_s = check_number("t_pick_s", t_pick_s, 0.0, 1e6, "s")
        for attempt in range(_SEQ_RETRIES):
            now = self._now()
            try:
                with self._tx("taking a sequence number", pass_unique=True) as cur:
                    cur.execute(
                        "SELECT 1 FROM contexts WHERE context_id = %s FOR UPDATE", (context_id,)
                    )
                    if cur.fetchone() is None:
                        raise FieldError(
                            "context id '%s': not in the catalogue; open it first "
                            "(Catalogue.open_context)" % context_id
                        )
                    cur.execute(
                        "INSERT INTO sherds (context_id, seq, status, pickup_x_m, pickup_y_m, "
                        "grasp_attempts, t_pick_s, rig, software_version, config_hash, "
                        "picked_at, updated_at) "
                        "SELECT %s, GREATEST(COALESCE(MAX(seq), 0), (SELECT COALESCE(MAX("
                        "seq_floor), 0) FROM context_claims WHERE context_id = %s)) + 1, "
                        "'picked', %s, %s, %s, %s, %s, %s, "
                        "%s, %s, %s FROM sherds WHERE context_id = %s "
                        "RETURNING sherd_id, seq",
                        (
                            context_id,
                            context_id,
                            px,
                            py,
                            grasp_attempts,
                            t_pick_s,
                            self._rig,
                            self._software_version,
                            self._config_hash,
                            now,
                            now,
                            context_id,
                        ),
                    )
                    row = cur.fetchone()
                    self._event(
                        cur, "picked", context_id, row["sherd_id"], {"seq": row["seq"]}, at=now
                    )
                break
            except psycopg2.errors.UniqueViolation:
                # only a writer that bypasses the lock can get here; take the next number
                self._log.warning(
                    "context '%s': sequence number taken by another writer, "
                    "retrying (%d)" % (context_id, attempt + 1)
                )
        else:
            raise CatalogueError(
                "context '%s': could not take a sequence number after %d tries"
                % (context_id, _SEQ_RETRIES)
            )
        return {
            "sherd_id": row["sherd_id"],
            "context_id": context_id,
            "seq": row["seq"],
            "find_id": _find_id(context_id, row["seq"]),
            "status": "picked",
        }

    def _advance(self, sherd_id, kind, *args, **kwargs):
        """``_advance_tx`` (one sherd's update), committed once even when the same call is
        made again after a ConnectionLostError."""
        call = ("advance", repr(sherd_id), kind, repr(args), repr(sorted(kwargs.items())))
        return self._once(
            call,
            lambda: self._advance_tx(sherd_id, kind, *args, **kwargs),
            self._replay_advance,
        )

    def _replay_advance(self, event):
        with self._tx("reading a sherd") as cur:
            cur.execute(
                "SELECT context_id, seq, status::text AS status FROM sherds WHERE sherd_id = %s",
                (event["sherd_id"],),
            )
            row = cur.fetchone()
        return {
            "sherd_id": event["sherd_id"],
            "context_id": row["context_id"],
            "seq": row["seq"],
            "find_id": _find_id(row["context_id"], row["seq"]),
            "status": row["status"],
        }

    def _advance_tx(
        self, sherd_id, kind, allowed_from, fields, to_status=None, detail=None, increments=()
    ):
        """Update one sherd in one transaction: fields, status, its timestamp, an event."""
        if isinstance(sherd_id, bool) or not isinstance(sherd_id, int):
            raise FieldError("sherd_id %r: must be the integer new_sherd() returned" % (sherd_id,))
        now = self._now()
        sets = [sql.SQL("{} = %s").format(sql.Identifier(k)) for k in fields]
        values = list(fields.values())
        for k in increments:
            sets.append(sql.SQL("{0} = {0} + 1").format(sql.Identifier(k)))
        if to_status is not None:
            sets.append(sql.SQL("status = %s::sherd_status"))
            values.append(to_status)
            at_column = _STATE_AT.get(to_status, to_status + "_at")
            sets.append(sql.SQL("{} = %s").format(sql.Identifier(at_column)))
            values.append(now)
        sets.append(sql.SQL("updated_at = %s"))
        values.append(now)
        query = sql.SQL(
            "UPDATE sherds SET {} WHERE sherd_id = %s "
            "AND status = ANY(%s::sherd_status[]) "
            "RETURNING context_id, seq, status::text AS status"
        ).format(sql.SQL(", ").join(sets))
        with self._tx("recording " + kind) as cur:
            cur.execute(query, values + [sherd_id, list(allowed_from)])
            row = cur.fetchone()
            if row is None:
                cur.execute(
                    "SELECT context_id, seq, status::text AS status FROM sherds "
                    "WHERE sherd_id = %s",
                    (sherd_id,),
                )
                found = cur.fetchone()
                if found is None:
                    raise FieldError("sherd_id %d: no such sherd in the catalogue" % sherd_id)
                raise StatusError(
                    "sherd %s is '%s': cannot record '%s' (only after %s)"
                    % (
                        _find_id(found["context_id"], found["seq"]),
                        found["status"],
                        kind,
                        ", ".join(allowed_from),
                    )
                )
            self._event(
                cur, kind, row["context_id"], sherd_id, dict(detail or {}, seq=row["seq"]), at=now
            )
        return {
            "sherd_id": sherd_id,
            "context_id": row["context_id"],
            "seq": row["seq"],
            "find_id": _find_id(row["context_id"], row["seq"]),
            "status": row["status"],
        }

    def record_mass(self, sherd_id, mass_g, t_weigh_s=None):
        """The scale's settled reading [g]; picked -> weighed (re-weighing is allowed, also of a
        sherd recorded mass_unstable: its reason is then cleared)."""
        mass_g = check_number("mass_g", mass_g, 0.0, 100000.0, "g", allow_none=False, lo_open=True)
        t_weigh_s = check_number("t_weigh_s", t_weigh_s, 0.0, 1e6, "s")
        return self._advance(
            sherd_id,
            "weighed",
            ("picked",) + WEIGHED,
            {"mass_g": mass_g, "mass_missing_reason": None, "t_weigh_s": t_weigh_s},
            "weighed",
            {"mass_g": mass_g},
        )

    def record_mass_by_difference(self, sherd_id, mass_g, weighed_g):
        """A sherd weighed with another lying on the pan too (a rider from a heap, left there
        when it was lifted off): its own mass [g] is the row's `weighed_g` less what stayed on
        the pan. Only while it is still on its way (weighed or photographed); no state change;
        the event keeps both figures."""
        mass_g = check_number("mass_g", mass_g, 0.0, 100000.0, "g", allow_none=False, lo_open=True)
        weighed_g = check_number("weighed_g", weighed_g, 0.0, 100000.0, "g", allow_none=False)
        return self._advance(
            sherd_id,
            "mass_by_difference",
            ("weighed", "photographed"),
            {"mass_g": mass_g},
            None,
            {"mass_g": mass_g, "weighed_g": weighed_g},
        )

    def record_mass_unstable(self, sherd_id, reason, t_weigh_s=None):
        """The scale gave no mass that can be trusted (no reading held steady, or it could not
        be tared): picked -> mass_unstable, with no mass and ``reason`` in mass_missing_reason.
        The sherd may then be photographed and done like a weighed one, or weighed again. A
        weighed sherd keeps its mass (StatusError): a failed re-weigh never erases one."""
        reason = check_text("reason", reason, 500, allow_none=False)
        if not reason.strip():
            raise FieldError(
                "reason '': must say why the mass is missing (e.g. 'the reading did not hold')"
            )
        t_weigh_s = check_number("t_weigh_s", t_weigh_s, 0.0, 1e6, "s")
        return self._advance(
            sherd_id,
            "mass_unstable",
            ("picked", "mass_unstable"),
            {"mass_g": None, "mass_missing_reason": reason, "t_weigh_s": t_weigh_s},
            "mass_unstable",
            {"reason": reason},
        )

    def record_dimensions(
        self, sherd_id, length_mm, width_mm, thickness_mm=None, vessel_diameter_mm=None
    ):
        """Size from perception [mm]; any unfinished state, no state change.
        `vessel_diameter_mm`: (diameter, 1-sigma uncertainty) or None (not told)."""
        diameter, sigma = vessel_diameter_mm or (None, None)
        f = {
            "length_mm": check_number(
                "length_mm", length_mm, 0.0, 2000.0, "mm", allow_none=False, lo_open=True
            ),
            "width_mm": check_number(
                "width_mm", width_mm, 0.0, 2000.0, "mm", allow_none=False, lo_open=True
            ),
            "thickness_mm": check_number(
                "thickness_mm", thickness_mm, 0.0, 500.0, "mm", lo_open=True
            ),
            "vessel_diameter_mm": check_number(
                "vessel_diameter_mm", diameter, 0.0, 5000.0, "mm", lo_open=True
            ),
            "vessel_diameter_sigma_mm": check_number(
                "vessel_diameter_sigma_mm", sigma, 0.0, 5000.0, "mm", lo_open=True
            ),
        }
        return self._advance(sherd_id, "measured", UNFINISHED, f, None, f)

    def record_photo(
        self,
        sherd_id,
        image_path,
        image_sha256,
        colour_munsell=None,
        colour_lab=None,
        chart_delta_e00=None,
        px_per_cm=None,
        t_photo_s=None,
    ):
        """The archived image (written completely before this call; see ImageArchive) and
        the colour measured on it; weighed or mass_unstable -> photographed (a re-shoot is
        allowed)."""
        f = {
            "image_path": check_text("image_path", image_path, 300, allow_none=False),
            "image_sha256": check_sha256("image_sha256", image_sha256),
            "t_photo_s": check_number("t_photo_s", t_photo_s, 0.0, 1e6, "s"),
        }
        f.update(_colour_fields(colour_munsell, colour_lab, chart_delta_e00, px_per_cm))
        if f["image_path"].startswith("/") or ".." in f["image_path"].split("/"):
            raise FieldError(
                "image_path '%s': must be relative to the archive root, without "
                "'..' (use ImageArchive.store's result)" % image_path
            )
        return self._advance(
            sherd_id,
            "photographed",
            WEIGHED + ("photographed",),
            f,
            "photographed",
            {"image_path": f["image_path"], "image_sha256": f["image_sha256"]},
        )

    def archive_photo(self, sherd_id, archive, image, **photo):
        """Write ``image`` to ``archive`` (atomically, with a JSON sidecar of the record),
        then record its path and SHA-256: the database only ever names complete files."""
        rec = self.get(sherd_id)
        if rec["status"] not in WEIGHED + ("photographed",):
            raise StatusError(
                "sherd %s is '%s': cannot record 'photographed' (only after "
                "%s)" % (rec["find_id"], rec["status"], ", ".join(WEIGHED + ("photographed",)))
            )
        sidecar = dict(
            rec, status="photographed", **{k: v for k, v in photo.items() if k != "colour_lab"}
        )
        if photo.get("colour_lab") is not None:
            lab = photo["colour_lab"]
            sidecar.update(colour_l=lab[0], colour_a=lab[1], colour_b=lab[2])
        owner = self.identity()
        rel, sha = archive.store(rec["context_id"], rec["seq"], image, sidecar, owner=owner)
        result = self.record_photo(sherd_id, rel, sha, **photo)
        self.refresh_sidecar(sherd_id, archive)  # the committed row (repaired at start if not)
        return result

    def record_archival(
        self,
        sherd_id,
        colour_munsell=None,
        colour_lab=None,
        chart_delta_e00=None,
        px_per_cm=None,
        size_mm=None,
    ):
        """What the archival photo's analysis measured, once it has finished: colour, the
        chart's CIEDE2000, px/cm and (length, width) [mm] from the scale bar. A photographed
        sherd, or one already done or lost after its photo (the analysis runs beside the
        batch); no state change. Only the values given are written."""
        f = _colour_fields(colour_munsell, colour_lab, chart_delta_e00, px_per_cm)
        if size_mm is not None:
            f["length_mm"] = check_number(
                "length_mm", size_mm[0], 0.0, 2000.0, "mm", allow_none=False, lo_open=True
            )
            f["width_mm"] = check_number(
                "width_mm", size_mm[1], 0.0, 2000.0, "mm", allow_none=False, lo_open=True
            )
        f = {k: v for k, v in f.items() if v is not None}
        return self._advance(
            sherd_id, "archival", ("photographed", "done", "lost"), f, None, dict(f)
        )

    def record_done(self, sherd_id, t_discard_s=None, timings=None, archive=None):
        """The sherd is in the discard box; photographed -> done (final). ``timings`` is
        ``{phase: seconds}`` for the phases in ``fields.PHASES`` (the paper's breakdown).
        With ``archive``, the image's JSON sidecar is rewritten with the final record."""
        f = {"t_discard_s": check_number("t_discard_s", t_discard_s, 0.0, 1e6, "s")}
        f.update(check_timings("timings", timings))
        result = self._advance(sherd_id, "done", ("photographed",), f, "done")
        if archive is not None:
            self.refresh_sidecar(sherd_id, archive)
        return result

    def record_bin(self, sherd_id, bin_name, reason=None):
        """The box the sherd is put into (the discard station or a sorting bin) and why (the
        `sorted` event); no state change. Before it is done: a resumed sherd is sorted again."""
        f = {"bin": check_text("bin", bin_name, 64, allow_none=False)}
        if not re.match(r"^[A-Za-z0-9_]{1,64}$", f["bin"]):
            raise FieldError("bin %r: must be a station name (letters, digits, _)" % bin_name)
        detail = {"bin": f["bin"], "reason": check_text("reason", (reason or "")[:500], 500)}
        return self._advance(sherd_id, "sorted", UNFINISHED, f, None, detail)

    def record_lost(self, sherd_id, reason, timings=None):
        """The sherd could not be found again; any unfinished state -> lost (final)."""
        reason = check_text("reason", reason, 500, allow_none=False)
        if not reason.strip():
            raise FieldError(
                "reason '': must say why the sherd is lost (e.g. 'dropped off the " "table')"
            )
        f = {"lost_reason": reason}
        f.update(check_timings("timings", timings))
        return self._advance(sherd_id, "lost", UNFINISHED, f, "lost", {"reason": reason})

    def record_drop(self, sherd_id, station=None):
        """The sherd slipped from the gripper (counted; no state change)."""
        check_text("station", station, 64)
        return self._advance(
            sherd_id, "drop", UNFINISHED, {}, None, {"station": station}, increments=("drops",)
        )

    def record_taken_over(self, sherd_id, pickup_xy):
        """The number of two sherds put back apart goes to the sherd picked next, at
        `pickup_xy` [m] (its dimensions follow); only while it is still 'picked'."""
        x = check_number("pickup_x_m", pickup_xy[0], -10.0, 10.0, "m", allow_none=False)
        y = check_number("pickup_y_m", pickup_xy[1], -10.0, 10.0, "m", allow_none=False)
        return self._advance(
            sherd_id,
            "taken_over",
            ("picked",),
            {"pickup_x_m": x, "pickup_y_m": y},
            None,
            {"pickup_x_m": x, "pickup_y_m": y},
        )

    def record_grasp_attempt(self, sherd_id, station=None):
        """One more grasp was tried (counted; no state change)."""
        check_text("station", station, 64)
        return self._advance(
            sherd_id,
            "grasp",
            UNFINISHED,
            {},
            None,
            {"station": station},
            increments=("grasp_attempts",),
        )

    def add_note(self, sherd_id, note):
        """Free text for the archaeologist (appended to the record's notes; once, even when
        made again after a ConnectionLostError)."""
        self._once(
            ("add_note", repr(sherd_id), repr(note)),
            lambda: self._add_note(sherd_id, note),
            lambda event: None,
        )

    def _add_note(self, sherd_id, note):
        check_text("note", note, 2000, allow_none=False)
        with self._tx("adding a note") as cur:
            cur.execute(
                "UPDATE sherds SET notes = concat_ws(E'\\n', notes, %s), updated_at = %s "
                "WHERE sherd_id = %s RETURNING context_id",
                (note, self._now(), sherd_id),
            )
            row = cur.fetchone()
            if row is None:
                raise FieldError("sherd_id %r: no such sherd in the catalogue" % (sherd_id,))
            self._event(cur, "note", row["context_id"], sherd_id, {"note": note})

    # --- reading ---
    def get(self, sherd_id):
        with self._tx("reading a sherd") as cur:
            cur.execute(
                "SELECT " + _SHERD_COLUMNS + " FROM sherds s JOIN contexts c "
                "USING (context_id) WHERE sherd_id = %s",
                (sherd_id,),
            )
            row = cur.fetchone()
        if row is None:
            raise FieldError("sherd_id %r: no such sherd in the catalogue" % (sherd_id,))
        return self._record(row)

    def sherds(self, context_id, statuses=None):
        """Every sherd of the context (optionally only those in ``statuses``), by seq."""
        validate_context_id(context_id)
        q = (
            "SELECT " + _SHERD_COLUMNS + " FROM sherds s JOIN contexts c USING (context_id) "
            "WHERE s.context_id = %s"
        )
        args = [context_id]
        if statuses is not None:
            q += " AND status::text = ANY(%s)"
            args.append(list(statuses))
        with self._tx("reading the sherds") as cur:
            cur.execute(q + " ORDER BY seq", args)
            return [self._record(r) for r in cur.fetchall()]

    def unfinished(self, context_id, rig=None):
        """Sherds of the context that are picked, mass_unstable, weighed or photographed (not
        done/lost), optionally only those recorded by ``rig``."""
        rows = self.sherds(context_id, UNFINISHED)
        return [r for r in rows if rig is None or r["rig"] == rig]

    def resume(self, context_id):
        """Start again on a context after a stop or crash: returns this rig's unfinished
        sherds (oldest first) for the caller to continue, and logs a 'resumed' event."""
        rows = self.unfinished(context_id, self._rig)
        with self._tx("logging the resume") as cur:
            self._event(cur, "resumed", context_id, detail={"unfinished": [r["seq"] for r in rows]})
        if rows:
            self._log.info(
                "context '%s': resuming %d unfinished sherds: %s"
                % (
                    context_id,
                    len(rows),
                    ", ".join("#%d (%s)" % (r["seq"], r["status"]) for r in rows),
                )
            )
        return rows

    def events(self, context_id):
        validate_context_id(context_id)
        with self._tx("reading the events") as cur:
            cur.execute(
                "SELECT event_id, at, context_id, sherd_id, kind, rig, detail "
                "FROM events WHERE context_id = %s ORDER BY event_id",
                (context_id,),
            )
            return [dict(r) for r in cur.fetchall()]

    def contexts(self):
        """Every context ID of the catalogue, sorted."""
        with self._tx("reading the contexts") as cur:
            cur.execute("SELECT context_id FROM contexts ORDER BY context_id")
            return [r["context_id"] for r in cur.fetchall()]

    # --- identity and the archive ---
    @property
    def rig(self) -> str:
        """The rig this catalogue records for (its rows' `rig`)."""
        return self._rig

    def identity(self):
        """This catalogue's UUID (table catalogue_identity, migration 0004), read once. The
        archive names files with it, so two catalogues never write the same file. A copy of
        the database (another name, or another server's system identifier) takes a new one
        the first time it is asked, with one log line."""
        if self._identity is not None:
            return self._identity
        sysid = self._system_identifier()
        with self._tx("reading the catalogue's identity") as cur:
            cur.execute(
                "SELECT catalogue_id::text AS id, database_name, system_identifier, "
                "current_database() AS db FROM catalogue_identity FOR UPDATE"
            )
            row = cur.fetchone()
            if row is None:
                cur.execute(
                    "INSERT INTO catalogue_identity (catalogue_id, database_name, "
                    "system_identifier) VALUES (gen_random_uuid(), current_database(), %s) "
                    "RETURNING catalogue_id::text AS id",
                    (sysid,),
                )
                ident = cur.fetchone()["id"]
                self._log.warning("catalogue: its identity was missing; it is now %s" % ident)
            elif row["database_name"] != row["db"] or (
                sysid is not None
                and row["system_identifier"] is not None
                and int(row["system_identifier"]) != sysid
            ):
                cur.execute(
                    "UPDATE catalogue_identity SET catalogue_id = gen_random_uuid(), "
                    "database_name = current_database(), system_identifier = %s, "
                    "created_at = now() RETURNING catalogue_id::text AS id",
                    (sysid,),
                )
                ident = cur.fetchone()["id"]
                self._log.warning(
                    "catalogue: database '%s' is a copy of catalogue %s (database '%s'); it "
                    "now has its own identity %s, so its archive files get names of their own"
                    % (row["db"], row["id"], row["database_name"], ident)
                )
            else:
                ident = row["id"]
                if row["system_identifier"] is None and sysid is not None:
                    cur.execute("UPDATE catalogue_identity SET system_identifier = %s", (sysid,))
        self._identity = ident
        return ident

    def _system_identifier(self):
        """The server's pg_control_system().system_identifier, or None where the role may
        not read it."""
        try:
            with self._tx("reading the server's identifier") as cur:
                cur.execute("SELECT system_identifier FROM pg_control_system()")
                return int(cur.fetchone()["system_identifier"])
        except ConnectionLostError:
            raise
        except CatalogueError:
            return None

    def refresh_sidecar(self, sherd_id, archive):
        """Rewrite the sherd's JSON sidecar from its committed row (nothing for a sherd
        without an image); returns the row."""
        rec = self.get(sherd_id)
        if rec["image_path"]:
            archive.write_sidecar(rec["context_id"], rec["seq"], rec, owner=self.identity())
        return rec

    @staticmethod
    def _record(row):
        rec = dict(row)
        rec["find_id"] = _find_id(rec["context_id"], rec["seq"])
        return rec
