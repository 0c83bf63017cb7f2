"""Context IDs as excavations write them (issue 19): stored exactly (NFC), a safe archive folder
derived from each, hostile ones refused with one line, files readable by the group; and a new
bag on a finished context only with `rascal run --continue` (a stopped run still resumes).
Real PostgreSQL throughout; the `rascal run` checks against a real roscore."""

import os
import stat
import subprocess
import unicodedata

import psycopg2
import pytest
from catalogue_helpers import PYTHON, FakeClock, subprocess_env

from rascal_tasks.catalogue import Catalogue, ContextIdError, ImageArchive, verify_archive
from rascal_tasks.catalogue.context_batches import (
    START_APPEND,
    START_NEW,
    START_RESUME,
    ContextInUse,
    context_state,
    log_batch,
    start_mode,
)
from rascal_tasks.catalogue.context_id import (
    MAX_FOLDER_BYTES,
    context_folder,
    context_from_folder,
    validate_context_id,
)

pytestmark = pytest.mark.timeout(120)

SCRIPT = os.path.join(
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts", "rascal"
)
WORKSPACE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(SCRIPT))))
PNG = b"\x89PNG\r\n\x1a\n"
KOELN_NFD = "Ko\u0308ln-1"  # 'o' + combining diaeresis, as some keyboards and macOS write it
EVERYDAY = ["TR1/1023", "SU 1023", "Köln-1", "TR1-1023", "a'; DROP TABLE sherds;--", "C:\\bag"]


# --- the rule ---
@pytest.mark.parametrize("value", EVERYDAY)
def test_everyday_context_ids_are_accepted_exactly(value):
    assert validate_context_id(value) == value


def test_a_decomposed_id_is_the_composed_one():
    assert validate_context_id(KOELN_NFD) == "Köln-1"


@pytest.mark.parametrize(
    "bad, why",
    [
        ("../x", "must not contain '..' as a path part"),
        ("TR1/../etc", "must not contain '..' as a path part"),
        ("a\\.\\b", "must not contain '.' as a path part"),
        ("a\x1bb", "must not contain control characters"),
        ("   ", "must not be only spaces"),
        (" SU 1023", "must not start or end with a space"),
        ("a\u2028b", "must not contain invisible characters (found U+2028)"),
        ("é" * 65, "is 65 characters long, at most 64"),
    ],
)
def test_hostile_ids_are_one_line_naming_the_rule(bad, why):
    with pytest.raises(ContextIdError) as err:
        validate_context_id(bad)
    msg = str(err.value)
    assert why in msg and "\n" not in msg and msg.startswith("context id '"), msg


def test_folder_names_are_safe_unique_and_reversible():
    ids = EVERYDAY + ["TR1%2F1023", "TR1_1023", ".x", "x.", "~a", "a b", "a  b", "ü", "u\u0308x"]
    folders = [context_folder(i) for i in ids]
    assert len(set(folders)) == len(ids)
    for i, f in zip(ids, folders, strict=True):
        assert "/" not in f and "\\" not in f and not f.startswith(".") and " " not in f, f
        assert f.isprintable() and context_from_folder(f) == validate_context_id(i)
    assert context_folder("TR1/1023") == "TR1%2F1023"
    assert context_folder("SU 1023") == "SU%201023"
    assert context_folder("Köln-1") == "Köln-1" and context_folder("TR1-1023") == "TR1-1023"
    # 64 emoji escape to 768 bytes: cut, with a hash that keeps them apart
    a, b = "\U0001f600" * 64, "\U0001f600" * 63 + "\U0001f601"
    fa, fb = context_folder(a), context_folder(b)
    assert fa != fb and len(fa.encode()) <= MAX_FOLDER_BYTES and context_from_folder(fa) is None


# --- in the catalogue and the archive ---
def test_ids_are_stored_exactly_and_archived_in_their_own_folder(migrated_dsn, tmp_path):
    cat = Catalogue.connect(migrated_dsn, rig="rig-1", config_hash="abc", clock=FakeClock())
    archive = ImageArchive(str(tmp_path / "archive"))
    old = os.umask(0o077)  # a strict umask: the archive still comes out readable by the group
    try:
        for n, ctx in enumerate(EVERYDAY + [KOELN_NFD]):
            ctx = validate_context_id(ctx)
            cat.open_context(ctx, "site")
            s = cat.new_sherd(ctx)["sherd_id"]
            cat.record_mass(s, 10.0)
            cat.archive_photo(s, archive, PNG + bytes([n]))
            cat.record_done(s, archive=archive)
    finally:
        os.umask(old)
    with psycopg2.connect(migrated_dsn) as conn, conn.cursor() as cur:
        cur.execute("SELECT context_id FROM contexts ORDER BY created_at")
        assert [r[0] for r in cur.fetchall()] == EVERYDAY  # Köln-1 once: NFD is the same id
        cur.execute("SELECT image_path FROM sherds WHERE context_id = 'TR1/1023'")
        (path,) = cur.fetchone()
    assert path.startswith("TR1%2F1023/1-") and path.endswith(".png")
    assert sorted(archive.context_dirs()) == sorted(EVERYDAY)
    assert verify_archive(cat, archive) == []  # integrity finds every file in its folder
    for top, dirs, files in os.walk(archive.root):
        for d in dirs:
            assert stat.S_IMODE(os.stat(os.path.join(top, d)).st_mode) == 0o755, d
        for f in files:
            assert stat.S_IMODE(os.stat(os.path.join(top, f)).st_mode) == 0o644, f
    assert stat.S_IMODE(os.stat(archive.root).st_mode) == 0o755
    cat.close()


