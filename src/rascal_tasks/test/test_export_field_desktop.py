"""`rascal export --format field-desktop|field-desktop-jsonl [--push URL]` against real PostgreSQL,
run as a user would (/usr/bin/python3 scripts/rascal).

Every file is read back by `field_read_csv` / `field_read_jsonl`, which apply Field Desktop's
import rules independently of the code under test (as dainst/idai-field's CSV parser,
convert-fields.ts, remove-null-properties.ts and Measurement.isValid do): headers, list
indices, row lengths, measurements (inputValue > 0, units), relations, empty strings."""

import base64
import http.server
import json
import os
import stat
import subprocess
import threading

import pytest
from catalogue_helpers import PYTHON, FakeClock, subprocess_env

from rascal_tasks.catalogue import Catalogue, ImageArchive, parse_csv

pytestmark = pytest.mark.timeout(120)

SCRIPT = os.path.join(
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts", "rascal"
)
CONTEXT = "TR1/1023"
PNG = b"\x89PNG\r\n\x1a\n"
UNITS = {"weight": {"mg", "g", "kg"}, "dimension": {"mm", "cm", "m"}}
MEASUREMENTS = {
    "weight": "weight",
    "dimensionLength": "dimension",
    "dimensionWidth": "dimension",
    "dimensionThickness": "dimension",
}
MEASUREMENT_KEYS = {"inputValue", "inputUnit", "isImprecise"}
POTTERY_FIELDS = {"identifier", "shortDescription", "description", "clayColorOutsideMunsell"}


def rascal(*args, env=None):
    e = subprocess_env()
    e.pop("RASCAL_DSN", None)
    e.pop("RASCAL_FIELD_PASSWORD", None)
    e.update(env or {})
    return subprocess.run(
        [PYTHON, SCRIPT, *args], capture_output=True, text=True, env=e, timeout=60
    )


# --- Field Desktop's reading, written from its rules ---
def _field_rows(text):
    """Rows as Field's CSV reader splits them: ',' between cells, '"' quoting with '""' for
    a quote, a line break ends a row outside quotes, zero-width characters dropped."""
    rows, row, cell, quoted, i = [], [], "", False, 0
    while i < len(text):
        c = text[i]
        if quoted:
            if c == '"' and text[i + 1 : i + 2] == '"':
                cell += '"'
                i += 1
            elif c == '"':
                quoted = False
            else:
                cell += c
        elif c == '"':
            quoted = True
        elif c == ",":
            row.append(cell)
            cell = ""
        elif c in "\r\n":
            row.append(cell)
            rows.append(row)
            row, cell = [], ""
            if c == "\r" and text[i + 1 : i + 2] == "\n":
                i += 1
        elif c not in "\u200b\u200c\u200d\ufeff":
            cell += c
        i += 1
    if cell or row:
        row.append(cell)
        rows.append(row)
    return rows


def field_read_csv(text):
    """The resources Field Desktop's CSV import makes of `text`, or AssertionError naming the
    rule a file breaks."""
    rows = _field_rows(text)
    headers, rows = rows[0], rows[1:]
    assert "" not in headers, "empty heading"
    for h in headers:
        assert not any(o.startswith(h + ".") for o in headers), "heading %s is also a node" % h
    for field in {h.split(".")[0] for h in headers if h.count(".") >= 2}:
        indices = sorted({int(h.split(".")[1]) for h in headers if h.startswith(field + ".")})
        assert indices == list(range(len(indices))), "indices of %s: %s" % (field, indices)
    resources = []
    for n, row in enumerate(rows, 1):
        assert len(row) == len(headers), "row %d has %d cells" % (n, len(row))
        res = {"relations": {}}
        for h, cell in zip(headers, row, strict=True):
            value = None if cell == "" else cell
            parts = h.split(".")
            if parts[0] == "relations":
                if value is not None:
                    res["relations"][parts[1]] = (
                        value if parts[1] == "isChildOf" else value.split(";")
                    )
            elif len(parts) == 1:
                if value is not None:
                    res[h] = value
            else:
                entries = res.setdefault(parts[0], [])
                idx = int(parts[1])
                while len(entries) <= idx:
                    entries.append({})
                entries[idx][parts[2]] = value
        for field in MEASUREMENTS:
            for m in res.get(field, []):
                if m.get("inputValue") is not None:
                    m["inputValue"] = float(m["inputValue"].replace(",", "."))
                if m.get("isImprecise") is not None:
                    assert m["isImprecise"] in ("true", "false"), m
                    m["isImprecise"] = m["isImprecise"] == "true"
        resources.append(res)
    check_resources(resources)
    return resources


