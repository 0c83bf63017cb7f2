"""A context's sherds as files Field Desktop (iDAI.field, dainst/idai-field) imports as they are:
resources of its ``Pottery`` category (a subcategory of ``Find``), as CSV or JSON Lines, and
the archival images beside them for Field's image import. No ROS here.

The rules are Field Desktop's own import code (desktop/src/app/components/import: the CSV
parser ``convert-csv-rows.ts`` / ``convert-fields.ts``, ``native-jsonl-parser.ts``,
``remove-null-properties.ts``, ``import-validator.ts``) and its default configuration
(core/config/Library/Categories.json, core/src/configuration/built-in-configuration.ts,
core/src/model/input-types/measurement.ts):

- a header is a field identifier; ``a.0.b`` is entry 0 of list ``a``; no header may be the
  prefix of another (``dimensionLength`` beside ``dimensionLength.0.inputValue`` fails), list
  indices run 0, 1, … without a gap, and every row has one cell per header;
- the file name names the category (a ``.``-separated segment ``Pottery``); cells are
  separated by ``,``, lists inside a cell by ``;``; an empty cell is "no value";
- ``weight`` and ``dimension*`` are measurement lists: each entry needs ``inputValue`` (a
  number; 0 counts as missing and a negative one is refused) and ``inputUnit`` (``mg|g|kg``
  for weight, ``mm|cm|m`` for a dimension); ``isImprecise`` is ``true|false``; an entry some
  rows leave half empty is refused (``validate``: every row of a file fills every entry);
- ``relations.isChildOf`` is one identifier (never a list) of a resource that already exists
  in the project (the context's Feature / stratigraphic unit); ``relations.isDepictedIn`` a
  list of image identifiers, which for images added with Field's image import are their file
  names: import the images first, then the Pottery file;
- strings must not be empty; Field trims them and drops zero-width characters, so a value
  with either would not arrive as written and is refused here.

What RASCAL records and where it goes: ``identifier`` = the find ID (``<context>-<seq>``,
stable, unique); ``shortDescription``; ``weight.0`` (g); ``dimensionLength.0``,
``dimensionWidth.0``, ``dimensionThickness.0`` (mm); ``clayColorOutsideMunsell`` (the Munsell
notation, left out while the colour stage gives none); ``description`` (status, lost reason,
why a mass is missing, drops, notes, the recording rig and software); ``relations.isChildOf``
(the context's identifier in the Field project: ``parent``); ``relations.isDepictedIn`` (the
exported image). Values are rounded to 0.1 g / 0.1 mm; one that would round to 0 is refused.
Sherds not yet done or lost (a batch still running or stopped) are left out and counted.
"""

import base64
import csv
import io
import json
import math
import os
import shutil
import tempfile
import urllib.error
import urllib.parse
import urllib.request

from .context_id import context_folder
from .errors import ArchiveError, FieldError
from .export import rounded

__all__ = [
    "CATEGORY",
    "FieldDesktopError",
    "FIELDS",
    "build_resources",
    "validate",
    "csv_files",
    "jsonl_text",
    "write_export",
    "image_list",
    "push",
]

CATEGORY = "Pottery"
IMAGE_CATEGORY = "Photo"  # a subcategory of Image in Field's default configuration
IMAGE_LIST = "field-image-import.json"  # in images/: the body of Field's POST /fileImport
ARRAY_SEPARATOR = ";"  # Field's CsvExportConsts.ARRAY_SEPARATOR
_ZERO_WIDTH = "\u200b\u200c\u200d\ufeff"  # dropped by Field's CSV parser
MEASUREMENT_UNITS = {"weight": ("mg", "g", "kg"), "dimension": ("mm", "cm", "m")}
_MEASUREMENT_KEYS = {"inputValue", "inputUnit", "isImprecise"}
# the fields written, with Field's input type (Find's and Pottery's default configuration)
FIELDS = {
    "identifier": "input",
    "shortDescription": "input",
    "description": "text",
    "weight": "weight",
    "dimensionLength": "dimension",
    "dimensionWidth": "dimension",
    "dimensionThickness": "dimension",
    "clayColorOutsideMunsell": "input",
}
RELATIONS = {"isChildOf": "one", "isDepictedIn": "list"}
# the RASCAL column behind each measurement field, its unit and precision
_MEASURED = (
    ("weight", "mass_g", "g"),
    ("dimensionLength", "length_mm", "mm"),
    ("dimensionWidth", "width_mm", "mm"),
    ("dimensionThickness", "thickness_mm", "mm"),
)
_SHORT = {
    "weight": "weight",
    "dimensionLength": "length",
    "dimensionWidth": "width",
    "dimensionThickness": "thickness",
}
EXPORTED_STATUSES = ("done", "lost")
DEFAULT_PARENT = "{context}"


