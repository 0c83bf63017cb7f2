"""``Catalogue``: what the robot recorded, one committed transaction per measurement.

A sherd's row moves through picked -> weighed -> photographed -> done (or lost from any
unfinished state). Each ``record_*`` call validates its input (a FieldError names the field
and the fix; nothing is written), updates the row, appends to the event log and commits
before it returns, so a crash loses at most the measurement in progress.

Sequence numbers are gap-free per context and safe under concurrent writers: the number is
taken as MAX(seq)+1 inside the inserting transaction while the context's row is locked
(SELECT ... FOR UPDATE), and UNIQUE (context_id, seq) backs it up. Nothing is counted in
Python. After a crash, ``resume(context_id)`` hands back the unfinished rows so the restarted
run continues them instead of recording the same sherd twice.

The connection, logger and clock are injected; nothing here imports ROS.
"""

import contextlib
import datetime
import json
import logging
import threading
import time

import psycopg2
import psycopg2.errors
import psycopg2.extras
from psycopg2 import sql

from .migrate import status as _migration_status
from .context_id import validate_context_id, validate_site_id
from .errors import CatalogueError, FieldError, StatusError
from .fields import (
    check_count,
    check_munsell,
    check_number,
    check_sha256,
    check_text,
    check_timings,
)

__all__ = ["Catalogue", "SOFTWARE_VERSION"]

SOFTWARE_VERSION = "rascal_tasks 0.1.0"
UNFINISHED = ("picked", "weighed", "photographed")
_SEQ_RETRIES = 5

_SHERD_COLUMNS = (
    "sherd_id, s.context_id, c.site_id, seq, status::text AS status, mass_g, length_mm, "
    "width_mm, thickness_mm, colour_munsell, colour_l, colour_a, colour_b, chart_delta_e00, "
    "px_per_cm, image_path, image_sha256, drops, grasp_attempts, pickup_x_m, pickup_y_m, "
    "t_pick_s, t_weigh_s, t_photo_s, t_discard_s, t_locomotion_s, t_grasping_s, "
    "t_data_collection_s, t_perception_s, lost_reason, notes, rig, software_version, "
    "config_hash, picked_at, weighed_at, photographed_at, done_at, lost_at, updated_at"
)


def _first_line(exc):
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0]