def field_read_jsonl(text):
    resources = []
    for line in text.splitlines():
        if line:
            res = json.loads(line)
            assert "id" not in res
            assert res.pop("category") == "Pottery"
            resources.append(res)
    check_resources(resources)
    return resources


def check_resources(resources):
    """Field's validation of what was read: every measurement entry complete and valid, text
    not empty, isChildOf one identifier, isDepictedIn a list, only Pottery's fields."""
    seen = set()
    for res in resources:
        ident = res["identifier"]
        assert ident and ident not in seen, ident
        seen.add(ident)
        for field, value in res.items():
            if field == "relations":
                continue
            if field in MEASUREMENTS:
                for m in value:
                    assert set(m) <= MEASUREMENT_KEYS, (ident, field, m)
                    assert m.get("inputValue") and m["inputValue"] > 0, (ident, field, m)
                    assert m.get("inputUnit") in UNITS[MEASUREMENTS[field]], (ident, field, m)
            else:
                assert field in POTTERY_FIELDS, field
                assert isinstance(value, str) and value.strip() == value != "", (ident, field)
        rel = res["relations"]
        assert isinstance(rel["isChildOf"], str) and rel["isChildOf"], ident
        assert isinstance(rel.get("isDepictedIn", []), list), ident


# --- a context as recorded ---
def record(dsn, archive, context=CONTEXT, masses=(17.94, 3.21)):
    """Sherd 1: every measurement and a colour; 2: no thickness, no colour; 3: lost;
    4: unfinished (weighed)."""
    cat = Catalogue.connect(dsn, rig="rig-1", config_hash="abc", clock=FakeClock())
    cat.open_context(context, "site")
    dims = [(40.56, 30.25, 6.04), (20.0, 15.0, None)]
    for i, (mass, d) in enumerate(zip(masses, dims, strict=True)):
        s = cat.new_sherd(context, pickup_xy=(0.1, 0.25))["sherd_id"]
        cat.record_dimensions(s, *d)
        cat.record_mass(s, mass)
        colour = {"colour_munsell": "10YR 7/3", "colour_lab": (70.0, 3.5, 18.25)} if i == 0 else {}
        cat.archive_photo(s, archive, PNG + bytes([i]), **colour)
        cat.record_done(s, archive=archive)
    cat.add_note(s, "rim, burnt edge")
    lost = cat.new_sherd(context)["sherd_id"]
    cat.record_lost(lost, "not found after 2 searches")
    cat.record_mass(cat.new_sherd(context)["sherd_id"], 5.0)
    cat.close()


@pytest.fixture
def recorded(migrated_dsn, tmp_path):
    archive = ImageArchive(str(tmp_path / "archive"))
    record(migrated_dsn, archive)
    return migrated_dsn, archive.root


def export(dsn, archive, out, fmt="field-desktop", *extra, env=None):
    return rascal(
        "--dsn",
        dsn,
        "export",
        "--context",
        CONTEXT,
        "--format",
        fmt,
        "--output",
        str(out),
        "--archive",
        archive,
        *extra,
        env=env,
    )


