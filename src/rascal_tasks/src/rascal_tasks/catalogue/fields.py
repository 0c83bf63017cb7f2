"""The sherd record's fields: names, types, units and checks, in one place.

``COLUMNS`` is the export order (what archaeologists import into their own databases); the
checks turn a bad value into a one-line FieldError that names the field and the fix.
"""

import math
import re

from .errors import FieldError

__all__ = [
    "COLUMNS",
    "COLUMN_TYPES",
    "STATUSES",
    "PHASES",
    "check_timings",
    "check_number",
    "check_count",
    "check_text",
    "check_sha256",
    "check_munsell",
]

STATUSES = ("picked", "mass_unstable", "weighed", "photographed", "done", "lost")
# the paper's breakdown of the time per sherd (columns t_<phase>_s)
PHASES = ("locomotion", "grasping", "data_collection", "perception")

# (export column, type, description). Types: text, int, float, timestamp.
COLUMNS = [
    ("find_id", "text", "context id and sequence number, <context>-<seq>"),
    ("site_id", "text", "excavation site code"),
    ("context_id", "text", "context (stratigraphic unit / bag) the sherd came from"),
    ("seq", "int", "sequence number within the context, gap-free from 1"),
    ("status", "text", "picked | mass_unstable | weighed | photographed | done | lost"),
    ("mass_g", "float", "mass [g]; empty when the scale gave none to trust (mass_missing_reason)"),
    ("mass_missing_reason", "text", "why there is no mass (the scale did not settle or tare)"),
    ("length_mm", "float", "maximum length [mm]"),
    ("width_mm", "float", "maximum width across the length [mm]"),
    ("thickness_mm", "float", "wall thickness [mm]"),
    ("vessel_diameter_mm", "float", "the vessel's outer diameter from the sherd's curvature [mm]"),
    ("vessel_diameter_sigma_mm", "float", "its 1-sigma uncertainty [mm]"),
    ("colour_munsell", "text", "Munsell notation of the photographed face, e.g. 5YR 6/4"),
    ("colour_l", "float", "CIE L* (D50) of the photographed face"),
    ("colour_a", "float", "CIE a* (D50)"),
    ("colour_b", "float", "CIE b* (D50)"),
    ("chart_delta_e00", "float", "mean CIEDE2000 of the colour chart after correction"),
    ("px_per_cm", "float", "image scale from the scale bar [px/cm]"),
    ("image_path", "text", "archival image, relative to the archive root"),
    ("image_sha256", "text", "SHA-256 of the archival image file"),
    ("drops", "int", "times the sherd slipped from the gripper"),
    ("grasp_attempts", "int", "grasps tried"),
    ("pickup_x_m", "float", "where it was picked up, x in base_link [m]"),
    ("pickup_y_m", "float", "where it was picked up, y in base_link [m]"),
    ("t_pick_s", "float", "time to find and pick it [s]"),
    ("t_weigh_s", "float", "time to weigh it [s]"),
    ("t_photo_s", "float", "time to photograph it [s]"),
    ("t_discard_s", "float", "time to put it in the discard box [s]"),
    ("t_locomotion_s", "float", "time spent moving the arm, all stations [s]"),
    ("t_grasping_s", "float", "time spent grasping and releasing [s]"),
    ("t_data_collection_s", "float", "time spent weighing and photographing [s]"),
    ("t_perception_s", "float", "time spent detecting [s]"),
    ("lost_reason", "text", "why it was recorded as lost"),
    ("bin", "text", "the box it went into: the discard box, or the sorting bin whose rule took it"),
    ("notes", "text", "free text"),
    ("rig", "text", "rig that recorded it"),
    ("software_version", "text", "recording software"),
    ("config_hash", "text", "hash of the site configuration in use"),
    ("picked_at", "timestamp", "when it was picked up (ISO 8601, UTC)"),
    ("weighed_at", "timestamp", "when its mass was recorded (or found untrustworthy)"),
    ("photographed_at", "timestamp", "when its image was archived"),
    ("done_at", "timestamp", "when it was discarded and its record completed"),
    ("lost_at", "timestamp", "when it was recorded as lost"),
    ("updated_at", "timestamp", "last change to the record"),
]
COLUMN_TYPES = {name: kind for name, kind, _ in COLUMNS}

_SHA256 = re.compile(r"^[0-9a-f]{64}$")
# Munsell notation as the colour pipeline writes it ('2.5YR 6/8', '3.4YR 5.6/7.1', 'N5'):
# checked loosely (alphabet and length); the colour code owns the exact grammar
_MUNSELL = re.compile(r"^[0-9A-Za-z][0-9A-Za-z./ ]{0,31}$")


def check_number(field, value, lo=None, hi=None, unit="", allow_none=True, lo_open=False):
    """``value`` as a float within [lo, hi] (or (lo, hi] with lo_open), else FieldError."""
    if value is None:
        if allow_none:
            return None
        raise FieldError("%s: is required (a number%s)" % (field, " in " + unit if unit else ""))
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise FieldError(
            "%s %r: must be a number%s" % (field, value, " in " + unit if unit else "")
        )
    v = float(value)
    rng = "%s%s, %s]" % (
        "(" if lo_open else "[",
        "-inf" if lo is None else "%g" % lo,
        "inf" if hi is None else "%g" % hi,
    )
    if (
        not math.isfinite(v)
        or (lo is not None and (v < lo or (lo_open and v == lo)))
        or (hi is not None and v > hi)
    ):
        raise FieldError(
            "%s %r: must be a finite number in %s%s"
            % (field, value, rng, " " + unit if unit else "")
        )
    return v


def check_count(field, value, hi=1000):
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= hi:
        raise FieldError("%s %r: must be a whole number in [0, %d]" % (field, value, hi))
    return value


def check_text(field, value, max_len=200, allow_none=True):
    if value is None and allow_none:
        return None
    if not isinstance(value, str):
        raise FieldError("%s %r: must be text" % (field, value))
    if len(value) > max_len:
        raise FieldError(
            "%s: is %d characters long, at most %d are allowed" % (field, len(value), max_len)
        )
    if "\x00" in value:
        raise FieldError("%s %r: must not contain NUL characters" % (field, value))
    return value


def check_sha256(field, value):
    if not isinstance(value, str) or not _SHA256.match(value):
        raise FieldError(
            "%s %r: must be 64 lower-case hex digits (hashlib.sha256().hexdigest())"
            % (field, value)
        )
    return value


def check_munsell(field, value):
    if value is None:
        return None
    if not isinstance(value, str) or not _MUNSELL.match(value):
        raise FieldError(
            "%s %r: must be Munsell notation 'hue value/chroma' such as "
            "'2.5YR 6/8' or a neutral such as 'N5'" % (field, value)
        )
    return value


def check_timings(field, timings):
    """``{phase: seconds}`` -> ``{'t_<phase>_s': float}``; phases from PHASES."""
    if timings is None:
        return {}
    if not isinstance(timings, dict):
        raise FieldError(
            "%s %r: must be a dict of seconds per phase (%s)" % (field, timings, ", ".join(PHASES))
        )
    out = {}
    for phase, seconds in timings.items():
        if phase not in PHASES:
            raise FieldError("%s: unknown phase %r (use %s)" % (field, phase, ", ".join(PHASES)))
        out["t_%s_s" % phase] = check_number("%s[%s]" % (field, phase), seconds, 0.0, 1e6, "s")
    return out
