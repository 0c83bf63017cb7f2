"""Several rigs, one catalogue: each rig's PostgreSQL replicated to a central server.

Each rig records into its own PostgreSQL, as before, so it keeps working without a network.
The central server subscribes to every rig's publication ``rascal_rig`` (PostgreSQL's own
logical replication; the rigs need ``wal_level = logical``): the tables in ``PUBLISHED`` arrive
there row by row, in commit order, and a rig that was offline is sent what it committed in the
meantime from its replication slot when it comes back (nothing lost, nothing applied twice).

Identity (migration 0007): ``add_rig`` gives each rig a node number from the central server;
the rig's keys (sherd_id, event_id, edit_id) come from its own block of 2^40, so rows of two
rigs never share a primary key. Find IDs (``<context>-<seq>``) stay unique because a context is
*claimed* by one rig at a time on the central server (``claim_context``, called when a rig opens
a context): a second rig is refused with one line naming the rig that holds it. A rig that
cannot reach the central server records under a *provisional* claim, registered on its next
contact; a context two rigs both took offline is a *clash* that ``status`` lists with the find
IDs recorded twice (the central server keeps both rows: replication never stops on it).

The central server (``init_central``): the same migrations, plus a trigger that lets a site or
context row sent by a second rig fall through (the first copy stays), and (context_id, seq) as
an index instead of a unique constraint, so no row a rig sends is ever refused.

Archival images travel separately (``push_archive``: a copy checked file by file against the
SHA-256 the catalogue holds; or rsync); ``verify_central`` checks the central archive against
the replicated catalogue. Errors are one line (CatalogueError and subclasses).
"""

import datetime
import hashlib
import os
import re
import shutil

import psycopg2
import psycopg2.extras

from .errors import CatalogueError, ConnectionLostError, FieldError

__all__ = [
    "PUBLICATION",
    "PUBLISHED",
    "CentralError",
    "ContextClaimed",
    "init_central",
    "add_rig",
    "rig_status",
    "claim_context",
    "release_context",
    "push_archive",
    "verify_central",
    "central_duplicates",
    "subscription_name",
]

PUBLICATION = "rascal_rig"
# every table of the catalogue that a rig writes (not catalogue_identity, rig_node,
# context_claims, central_rigs, schema_migrations: those are each database's own)
PUBLISHED = ("sites", "contexts", "sherds", "events", "sherd_edits", "sherd_rerecords")
CLAIM_TIMEOUT = 3.0  # seconds to wait for the central server when claiming
NODE_BITS = 40
_RIG_NAME = re.compile(r"^[a-z0-9_][a-z0-9_-]{0,39}$")
_CHUNK = 1 << 20


class CentralError(CatalogueError):
    """Something about the central server or a rig's link to it (exit 3)."""


class ContextClaimed(CatalogueError):
    """Another rig holds the context (exit 4: busy)."""


def subscription_name(rig_name):
    return "rascal_" + rig_name.replace("-", "_")


def _first_line(exc):
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0]


def _mask(dsn):
    dsn = re.sub(r"(://[^:/@]*:)[^@]*@", r"\1***@", dsn)
    return re.sub(r"(password\s*=\s*)\S+", r"\1***", dsn)


def _connect(dsn, timeout, what):
    try:
        conn = psycopg2.connect(
            dsn, connect_timeout=max(1, int(round(timeout))), application_name="rascal-central"
        )
    except psycopg2.OperationalError as e:
        raise ConnectionLostError(
            "%s %s: cannot connect (%s)" % (what, _mask(dsn), _first_line(e)),
            reason=_first_line(e),
        ) from None
    except psycopg2.Error as e:
        raise CentralError(
            "%s %s: not a valid DSN (%s)" % (what, _mask(dsn), _first_line(e))
        ) from None
    return conn


