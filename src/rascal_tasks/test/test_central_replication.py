"""Two rigs, one central server (issue 20): three PostgreSQL clusters on this machine.

Rig A records a context before it joins (its keys are moved into its block), both rigs join
the central server (`rascal central init` / `add-rig`), both record; rig B is cut off for part
of the time (its subscription disabled and the central server unreachable for its claims) and
records on, taking a new context provisionally; rig A's cluster is stopped and started again.
A context claimed by A is refused to B with one line naming A, then handed over with
`rascal central release`. At the end the central catalogue holds every row of both rigs exactly
once, every find ID once, and the central archive matches it (`rascal verify --central`).
The catalogue rows are written through the catalogue's Python API (the robot is covered
elsewhere).
"""

import io
import os
import time

import psycopg2
import pytest

import pg_clusters

PNG = b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4
DEADLINE_S = 30.0


def _rascal(*argv):
    from rascal_tasks.cli import main

    out = io.StringIO()
    code = main(list(argv), out=out)
    return code, out.getvalue()


@pytest.fixture(scope="module")
def clusters():
    why = pg_clusters.available()
    if why:
        pytest.skip(why)
    pg_clusters.sweep()
    made = []
    try:
        for opts in (["wal_retrieve_retry_interval=500ms"], [], []):
            made.append(pg_clusters.Cluster(["fsync=off"] + opts))
        pg_clusters.create_all(made)
        yield made  # central, rig A, rig B
    finally:
        for c in made:
            c.drop()


def _catalogue(dsn, rig):
    from rascal_tasks.catalogue import Catalogue

    return Catalogue.connect(dsn, rig=rig, config_hash="cafe0123")


def _record(cat, archive, context, n):
    ids = []
    for _ in range(n):
        s = cat.new_sherd(context, pickup_xy=[0.15, 0.25])
        cat.record_mass(s["sherd_id"], 12.5 + len(ids))
        cat.record_dimensions(s["sherd_id"], 40.0, 30.0, 7.0)
        cat.archive_photo(s["sherd_id"], archive, PNG + os.urandom(32), colour_munsell="5YR 6/4")
        cat.record_done(s["sherd_id"], archive=archive)
        ids.append(s["seq"])
    return ids


def _fingerprint(dsn, table, key, where=""):
    conn = psycopg2.connect(dsn)
    try:
        with conn, conn.cursor() as cur:
            cur.execute(
                "SELECT count(*), md5(string_agg(t::text, '|' ORDER BY %s)) FROM %s t %s"
                % (key, table, where)
            )
            return cur.fetchone()
    finally:
        conn.close()


def _caught_up(central, rigs):
    from rascal_tasks.catalogue.central import node_block

    if _q(central, "SELECT count(*) FROM pg_subscription_rel WHERE srsubstate <> 'r'")[0][0]:
        return False  # a table still being copied
    for node, dsn in rigs:
        lo, hi = node_block(node)
        for table, key in (("sherds", "sherd_id"), ("events", "event_id")):
            where = "WHERE %s BETWEEN %d AND %d" % (key, lo, hi)
            if _fingerprint(dsn, table, key, where) != _fingerprint(central, table, key, where):
                return False
    return True


def _wait_caught_up(central, rigs, timeout=DEADLINE_S):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if _caught_up(central, rigs):
            return time.monotonic()
        time.sleep(0.2)
    raise AssertionError("central server not caught up after %.0f s" % timeout)


def _q(dsn, query, args=()):
    conn = psycopg2.connect(dsn)
    try:
        with conn, conn.cursor() as cur:
            cur.execute(query, args)
            return cur.fetchall() if cur.description else None
    finally:
        conn.close()


