"""A lost sherd found again (``rascal rerecord FIND_ID``): put back on the pickup mat, it is
picked, weighed and photographed by an ordinary batch of its context into a new row, and that
row is linked to the lost one (table ``sherd_rerecords``, migration 0005). The lost row is not
changed: it stays the record of what happened.

``start_rerecord`` checks the find ID and notes the context's last number before the batch
(once: a re-record stopped halfway and started again keeps it); ``link_rerecord`` links the one
row the batch numbered after it. No ROS here: the batch is run by the caller (the CLI runs
``rascal run``'s own code).
"""

import datetime
import json
import time

from psycopg2.extras import RealDictCursor

from .errors import FieldError
from .queries import find_sherd

__all__ = ["start_rerecord", "link_rerecord", "rerecord_links"]


def _now(clock):
    return datetime.datetime.fromtimestamp(clock(), tz=datetime.timezone.utc)


def start_rerecord(conn, find_id, who, clock=time.time):
    """Check that ``find_id`` is a lost sherd not yet re-recorded and note where its context's
    numbering stands. Returns ``{sherd_id, context_id, find_id, after_seq, resumed}``;
    FieldError (one line, nothing written) otherwise."""
    if not isinstance(who, str) or not who.strip() or len(who) > 64:
        raise FieldError("--who %r: must name the person (at most 64 characters)" % (who,))
    rec = find_sherd(conn, find_id)
    if rec["status"] != "lost":
        raise FieldError(
            "sherd %s is '%s', not lost: only a lost sherd is re-recorded (a wrong value is "
            "corrected with `rascal edit`)" % (find_id, rec["status"])
        )
    with conn, conn.cursor(cursor_factory=RealDictCursor) as cur:
        cur.execute(
            "SELECT after_seq, new_sherd_id FROM sherd_rerecords WHERE lost_sherd_id = %s "
            "FOR UPDATE",
            (rec["sherd_id"],),
        )
        row = cur.fetchone()
        if row is not None and row["new_sherd_id"] is not None:
            cur.execute("SELECT seq FROM sherds WHERE sherd_id = %s", (row["new_sherd_id"],))
            raise FieldError(
                "sherd %s: already re-recorded as %s-%d"
                % (find_id, rec["context_id"], cur.fetchone()["seq"])
            )
        if row is None:
            cur.execute(
                "SELECT max(seq) AS last FROM sherds WHERE context_id = %s", (rec["context_id"],)
            )
            after = cur.fetchone()["last"]
            cur.execute(
                "INSERT INTO sherd_rerecords (lost_sherd_id, after_seq, started_at, who) "
                "VALUES (%s, %s, %s, %s)",
                (rec["sherd_id"], after, _now(clock), who.strip()),
            )
        else:
            after = row["after_seq"]
    return {
        "sherd_id": rec["sherd_id"],
        "context_id": rec["context_id"],
        "find_id": rec["find_id"],
        "after_seq": after,
        "resumed": row is not None,
    }


def link_rerecord(conn, started, clock=time.time):
    """After the batch: link the one row numbered after ``started['after_seq']`` to the lost
    sherd. Returns ``(new find ID or None, [find IDs numbered since])``: None when none or
    several were numbered (then nothing is linked and the caller says why)."""
    with conn, conn.cursor(cursor_factory=RealDictCursor) as cur:
        cur.execute(
            "SELECT sherd_id, seq, status::text AS status FROM sherds "
            "WHERE context_id = %s AND seq > %s ORDER BY seq",
            (started["context_id"], started["after_seq"]),
        )
        rows = cur.fetchall()
        found = ["%s-%d" % (started["context_id"], r["seq"]) for r in rows]
        if len(rows) != 1:
            return None, found
        new = rows[0]
        now = _now(clock)
        cur.execute(
            "UPDATE sherd_rerecords SET new_sherd_id = %s, linked_at = %s "
            "WHERE lost_sherd_id = %s AND new_sherd_id IS NULL RETURNING who",
            (new["sherd_id"], now, started["sherd_id"]),
        )
        linked = cur.fetchone()
        if linked is None:
            raise FieldError("sherd %s: already re-recorded" % started["find_id"])
        for sherd_id, detail in (
            (started["sherd_id"], {"rerecorded_as": found[0]}),
            (new["sherd_id"], {"rerecord_of": started["find_id"]}),
        ):
            detail["who"] = linked["who"]
            cur.execute(
                "INSERT INTO events (at, context_id, sherd_id, kind, rig, detail) "
                "VALUES (%s, %s, %s, 'rerecorded', NULL, %s)",
                (now, started["context_id"], sherd_id, json.dumps(detail, sort_keys=True)),
            )
    return found[0], found


def rerecord_links(conn, sherd_id):
    """``{'rerecorded_as': find ID or None, 'rerecord_of': find ID or None}`` of one sherd."""
    with conn, conn.cursor() as cur:
        cur.execute(
            "SELECT n.context_id || '-' || n.seq FROM sherd_rerecords r "
            "JOIN sherds n ON n.sherd_id = r.new_sherd_id WHERE r.lost_sherd_id = %s",
            (sherd_id,),
        )
        as_ = cur.fetchone()
        cur.execute(
            "SELECT l.context_id || '-' || l.seq FROM sherd_rerecords r "
            "JOIN sherds l ON l.sherd_id = r.lost_sherd_id WHERE r.new_sherd_id = %s",
            (sherd_id,),
        )
        of = cur.fetchone()
    return {"rerecorded_as": as_[0] if as_ else None, "rerecord_of": of[0] if of else None}