def _check_rig_name(name):
    if not isinstance(name, str) or not _RIG_NAME.match(name):
        raise FieldError(
            "rig name %r: must be 1-40 characters a-z, 0-9, '_' or '-' (it names the "
            "rig's subscription on the central server)" % (name,)
        )
    return name


def node_block(node_no):
    """``(first, last)`` key of node ``node_no``'s block."""
    base = node_no << NODE_BITS
    return base + 1, base + (1 << NODE_BITS) - 1


# --- the central server ---
_CENTRAL_SQL = """
CREATE OR REPLACE FUNCTION public.rascal_central_first_copy() RETURNS trigger
LANGUAGE plpgsql SET search_path = public AS $$  -- the apply worker's search_path is empty
BEGIN
    IF TG_TABLE_NAME = 'sites' THEN
        PERFORM 1 FROM public.sites WHERE site_id = NEW.site_id;
    ELSE
        PERFORM 1 FROM public.contexts WHERE context_id = NEW.context_id;
    END IF;
    IF FOUND THEN
        RETURN NULL;  -- a second rig's copy of a site or context: the first one stays
    END IF;
    RETURN NEW;
END
$$;
DROP TRIGGER IF EXISTS rascal_central_first_copy ON sites;
CREATE TRIGGER rascal_central_first_copy BEFORE INSERT ON sites
    FOR EACH ROW EXECUTE FUNCTION rascal_central_first_copy();
ALTER TABLE sites ENABLE ALWAYS TRIGGER rascal_central_first_copy;
DROP TRIGGER IF EXISTS rascal_central_first_copy ON contexts;
CREATE TRIGGER rascal_central_first_copy BEFORE INSERT ON contexts
    FOR EACH ROW EXECUTE FUNCTION rascal_central_first_copy();
ALTER TABLE contexts ENABLE ALWAYS TRIGGER rascal_central_first_copy;
ALTER TABLE sherds DROP CONSTRAINT IF EXISTS sherds_context_seq_unique;
CREATE INDEX IF NOT EXISTS sherds_find_id ON sherds (context_id, seq);
UPDATE rig_node SET rig_name = 'central' WHERE rig_name IS NULL AND node_no = 0;
"""


def init_central(conn):
    """Make a migrated catalogue the central server (idempotent). Returns True when it
    changed something."""
    with conn, conn.cursor() as cur:
        cur.execute(
            "SELECT count(*) FROM pg_trigger WHERE tgname = 'rascal_central_first_copy' "
            "AND tgenabled = 'A'"
        )
        done = cur.fetchone()[0] == 2
        cur.execute("SELECT node_no FROM rig_node")
        if cur.fetchone()[0] != 0:
            raise CentralError(
                "this catalogue is a rig (it joined a central server); the central server "
                "needs a database of its own"
            )
        cur.execute(_CENTRAL_SQL)
    return not done


def _is_central(cur):
    cur.execute(
        "SELECT count(*) FROM pg_trigger WHERE tgname = 'rascal_central_first_copy' "
        "AND tgenabled = 'A'"
    )
    return cur.fetchone()[0] == 2