class FieldDesktopError(FieldError):
    """A value Field Desktop's importer would refuse; the message names the sherd and field."""


def parent_identifier(template, context_id):
    """The context's identifier in the Field project from the template (``{context}`` is
    RASCAL's context ID; the default is the ID itself)."""
    if not isinstance(template, str) or not template.strip():
        raise FieldError(
            "export.field_desktop.parent %r: must be the parent's identifier or a template "
            "with {context}, e.g. 'SE {context}'" % (template,)
        )
    try:
        return template.format(context=context_id)
    except (KeyError, IndexError, ValueError) as e:
        raise FieldError(
            "export.field_desktop.parent %r: not a template (%s); write {context} for the "
            "context id and {{ }} for braces" % (template, e)
        ) from None


def image_name(context_id, seq):
    """The file name an exported image gets (and the identifier Field's image import gives
    it): the find ID made safe as a file name, unique across contexts."""
    return "%s-%d.png" % (context_folder(context_id), seq)


def _description(rec):
    parts = []
    if rec["status"] == "lost":
        parts.append("lost during recording: %s" % rec["lost_reason"])
    if rec["mass_g"] is None and rec.get("mass_missing_reason"):
        parts.append("no mass: %s" % rec["mass_missing_reason"])
    if rec.get("vessel_diameter_mm"):
        parts.append(
            "vessel diameter about %.0f ± %.0f mm (from the sherd's curvature)"
            % (rec["vessel_diameter_mm"], rec["vessel_diameter_sigma_mm"])
        )
    if rec.get("drops"):
        parts.append(
            "dropped %d time%s by the gripper" % (rec["drops"], "" if rec["drops"] == 1 else "s")
        )
    if rec.get("notes"):
        parts.append("notes: %s" % rec["notes"])
    recorded = "recorded by RASCAL %s on rig %s" % (rec.get("software_version"), rec.get("rig"))
    when = rec.get("done_at") or rec.get("lost_at")
    if when is not None:
        recorded += " at %s" % when.strftime("%Y-%m-%d %H:%M %Z").strip()
    parts.append(recorded)
    if rec.get("image_sha256"):
        parts.append("archival image %s (SHA-256 %s)" % (rec["image_path"], rec["image_sha256"]))
    # one line: Field's CSV keeps line breaks only inside quotes, and they read badly in its list
    return "; ".join(" ".join(str(p).split()) for p in parts)


def build_resources(context_id, records, parent, images=True):
    """``(resources, left_out)``: one Field resource (a dict shaped as in Field's JSON Lines)
    per done or lost sherd, and the find IDs of the sherds left out (unfinished)."""
    resources, left_out = [], []
    for rec in records:
        if rec["status"] not in EXPORTED_STATUSES:
            left_out.append(rec["find_id"])
            continue
        res = {
            "identifier": rec["find_id"],
            "category": CATEGORY,
            "shortDescription": "sherd %d of context %s" % (rec["seq"], context_id),
        }
        for field, column, unit in _MEASURED:
            value = rec.get(column)
            if value is None:
                continue
            res[field] = [
                {"inputValue": rounded(column, value), "inputUnit": unit, "isImprecise": False}
            ]
        if rec.get("colour_munsell"):
            res["clayColorOutsideMunsell"] = rec["colour_munsell"]
        res["description"] = _description(rec)
        relations = {"isChildOf": parent}
        if images and rec.get("image_path"):
            relations["isDepictedIn"] = [image_name(context_id, rec["seq"])]
        res["relations"] = relations
        resources.append(res)
    return resources, left_out


