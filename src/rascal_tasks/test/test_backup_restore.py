"""`rascal backup` / `rascal restore` with the real pg_dump and pg_restore of the server's
version: a round trip restores every column of every table and every archive file exactly;
a non-empty target, a damaged backup and an existing output are refused with one line."""

import hashlib
import io
import json
import os
import re
import tarfile

import psycopg2
import pytest
from test_catalogue_verbs import fill_catalogue, one_error_line, query, rascal

from rascal_tasks.catalogue import Catalogue, ImageArchive, available, verify_archive
from rascal_tasks.catalogue.backup import find_pg_tool, tool_connection
from rascal_tasks.catalogue.scratch import create_database, drop_database, dsn_of

pytestmark = pytest.mark.timeout(180)

ADMIN_DSN = os.environ.get("RASCAL_TEST_PG_DSN", "postgresql://rascal:rascal@127.0.0.1:5432/rascal")
TABLES = ("sites", "contexts", "sherds", "events", "sherd_edits", "schema_migrations")


@pytest.fixture
def empty_db():
    """Makes fresh empty databases (the restore targets); drops them afterwards."""
    admin = psycopg2.connect(ADMIN_DSN)
    admin.autocommit = True
    names = []

    def make():
        names.append(create_database(admin))
        return dsn_of(ADMIN_DSN, names[-1])

    yield make
    for name in names:
        drop_database(admin, name)
    admin.close()


@pytest.fixture
def source(migrated_dsn, tmp_path):
    """A catalogue with two contexts, a lost and an unfinished sherd, images and an edit."""
    archive = tmp_path / "archive"
    fill_catalogue(migrated_dsn, archive)
    r = rascal(
        "--dsn",
        migrated_dsn,
        "edit",
        "TR1-1023-1",
        "mass=18.2",
        "--reason",
        "reweighed",
        "--archive",
        str(archive),
    )
    assert r.returncode == 0, r.stderr
    return migrated_dsn, str(archive)


def tables(dsn):
    """Every row of every catalogue table, every column, in key order."""
    conn = psycopg2.connect(dsn)
    try:
        with conn, conn.cursor() as cur:
            out = {}
            for t in TABLES:
                cur.execute("SELECT * FROM %s ORDER BY 1" % t)  # table names: constants
                out[t] = ([d[0] for d in cur.description], cur.fetchall())
            cur.execute(
                "SELECT conrelid::regclass::text, conname, pg_get_constraintdef(oid) "
                "FROM pg_constraint WHERE connamespace = 'public'::regnamespace ORDER BY 1, 2"
            )
            # a restored CHECK may be printed with other brackets (BETWEEN's ANDs re-nested)
            out["constraints"] = [(t, n, re.sub(r"[()\s]", "", d)) for t, n, d in cur.fetchall()]
            cur.execute("SELECT tgname FROM pg_trigger WHERE NOT tgisinternal ORDER BY 1")
            out["triggers"] = cur.fetchall()
            cur.execute("SELECT catalogue_id FROM catalogue_identity")
            out["identity"] = cur.fetchall()
    finally:
        conn.close()
    return out


def files(root):
    """``{relative path: SHA-256}`` of every file under ``root``."""
    out = {}
    for folder, _, names in os.walk(root):
        for n in names:
            path = os.path.join(folder, n)
            with open(path, "rb") as f:
                out[os.path.relpath(path, root)] = hashlib.sha256(f.read()).hexdigest()
    return out


