"""Crash and concurrency tests with real writer processes (/usr/bin/python3 children)."""

import os
import signal
import subprocess

import pytest
from catalogue_helpers import PYTHON, subprocess_env

from rascal_tasks.catalogue import Catalogue, ImageArchive

pytestmark = pytest.mark.timeout(120)

PNG = b"\x89PNG\r\n\x1a\n" + b"\x00" * 64

WRITER = r"""
import sys, time
from rascal_tasks.catalogue import Catalogue
dsn, context = sys.argv[1], sys.argv[2]
cat = Catalogue.connect(dsn, rig='rig-a', config_hash='cfg1')
cat.open_context(context, 'site')
s = cat.new_sherd(context, pickup_xy=(0.1, 0.2), t_pick_s=5.0)
cat.record_dimensions(s['sherd_id'], 50.0, 40.0, 7.0)
cat.record_mass(s['sherd_id'], 26.0, t_weigh_s=4.0)
print('WEIGHED', s['sherd_id'], flush=True)
time.sleep(120)  # waiting for the archival camera: killed here
"""

COUNTER = r"""
import os, sys, time
from rascal_tasks.catalogue import Catalogue
dsn, context, go, n = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
cat = Catalogue.connect(dsn, rig='rig-%d' % os.getpid(), config_hash='cfg1')
print('READY', flush=True)
while not os.path.exists(go):
    time.sleep(0.001)
for _ in range(n):
    print(cat.new_sherd(context)['seq'], flush=True)
"""


def test_crash_between_weighed_and_photographed_resumes_without_duplicates(migrated_dsn, tmp_path):
    proc = subprocess.Popen(
        [PYTHON, "-c", WRITER, migrated_dsn, "CTX-9"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=subprocess_env(),
    )
    try:
        line = proc.stdout.readline()
        assert line.startswith("WEIGHED"), proc.stderr.read()
        sherd_id = int(line.split()[1])
        os.kill(proc.pid, signal.SIGKILL)
        assert proc.wait(30) == -signal.SIGKILL
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()

    cat = Catalogue.connect(migrated_dsn, rig="rig-a", config_hash="cfg1")
    reopened = cat.open_context("CTX-9", "site")
    assert not reopened["created"] and reopened["unfinished"] == 1
    todo = cat.resume("CTX-9")
    assert [(r["sherd_id"], r["seq"], r["status"], r["mass_g"]) for r in todo] == [
        (sherd_id, 1, "weighed", 26.0)
    ]
    # the restarted run carries on with the same sherd
    archive = ImageArchive(str(tmp_path))
    cat.archive_photo(sherd_id, archive, PNG, t_photo_s=7.0)
    cat.record_done(sherd_id, t_discard_s=3.0)
    nxt = cat.new_sherd("CTX-9")
    rows = cat.sherds("CTX-9")
    assert [(r["seq"], r["status"]) for r in rows] == [(1, "done"), (2, "picked")]
    assert nxt["seq"] == 2
    assert rows[0]["length_mm"] == 50.0 and rows[0]["t_weigh_s"] == 4.0
    assert [r["seq"] for r in cat.resume("CTX-9")] == [2]
    kinds = [e["kind"] for e in cat.events("CTX-9")]
    assert kinds.count("picked") == 2 and kinds.count("weighed") == 1 and "resumed" in kinds
    cat.close()


def test_two_writer_processes_on_one_context_get_distinct_gap_free_numbers(migrated_dsn, tmp_path):
    setup = Catalogue.connect(migrated_dsn, rig="setup", config_hash="cfg1")
    setup.open_context("SHARED", "site")
    go = str(tmp_path / "go")
    n = 60
    procs = [
        subprocess.Popen(
            [PYTHON, "-c", COUNTER, migrated_dsn, "SHARED", go, str(n)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=subprocess_env(),
        )
        for _ in range(2)
    ]
    try:
        for p in procs:
            assert p.stdout.readline().strip() == "READY", p.stderr.read()
        open(go, "w").close()
        outs = [p.communicate(timeout=90) for p in procs]
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
                p.wait()
    assert [p.returncode for p in procs] == [0, 0], [o[1] for o in outs]
    seqs = [[int(x) for x in out.split()] for out, _ in outs]
    assert all(len(s) == n for s in seqs)
    assert sorted(seqs[0] + seqs[1]) == list(range(1, 2 * n + 1))
    assert not set(seqs[0]) & set(seqs[1])
    rows = setup.sherds("SHARED")
    assert [r["seq"] for r in rows] == list(range(1, 2 * n + 1))
    assert len({r["rig"] for r in rows}) == 2
    setup.close()


def test_resume_only_hands_back_this_rigs_rows(migrated_dsn):
    a = Catalogue.connect(migrated_dsn, rig="rig-a", config_hash="h")
    b = Catalogue.connect(migrated_dsn, rig="rig-b", config_hash="h")
    a.open_context("C", "site")
    a.new_sherd("C")
    b.new_sherd("C")
    assert [r["seq"] for r in a.resume("C")] == [1]
    assert [r["seq"] for r in b.resume("C")] == [2]
    assert len(a.unfinished("C")) == 2
    a.close()
    b.close()


def test_killed_writer_holding_the_numbering_lock_does_not_block_others(migrated_dsn):
    locker = r"""
import sys, time, psycopg2
conn = psycopg2.connect(sys.argv[1])
cur = conn.cursor()
cur.execute("SELECT 1 FROM contexts WHERE context_id = 'C' FOR UPDATE")
print('LOCKED', flush=True)
time.sleep(120)
"""
    cat = Catalogue.connect(migrated_dsn, rig="r", config_hash="h")
    cat.open_context("C", "site")
    proc = subprocess.Popen(
        [PYTHON, "-c", locker, migrated_dsn],
        stdout=subprocess.PIPE,
        text=True,
        env=subprocess_env(),
    )
    try:
        assert proc.stdout.readline().strip() == "LOCKED"
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert cat.new_sherd("C")["seq"] == 1  # (the module's timeout catches a hang)
    cat.close()


def test_lost_database_connection_is_one_line_and_reconnect_resumes(migrated_dsn):
    import psycopg2

    from rascal_tasks.catalogue import CatalogueError

    cat = Catalogue.connect(migrated_dsn, rig="rig-a", config_hash="h")
    cat.open_context("C", "site")
    s = cat.new_sherd("C")
    cat.record_mass(s["sherd_id"], 30.0)
    pid = cat.connection.get_backend_pid()
    admin = psycopg2.connect(migrated_dsn)
    admin.autocommit = True
    with admin.cursor() as cur:
        cur.execute("SELECT pg_terminate_backend(%s)", (pid,))  # as a server restart would
    admin.close()
    with pytest.raises(CatalogueError, match="connection lost while recording photographed"):
        cat.record_photo(s["sherd_id"], "C/1.png", "a" * 64)
    cat.reconnect()
    assert [(r["seq"], r["status"], r["mass_g"]) for r in cat.resume("C")] == [(1, "weighed", 30.0)]
    cat.close()