# --- the importer's rules ---
def _refuse(res, field, why):
    raise FieldDesktopError(
        "sherd %s: %s %s; Field Desktop's import would refuse it (correct it with `rascal "
        "edit`, or leave the sherd out)" % (res.get("identifier", "?"), field, why)
    )


def _check_text(res, field, value):
    if not isinstance(value, str) or value == "":
        _refuse(res, field, "is empty or not text")
    if value != value.strip():
        _refuse(res, field, "%r starts or ends with a space (Field trims it)" % value)
    if any(c in value for c in _ZERO_WIDTH):
        _refuse(res, field, "holds a zero-width character (Field's CSV parser drops it)")
    if "\n" in value or "\r" in value:
        _refuse(res, field, "holds a line break")


def _check_measurement(res, field, kind, entries):
    if not isinstance(entries, list) or not entries:
        _refuse(res, field, "must be a list of measurements")
    for i, m in enumerate(entries):
        where = "%s.%d" % (field, i)
        if not isinstance(m, dict):
            _refuse(res, where, "is not a measurement")
        extra = set(m) - _MEASUREMENT_KEYS
        if extra:
            _refuse(res, where, "has sub-fields %s that this export does not write" % sorted(extra))
        value = m.get("inputValue")
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            _refuse(res, where + ".inputValue", "is %r, not a number" % (value,))
        if not math.isfinite(value) or value <= 0:
            _refuse(res, where + ".inputValue", "is %r; it must be above 0" % (value,))
        if m.get("inputUnit") not in MEASUREMENT_UNITS[kind]:
            _refuse(
                res,
                where + ".inputUnit",
                "is %r; a %s takes %s"
                % (m.get("inputUnit"), kind, "|".join(MEASUREMENT_UNITS[kind])),
            )
        if not isinstance(m.get("isImprecise", False), bool):
            _refuse(res, where + ".isImprecise", "must be true or false")


def validate(resources):
    """Hold each resource against Field Desktop's import rules (see the module's text);
    FieldDesktopError naming the first sherd and field that breaks one."""
    seen = set()
    for res in resources:
        _check_text(res, "identifier", res.get("identifier"))
        if res["identifier"] in seen:
            _refuse(res, "identifier", "is used twice in one import")
        seen.add(res["identifier"])
        if res.get("category") != CATEGORY:
            _refuse(res, "category", "is %r, not %s" % (res.get("category"), CATEGORY))
        for field, value in res.items():
            if field in ("category", "relations"):
                continue
            kind = FIELDS.get(field)
            if kind is None:
                _refuse(res, field, "is not a field of Field's %s category" % CATEGORY)
            if kind in MEASUREMENT_UNITS:
                _check_measurement(res, field, kind, value)
            else:
                _check_text(res, field, value)
        relations = res.get("relations") or {}
        if "isChildOf" not in relations:
            _refuse(res, "relations.isChildOf", "is missing (a find must lie in its context)")
        for name, value in relations.items():
            where = "relations.%s" % name
            shape = RELATIONS.get(name)
            if shape is None:
                _refuse(res, where, "is not a relation this export writes")
            targets = [value] if shape == "one" else value
            if shape == "list" and (not isinstance(value, list) or not value):
                _refuse(res, where, "must be a list of identifiers")
            for t in targets:
                _check_text(res, where, t)
                if ARRAY_SEPARATOR in t:
                    _refuse(res, where, "%r holds ';', Field's list separator" % t)
    return resources


# --- the files ---
def _flatten(res):
    """Field's CSV headers and cells of one resource (``weight.0.inputValue`` …)."""
    cells = {}
    for field, value in res.items():
        if field == "category":
            continue
        if field == "relations":
            for name, target in value.items():
                cells["relations." + name] = (
                    target if isinstance(target, str) else ARRAY_SEPARATOR.join(target)
                )
        elif isinstance(value, list):
            for i, entry in enumerate(value):
                for key, v in entry.items():
                    if isinstance(v, bool):
                        v = "true" if v else "false"
                    elif isinstance(v, float):
                        v = repr(v)
                    cells["%s.%d.%s" % (field, i, key)] = str(v)
        else:
            cells[field] = value
    return cells


