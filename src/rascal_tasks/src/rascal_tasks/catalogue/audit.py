"""Corrections by a person (``rascal edit``), each with its trace in the audit trail.

Only the fields a finds specialist checks by hand may be changed (``EDITABLE``): the mass, the
three dimensions, the Munsell colour and the notes, in the units the catalogue stores (g, mm).
What the rig did is not editable: the status, the times, the image and its hash, the measured
L*a*b*, the provenance. A status stays the record of what happened to the sherd on the rig
(and the CHECK constraints and the resume logic rest on it); a lost sherd found again is
recorded afresh, not edited into ``done``.

A sherd is edited once it is final (done or lost): while the rig may still write to the row,
an edit could be overwritten without a trace. Each changed field gets one ``sherd_edits`` row
(who, when, field, old and new value, reason; migration 0005), and the change, those rows and
an ``edited`` event are one transaction: all of it is committed or none. A value given that
equals the stored one is no change and leaves no row. No ROS here; the connection is passed in.
"""

import datetime
import json
import re
import time
import uuid

from psycopg2.extras import RealDictCursor

from .errors import FieldError
from .fields import check_munsell, check_number, check_text
from .queries import find_sherd, parse_find_id

__all__ = ["EDITABLE", "ALIASES", "EDIT_STATUSES", "parse_assignment", "check_edit", "edit_sherd"]

# column -> (kind, unit, upper bound): the bounds of the rig's own record_* checks
EDITABLE = {
    "mass_g": ("number", "g", 100000.0),
    "length_mm": ("number", "mm", 2000.0),
    "width_mm": ("number", "mm", 2000.0),
    "thickness_mm": ("number", "mm", 500.0),
    "colour_munsell": ("munsell", "", None),
    "notes": ("text", "", 2000),
}
ALIASES = {
    "mass": "mass_g",
    "length": "length_mm",
    "width": "width_mm",
    "thickness": "thickness_mm",
    "colour": "colour_munsell",
    "color": "colour_munsell",
    "munsell": "colour_munsell",
    "note": "notes",
}
EDIT_STATUSES = ("done", "lost")
_FIELD_HINT = "editable: %s (or mass, length, width, thickness, colour)" % ", ".join(EDITABLE)
_WHY_NOT = {
    "status": "the status is the rig's record of what happened; add a note instead",
    "lost_reason": "it is the rig's record of what happened; add a note instead",
    "mass_missing_reason": "it goes when a mass is entered (mass_g=...)",
    "image_path": "the image is the rig's; `rascal verify` checks it",
    "image_sha256": "the image is the rig's; `rascal verify` checks it",
}


def parse_assignment(text):
    """``FIELD=VALUE`` -> ``(column, value)`` converted and checked (numbers in the stored
    unit, optionally written after the number: '17.9', '17.9 g'; notes may be emptied with
    'notes='). FieldError names the field and the fix."""
    if not isinstance(text, str) or "=" not in text:
        raise FieldError(
            "%r: write FIELD=VALUE, e.g. mass_g=17.9 or colour='5YR 6/4' (%s)" % (text, _FIELD_HINT)
        )
    name, value = text.split("=", 1)
    name = name.strip().lower()
    column = ALIASES.get(name, name)
    if column not in EDITABLE:
        why = _WHY_NOT.get(column)
        raise FieldError(
            "field '%s': not editable%s (%s)" % (name, "; " + why if why else "", _FIELD_HINT)
        )
    kind, unit, top = EDITABLE[column]
    if kind == "number":
        return column, _number(column, value, unit, top)
    if kind == "munsell":
        value = value.strip()
        if not value:
            raise FieldError(
                "%s: cannot be emptied; give a Munsell notation such as '5YR 6/4'" % column
            )
        return column, check_munsell(column, value)
    value = check_text(column, value, top, allow_none=False)
    return column, (value if value.strip() else None)


def _number(column, text, unit, top):
    t = text.strip()
    m = re.fullmatch(r"([-+0-9.eE]+)\s*([A-Za-z]*)", t)
    if not t or m is None:
        raise FieldError(
            "%s %r: must be a number in %s, e.g. %s=12.5 (a recorded value cannot be emptied)"
            % (column, text, unit, column)
        )
    if m.group(2) and m.group(2) != unit:
        raise FieldError(
            "%s %r: give it in %s, as the catalogue stores it (e.g. %s=12.5)"
            % (column, text, unit, column)
        )
    try:
        v = float(m.group(1))
    except ValueError:
        raise FieldError("%s %r: must be a number in %s" % (column, text, unit)) from None
    return check_number(column, v, 0.0, top, unit, allow_none=False, lo_open=True)