def add_rig(central_dsn, rig_dsn, rig_name, publisher_dsn=None, central_dsn_for_rig=None):
    """Join a rig to the central server: a node number from the central server, the rig's
    keys moved into its block, the publication on the rig, the subscription on the central
    server (which first copies what the rig holds, then streams). Idempotent for the same
    rig. ``publisher_dsn`` is the rig as the central server reaches it (default
    ``rig_dsn``); ``central_dsn_for_rig`` the central server as the rig reaches it, for
    claims (default ``central_dsn``). Both servers' roles must be superusers or own the
    tables (the rig's role needs REPLICATION). Returns a dict of what it did."""
    _check_rig_name(rig_name)
    publisher_dsn = publisher_dsn or rig_dsn
    central_dsn_for_rig = central_dsn_for_rig or central_dsn
    sub = subscription_name(rig_name)
    central = _connect(central_dsn, 10, "central server")
    rig = None
    try:
        with central, central.cursor() as cur:
            if not _is_central(cur):
                raise CentralError(
                    "%s is not a central server yet; run `rascal central init` on it first"
                    % _mask(central_dsn)
                )
            cur.execute("LOCK TABLE central_rigs IN SHARE ROW EXCLUSIVE MODE")
            cur.execute("SELECT node_no FROM central_rigs WHERE rig_name = %s", (rig_name,))
            row = cur.fetchone()
            if row is None:
                cur.execute("SELECT COALESCE(max(node_no), 0) + 1 FROM central_rigs")
                node_no = cur.fetchone()[0]
                cur.execute(
                    "INSERT INTO central_rigs (rig_name, node_no, subscription, publisher) "
                    "VALUES (%s, %s, %s, %s)",
                    (rig_name, node_no, sub, _mask(publisher_dsn)),
                )
            else:
                node_no = row[0]
        rig = _connect(rig_dsn, 10, "rig")
        with rig, rig.cursor() as cur:
            cur.execute("SELECT current_setting('wal_level')")
            if cur.fetchone()[0] != "logical":
                raise CentralError(
                    "rig %s: wal_level is not 'logical'; set wal_level = logical in its "
                    "postgresql.conf and restart PostgreSQL" % _mask(rig_dsn)
                )
            cur.execute("SELECT node_no, rig_name FROM rig_node")
            cur_node, cur_name = cur.fetchone()
            if cur_node not in (0, node_no):
                raise CentralError(
                    "rig %s is node %d of a central server already (as '%s'), not node %d"
                    % (_mask(rig_dsn), cur_node, cur_name, node_no)
                )
            try:
                cur.execute(
                    "SELECT rascal_join_node(%s, %s, %s)", (node_no, rig_name, central_dsn_for_rig)
                )
            except psycopg2.Error as e:
                raise CentralError("rig %s: %s" % (_mask(rig_dsn), _first_line(e))) from None
            moved = cur.fetchone()[0]
            cur.execute("SELECT 1 FROM pg_publication WHERE pubname = %s", (PUBLICATION,))
            if cur.fetchone() is None:
                cur.execute(
                    "CREATE PUBLICATION %s FOR TABLE %s" % (PUBLICATION, ", ".join(PUBLISHED))
                )
        central.autocommit = True  # CREATE SUBSCRIPTION may not run inside a transaction
        with central.cursor() as cur:
            cur.execute("SELECT subenabled FROM pg_subscription WHERE subname = %s", (sub,))
            found = cur.fetchone()
            try:
                if found is None:
                    cur.execute(
                        "CREATE SUBSCRIPTION %s CONNECTION %%s PUBLICATION %s "
                        "WITH (copy_data = true)" % (sub, PUBLICATION),
                        (publisher_dsn,),
                    )
                elif not found[0]:
                    cur.execute("ALTER SUBSCRIPTION %s ENABLE" % sub)
            except psycopg2.Error as e:
                raise CentralError(
                    "central server: cannot subscribe to rig '%s' at %s: %s"
                    % (rig_name, _mask(publisher_dsn), _first_line(e))
                ) from None
    finally:
        central.close()
        if rig is not None:
            rig.close()
    return {"rig": rig_name, "node_no": node_no, "moved": moved, "subscription": sub}