def test_two_rigs_replicate_to_central(clusters, tmp_path):
    from rascal_tasks.catalogue import ImageArchive, migrate
    from rascal_tasks.catalogue.central import claim_context

    central, rig_a, rig_b = clusters
    for c in clusters:
        conn = psycopg2.connect(c.dsn)
        migrate(conn)
        conn.close()
    arch_a = ImageArchive(str(tmp_path / "archive-a"), fsync=False)
    arch_b = ImageArchive(str(tmp_path / "archive-b"), fsync=False)
    central_root = tmp_path / "archive-central"

    # rig A records before it has joined: numbering as before (keys from 1)
    a = _catalogue(rig_a.dsn, "rig-a")
    a.open_context("TR1-1", "SITE1")
    assert _record(a, arch_a, "TR1-1", 3) == [1, 2, 3]
    assert _q(rig_a.dsn, "SELECT min(sherd_id) FROM sherds") == [(1,)]
    from rascal_tasks.catalogue import edit_sherd

    edit_sherd(a.connection, "TR1-1-2", ["mass=13.1"], "reweighed after cleaning", "tester")
    a.close()

    # the central server and both rigs
    code, out = _rascal("--dsn", central.dsn, "central", "init")
    assert code == 0, out
    code, out = _rascal("--dsn", central.dsn, "central", "add-rig", "rig-a", "--rig-dsn", rig_a.dsn)
    assert code == 0 and "node 1" in out and "3 sherds recorded before joining" in out, out
    code, out = _rascal("--dsn", central.dsn, "central", "add-rig", "rig-b", "--rig-dsn", rig_b.dsn)
    assert code == 0 and "node 2" in out, out
    code, out = _rascal("--dsn", central.dsn, "central", "add-rig", "rig-b", "--rig-dsn", rig_b.dsn)
    assert code == 0 and "node 2" in out, out  # again: nothing changes
    assert _q(rig_a.dsn, "SELECT min(sherd_id) >> 40, max(sherd_id) >> 40 FROM sherds") == [(1, 1)]
    # the audit trail moved with its sherd, and stays append-only
    assert _q(
        rig_a.dsn,
        "SELECT e.edit_id >> 40, s.seq, e.reason FROM sherd_edits e JOIN sherds s USING (sherd_id)",
    ) == [(1, 2, "reweighed after cleaning")]
    with pytest.raises(psycopg2.Error, match="audit trail"):
        _q(rig_a.dsn, "UPDATE sherd_edits SET reason = 'x'")

    a = _catalogue(rig_a.dsn, "rig-a")
    b = _catalogue(rig_b.dsn, "rig-b")
    a.open_context("TR1-1", "SITE1")  # claimed centrally by rig-a
    b.open_context("TR1-2", "SITE1")  # the same site from two rigs: no conflict
    assert _record(a, arch_a, "TR1-1", 4) == [4, 5, 6, 7]
    assert _record(b, arch_b, "TR1-2", 4) == [1, 2, 3, 4]

    # a context another rig holds is refused with one line naming it (exit 4)
    code, out = _rascal("--dsn", rig_b.dsn, "central", "claim", "--context", "TR1-1")
    assert code == 4

    from rascal_tasks.catalogue.central import ContextClaimed

    with pytest.raises(ContextClaimed, match=r"^context TR1-1 is claimed by rig rig-a .*"):
        b.open_context("TR1-1", "SITE1")

    # rig B loses the network: the central server stops receiving, claims cannot reach it
    central.psql("ALTER SUBSCRIPTION rascal_rig_b DISABLE", db="rascal")
    b_link = _q(rig_b.dsn, "SELECT central_dsn FROM rig_node")[0][0]
    _q(rig_b.dsn, "UPDATE rig_node SET central_dsn = %s", (b_link.replace(str(central.port), "9"),))
    assert claim_context(b, "TR1-2") == "held"  # held before: recorded on
    assert _record(b, arch_b, "TR1-2", 3) == [5, 6, 7]
    b.open_context("TR1-3", "SITE1")  # new while offline: provisional
    assert _q(rig_b.dsn, "SELECT state FROM context_claims WHERE context_id = 'TR1-3'") == [
        ("provisional",)
    ]
    assert _record(b, arch_b, "TR1-3", 5) == [1, 2, 3, 4, 5]
    assert _record(a, arch_a, "TR1-1", 2) == [8, 9]  # rig A goes on meanwhile
    code, out = _rascal("--dsn", central.dsn, "central", "status")
    assert code == 1 and "disabled" in out, out
    assert _q(central.dsn, "SELECT count(*) FROM sherds WHERE context_id = 'TR1-3'") == [(0,)]

    # rig A's server restarts while rig B is still cut off
    a.close()
    rig_a.stop()
    rig_a.start()
    a = _catalogue(rig_a.dsn, "rig-a")
    assert _record(a, arch_a, "TR1-1", 2) == [10, 11]

    # rig B back: its claim is registered, the central server catches up
    _q(rig_b.dsn, "UPDATE rig_node SET central_dsn = %s", (b_link,))
    code, out = _rascal("--dsn", rig_b.dsn, "central", "sync-claims")
    assert code == 0 and "TR1-3" in out, out
    central.psql("ALTER SUBSCRIPTION rascal_rig_b ENABLE", db="rascal")
    assert _q(central.dsn, "SELECT rig_name, state FROM context_claims ORDER BY context_id") == [
        ("rig-a", "held"),
        ("rig-b", "held"),
        ("rig-b", "held"),
    ]

    # a context handed over: rig A releases it, rig B numbers on after A's last sherd
    code, out = _rascal("--dsn", rig_a.dsn, "central", "release", "--context", "TR1-1")
    assert code == 0 and "last number 11" in out, out
    b.open_context("TR1-1", "SITE1")
    assert _record(b, arch_b, "TR1-1", 2) == [12, 13]
    with pytest.raises(ContextClaimed, match="claimed by rig rig-b"):
        a.open_context("TR1-1", "SITE1")
    a.close()
    b.close()

    # archives to the central archive, checked by SHA-256
    for rig, root in ((rig_a, arch_a.root), (rig_b, arch_b.root)):
        code, out = _rascal(
            "--dsn",
            rig.dsn,
            "central",
            "push-archive",
            "--archive",
            root,
            "--to",
            str(central_root),
        )
        assert code == 0 and "0 problems" in out, out

    _wait_caught_up(central.dsn, [(1, rig_a.dsn), (2, rig_b.dsn)])

    # every row exactly once
    rows_a = _q(rig_a.dsn, "SELECT sherd_id, context_id, seq, status::text FROM sherds")
    rows_b = _q(rig_b.dsn, "SELECT sherd_id, context_id, seq, status::text FROM sherds")
    rows_c = _q(central.dsn, "SELECT sherd_id, context_id, seq, status::text FROM sherds")
    assert len(rows_a) == 11 and len(rows_b) == 14
    assert sorted(rows_c) == sorted(rows_a + rows_b)
    assert _q(central.dsn, "SELECT count(*) FROM (SELECT DISTINCT context_id, seq FROM sherds) s")[
        0
    ][0] == len(rows_c)
    assert {r[3] for r in rows_c} == {"done"}
    events = sum(_q(d, "SELECT count(*) FROM events")[0][0] for d in (rig_a.dsn, rig_b.dsn))
    assert _q(central.dsn, "SELECT count(*), count(DISTINCT event_id) FROM events") == [
        (events, events)
    ]
    assert _q(central.dsn, "SELECT count(*) FROM sites") == [(1,)]
    assert _q(central.dsn, "SELECT edit_id >> 40, sherd_id >> 40 FROM sherd_edits") == [(1, 1)]
    assert _q(central.dsn, "SELECT context_id FROM contexts ORDER BY 1") == [
        ("TR1-1",),
        ("TR1-2",),
        ("TR1-3",),
    ]

    # the central archive against the replicated catalogue
    code, out = _rascal("--dsn", central.dsn, "verify", "--central", "--archive", str(central_root))
    assert code == 0 and "25 images checked, 0 problems" in out, out
    victim = _q(central.dsn, "SELECT image_path FROM sherds ORDER BY sherd_id LIMIT 1")[0][0]
    (central_root / victim).write_bytes(PNG)
    code, out = _rascal("--dsn", central.dsn, "verify", "--central", "--archive", str(central_root))
    assert code == 1 and "changed: TR1-1-1 (rig rig-a)" in out, out

    code, out = _rascal("--dsn", central.dsn, "central", "status")
    assert code == 0, out
    assert "rig-a" in out and "rig-b" in out and "2 streaming" in out, out