def test_field_desktop_csv_imports_as_field_reads_it(recorded, tmp_path):
    dsn, archive = recorded
    out = tmp_path / "out"
    r = export(dsn, archive, out, "field-desktop", "--parent", "SE {context}")
    assert r.returncode == 1, r.stderr  # the unfinished sherd is left out, and said so
    lines = r.stderr.strip().splitlines()
    assert "1 unfinished sherd left out (TR1/1023-4)" in lines[-1], lines
    names = sorted(p.name for p in out.iterdir())
    assert names == [
        "TR1%2F1023-without-thickness.Pottery.csv",
        "TR1%2F1023-without-weight-length-width-thickness.Pottery.csv",
        "TR1%2F1023.Pottery.csv",
        "images",
    ], names
    got = {}
    for f in out.glob("*.Pottery.csv"):
        text = f.read_bytes().decode("utf-8")  # UTF-8, no BOM
        for res in field_read_csv(text):
            got[res["identifier"]] = res
    assert sorted(got) == ["TR1/1023-1", "TR1/1023-2", "TR1/1023-3"]
    one, two, lost = got["TR1/1023-1"], got["TR1/1023-2"], got["TR1/1023-3"]
    # rounded to what was measured: 0.1 g, 0.1 mm (30.25 is 30.3, half up)
    assert one["weight"] == [{"inputValue": 17.9, "inputUnit": "g", "isImprecise": False}]
    assert [one[f][0]["inputValue"] for f in list(MEASUREMENTS)[1:]] == [40.6, 30.3, 6.0]
    assert {one[f][0]["inputUnit"] for f in list(MEASUREMENTS)[1:]} == {"mm"}
    assert one["clayColorOutsideMunsell"] == "10YR 7/3"
    assert "dimensionThickness" not in two and "clayColorOutsideMunsell" not in two
    assert "notes: rim, burnt edge" in two["description"]
    assert "lost during recording: not found after 2 searches" in lost["description"]
    assert not any(f in lost for f in MEASUREMENTS)
    assert {r["relations"]["isChildOf"] for r in got.values()} == {"SE TR1/1023"}
    # images: each one a file in images/ under the name isDepictedIn gives, the archive's bytes
    for ident, res in got.items():
        depicted = res["relations"].get("isDepictedIn")
        if ident == "TR1/1023-3":
            assert depicted is None
            continue
        (name,) = depicted
        seq = int(ident.rsplit("-", 1)[1])
        assert (out / "images" / name).read_bytes() == PNG + bytes([seq - 1])
    # readable by the group: files 0644, folders 0755
    for p in [out, out / "images", *out.iterdir(), *(out / "images").iterdir()]:
        mode = stat.S_IMODE(p.stat().st_mode)
        assert mode == (0o755 if p.is_dir() else 0o644), (p, oct(mode))
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no staging left


def test_field_desktop_jsonl_holds_the_same_resources(recorded, tmp_path):
    dsn, archive = recorded
    r = export(dsn, archive, tmp_path / "csv", "field-desktop")
    csv_res = {}
    for f in (tmp_path / "csv").glob("*.csv"):
        csv_res.update({x["identifier"]: x for x in field_read_csv(f.read_text("utf-8"))})
    r = export(dsn, archive, tmp_path / "jsonl", "field-desktop-jsonl")
    assert r.returncode == 1, r.stderr
    (f,) = (tmp_path / "jsonl").glob("*.jsonl")
    assert f.name == "TR1%2F1023.Pottery.jsonl"
    jsonl_res = {x["identifier"]: x for x in field_read_jsonl(f.read_text("utf-8"))}
    assert jsonl_res == csv_res
    assert jsonl_res["TR1/1023-1"]["relations"]["isChildOf"] == CONTEXT  # default: the id


def test_a_value_field_would_refuse_is_one_line_and_nothing_is_written(migrated_dsn, tmp_path):
    archive = ImageArchive(str(tmp_path / "archive"))
    record(migrated_dsn, archive, masses=(17.94, 0.04))  # 0.04 g is 0.0 g at 0.1 g
    out = tmp_path / "out"
    out.mkdir()
    r = export(migrated_dsn, archive.root, out)
    assert r.returncode == 2, r.stderr
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith("rascal: error: sherd TR1/1023-2: weight.0.inputValue is 0.0"), line
    assert "above 0" in line
    assert list(out.iterdir()) == []  # no partial files


def test_a_missing_archival_image_is_a_fault_and_nothing_is_written(recorded, tmp_path):
    dsn, archive = recorded
    (image,) = (tmp_path / "archive" / "TR1%2F1023").glob("2-*.png")
    image.unlink()
    r = export(dsn, archive, tmp_path / "out")
    assert r.returncode == 3, r.stderr
    (line,) = r.stderr.strip().splitlines()
    assert "sherd TR1/1023-2: archival image" in line and "is missing" in line, line
    assert not (tmp_path / "out").exists() or list((tmp_path / "out").iterdir()) == []