def _who(who):
    who = check_text("--who", who, 64, allow_none=False)
    if not who.strip() or any(ord(c) < 32 for c in who):
        raise FieldError("--who %r: must name the person making the change" % (who,))
    return who.strip()


def _reason(reason):
    if reason is None or (isinstance(reason, str) and not reason.strip()):
        raise FieldError(
            "--reason: required; say why the value changes, e.g. --reason 'reweighed after "
            "cleaning'"
        )
    return check_text("--reason", reason, 500, allow_none=False).strip()


def check_edit(find_id, assignments, reason, who):
    """The input of an edit checked before anything is read or written: ``(reason, who,
    (context_id, seq), {column: value})``, or FieldError naming the field and the fix."""
    reason = _reason(reason)
    who = _who(who)
    where = parse_find_id(find_id)
    wanted = {}
    for a in assignments or ():
        column, value = parse_assignment(a)
        if column in wanted:
            raise FieldError("%s: given twice; give each field once" % column)
        wanted[column] = value
    if not wanted:
        raise FieldError("nothing to change: give FIELD=VALUE, e.g. mass_g=17.9 (%s)" % _FIELD_HINT)
    return reason, who, where, wanted


def edit_sherd(conn, find_id, assignments, reason, who, clock=time.time):
    """Change the fields of one final sherd and write the audit trail, in one transaction.

    ``assignments`` are ``FIELD=VALUE`` strings (see ``parse_assignment``). Returns
    ``{find_id, sherd_id, change_id, changes: [(column, old, new)]}`` (no changes, no
    rows written, when every value equals the stored one). Raises FieldError (nothing
    written) for an unknown find ID, a field that is not editable, a bad value, a field given
    twice, a missing reason or a sherd still being recorded."""
    reason, who, (context_id, seq), wanted = check_edit(find_id, assignments, reason, who)
    now = datetime.datetime.fromtimestamp(clock(), tz=datetime.timezone.utc)
    change_id = str(uuid.uuid4())
    with conn, conn.cursor(cursor_factory=RealDictCursor) as cur:
        cur.execute(
            "SELECT sherd_id, status::text AS status, mass_missing_reason, "
            + ", ".join(EDITABLE)
            + " FROM sherds WHERE context_id = %s AND seq = %s FOR UPDATE",
            (context_id, seq),
        )
        row = cur.fetchone()
        if row is not None:
            changes = _apply(
                cur, row, wanted, find_id, context_id, seq, now, who, reason, change_id
            )
    if row is None:
        find_sherd(conn, find_id)  # raises the one line naming what the catalogue holds
        raise FieldError("find id '%s': no such sherd" % find_id)
    return {
        "find_id": find_id,
        "sherd_id": row["sherd_id"],
        "change_id": change_id if changes else None,
        "changes": changes,
    }


def _apply(cur, row, wanted, find_id, context_id, seq, now, who, reason, change_id):
    """The UPDATE, its audit rows and the event, inside the caller's transaction; returns
    ``[(column, old, new)]``."""
    if row["status"] not in EDIT_STATUSES:
        raise FieldError(
            "sherd %s is '%s': still being recorded; edit it once it is done or lost "
            "(`rascal run --context %s` finishes it)" % (find_id, row["status"], context_id)
        )
    changes = [(c, row[c], v) for c, v in wanted.items() if row[c] != v]
    # a mass entered by hand replaces the reason why the scale gave none
    if any(c == "mass_g" for c, _, _ in changes) and row["mass_missing_reason"] is not None:
        changes.append(("mass_missing_reason", row["mass_missing_reason"], None))
    if not changes:
        return changes
    cur.execute(
        "UPDATE sherds SET "
        + ", ".join("%s = %%s" % c for c, _, _ in changes)  # columns: EDITABLE's keys only
        + ", updated_at = %s WHERE sherd_id = %s",
        [new for _, _, new in changes] + [now, row["sherd_id"]],
    )
    for column, old, new in changes:
        cur.execute(
            "INSERT INTO sherd_edits (sherd_id, change_id, at, who, field, old_value, "
            "new_value, reason) VALUES (%s, %s, %s, %s, %s, %s, %s, %s)",
            (
                row["sherd_id"],
                change_id,
                now,
                who,
                column,
                json.dumps(old),
                json.dumps(new),
                reason,
            ),
        )
    detail = {
        "seq": seq,
        "change_id": change_id,
        "who": who,
        "fields": [c for c, _, _ in changes],
        "reason": reason,
    }
    cur.execute(
        "INSERT INTO events (at, context_id, sherd_id, kind, rig, detail) "
        "VALUES (%s, %s, %s, 'edited', NULL, %s)",
        (now, context_id, row["sherd_id"], json.dumps(detail, sort_keys=True)),
    )
    return changes