def test_round_trip_restores_every_row_and_file_exactly(source, empty_db, tmp_path):
    dsn, archive = source
    backup = str(tmp_path / "site.rascal-backup.tar")
    r = rascal("--dsn", dsn, "backup", "--output", backup, "--archive", archive)
    assert r.returncode == 0, r.stderr
    assert "2 contexts, 5 sherds, 6 files" in r.stdout and "rascal:rascal@" not in r.stdout
    with tarfile.open(backup) as tar:
        names = tar.getnames()
        manifest = json.loads(tar.extractfile("manifest.json").read())
    assert names[0] == "catalogue.dump" and names[-1] == "manifest.json"
    assert sorted(n for n in names if n.startswith("archive/")) == sorted(
        "archive/" + p for p in files(archive)
    )
    assert manifest["counts"] == {
        t: query(dsn, "SELECT count(*) FROM %s" % t)[0][0]  # table names: constants
        for t in ("contexts", "sherds", "events", "sherd_edits")
    }
    assert manifest["counts"]["sherd_edits"] == 1
    assert [m["version"] for m in manifest["migrations"]] == [m.version for m in available()]
    assert manifest["problems"] == [] and manifest["pg_dump"].startswith("pg_dump (PostgreSQL)")
    with tarfile.open(backup) as tar:  # pg_dump's custom format (-Fc) starts with PGDMP
        assert tar.extractfile("catalogue.dump").read(5) == b"PGDMP"

    target, restored = empty_db(), str(tmp_path / "restored")
    r = rascal("restore", backup, "--dsn", target, "--archive", restored, umask=0o077)
    assert r.returncode == 0, r.stderr
    assert "every SHA-256 checked" in r.stdout
    assert os.stat(restored).st_mode & 0o777 == 0o755
    for folder, dirs, names in os.walk(restored):  # readable by the group, whatever the umask
        assert all(os.stat(os.path.join(folder, d)).st_mode & 0o777 == 0o755 for d in dirs)
        assert all(os.stat(os.path.join(folder, n)).st_mode & 0o777 == 0o644 for n in names)
    assert tables(target) == tables(dsn)  # every column of every row, constraints, triggers
    assert files(restored) == files(archive)  # every file, byte for byte
    cat = Catalogue.connect(target, rig="rig-1", config_hash="abc")
    try:
        assert verify_archive(cat, ImageArchive(restored)) == []  # same identity, same names
        assert cat.new_sherd("TR1-1023")["seq"] == 5  # sequences restored too: it goes on
    finally:
        cat.close()

    # a non-empty target is refused with one line, nothing changed
    before = tables(target)
    r = rascal("restore", backup, "--dsn", target, "--archive", str(tmp_path / "other"))
    assert r.returncode == 2 and r.stdout == ""
    line = one_error_line(r)
    assert "is not empty" in line and "sherds with 6 rows" in line and "--force" in line
    assert "rascal:rascal@" not in line
    assert tables(target) == before and not os.path.exists(tmp_path / "other")
    # so is a non-empty archive folder, even with an empty database
    r = rascal("restore", backup, "--dsn", empty_db(), "--archive", restored)
    assert r.returncode == 2 and "--archive %s is not empty" % restored in one_error_line(r)

    # --force replaces the catalogue in it with the backup's
    r = rascal("restore", backup, "--dsn", target, "--archive", restored, "--force")
    assert r.returncode == 0, r.stderr
    assert tables(target) == tables(dsn) and files(restored) == files(archive)


def test_a_damaged_backup_is_refused_before_anything_changes(source, empty_db, tmp_path):
    dsn, archive = source
    backup = str(tmp_path / "b.tar")
    assert rascal("--dsn", dsn, "backup", "-o", backup, "--archive", archive).returncode == 0
    with tarfile.open(backup) as tar:
        image = next(m for m in tar.getmembers() if m.name.endswith(".png"))
    with open(backup, "r+b") as f:  # one byte of an image flipped
        f.seek(image.offset_data + image.size - 1)
        b = f.read(1)
        f.seek(-1, os.SEEK_CUR)
        f.write(bytes([b[0] ^ 0xFF]))
    target, restored = empty_db(), str(tmp_path / "restored")
    r = rascal("restore", backup, "--dsn", target, "--archive", restored)
    assert r.returncode == 2
    line = one_error_line(r)
    assert image.name in line and "SHA-256" in line and "damaged" in line
    assert query(target, "SELECT count(*) FROM pg_tables WHERE schemaname = 'public'") == [(0,)]
    assert not os.path.exists(restored)

    not_a_backup = tmp_path / "notes.txt"
    not_a_backup.write_text("hello")
    r = rascal("restore", str(not_a_backup), "--dsn", target, "--archive", restored)
    assert r.returncode == 2 and "not a RASCAL backup" in one_error_line(r)