def test_csv_and_json_exports_round_to_measured_precision(recorded, tmp_path):
    dsn, _ = recorded
    r = rascal("--dsn", dsn, "export", "--context", CONTEXT, "--format", "csv")
    assert r.returncode == 0, r.stderr
    first = parse_csv(r.stdout)[0]
    assert (first["mass_g"], first["length_mm"], first["width_mm"]) == (17.9, 40.6, 30.3)
    assert first["colour_b"] == 18.3 and first["find_id"] == "TR1/1023-1"
    out = tmp_path / "x.json"
    r = rascal(
        "--dsn", dsn, "export", "--context", CONTEXT, "--format", "json", "--output", str(out)
    )
    assert r.returncode == 0, r.stderr
    doc = json.loads(out.read_text("utf-8"))
    assert doc["sherds"][0]["mass_g"] == 17.9 and doc["sherds"][0]["thickness_mm"] == 6.0
    assert stat.S_IMODE(out.stat().st_mode) == 0o644


class _FieldDesktop(http.server.BaseHTTPRequestHandler):
    """Field Desktop's import endpoint as far as the export uses it: POST /import/<format>,
    basic auth (any user, the password), the file as the body; 200 with successfulImports."""

    password = "field-secret"
    seen = []

    def do_POST(self):
        body = self.rfile.read(int(self.headers["Content-Length"])).decode("utf-8")
        auth = self.headers.get("Authorization", "")
        user_pw = base64.b64decode(auth[6:]).decode() if auth.startswith("Basic ") else ""
        self.seen.append((self.command, self.path, user_pw, body))
        if user_pw.split(":", 1)[-1] != self.password:
            return self._send(401, {"status": 401, "reason": "Name or password is incorrect."})
        if self.path.startswith("/import/csv?category=Pottery"):
            return self._send(200, {"successfulImports": len(field_read_csv(body))})
        if self.path.startswith("/import/jsonl"):
            return self._send(200, {"successfulImports": len(field_read_jsonl(body))})
        return self._send(400, {"error": "Unsupported format"})

    def _send(self, code, doc):
        blob = json.dumps(doc).encode()
        self.send_response(code)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(blob)))
        self.end_headers()
        self.wfile.write(blob)

    def log_message(self, *args):
        pass


@pytest.fixture
def field_desktop():
    _FieldDesktop.seen = []
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _FieldDesktop)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield "http://127.0.0.1:%d" % server.server_address[1]
    server.shutdown()
    server.server_close()
    thread.join(10)


def test_push_posts_each_file_to_field_desktop_with_its_password(recorded, tmp_path, field_desktop):
    dsn, archive = recorded
    out = tmp_path / "out"
    r = export(
        dsn,
        archive,
        out,
        "field-desktop",
        "--push",
        field_desktop,
        env={"RASCAL_FIELD_PASSWORD": "field-secret"},
    )
    assert r.returncode == 1, r.stderr  # the unfinished sherd, as without --push
    assert "Field Desktop at %s imported 3 resources" % field_desktop in r.stderr
    files = {p.read_text("utf-8") for p in out.glob("*.csv")}
    assert len(_FieldDesktop.seen) == 3
    for method, path, user_pw, body in _FieldDesktop.seen:
        assert (method, path) == ("POST", "/import/csv?category=Pottery")
        assert user_pw.endswith(":field-secret")
        assert body in files
    # JSON Lines: one POST; a wrong password: one line naming Field's answer, exit 3
    _FieldDesktop.seen.clear()
    r = export(dsn, archive, tmp_path / "j", "field-desktop-jsonl", "--push", field_desktop)
    assert r.returncode == 3, r.stderr
    line = r.stderr.strip().splitlines()[-1]
    assert "refused TR1%2F1023.Pottery.jsonl: HTTP 401" in line, line
    assert "Name or password is incorrect" in line and "--field-password" in line, line
    r = export(
        dsn,
        archive,
        tmp_path / "j",
        "field-desktop-jsonl",
        "--push",
        field_desktop,
        "--field-password",
        "field-secret",
    )
    assert r.returncode == 1 and "imported 3 resources" in r.stderr, r.stderr
    assert [s[1] for s in _FieldDesktop.seen] == ["/import/jsonl?category=Pottery"] * 2