def rig_status(central_conn, probe_rigs=True, now=None):
    """One dict per rig added to the central server: its node, whether its subscription is
    enabled and streaming, when the central server last heard from it, the newest row it
    sent, how many sherds it sent, and (``probe_rigs``, the rig reachable from here) its lag:
    how far the central server is behind what the rig committed (bytes of WAL and seconds)."""
    with central_conn, central_conn.cursor(cursor_factory=psycopg2.extras.RealDictCursor) as cur:
        cur.execute(
            "SELECT r.rig_name, r.node_no, r.subscription, r.publisher, s.subenabled AS enabled, "
            "s.subconninfo AS conninfo, st.pid, st.last_msg_receipt_time AS last_seen, "
            "st.latest_end_lsn::text AS applied_lsn, now() AS now "
            "FROM central_rigs r LEFT JOIN pg_subscription s ON s.subname = r.subscription "
            "LEFT JOIN pg_stat_subscription st ON st.subid = s.oid AND st.relid IS NULL "
            "ORDER BY r.node_no"
        )
        rigs = [dict(r) for r in cur.fetchall()]
        for r in rigs:
            lo, hi = node_block(r["node_no"])
            cur.execute(
                "SELECT count(*) AS n, max(updated_at) AS newest FROM sherds "
                "WHERE sherd_id BETWEEN %s AND %s",
                (lo, hi),
            )
            got = cur.fetchone()
            r["sherds"], r["newest_row"] = got["n"], got["newest"]
            cur.execute(
                "SELECT count(*) AS n FROM pg_subscription_rel sr JOIN pg_subscription s "
                "ON s.oid = sr.srsubid WHERE s.subname = %s AND sr.srsubstate <> 'r'",
                (r["subscription"],),
            )
            r["tables_copying"] = cur.fetchone()["n"]
    for r in rigs:
        now = r.pop("now")
        if r["enabled"] is None:
            r["state"] = "no subscription"
        elif not r["enabled"]:
            r["state"] = "disabled"
        elif r["pid"] is None:
            r["state"] = "not connected"
        elif r["tables_copying"]:
            r["state"] = "copying"
        else:
            r["state"] = "streaming"
        r["seen_ago_s"] = (
            (now - r["last_seen"]).total_seconds() if r["last_seen"] is not None else None
        )
        r["lag_bytes"] = r["lag_s"] = r["probe"] = None
        conninfo = r.pop("conninfo")
        if probe_rigs and conninfo:
            r.update(_probe_rig(conninfo, r["subscription"]))
    return rigs


def _probe_rig(conninfo, slot):
    """The rig's own view of its replication slot: WAL not yet confirmed by the central
    server (bytes) and the walsender's replay lag (seconds, 0 when idle and caught up)."""
    try:
        conn = _connect(conninfo, 2, "rig")
    except CatalogueError as e:
        return {"probe": "rig unreachable from here (%s)" % (getattr(e, "reason", None) or e)}
    try:
        with conn, conn.cursor() as cur:
            cur.execute(
                "SELECT pg_wal_lsn_diff(pg_current_wal_lsn(), confirmed_flush_lsn)::bigint, "
                "active FROM pg_replication_slots WHERE slot_name = %s",
                (slot,),
            )
            row = cur.fetchone()
            if row is None:
                return {"probe": "no replication slot %s on the rig" % slot}
            cur.execute(
                "SELECT EXTRACT(epoch FROM COALESCE(replay_lag, '0'::interval))::float8 "
                "FROM pg_stat_replication WHERE application_name = %s",
                (slot,),
            )
            lag = cur.fetchone()
        return {"lag_bytes": row[0], "lag_s": lag[0] if lag else None, "probe": "ok"}
    except psycopg2.Error as e:
        return {"probe": "rig: %s" % _first_line(e)}
    finally:
        conn.close()


def central_duplicates(central_conn):
    """Find IDs the central server holds more than once (only after a clash: two rigs that
    both recorded a context while offline), as ``[(find_id, [rig, ...]), ...]``."""
    with central_conn, central_conn.cursor() as cur:
        cur.execute(
            "SELECT context_id, seq, array_agg(rig ORDER BY sherd_id) FROM sherds "
            "GROUP BY context_id, seq HAVING count(*) > 1 ORDER BY context_id, seq"
        )
        return [("%s-%d" % (c, s), list(rigs)) for c, s, rigs in cur.fetchall()]


# --- claims (on a rig) ---
def _local_link(cat):
    with cat._tx("reading the rig's link to the central server") as cur:
        cur.execute("SELECT node_no, rig_name, central_dsn FROM rig_node")
        return cur.fetchone()


