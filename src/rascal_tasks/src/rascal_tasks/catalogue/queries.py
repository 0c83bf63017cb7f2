"""Reading the catalogue as an archaeologist does: the contexts with their totals
(``rascal contexts``), one sherd by its find ID with its history (``rascal show``), and sherds
chosen by context, status, mass, length, colour and date (``rascal search``).

Every value from the user reaches SQL as a query parameter. Context IDs are opaque strings
here: they are looked up, never parsed or checked against a pattern. Times are returned as
aware datetimes; ``local_iso`` writes them in the local time zone with its offset. No ROS here;
the connection is passed in.
"""

import datetime
import json
import re
import unicodedata

from psycopg2.extras import RealDictCursor

from .errors import FieldError
from .fields import COLUMNS, STATUSES, check_number

__all__ = [
    "parse_find_id",
    "parse_when",
    "local_iso",
    "contexts_summary",
    "find_sherd",
    "sherd_history",
    "search_sherds",
    "format_table",
    "to_jsonable",
]

_FIND_ID = re.compile(r"^(.+)-([1-9][0-9]{0,8})$", re.S)
_COLOUR_PREFIX = re.compile(r"^[0-9A-Za-z][0-9A-Za-z./ ]{0,31}$")
_EXPORT_ORDER = [name for name, _, _ in COLUMNS]
# when a sherd was last recorded by the rig: the latest state change (an edit is not one)
_LAST_RECORDED = "greatest(s.picked_at, s.weighed_at, s.photographed_at, s.done_at, s.lost_at)"


def parse_find_id(find_id):
    """``(context_id, seq)`` of a find ID ``<context>-<seq>`` (the context may itself hold
    '-'); FieldError naming the form otherwise."""
    if not isinstance(find_id, str) or "\x00" in find_id or not _FIND_ID.match(find_id):
        raise FieldError(
            "find id %r: must be <context>-<number> as `rascal search` lists it, "
            "e.g. TR1-1023-4" % (find_id,)
        )
    m = _FIND_ID.match(find_id)
    return _nfc(m.group(1)), int(m.group(2))


def _nfc(text):
    """Context IDs are stored NFC-normalised: 'Köln' typed decomposed still finds 'Köln'."""
    return unicodedata.normalize("NFC", text)


def parse_when(text, field, end=False):
    """A date ``YYYY-MM-DD`` or an ISO 8601 date and time as an aware datetime; times without
    an offset are local. A bare date stands for its whole (local) day: with ``end`` the first
    moment after it, so ``--until 2026-11-23`` includes that day."""
    if not isinstance(text, str):
        raise FieldError("%s %r: must be a date YYYY-MM-DD" % (field, text))
    try:
        if re.fullmatch(r"\d{4}-\d{2}-\d{2}", text.strip()):
            day = datetime.date.fromisoformat(text.strip())
            if end:
                day += datetime.timedelta(days=1)
            when = datetime.datetime(day.year, day.month, day.day)
        else:
            when = datetime.datetime.fromisoformat(text.strip())
    except ValueError:
        raise FieldError(
            "%s %r: must be a date YYYY-MM-DD or a date and time YYYY-MM-DDTHH:MM[:SS][+HH:MM]"
            % (field, text)
        ) from None
    return when.astimezone() if when.tzinfo is None else when


def local_iso(ts):
    """An aware datetime as ISO 8601 in the local time zone, with its offset; None stays."""
    if ts is None:
        return None
    return ts.astimezone().isoformat(timespec="seconds")


def _ordered(row):
    """A sherd row with the export's columns first (in their order), then any others."""
    rec = dict(row)
    rec["find_id"] = "%s-%d" % (rec["context_id"], rec["seq"])
    first = [k for k in _EXPORT_ORDER if k in rec]
    return {k: rec[k] for k in first + sorted(k for k in rec if k not in first)}


_SELECT_SHERDS = (
    "SELECT s.*, s.status::text AS status, c.site_id FROM sherds s JOIN contexts c "
    "USING (context_id)"
)