def _header_order(keys):
    order = list(FIELDS) + ["relations." + r for r in RELATIONS]
    rank = {k: i for i, k in enumerate(order)}
    return sorted(keys, key=lambda k: (rank.get(k.split(".")[0], rank.get(k, len(order))), k))


def csv_files(name, resources):
    """``[(file name, text)]``: one CSV per set of measurements the rows fill, so that no row
    leaves a cell of a measurement entry empty (a plain field or a relation may be empty: Field
    reads that as no value). Sherds with every measurement go to ``<name>.Pottery.csv``, the
    others to ``<name>-without-<length|width|thickness|weight…>.Pottery.csv``."""
    measured = [field for field, _, _ in _MEASURED]
    groups = {}
    for res in resources:
        has = tuple(f for f in measured if f in res)
        groups.setdefault(has, []).append(_flatten(res))
    files = []
    for has, rows in sorted(groups.items(), key=lambda kv: -len(kv[0])):
        missing = [_SHORT[f] for f in measured if f not in has]
        stem = name if not missing else "%s-without-%s" % (name, "-".join(missing))
        headers = _header_order(set().union(*rows))
        out = io.StringIO()
        w = csv.writer(out, lineterminator="\n")
        w.writerow(headers)
        for cells in rows:
            w.writerow([cells.get(h, "") for h in headers])
        files.append(("%s.%s.csv" % (stem, CATEGORY), out.getvalue()))
    return files


def jsonl_text(resources):
    """Field's JSON Lines import: one resource object per line."""
    return "".join(json.dumps(r, ensure_ascii=False) + "\n" for r in resources)


def image_list(directory, names, category=IMAGE_CATEGORY):
    """The image list of Field Desktop's image import for the files ``names`` of
    ``<directory>/images``: the JSON body of its REST endpoint ``POST /fileImport``
    (``filePaths``: absolute paths, whose file names become the images' identifiers, the names
    ``relations.isDepictedIn`` gives; ``category``: the image category). Import the images
    before the Pottery file, so that the relations find them."""
    folder = os.path.abspath(os.path.join(directory, "images"))
    doc = {
        "filePaths": [os.path.join(folder, name) for name in names],
        "category": category,
        "readCreatorsFromMetadata": False,
    }
    return json.dumps(doc, ensure_ascii=False, indent=1) + "\n"


def export_name(context_id):
    """The file name stem of a context's export: its folder name with '.' as '_' (Field
    reads the category from the '.'-separated parts of the name)."""
    return context_folder(context_id).replace(".", "_")


def write_export(
    directory,
    context_id,
    records,
    archive_root,
    parent,
    fmt="csv",
    file_mode=0o644,
    dir_mode=0o755,
):
    """Validate, then write the export of one context into ``directory``: the Pottery file(s)
    and ``images/<find>.png`` (copies of the archival images) with the list of Field's image
    import, ``images/field-image-import.json`` (``image_list``). Nothing is written when a value
    is refused or a file cannot be read; files appear under their final names only when all
    are complete (written in a temporary folder, then renamed). Returns
    ``{'files': [paths], 'resources': n, 'left_out': [find ids], 'bodies': [(name, text)]}``."""
    resources, left_out = build_resources(context_id, records, parent, images=True)
    validate(resources)
    name = export_name(context_id)
    if fmt == "csv":
        bodies = csv_files(name, resources)
    elif fmt == "jsonl":
        bodies = [("%s.%s.jsonl" % (name, CATEGORY), jsonl_text(resources))]
    else:
        raise FieldError("format %r: must be csv or jsonl" % (fmt,))
    images = []
    depicted = [n for res in resources for n in res["relations"].get("isDepictedIn", [])]
    for rec in records:
        if rec["status"] in EXPORTED_STATUSES and rec.get("image_path"):
            src = os.path.realpath(os.path.join(archive_root, rec["image_path"]))
            if not os.path.isfile(src):
                raise ArchiveError(  # a fault of the archive (exit 3), not of the input
                    "sherd %s: archival image %s is missing from the archive %s; restore it "
                    "(`rascal verify`) or pass --archive" % (rec["find_id"], src, archive_root)
                )
            images.append((image_name(context_id, rec["seq"]), src))
    if sorted(depicted) != sorted(name for name, _ in images):  # pragma: no cover - a bug
        raise FieldError("export: isDepictedIn %s and images %s differ" % (depicted, images))
    from .archive import make_dirs

    make_dirs(directory, dir_mode)
    stage = tempfile.mkdtemp(prefix=".rascal-export.", dir=directory)
    try:
        staged = []
        for fname, text in bodies:
            path = os.path.join(stage, fname)
            with open(path, "w", encoding="utf-8", newline="") as f:
                f.write(text)
            staged.append((path, os.path.join(directory, fname)))
        if images:
            os.mkdir(os.path.join(stage, "images"))
        for fname, src in images:
            path = os.path.join(stage, "images", fname)
            shutil.copyfile(src, path)
            staged.append((path, os.path.join(directory, "images", fname)))
        listed = None
        if images:
            listed = os.path.join(stage, "images", IMAGE_LIST)
            with open(listed, "w", encoding="utf-8") as f:
                f.write(image_list(directory, [name for name, _ in images]))
        for path, _ in staged + ([(listed, None)] if listed else []):
            os.chmod(path, file_mode)
        if images:
            make_dirs(os.path.join(directory, "images"), dir_mode)
        for path, final in staged:
            os.replace(path, final)
        if listed:  # last: the list names only files that are in place
            os.replace(listed, os.path.join(directory, "images", IMAGE_LIST))
    finally:
        shutil.rmtree(stage, ignore_errors=True)
    return {
        "files": [final for _, final in staged],
        "image_list": os.path.join(directory, "images", IMAGE_LIST) if images else None,
        "resources": len(resources),
        "left_out": left_out,
        "bodies": bodies,
    }