def claim_context(cat, context_id, timeout=CLAIM_TIMEOUT, central_dsn=None):
    """Claim ``context_id`` for this rig (``cat``: its Catalogue) on the central server.

    Standalone catalogue: nothing (None). Online: 'held', or ContextClaimed naming the rig
    that holds it; the rig numbers on after the last number the central server knows of the
    context. Offline: a context this rig holds is recorded on ('held'); any other is claimed
    provisionally ('provisional', one warning line), registered on the next contact.
    ``central_dsn`` overrides the DSN stored when the rig joined."""
    link = _local_link(cat)
    if link is None or not link["central_dsn"]:
        return None
    me = link["rig_name"]
    dsn = central_dsn or link["central_dsn"]
    with cat._tx("reading the context's claim") as cur:
        cur.execute(
            "SELECT state, seq_floor FROM context_claims WHERE context_id = %s", (context_id,)
        )
        local = cur.fetchone()
    if local is not None and local["state"] == "clash":
        raise ContextClaimed(
            "context %s: this rig and another both recorded it while offline (a clash); a "
            "person must look (`rascal central status` on the central server lists the find "
            "IDs recorded twice)" % context_id
        )
    try:
        central = _connect(dsn, timeout, "central server")
    except ConnectionLostError as e:
        if local is not None and local["state"] in ("held", "provisional"):
            return local["state"]
        with cat._tx("claiming the context provisionally") as cur:
            cur.execute(
                "INSERT INTO context_claims (context_id, rig_name, state, claimed_at) "
                "VALUES (%s, %s, 'provisional', now()) ON CONFLICT (context_id) DO UPDATE "
                "SET state = 'provisional', rig_name = EXCLUDED.rig_name, "
                "claimed_at = now(), released_at = NULL",
                (context_id, me),
            )
        cat._log.warning(
            "central server unreachable (%s): context %s claimed provisionally by rig %s; the "
            "claim is registered when the central server is reachable again (if another rig "
            "took the context meanwhile, both records are kept and `rascal central status` "
            "lists them)" % (e.reason or e, context_id, me)
        )
        return "provisional"
    try:
        _register_provisional(cat, central, me, skip=context_id)
        return _claim_online(cat, central, me, context_id)
    except psycopg2.Error as e:
        raise CentralError(
            "central server: claiming %s: %s" % (context_id, _first_line(e))
        ) from None
    finally:
        central.close()


def _claim_online(cat, central, me, context_id, provisional=False):
    """Claim on the central server; returns 'held' (or 'clash' for a provisional claim
    another rig beat), raises ContextClaimed for a new claim another rig holds."""
    with central, central.cursor(cursor_factory=psycopg2.extras.RealDictCursor) as cur:
        cur.execute(
            "INSERT INTO context_claims (context_id, rig_name, state) VALUES (%s, %s, 'held') "
            "ON CONFLICT (context_id) DO NOTHING",
            (context_id, me),
        )
        cur.execute(
            "SELECT rig_name, state, last_seq, claimed_at FROM context_claims "
            "WHERE context_id = %s FOR UPDATE",
            (context_id,),
        )
        row = cur.fetchone()
        if row["rig_name"] != me and row["state"] in ("held", "provisional"):
            if provisional:
                state = "clash"
            else:
                raise ContextClaimed(
                    "context %s is claimed by rig %s (since %s UTC); record it there, or run "
                    "`rascal central release --context %s` on rig %s first"
                    % (
                        context_id,
                        row["rig_name"],
                        row["claimed_at"]
                        .astimezone(datetime.timezone.utc)
                        .strftime("%Y-%m-%d %H:%M:%S"),
                        context_id,
                        row["rig_name"],
                    )
                )
        else:
            state = "held"
        floor = 0
        if state == "held":
            cur.execute(
                "SELECT COALESCE(max(seq), 0) AS top FROM sherds WHERE context_id = %s",
                (context_id,),
            )
            floor = max(cur.fetchone()["top"], row["last_seq"] or 0)
            if row["rig_name"] != me or row["state"] != "held":
                cur.execute(
                    "UPDATE context_claims SET rig_name = %s, state = 'held', seq_floor = %s, "
                    "claimed_at = now(), released_at = NULL, last_seq = NULL "
                    "WHERE context_id = %s",
                    (me, floor, context_id),
                )
    with cat._tx("recording the context's claim") as cur:
        cur.execute(
            "INSERT INTO context_claims (context_id, rig_name, state, seq_floor) "
            "VALUES (%s, %s, %s, %s) ON CONFLICT (context_id) DO UPDATE SET state = "
            "EXCLUDED.state, rig_name = EXCLUDED.rig_name, released_at = NULL, "
            "seq_floor = GREATEST(context_claims.seq_floor, EXCLUDED.seq_floor)",
            (context_id, me, state, floor),
        )
    if state == "clash":
        cat._log.warning(
            "context %s: recorded on this rig while offline, but rig %s claimed it first; both "
            "records are kept on the central server; a person must look"
            % (context_id, row["rig_name"])
        )
    return state