def contexts_summary(conn):
    """Every context, by ID: ``{context_id, site_id, description, sherds, by_status
    {status: n for every status}, rerecorded (lost sherds recorded again in a row of their
    own), mass_g (sum of the recorded masses, a re-recorded sherd's once), without_mass,
    first_recorded, last_recorded}`` (timestamps aware; None for a context without sherds)."""
    with conn, conn.cursor(cursor_factory=RealDictCursor) as cur:
        cur.execute(
            "SELECT c.context_id, c.site_id, c.description, count(s.sherd_id) AS sherds, "
            "count(r.lost_sherd_id) AS rerecorded, "
            "sum(s.mass_g) FILTER (WHERE r.lost_sherd_id IS NULL) AS mass_g, "
            "count(s.sherd_id) FILTER (WHERE s.mass_g IS NULL AND r.lost_sherd_id IS NULL) "
            "AS without_mass, "
            "min(s.picked_at) AS first_recorded, max(" + _LAST_RECORDED + ") AS last_recorded "
            "FROM contexts c LEFT JOIN sherds s USING (context_id) "
            "LEFT JOIN sherd_rerecords r "
            "ON r.lost_sherd_id = s.sherd_id AND r.new_sherd_id IS NOT NULL "
            "GROUP BY c.context_id, c.site_id, c.description ORDER BY c.context_id"
        )
        rows = [dict(r) for r in cur.fetchall()]
        cur.execute(
            "SELECT context_id, status::text AS status, count(*) AS n FROM sherds "
            "GROUP BY context_id, status"
        )
        counts = {(r["context_id"], r["status"]): r["n"] for r in cur.fetchall()}
    for r in rows:
        r["by_status"] = {st: counts.get((r["context_id"], st), 0) for st in STATUSES}
    return rows


def find_sherd(conn, find_id):
    """The row of one sherd (every column, export columns first, plus ``find_id`` and
    ``site_id``), or FieldError naming what the catalogue does hold."""
    context_id, seq = parse_find_id(find_id)
    with conn, conn.cursor(cursor_factory=RealDictCursor) as cur:
        cur.execute(_SELECT_SHERDS + " WHERE s.context_id = %s AND s.seq = %s", (context_id, seq))
        row = cur.fetchone()
        if row is not None:
            return _ordered(row)
        cur.execute(
            "SELECT count(s.sherd_id) AS n FROM contexts c LEFT JOIN sherds s "
            "USING (context_id) WHERE c.context_id = %s GROUP BY c.context_id",
            (context_id,),
        )
        found = cur.fetchone()
    if found is None:
        raise FieldError(
            "find id '%s': no context '%s' in the catalogue; `rascal contexts` lists them"
            % (find_id, context_id)
        )
    raise FieldError(
        "find id '%s': no such sherd; context '%s' holds sherds 1 to %d"
        % (find_id, context_id, found["n"])
        if found["n"]
        else "find id '%s': no such sherd; context '%s' holds none" % (find_id, context_id)
    )


def sherd_history(conn, sherd_id):
    """``(events, edits)`` of one sherd, oldest first: what the rig recorded (the event log)
    and what people changed (the audit trail of ``rascal edit``)."""
    with conn, conn.cursor(cursor_factory=RealDictCursor) as cur:
        cur.execute(
            "SELECT at, kind, rig, detail FROM events WHERE sherd_id = %s ORDER BY event_id",
            (sherd_id,),
        )
        events = [dict(r) for r in cur.fetchall()]
        cur.execute(
            "SELECT at, who, field, old_value, new_value, reason, change_id::text AS change_id "
            "FROM sherd_edits WHERE sherd_id = %s ORDER BY edit_id",
            (sherd_id,),
        )
        edits = [dict(r) for r in cur.fetchall()]
    for e in events:
        e["detail"] = {k: v for k, v in (e["detail"] or {}).items() if k != "op"}
    return events, edits


def _range(field, lo, hi, unit, top):
    lo = check_number(field + "-min", lo, 0.0, top, unit)
    hi = check_number(field + "-max", hi, 0.0, top, unit)
    if lo is not None and hi is not None and lo > hi:
        raise FieldError("%s-min %g is above %s-max %g; swap them" % (field, lo, field, hi))
    return lo, hi