def test_configured_modes_are_used(tmp_path):
    archive = ImageArchive(str(tmp_path / "a"), file_mode=0o640, dir_mode=0o750)
    rel, _ = archive.store("SU 1023", 1, PNG)
    assert stat.S_IMODE(os.stat(archive.path(rel)).st_mode) == 0o640
    assert stat.S_IMODE(os.stat(os.path.dirname(archive.path(rel))).st_mode) == 0o750
    with pytest.raises(ValueError, match="archive.file_mode 644: must be permission bits"):
        ImageArchive(str(tmp_path / "b"), file_mode=644)


@pytest.mark.parametrize("bad", ["../x", "a/./b", " a", "a\x01", unicodedata.normalize("NFD", "ö")])
def test_database_refuses_what_python_refuses(migrated_dsn, bad):
    conn = psycopg2.connect(migrated_dsn)
    with conn, conn.cursor() as cur:
        cur.execute("INSERT INTO sites (site_id) VALUES ('site')")
    with pytest.raises(psycopg2.errors.CheckViolation), conn, conn.cursor() as cur:
        cur.execute("INSERT INTO contexts (context_id, site_id) VALUES (%s, 'site')", (bad,))
    with pytest.raises(psycopg2.errors.CheckViolation), conn, conn.cursor() as cur:
        cur.execute("INSERT INTO sites (site_id) VALUES ('SU 1023')")  # sites: the old alphabet
    conn.close()


# --- a new bag on a finished context ---
def _context_with(dsn, ctx, n, last_event=None):
    cat = Catalogue.connect(dsn, rig="rig-1", config_hash="abc", clock=FakeClock())
    cat.open_context(ctx, "site")
    for _ in range(n):
        s = cat.new_sherd(ctx)["sherd_id"]
        cat.record_lost(s, "test")
    cat.close()
    conn = psycopg2.connect(dsn)
    if last_event == "complete":
        log_batch(conn, ctx, "rig-1", "batch_started")
        log_batch(conn, ctx, "rig-1", "batch_ended", {"exit": 0})
    elif last_event == "stopped":
        log_batch(conn, ctx, "rig-1", "batch_ended", {"exit": 0})
        log_batch(conn, ctx, "rig-1", "batch_started", {"append": True})  # then killed
    elif last_event == "fault":
        log_batch(conn, ctx, "rig-1", "batch_started")
        log_batch(conn, ctx, "rig-1", "batch_ended", {"exit": 3})
    return conn


def test_start_mode_from_the_catalogue(migrated_dsn):
    conn = psycopg2.connect(migrated_dsn)
    assert start_mode(context_state(conn, "NEW"), "NEW") == START_NEW
    for ctx, event, mode in [
        ("C-STOPPED", "stopped", START_RESUME),
        ("C-FAULT", "fault", START_RESUME),
    ]:
        c = _context_with(migrated_dsn, ctx, 2, event)
        assert start_mode(context_state(c, ctx), ctx) == mode, ctx
        c.close()
    for ctx, event in [("C-DONE", "complete"), ("C-OLD", None)]:  # C-OLD: before batch events
        c = _context_with(migrated_dsn, ctx, 3, event)
        state = context_state(c, ctx)
        assert start_mode(state, ctx, append=True) == START_APPEND
        with pytest.raises(ContextInUse) as err:
            start_mode(state, ctx)
        msg = str(err.value)
        assert "already holds 3 sherds" in msg and "pass --continue" in msg, msg
        assert "(numbered from 4)" in msg and "\n" not in msg
        c.close()
    conn.close()


def _run(master, dsn, ctx, *extra):
    env = dict(subprocess_env(), **master.env)
    env.pop("RASCAL_DSN", None)
    return subprocess.run(
        [PYTHON, SCRIPT, "--dsn", dsn, "run", "--context", ctx, *extra],
        capture_output=True,
        text=True,
        env=env,
        timeout=90,
        cwd=WORKSPACE,
    )


def test_rascal_run_refuses_a_finished_context_without_continue(ros_master, migrated_dsn, tmp_path):
    ros_master.run(["rosparam", "load", os.path.join(WORKSPACE, "config", "rascal.yaml")])
    ros_master.run(["rosparam", "set", "/archive/root", str(tmp_path / "archive")])
    ros_master.run(["rosparam", "set", "/rig/node_wait", "1.0"])
    ros_master.run(["rosparam", "set", "/rig/name", "ctx-test-%d" % os.getpid()])
    _context_with(migrated_dsn, "SU 1023", 2, "complete").close()
    r = _run(ros_master, migrated_dsn, "SU 1023")
    assert r.returncode == 2, r.stdout + r.stderr
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith("error: context id 'SU 1023': already holds 2 sherds"), line
    assert "pass --continue" in line
    # --continue passes the check: the run goes on to wait for the rig's nodes (none here)
    r = _run(ros_master, migrated_dsn, "SU 1023", "--continue")
    assert r.returncode == 3 and "not running" in r.stderr, r.stdout + r.stderr
    assert "already holds" not in r.stderr
    # a run that stopped (here: killed after batch_started) is resumed by the same command
    _context_with(migrated_dsn, "TR1/1023", 1, "stopped").close()
    r = _run(ros_master, migrated_dsn, unicodedata.normalize("NFD", "TR1/1023"))
    assert r.returncode == 3 and "already holds" not in r.stderr, r.stdout + r.stderr
    assert "resuming context TR1/1023: 1 sherds recorded" in r.stdout, r.stdout
    # a hostile id: one line, exit 2, before anything else
    r = _run(ros_master, migrated_dsn, "../etc")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