def test_backup_names_a_missing_image_and_never_replaces_a_file(source, empty_db, tmp_path):
    dsn, archive = source
    backup = tmp_path / "b.tar"
    backup.write_text("an older backup")
    r = rascal("--dsn", dsn, "backup", "--output", str(backup), "--archive", archive)
    assert r.returncode == 2 and "exists" in one_error_line(r)
    assert backup.read_text() == "an older backup"

    gone = next(p for p in files(archive) if p.startswith("TR2-7/") and p.endswith(".png"))
    os.unlink(os.path.join(archive, gone))
    fresh = str(tmp_path / "c.tar")
    r = rascal("--dsn", dsn, "backup", "--output", fresh, "--archive", archive)
    assert r.returncode == 1, r.stderr  # written, but a person must look
    assert "TR2-7-1: image %s is missing" % gone in r.stderr
    with tarfile.open(fresh) as tar:
        assert "archive/" + gone not in tar.getnames()
    # restored, the rest is there and the gap is said again
    restored = str(tmp_path / "restored")
    r = rascal("restore", fresh, "--dsn", empty_db(), "--archive", restored)
    assert r.returncode == 1 and "not in the backup: TR2-7-1: image %s" % gone in r.stderr
    assert files(restored) == files(archive)


def test_the_password_never_reaches_a_command_line():
    conninfo, env = tool_connection("postgresql://rascal:s3cret@db.example:5433/cat")
    assert "s3cret" not in conninfo and env["PGPASSWORD"] == "s3cret"
    assert "host=db.example" in conninfo and "port=5433" in conninfo and "dbname=cat" in conninfo
    conninfo, env = tool_connection("host=127.0.0.1 user=rascal password=x dbname=y")
    assert "password" not in conninfo and env["PGPASSWORD"] == "x"


def test_the_tools_match_the_server_version(migrated_dsn):
    major = query(migrated_dsn, "SELECT current_setting('server_version_num')::int / 10000")[0][0]
    for name in ("pg_dump", "pg_restore"):
        assert os.access(find_pg_tool(name, major), os.X_OK)


def test_a_dump_pg_restore_refuses_is_one_line_exit_3_and_leaves_nothing(empty_db, tmp_path):
    """A backup consistent with its manifest whose dump pg_restore cannot read."""
    dump = b"PGDMP this is not a dump"
    manifest = {
        "format": "rascal-backup",
        "version": 1,
        "counts": {"sherds": 0},
        "files": [
            {
                "name": "catalogue.dump",
                "size": len(dump),
                "sha256": hashlib.sha256(dump).hexdigest(),
            }
        ],
    }
    backup = str(tmp_path / "bad-dump.tar")
    with tarfile.open(backup, "w") as tar:
        for name, blob in (("catalogue.dump", dump), ("manifest.json", json.dumps(manifest))):
            blob = blob if isinstance(blob, bytes) else blob.encode()
            info = tarfile.TarInfo(name)
            info.size = len(blob)
            tar.addfile(info, io.BytesIO(blob))
    target, restored = empty_db(), str(tmp_path / "restored")
    r = rascal("restore", backup, "--dsn", target, "--archive", restored)
    assert r.returncode == 3
    assert "pg_restore into" in one_error_line(r) and "rascal:rascal@" not in r.stderr
    assert query(target, "SELECT count(*) FROM pg_tables WHERE schemaname = 'public'") == [(0,)]
    assert not os.path.exists(restored)