def _register_provisional(cat, central, me, skip=None):
    with cat._tx("reading provisional claims") as cur:
        cur.execute("SELECT context_id FROM context_claims WHERE state = 'provisional'")
        pending = [r["context_id"] for r in cur.fetchall() if r["context_id"] != skip]
    for context_id in pending:
        _claim_online(cat, central, me, context_id, provisional=True)
    return pending


def sync_claims(cat, timeout=CLAIM_TIMEOUT):
    """Register this rig's provisional claims on the central server; returns their
    context IDs (ConnectionLostError when it is unreachable)."""
    link = _local_link(cat)
    if link is None or not link["central_dsn"]:
        raise CentralError(
            "this catalogue has not joined a central server (rascal central add-rig)"
        )
    central = _connect(link["central_dsn"], timeout, "central server")
    try:
        return _register_provisional(cat, central, link["rig_name"])
    finally:
        central.close()


def release_context(cat, context_id, timeout=CLAIM_TIMEOUT):
    """Give up this rig's claim on ``context_id`` (online only), so another rig may record
    it; the central server remembers the last number, which the next rig numbers on from."""
    link = _local_link(cat)
    if link is None or not link["central_dsn"]:
        raise CentralError(
            "this catalogue has not joined a central server (rascal central add-rig)"
        )
    me = link["rig_name"]
    with cat._tx("reading the context") as cur:
        cur.execute(
            "SELECT GREATEST(COALESCE((SELECT max(seq) FROM sherds WHERE context_id = %s), 0), "
            "COALESCE((SELECT seq_floor FROM context_claims WHERE context_id = %s), 0)) AS top, "
            "(SELECT count(*) FROM sherds WHERE context_id = %s AND status NOT IN "
            "('done', 'lost')) AS open",
            (context_id, context_id, context_id),
        )
        got = cur.fetchone()
    if got["open"]:
        raise FieldError(
            "context %s: %d sherds unfinished on this rig; finish the batch (rascal run "
            "--context %s) before releasing it" % (context_id, got["open"], context_id)
        )
    central = _connect(link["central_dsn"], timeout, "central server")
    try:
        with central, central.cursor() as cur:
            cur.execute(
                "UPDATE context_claims SET state = 'released', last_seq = %s, "
                "released_at = now() WHERE context_id = %s AND rig_name = %s "
                "AND state IN ('held', 'provisional') RETURNING 1",
                (got["top"], context_id, me),
            )
            if cur.fetchone() is None:
                raise FieldError(
                    "context %s: not claimed by rig %s on the central server" % (context_id, me)
                )
    finally:
        central.close()
    with cat._tx("releasing the context") as cur:
        cur.execute(
            "UPDATE context_claims SET state = 'released', last_seq = %s, released_at = now() "
            "WHERE context_id = %s",
            (got["top"], context_id),
        )
    return got["top"]