def _find_id(context_id, seq):
    return "%s-%d" % (context_id, seq)


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

    @classmethod
    def connect(cls, dsn, rig, config_hash, connect_timeout=5.0, **kwargs):
        """Open a connection and check that the schema is up to date."""
        try:
            conn = psycopg2.connect(
                dsn, connect_timeout=max(1, int(round(connect_timeout))), application_name="rascal"
            )
        except psycopg2.OperationalError as e:
            raise CatalogueError(
                "database.dsn: cannot connect (%s); is PostgreSQL running and "
                "the DSN right?" % str(e).strip().splitlines()[0]
            ) from None
        cat = cls(conn, rig, config_hash, **kwargs)
        cat._dsn, cat._connect_timeout = dsn, connect_timeout
        cat.check_schema()
        return cat

    def reconnect(self):
        """Open a new connection with the DSN given to ``connect`` (after the database was
        restarted). Nothing is retried: call ``resume`` to see what was saved."""
        if self._dsn is None:
            raise CatalogueError(
                "reconnect: this catalogue was built on a connection, not a "
                "DSN; use Catalogue.connect(dsn, ...)"
            )
        with self._lock:
            try:
                self._conn.close()
            except psycopg2.Error:
                pass
            try:
                self._conn = psycopg2.connect(
                    self._dsn,
                    connect_timeout=max(1, int(round(self._connect_timeout))),
                    application_name="rascal",
                )
            except psycopg2.OperationalError as e:
                raise CatalogueError(
                    "database.dsn: cannot connect (%s); is PostgreSQL running?"
                    % str(e).strip().splitlines()[0]
                ) from None
            self._conn.autocommit = False

    @property
    def connection(self):
        return self._conn

    def close(self):
        self._conn.close()

    def check_schema(self):
        """Raise CatalogueError unless every shipped migration has been applied."""
        pending = [r for r in _migration_status(self._conn) if r[3] != "applied"]
        if pending:
            raise CatalogueError(
                "database schema is not up to date (%s); run `rascal db migrate`"
                % ", ".join("%04d_%s: %s" % (v, n, st) for v, n, _, st in pending)
            )

    # --- helpers ---
    def _now(self):
        return datetime.datetime.fromtimestamp(self._clock(), tz=datetime.timezone.utc)

    @contextlib.contextmanager
    def _tx(self, what):
        """One transaction: commit on success, roll back on any error. Database failures
        become one-line CatalogueErrors (a UniqueViolation is left to new_sherd)."""
        with self._lock:
            try:
                with (
                    self._conn,
                    self._conn.cursor(cursor_factory=psycopg2.extras.RealDictCursor) as cur,
                ):
                    yield cur
            except psycopg2.errors.UniqueViolation:
                raise
            except (psycopg2.OperationalError, psycopg2.InterfaceError) as e:
                raise CatalogueError(
                    "database: connection lost while %s (%s); what was not committed is not "
                    "saved: reconnect and resume" % (what, _first_line(e))
                ) from e
            except psycopg2.Error as e:
                raise CatalogueError("database refused %s: %s" % (what, _first_line(e))) from e

    def _event(self, cur, kind, context_id=None, sherd_id=None, detail=None, at=None):
        cur.execute(
            "INSERT INTO events (at, context_id, sherd_id, kind, rig, detail) "
            "VALUES (%s, %s, %s, %s, %s, %s)",
            (
                at or self._now(),
                context_id,
                sherd_id,
                kind,
                self._rig,
                json.dumps(detail or {}, sort_keys=True),
            ),
        )

    # --- sites and contexts ---
    def open_context(self, context_id, site_id, description=None):
        """Create the context (and its site) if new; re-opening is harmless. Returns
        ``{'context_id', 'site_id', 'created': bool, 'sherds': n, 'unfinished': n}``."""
        validate_context_id(context_id)
        validate_site_id(site_id)
        check_text("description", description, 500)
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
                "('picked', 'weighed', 'photographed')) AS open "
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

    # --- one sherd ---
    def new_sherd(self, context_id, pickup_xy=None, grasp_attempts=1, t_pick_s=None):
        """Record a newly picked sherd; returns its record with the next ``seq``."""
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
                with self._tx("taking a sequence number") as cur:
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
                        "SELECT %s, COALESCE(MAX(seq), 0) + 1, 'picked', %s, %s, %s, %s, %s, %s, "
                        "%s, %s, %s FROM sherds WHERE context_id = %s "
                        "RETURNING sherd_id, seq",
                        (
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

    def _advance(
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
            sets.append(sql.SQL("{} = %s").format(sql.Identifier(to_status + "_at")))
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
        """The scale's stable reading [g]; picked -> weighed (re-weighing is allowed)."""
        mass_g = check_number("mass_g", mass_g, 0.0, 100000.0, "g", allow_none=False, lo_open=True)
        t_weigh_s = check_number("t_weigh_s", t_weigh_s, 0.0, 1e6, "s")
        return self._advance(
            sherd_id,
            "weighed",
            ("picked", "weighed"),
            {"mass_g": mass_g, "t_weigh_s": t_weigh_s},
            "weighed",
            {"mass_g": mass_g},
        )

    def record_dimensions(self, sherd_id, length_mm, width_mm, thickness_mm=None):
        """Size from perception [mm]; any unfinished state, no state change."""
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
        the colour measured on it; weighed -> photographed (a re-shoot is allowed)."""
        f = {
            "image_path": check_text("image_path", image_path, 300, allow_none=False),
            "image_sha256": check_sha256("image_sha256", image_sha256),
            "colour_munsell": check_munsell("colour_munsell", colour_munsell),
            "chart_delta_e00": check_number("chart_delta_e00", chart_delta_e00, 0.0, 200.0),
            "px_per_cm": check_number("px_per_cm", px_per_cm, 0.0, 1e5, "px/cm", lo_open=True),
            "t_photo_s": check_number("t_photo_s", t_photo_s, 0.0, 1e6, "s"),
        }
        if colour_lab is not None:
            if not isinstance(colour_lab, (list, tuple)) or len(colour_lab) != 3:
                raise FieldError("colour_lab %r: must be [L*, a*, b*] (D50)" % (colour_lab,))
            f["colour_l"] = check_number("colour_lab[0] (L*)", colour_lab[0], 0.0, 100.0)
            f["colour_a"] = check_number("colour_lab[1] (a*)", colour_lab[1], -200.0, 200.0)
            f["colour_b"] = check_number("colour_lab[2] (b*)", colour_lab[2], -200.0, 200.0)
        if f["image_path"].startswith("/") or ".." in f["image_path"].split("/"):
            raise FieldError(
                "image_path '%s': must be relative to the archive root, without "
                "'..' (use ImageArchive.store's result)" % image_path
            )
        return self._advance(
            sherd_id,
            "photographed",
            ("weighed", "photographed"),
            f,
            "photographed",
            {"image_path": f["image_path"], "image_sha256": f["image_sha256"]},
        )

    def archive_photo(self, sherd_id, archive, image, **photo):
        """Write ``image`` to ``archive`` (atomically, with a JSON sidecar of the record),
        then record its path and SHA-256: the database only ever names complete files."""
        rec = self.get(sherd_id)
        if rec["status"] not in ("weighed", "photographed"):
            raise StatusError(
                "sherd %s is '%s': cannot record 'photographed' (only after "
                "weighed, photographed)" % (rec["find_id"], rec["status"])
            )
        sidecar = dict(
            rec, status="photographed", **{k: v for k, v in photo.items() if k != "colour_lab"}
        )
        if photo.get("colour_lab") is not None:
            lab = photo["colour_lab"]
            sidecar.update(colour_l=lab[0], colour_a=lab[1], colour_b=lab[2])
        rel, sha = archive.store(rec["context_id"], rec["seq"], image, sidecar)
        return self.record_photo(sherd_id, rel, sha, **photo)

    def record_done(self, sherd_id, t_discard_s=None, timings=None, archive=None):
        """The sherd is in the discard box; photographed -> done (final). ``timings`` is
        ``{phase: seconds}`` for the phases in ``fields.PHASES`` (the paper's breakdown).
        With ``archive``, the image's JSON sidecar is rewritten with the final record."""
        f = {"t_discard_s": check_number("t_discard_s", t_discard_s, 0.0, 1e6, "s")}
        f.update(check_timings("timings", timings))
        result = self._advance(sherd_id, "done", ("photographed",), f, "done")
        if archive is not None:
            archive.write_sidecar(result["context_id"], result["seq"], self.get(sherd_id))
        return result

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
        """Free text for the archaeologist (appended to the record's notes)."""
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
        """Sherds of the context that are picked, weighed or photographed (not done/lost),
        optionally only those recorded by ``rig``."""
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

    @staticmethod
    def _record(row):
        rec = dict(row)
        rec["find_id"] = _find_id(rec["context_id"], rec["seq"])
        return rec