# --- a running Field Desktop ---
def push(url, bodies, password, fmt="csv", timeout=60.0, user="rascal"):
    """POST each file to Field Desktop's import endpoint (``<url>/import/csv?category=Pottery``
    or ``<url>/import/jsonl``, HTTP basic auth with the password of Field's settings;
    Field ignores the user name). Returns the number of resources Field imported; a refusal is
    a RuntimeError whose one line carries Field's own message."""
    base = url.rstrip("/")
    if not base.startswith(("http://", "https://")):
        raise FieldError(
            "--push %r: must be Field Desktop's address, e.g. http://localhost:3000" % url
        )
    query = urllib.parse.urlencode({"category": CATEGORY})
    endpoint = "%s/import/%s?%s" % (base, "csv" if fmt == "csv" else "jsonl", query)
    token = base64.b64encode(("%s:%s" % (user, password or "")).encode("utf-8")).decode("ascii")
    imported = 0
    for fname, text in bodies:
        req = urllib.request.Request(
            endpoint,
            data=text.encode("utf-8"),
            method="POST",
            headers={
                "Authorization": "Basic " + token,
                "Content-Type": "text/plain; charset=utf-8",
            },
        )
        try:
            with urllib.request.urlopen(req, timeout=timeout) as resp:
                body = resp.read().decode("utf-8", "replace")
        except urllib.error.HTTPError as e:
            detail = e.read().decode("utf-8", "replace")
            raise RuntimeError(
                "Field Desktop at %s refused %s: HTTP %d %s%s"
                % (base, fname, e.code, _field_message(detail), _hint(e.code))
            ) from None
        except (urllib.error.URLError, OSError) as e:
            reason = getattr(e, "reason", e)
            raise RuntimeError(
                "Field Desktop at %s: cannot reach it (%s); start Field Desktop and check the "
                "address and port in its settings" % (base, reason)
            ) from None
        try:
            imported += int(json.loads(body).get("successfulImports", 0))
        except (ValueError, AttributeError, TypeError):
            pass
    return imported


def _field_message(text):
    try:
        doc = json.loads(text)
    except ValueError:
        return (" " + " ".join(text.split()))[:300] if text.strip() else ""
    parts = [str(doc.get("error") or doc.get("reason") or "")]
    parts += [str(e) for e in doc.get("importErrors") or []]
    msg = "; ".join(p for p in parts if p)
    return (": " + " ".join(msg.split()))[:500] if msg else ""


def _hint(code):
    if code == 401:
        return (
            " (wrong password: use the one in Field Desktop's settings, --field-password or "
            "$RASCAL_FIELD_PASSWORD)"
        )
    return ""