def search_sherds(
    conn,
    context=None,
    statuses=None,
    mass_min=None,
    mass_max=None,
    length_min=None,
    length_max=None,
    colour=None,
    since=None,
    until=None,
    limit=None,
):
    """Sherds matching every filter given, by context and number. Ranges are inclusive (mass
    in g, length in mm; a sherd without the value does not match a range on it); ``colour``
    is a prefix of the Munsell notation, any case ('5YR' matches '5YR 6/4', not '7.5YR 6/4');
    ``since`` (inclusive) and ``until`` (exclusive) are aware datetimes compared with when the
    sherd was picked up."""
    where, args = [], []
    if context is not None:
        if not isinstance(context, str) or "\x00" in context:
            raise FieldError(
                "--context %r: must be a context ID as `rascal contexts` lists it" % (context,)
            )
        where.append("s.context_id = %s")
        args.append(_nfc(context))
    if statuses:
        bad = [s for s in statuses if s not in STATUSES]
        if bad:
            raise FieldError("--status %r: must be one of %s" % (bad[0], ", ".join(STATUSES)))
        where.append("s.status::text = ANY(%s)")
        args.append(list(statuses))
    for column, field, lo, hi, unit, top in (
        ("mass_g", "--mass", mass_min, mass_max, "g", 100000.0),
        ("length_mm", "--length", length_min, length_max, "mm", 2000.0),
    ):
        lo, hi = _range(field, lo, hi, unit, top)
        if lo is not None:
            where.append("s.%s >= %%s" % column)  # column names are constants above
            args.append(lo)
        if hi is not None:
            where.append("s.%s <= %%s" % column)
            args.append(hi)
    if colour is not None:
        if not isinstance(colour, str) or not _COLOUR_PREFIX.match(colour):
            raise FieldError(
                "--colour %r: must be the start of a Munsell notation, e.g. 5YR or '10YR 6'"
                % (colour,)
            )
        where.append("upper(left(s.colour_munsell, length(%s))) = upper(%s)")
        args += [colour, colour]
    for field, when in (("--since", since), ("--until", until)):
        if when is not None and (not isinstance(when, datetime.datetime) or when.tzinfo is None):
            raise FieldError("%s %r: must be an aware datetime (parse_when)" % (field, when))
    if since is not None and until is not None and since >= until:
        raise FieldError(
            "--since %s is not before --until %s; swap them" % (local_iso(since), local_iso(until))
        )
    if since is not None:
        where.append("s.picked_at >= %s")
        args.append(since)
    if until is not None:
        where.append("s.picked_at < %s")
        args.append(until)
    q = _SELECT_SHERDS + (" WHERE " + " AND ".join(where) if where else "")
    q += " ORDER BY s.context_id, s.seq"
    if limit is not None:
        if isinstance(limit, bool) or not isinstance(limit, int) or limit < 1:
            raise FieldError("--limit %r: must be a whole number >= 1" % (limit,))
        q += " LIMIT %s"
        args.append(limit)
    with conn, conn.cursor(cursor_factory=RealDictCursor) as cur:
        cur.execute(q, args)
        return [_ordered(r) for r in cur.fetchall()]


def format_table(headers, rows, right=()):
    """Lines of a plain text table: a header, a rule, one line per row; columns whose index is
    in ``right`` are right-aligned (numbers). None shows as '–'."""
    cells = [[("–" if v is None else str(v)) for v in row] for row in rows]
    widths = [max([len(h)] + [len(r[i]) for r in cells]) for i, h in enumerate(headers)]

    def line(values):
        parts = [
            v.rjust(widths[i]) if i in right else v.ljust(widths[i]) for i, v in enumerate(values)
        ]
        return "  ".join(parts).rstrip()

    return [line(headers), line(["-" * w for w in widths])] + [line(r) for r in cells]


def to_jsonable(value):
    """Rows as JSON values: datetimes as local ISO 8601 with offset."""
    return json.loads(json.dumps(value, default=_json_default))


def _json_default(value):
    if isinstance(value, datetime.datetime):
        return local_iso(value)
    if isinstance(value, datetime.date):
        return value.isoformat()
    raise TypeError("cannot write %r as JSON" % (value,))