# --- the archive ---
def _sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(_CHUNK), b""):
            h.update(block)
    return h.hexdigest()


def _inside(root, rel):
    full = os.path.realpath(os.path.join(root, rel))
    if os.path.commonpath([full, os.path.realpath(root)]) != os.path.realpath(root):
        raise FieldError("image_path '%s': points outside the archive %s" % (rel, root))
    return full


def push_archive(conn, archive_root, central_root, file_mode=0o644, dir_mode=0o755):
    """Copy every image the rig's catalogue (``conn``) names, and its sidecar, from the
    rig's archive to the central archive (a mounted folder), skipping files already there
    with the right SHA-256; each copy is written to a temporary name, checked against the
    catalogue's SHA-256 and then renamed. Returns ``{'copied', 'present', 'problems'}``."""
    with conn, conn.cursor() as cur:
        cur.execute(
            "SELECT context_id, seq, image_path, image_sha256 FROM sherds "
            "WHERE image_path IS NOT NULL ORDER BY sherd_id"
        )
        rows = cur.fetchall()
    copied = present = 0
    problems = []
    for context_id, seq, rel, sha in rows:
        src = _inside(archive_root, rel)
        dst = _inside(central_root, rel)
        if os.path.exists(dst) and _sha256(dst) == sha:
            present += 1
        else:
            if not os.path.exists(src) or _sha256(src) != sha:
                problems.append(
                    "%s-%d: %s is missing or changed on the rig; `rascal verify` there says "
                    "more" % (context_id, seq, rel)
                )
                continue
            os.makedirs(os.path.dirname(dst), mode=dir_mode, exist_ok=True)
            tmp = dst + ".part"
            shutil.copyfile(src, tmp)
            if _sha256(tmp) != sha:
                os.unlink(tmp)
                problems.append("%s-%d: %s changed while copying" % (context_id, seq, rel))
                continue
            os.chmod(tmp, file_mode)
            os.replace(tmp, dst)
            copied += 1
        side = os.path.splitext(rel)[0] + ".json"
        if os.path.exists(_inside(archive_root, side)):
            shutil.copyfile(_inside(archive_root, side), _inside(central_root, side) + ".part")
            os.chmod(_inside(central_root, side) + ".part", file_mode)
            os.replace(_inside(central_root, side) + ".part", _inside(central_root, side))
    return {"copied": copied, "present": present, "problems": problems}


def verify_central(central_conn, central_root, context_id=None):
    """Every image the central catalogue names is in the central archive with the SHA-256
    the catalogue holds; one line per missing or changed file, and one per find ID held
    twice."""
    q = (
        "SELECT context_id, seq, rig, image_path, image_sha256 FROM sherds "
        "WHERE image_path IS NOT NULL"
    )
    args = []
    if context_id is not None:
        q += " AND context_id = %s"
        args.append(context_id)
    with central_conn, central_conn.cursor() as cur:
        cur.execute(q + " ORDER BY context_id, seq, sherd_id", args)
        rows = cur.fetchall()
    problems = []
    for ctx, seq, rig, rel, sha in rows:
        path = _inside(central_root, rel)
        if not os.path.exists(path):
            problems.append(
                "missing: %s-%d (rig %s): %s; push the rig's archive (`rascal central "
                "push-archive` on rig %s)" % (ctx, seq, rig, rel, rig)
            )
        elif _sha256(path) != sha:
            problems.append(
                "changed: %s-%d (rig %s): %s does not have the SHA-256 the catalogue holds; "
                "push it again from rig %s" % (ctx, seq, rig, rel, rig)
            )
    for find_id, rigs in central_duplicates(central_conn):
        if context_id is None or find_id.startswith(context_id + "-"):
            problems.append(
                "twice: %s recorded by %s (a clash); a person must look"
                % (find_id, ", ".join(rigs))
            )
    return problems, len(rows)
