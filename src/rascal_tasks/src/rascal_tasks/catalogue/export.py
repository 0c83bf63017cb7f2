"""Export of a context's sherds as CSV or JSON, in the column order of ``fields.COLUMNS``.

CSV: a header row, then one row per sherd; floats rounded to the precision they were measured
to (``PRECISION``: 0.1 g, 0.1 mm, …) and written with Python's shortest representation,
timestamps as ISO 8601 in UTC, a missing value as an empty cell. JSON rounds the same way.
JSON: ``{"format", "version", "context": {...}, "columns": [...], "sherds": [{...}]}`` with
numbers as numbers and missing values as null. ``parse_csv`` reads the CSV back into the
same Python values (the round trip the tests check).
"""

import csv
import datetime
import decimal
import io
import json

from .context_id import validate_context_id
from .errors import FieldError
from .fields import COLUMN_TYPES, COLUMNS

__all__ = [
    "EXPORT_FORMAT",
    "PRECISION",
    "export_records",
    "rounded",
    "to_csv",
    "to_json",
    "parse_csv",
    "json_default",
]

EXPORT_FORMAT = "rascal-catalogue-export"
EXPORT_VERSION = 1

# Decimal places a float column is exported with: what the rig resolves, not the 14 digits of
# a double (scale 0.1 g; outline 0.1 mm; L*a*b* 0.1; pickup 0.1 mm; times 0.1 s).
PRECISION = {
    "mass_g": 1,
    "length_mm": 1,
    "width_mm": 1,
    "thickness_mm": 1,
    "vessel_diameter_mm": 0,
    "vessel_diameter_sigma_mm": 0,
    "colour_l": 1,
    "colour_a": 1,
    "colour_b": 1,
    "chart_delta_e00": 2,
    "px_per_cm": 1,
    "pickup_x_m": 4,
    "pickup_y_m": 4,
}
_TIME_PLACES = 1  # every t_*_s column


def rounded(name, value):
    """``value`` of float column ``name`` rounded to its exported precision (None stays)."""
    if value is None:
        return None
    places = PRECISION.get(name, _TIME_PLACES if name.startswith("t_") else None)
    if places is None:
        return float(value)
    # half up on the decimal a person reads (30.25 mm is 30.3, as on paper), not half-even
    # on the binary double (round(30.25, 1) is 30.2)
    exact = decimal.Decimal(repr(float(value)))
    return float(exact.quantize(decimal.Decimal(1).scaleb(-places), decimal.ROUND_HALF_UP))


_SELECT = (
    "SELECT s.context_id || '-' || s.seq AS find_id, c.site_id, s.context_id, s.seq, "
    "s.status::text AS status, mass_g, mass_missing_reason, length_mm, width_mm, thickness_mm, "
    "vessel_diameter_mm, vessel_diameter_sigma_mm, "
    "colour_munsell, "
    "colour_l, colour_a, colour_b, chart_delta_e00, px_per_cm, image_path, image_sha256, drops, "
    "grasp_attempts, pickup_x_m, pickup_y_m, t_pick_s, t_weigh_s, t_photo_s, t_discard_s, "
    "t_locomotion_s, t_grasping_s, t_data_collection_s, t_perception_s, "
    "lost_reason, bin, notes, rig, software_version, config_hash, picked_at, weighed_at, "
    "photographed_at, done_at, lost_at, updated_at "
    "FROM sherds s JOIN contexts c USING (context_id) WHERE s.context_id = %s ORDER BY s.seq"
)


def export_records(conn, context_id):
    """``(context, records)``: the context's row and its sherds as dicts in export order."""
    context_id = validate_context_id(context_id)
    with conn, conn.cursor() as cur:
        cur.execute(
            "SELECT context_id, site_id, description, created_at FROM contexts "
            "WHERE context_id = %s",
            (context_id,),
        )
        ctx = cur.fetchone()
        if ctx is None:
            raise FieldError(
                "context id '%s': not in the catalogue (check the id; "
                "`rascal db status` shows the database in use)" % context_id
            )
        context = dict(
            zip(("context_id", "site_id", "description", "created_at"), ctx, strict=True)
        )
        cur.execute(_SELECT, (context_id,))
        names = [d[0] for d in cur.description]
        assert names == [c[0] for c in COLUMNS], names
        records = [dict(zip(names, row, strict=True)) for row in cur.fetchall()]
    return context, records


def _utc(ts):
    return ts.astimezone(datetime.timezone.utc).isoformat()


def json_default(value):
    if isinstance(value, datetime.datetime):
        return _utc(value)
    raise TypeError("cannot export %r" % (value,))


def _rounded_record(rec):
    return {
        name: rounded(name, rec[name]) if kind == "float" else rec[name]
        for name, kind, _ in COLUMNS
    }


def to_json(context, records):
    doc = {
        "format": EXPORT_FORMAT,
        "version": EXPORT_VERSION,
        "context": context,
        "columns": [{"name": n, "type": t, "description": d} for n, t, d in COLUMNS],
        "sherds": [_rounded_record(r) for r in records],
    }
    return json.dumps(doc, default=json_default, indent=1, ensure_ascii=False) + "\n"


def _cell(name, kind, value):
    if value is None:
        return ""
    if kind == "float":
        return repr(rounded(name, value))
    if kind == "timestamp":
        return _utc(value)
    return str(value)


def to_csv(records):
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow([name for name, _, _ in COLUMNS])
    for rec in records:
        w.writerow([_cell(name, kind, rec[name]) for name, kind, _ in COLUMNS])
    return out.getvalue()


def _parse(kind, text):
    if text == "":
        return None
    if kind == "int":
        return int(text)
    if kind == "float":
        return float(text)
    if kind == "timestamp":
        return datetime.datetime.fromisoformat(text)
    return text


def parse_csv(text):
    """Records from ``to_csv`` output, with the column types restored."""
    reader = csv.DictReader(io.StringIO(text))
    return [{k: _parse(COLUMN_TYPES[k], v) for k, v in row.items()} for row in reader]
