"""Catalogue core tests against a real PostgreSQL (the `pg_dsn` fixture's throw-away database)."""

import json
import math
import os
import shutil
import threading
import uuid

import psycopg2
import psycopg2.errors
import pytest

from rascal_tasks.catalogue import (
    COLUMNS,
    Catalogue,
    CatalogueError,
    ContextIdError,
    FieldError,
    ImageArchive,
    MigrationError,
    StatusError,
    available,
    export_records,
    migrate,
    parse_csv,
    status,
    to_csv,
    to_json,
    verify_archive,
)
from rascal_tasks.catalogue.archive import sidecar_relpath
from rascal_tasks.catalogue.export import rounded
from rascal_tasks.catalogue.migrate import MIGRATIONS_DIR
from rascal_tasks.catalogue.scratch import create_database, drop_database

PNG = b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4


def count(conn, table):
    with conn, conn.cursor() as cur:
        cur.execute("SELECT count(*) FROM " + table)  # table names are constants of this test
        return cur.fetchone()[0]


def full_sherd(cat, archive, context="TR1-1023"):
    """One sherd carried through every state with every field set."""
    s = cat.new_sherd(context, pickup_xy=(0.161, 0.247), grasp_attempts=1, t_pick_s=12.5)
    cat.record_grasp_attempt(s["sherd_id"], "scale")
    cat.record_drop(s["sherd_id"], "scale")
    cat.record_dimensions(s["sherd_id"], 52.4, 41.0, 7.2)
    cat.record_mass(s["sherd_id"], 25.3, t_weigh_s=6.75)
    cat.archive_photo(
        s["sherd_id"],
        archive,
        PNG,
        colour_munsell="2.5YR 6/8",
        colour_lab=(62.5, 21.25, 30.125),
        chart_delta_e00=1.7,
        px_per_cm=21.3,
        t_photo_s=8.0,
    )
    cat.add_note(s["sherd_id"], "rim, burnt edge")
    side = archive.path(sidecar_relpath(cat.get(s["sherd_id"])["image_path"]))
    with open(side) as f:
        assert json.load(f)["status"] == "photographed"
    cat.record_done(
        s["sherd_id"],
        t_discard_s=5.5,
        timings={"locomotion": 21.5, "grasping": 9.25, "data_collection": 4.5, "perception": 1.125},
        archive=archive,
    )
    with open(side) as f:
        final = json.load(f)
    assert final["status"] == "done" and final["mass_g"] == 25.3
    assert final["image_sha256"] == cat.get(s["sherd_id"])["image_sha256"]
    return s


# --- migrations ---
def test_migrations_apply_from_empty_and_rerun_is_a_no_op(pg_dsn):
    conn = psycopg2.connect(pg_dsn)
    assert [r[3] for r in status(conn)] == ["pending"] * len(available())
    assert migrate(conn) == [m.version for m in available()]
    assert migrate(conn) == []
    assert {r[3] for r in status(conn)} == {"applied"}
    for table in ("sites", "contexts", "sherds", "events", "schema_migrations"):
        assert count(conn, table) >= 0
    assert count(conn, "schema_migrations") == len(available())
    conn.close()


def test_concurrent_migrators_apply_each_migration_once(pg_dsn):
    results, errors = [], []

    def run():
        try:
            c = psycopg2.connect(pg_dsn)
            results.append(migrate(c))
            c.close()
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=run) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert not errors
    # each migration is its own transaction, so the migrators may share the work, never repeat it
    applied = sorted(v for r in results for v in r)
    assert len(results) == 3 and applied == [m.version for m in available()]


def test_edited_migration_is_refused(pg_dsn, tmp_path):
    mig_dir = tmp_path / "migrations"
    shutil.copytree(MIGRATIONS_DIR, mig_dir)
    conn = psycopg2.connect(pg_dsn)
    migrate(conn, directory=str(mig_dir))
    first = sorted(os.listdir(mig_dir))[0]
    with open(mig_dir / first, "a") as f:
        f.write("\n-- edited after release\n")
    with pytest.raises(MigrationError, match="changed after it was applied"):
        migrate(conn, directory=str(mig_dir))
    assert [r[3] for r in status(conn, directory=str(mig_dir))][0] == "changed"
    conn.close()


def test_catalogue_refuses_an_unmigrated_database(pg_dsn):
    with pytest.raises(CatalogueError, match="rascal db migrate"):
        Catalogue.connect(pg_dsn, rig="r", config_hash="h")


# --- the catalogue's identity (migration 0004) and the archive's file names ---
def test_identity_is_one_per_database_and_names_the_archived_files(
    catalogue, migrated_dsn, tmp_path
):
    ident = catalogue.identity()
    assert str(uuid.UUID(ident)) == ident
    other = Catalogue.connect(migrated_dsn, rig="rig-2", config_hash="h")
    assert other.identity() == ident  # another rig on the same catalogue
    other.close()
    archive = ImageArchive(str(tmp_path))
    catalogue.open_context("TR1-1023", "site")
    s = full_sherd(catalogue, archive)
    rel = catalogue.get(s["sherd_id"])["image_path"]
    assert rel == "TR1-1023/1-%s.png" % ident.replace("-", "")[:12]
    assert sorted(os.listdir(tmp_path / "TR1-1023")) == sorted(
        [os.path.basename(rel), os.path.basename(rel)[:-4] + ".json"]
    )


def test_a_copied_database_takes_an_identity_of_its_own(migrated_dsn):
    cat = Catalogue.connect(migrated_dsn, rig="r", config_hash="h")
    original = cat.identity()
    cat.close()
    admin_dsn = os.environ.get(
        "RASCAL_TEST_PG_DSN", "postgresql://rascal:rascal@127.0.0.1:5432/rascal"
    )
    admin = psycopg2.connect(admin_dsn)
    admin.autocommit = True
    copy = create_database(admin, template=migrated_dsn.rsplit("/", 1)[1])
    try:
        lines = []

        class Log:
            info = warning = staticmethod(lines.append)

        twin = Catalogue.connect(
            migrated_dsn.rsplit("/", 1)[0] + "/" + copy, rig="r", config_hash="h", logger=Log()
        )
        assert twin.identity() not in (None, original)
        assert any("is a copy of catalogue %s" % original in line for line in lines)
        twin.close()
        cat = Catalogue.connect(migrated_dsn, rig="r", config_hash="h")
        assert cat.identity() == original
        cat.close()
    finally:
        drop_database(admin, copy)
        admin.close()


# --- contexts and numbering ---
def test_numbering_is_per_context_and_starts_at_one(catalogue):
    catalogue.open_context("A-1", "site")
    catalogue.open_context("B-1", "site")
    seqs = [catalogue.new_sherd(ctx)["seq"] for ctx in ("A-1", "A-1", "B-1", "A-1")]
    assert seqs == [1, 2, 1, 3]


def test_reopening_a_context_is_idempotent_and_reports_progress(catalogue):
    first = catalogue.open_context("C1", "site", "bag 7")
    catalogue.new_sherd("C1")
    again = catalogue.open_context("C1", "site")
    assert first["created"] and not again["created"]
    assert again["sherds"] == 1 and again["unfinished"] == 1
    assert count(catalogue.connection, "contexts") == 1


def test_context_of_another_site_is_refused(catalogue):
    catalogue.open_context("C1", "site-a")
    with pytest.raises(FieldError, match="already belongs to site 'site-a'"):
        catalogue.open_context("C1", "site-b")


def test_sherd_in_an_unopened_context_is_refused_without_taking_a_number(catalogue):
    with pytest.raises(FieldError, match="open it first"):
        catalogue.new_sherd("NOPE")
    catalogue.open_context("NOPE", "site")
    assert catalogue.new_sherd("NOPE")["seq"] == 1


def test_unique_constraint_backs_the_numbering(catalogue):
    catalogue.open_context("C1", "site")
    catalogue.new_sherd("C1")
    conn = catalogue.connection
    with pytest.raises(psycopg2.errors.UniqueViolation):
        with conn, conn.cursor() as cur:
            cur.execute(
                "INSERT INTO sherds (context_id, seq, rig, software_version, "
                "config_hash, picked_at, updated_at) VALUES ('C1', 1, 'r', 'v', 'h', "
                "now(), now())"
            )


def test_concurrent_writers_in_threads_get_distinct_gap_free_numbers(migrated_dsn):
    setup = Catalogue.connect(migrated_dsn, rig="r", config_hash="h")
    setup.open_context("SHARED", "site")
    got, errors = [], []
    barrier = threading.Barrier(4)

    def writer():
        try:
            cat = Catalogue.connect(migrated_dsn, rig="r", config_hash="h")
            barrier.wait(10)
            for _ in range(25):
                got.append(cat.new_sherd("SHARED")["seq"])
            cat.close()
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=writer) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert not errors
    assert sorted(got) == list(range(1, 101))
    assert [r["seq"] for r in setup.sherds("SHARED")] == list(range(1, 101))
    setup.close()


# --- hostile context ids ---
# refused as context ids (any printable text is a context id; test_context_ids.py) and as
# site ids (the small alphabet)
HOSTILE = [
    ("../../etc", "must not contain '..' as a path part"),
    ("x" * 65, "is 65 characters long, at most 64"),
    ("\x00", "must not contain control characters"),
    ("", "must not be empty"),
    ("..", "must not contain '..' as a path part"),
    ("tab\there", "must not contain control characters"),
    ("  ", "must not be only spaces"),
    ("a\u200bb", "must not contain invisible characters"),
]


@pytest.mark.parametrize("bad, why", HOSTILE)
def test_hostile_context_ids_are_refused_and_nothing_is_written(catalogue, tmp_path, bad, why):
    archive = ImageArchive(str(tmp_path / "archive"))
    catalogue.open_context("GOOD", "site")
    good = catalogue.new_sherd("GOOD")
    before = {t: count(catalogue.connection, t) for t in ("sites", "contexts", "sherds", "events")}
    for site, call in (
        (False, lambda: catalogue.open_context(bad, "site")),
        (True, lambda: catalogue.open_context("GOOD2", bad)),
        (False, lambda: catalogue.new_sherd(bad)),
        (False, lambda: catalogue.sherds(bad)),
        (False, lambda: export_records(catalogue.connection, bad)),
        (False, lambda: archive.store(bad, 1, PNG)),
    ):
        with pytest.raises(ContextIdError) as err:
            call()
        msg = str(err.value)
        assert "\n" not in msg
        if site:
            assert msg.startswith("site id") and msg.endswith(
                "(use letters, digits, '-', '_', '.')"
            )
        else:
            assert why in msg and msg.startswith("context id '"), msg
            assert msg.endswith(
                "(any printable text up to 64 characters, e.g. TR1/1023, SU 1023, Köln-1)"
            )
    after = {t: count(catalogue.connection, t) for t in ("sites", "contexts", "sherds", "events")}
    assert after == before
    assert not os.path.exists(tmp_path / "archive") or os.listdir(tmp_path / "archive") == []
    assert catalogue.get(good["sherd_id"])["status"] == "picked"  # sherds table intact


def test_database_refuses_bad_ids_even_when_python_is_bypassed(catalogue):
    conn = catalogue.connection
    with pytest.raises(psycopg2.errors.CheckViolation):
        with conn, conn.cursor() as cur:
            cur.execute("INSERT INTO sites (site_id) VALUES (%s)", ("a'; DROP TABLE sherds;--",))
    assert count(conn, "sherds") == 0  # the table is still there


# --- states and fields ---
def test_full_record_moves_through_every_state(catalogue, tmp_path):
    archive = ImageArchive(str(tmp_path))
    catalogue.open_context("TR1-1023", "site")
    s = full_sherd(catalogue, archive)
    rec = catalogue.get(s["sherd_id"])
    assert rec["status"] == "done" and rec["find_id"] == "TR1-1023-1"
    assert rec["drops"] == 1 and rec["grasp_attempts"] == 2
    assert rec["picked_at"] < rec["weighed_at"] < rec["photographed_at"] < rec["done_at"]
    assert archive.verify(rec["image_path"], rec["image_sha256"])
    assert verify_archive(catalogue, archive) == []  # the sidecar holds the final row
    kinds = [e["kind"] for e in catalogue.events("TR1-1023")]
    assert kinds == [
        "context_opened",
        "picked",
        "grasp",
        "drop",
        "measured",
        "weighed",
        "photographed",
        "note",
        "done",
    ]


def test_each_measurement_is_committed_when_taken(catalogue, migrated_dsn):
    catalogue.open_context("C1", "site")
    s = catalogue.new_sherd("C1")
    catalogue.record_mass(s["sherd_id"], 12.5)
    other = psycopg2.connect(migrated_dsn)  # another session sees it at once
    with other, other.cursor() as cur:
        cur.execute("SELECT status::text, mass_g FROM sherds WHERE sherd_id = %s", (s["sherd_id"],))
        assert cur.fetchone() == ("weighed", 12.5)
    other.close()


@pytest.mark.parametrize(
    "call, allowed",
    [
        (lambda c, i: c.record_done(i), "photographed"),
        (
            lambda c, i: c.record_photo(i, "C1/1.png", "a" * 64),
            "mass_unstable, weighed, photographed",
        ),
    ],
)
def test_states_cannot_be_skipped(catalogue, call, allowed):
    catalogue.open_context("C1", "site")
    s = catalogue.new_sherd("C1")
    with pytest.raises(StatusError, match="sherd C1-1 is 'picked'.*only after %s" % allowed):
        call(catalogue, s["sherd_id"])
    assert catalogue.get(s["sherd_id"])["status"] == "picked"


def test_final_states_cannot_be_changed_but_reweighing_is_allowed(catalogue):
    catalogue.open_context("C1", "site")
    s = catalogue.new_sherd("C1")["sherd_id"]
    catalogue.record_mass(s, 10.0)
    catalogue.record_mass(s, 10.4)
    assert catalogue.get(s)["mass_g"] == 10.4
    catalogue.record_lost(s, "dropped off the table")
    with pytest.raises(StatusError, match="is 'lost'"):
        catalogue.record_mass(s, 11.0)
    with pytest.raises(StatusError):
        catalogue.record_drop(s)


def test_a_mass_by_difference_corrects_a_sherd_on_its_way_and_keeps_both_figures(
    catalogue, tmp_path
):
    # weighed with a rider that then stayed on the pan: corrected while weighed or
    # photographed, the event keeps what was weighed; refused once done, and refused bad
    catalogue.open_context("C1", "site")
    s = catalogue.new_sherd("C1")["sherd_id"]
    with pytest.raises(StatusError, match="is 'picked'.*only after weighed, photographed"):
        catalogue.record_mass_by_difference(s, 7.3, 16.5)
    catalogue.record_mass(s, 16.5)
    catalogue.archive_photo(s, ImageArchive(str(tmp_path)), PNG)
    assert catalogue.get(s)["status"] == "photographed"
    catalogue.record_mass_by_difference(s, 7.3, 16.5)
    assert catalogue.get(s)["mass_g"] == 7.3
    (event,) = [e for e in catalogue.events("C1") if e["kind"] == "mass_by_difference"]
    assert event["detail"]["mass_g"] == 7.3 and event["detail"]["weighed_g"] == 16.5
    with pytest.raises(FieldError, match="mass_g"):
        catalogue.record_mass_by_difference(s, 0.0, 16.5)
    catalogue.record_done(s)
    with pytest.raises(StatusError, match="is 'done'"):
        catalogue.record_mass_by_difference(s, 7.0, 7.3)
    assert catalogue.get(s)["mass_g"] == 7.3


@pytest.mark.parametrize("value", [0, -3.0, float("nan"), float("inf"), "heavy", True, None, 1e6])
def test_bad_mass_is_refused_naming_the_field_and_nothing_changes(catalogue, value):
    catalogue.open_context("C1", "site")
    s = catalogue.new_sherd("C1")["sherd_id"]
    events = len(catalogue.events("C1"))
    with pytest.raises(FieldError) as err:
        catalogue.record_mass(s, value)
    assert str(err.value).startswith("mass_g") and "\n" not in str(err.value)
    assert catalogue.get(s)["status"] == "picked" and catalogue.get(s)["mass_g"] is None
    assert len(catalogue.events("C1")) == events


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"image_sha256": "XYZ"}, "image_sha256"),
        ({"image_path": "/etc/passwd"}, "image_path"),
        ({"image_path": "C1/../../x.png"}, "image_path"),
        ({"colour_lab": (50, 0)}, "colour_lab"),
        ({"colour_munsell": "5YR'; --"}, "colour_munsell"),
        ({"px_per_cm": 0}, "px_per_cm"),
    ],
)
def test_bad_photo_fields_are_refused(catalogue, kwargs, field):
    catalogue.open_context("C1", "site")
    s = catalogue.new_sherd("C1")["sherd_id"]
    catalogue.record_mass(s, 20.0)
    args = dict({"image_path": "C1/1.png", "image_sha256": "a" * 64}, **kwargs)
    with pytest.raises(FieldError, match="^" + field):
        catalogue.record_photo(s, **args)
    assert catalogue.get(s)["status"] == "weighed"


@pytest.mark.parametrize(
    "timings, why",
    [
        ({"teleport": 1.0}, "unknown phase 'teleport'"),
        ({"grasping": -1.0}, r"timings\[grasping\]"),
        ([1, 2], "must be a dict"),
    ],
)
def test_bad_timings_are_refused(catalogue, tmp_path, timings, why):
    catalogue.open_context("C1", "site")
    s = catalogue.new_sherd("C1")["sherd_id"]
    catalogue.record_mass(s, 20.0)
    catalogue.archive_photo(s, ImageArchive(str(tmp_path)), PNG)
    with pytest.raises(FieldError, match=why):
        catalogue.record_done(s, timings=timings)
    assert catalogue.get(s)["status"] == "photographed"


def test_unknown_sherd_id_is_a_field_error(catalogue):
    with pytest.raises(FieldError, match="no such sherd"):
        catalogue.record_mass(999, 1.0)


def test_injected_clock_sets_the_timestamps(migrated_dsn):
    cat = Catalogue.connect(migrated_dsn, rig="r", config_hash="h", clock=lambda: 1.8e9)
    cat.open_context("C1", "site")
    s = cat.new_sherd("C1")
    assert cat.get(s["sherd_id"])["picked_at"].timestamp() == 1.8e9
    cat.close()


def test_rig_and_config_hash_are_recorded_with_every_sherd(catalogue):
    catalogue.open_context("C1", "site")
    rec = catalogue.get(catalogue.new_sherd("C1")["sherd_id"])
    assert (rec["rig"], rec["config_hash"]) == ("test-rig", "cafe0123")
    assert rec["software_version"].startswith("rascal_tasks")


# --- export ---
def _same(name, kind, a, b):
    if kind == "float" and a is not None:  # exported at the precision it was measured to
        return math.isclose(a, rounded(name, b), rel_tol=0, abs_tol=0)
    return a == b


def test_export_round_trips_every_field(catalogue, tmp_path):
    archive = ImageArchive(str(tmp_path))
    catalogue.open_context("TR1-1023", "site-7")
    full_sherd(catalogue, archive)
    lost = catalogue.new_sherd("TR1-1023", pickup_xy=(0.2, 0.3))
    catalogue.record_lost(
        lost["sherd_id"], "not found after 2 searches", timings={"locomotion": 3.0}
    )
    unfinished = catalogue.new_sherd("TR1-1023")
    catalogue.record_mass(unfinished["sherd_id"], 3.25)

    db = catalogue.sherds("TR1-1023")
    context, records = export_records(catalogue.connection, "TR1-1023")
    assert [r["seq"] for r in records] == [1, 2, 3]
    assert context["site_id"] == "site-7"

    doc = json.loads(to_json(context, records))
    assert [c["name"] for c in doc["columns"]] == [c[0] for c in COLUMNS]
    from_csv = parse_csv(to_csv(records))
    for exported in (doc["sherds"], from_csv):
        assert len(exported) == 3
        for rec, row in zip(db, exported, strict=True):
            assert list(row) == [c[0] for c in COLUMNS]
            for name, kind, _ in COLUMNS:
                value = row[name]
                if kind == "timestamp" and isinstance(value, str):
                    import datetime

                    value = datetime.datetime.fromisoformat(value)
                assert _same(name, kind, value, rec[name]), (name, value, rec[name])
    first = from_csv[0]
    assert first["mass_g"] == 25.3 and first["colour_b"] == 30.1  # 30.125 at 0.1
    assert first["notes"] == "rim, burnt edge" and first["find_id"] == "TR1-1023-1"
    assert first["t_grasping_s"] == 9.3 and first["t_perception_s"] == 1.1  # 9.25, 1.125
    assert from_csv[1]["lost_reason"] == "not found after 2 searches"
    assert from_csv[1]["t_locomotion_s"] == 3.0 and from_csv[1]["t_grasping_s"] is None
    assert from_csv[2]["status"] == "weighed" and from_csv[2]["image_path"] is None


def test_export_of_unknown_context_says_so(catalogue):
    with pytest.raises(FieldError, match="context id 'NOPE': not in the catalogue"):
        export_records(catalogue.connection, "NOPE")


# --- mass_unstable: weighed without a mass that can be trusted ---
UNSTEADY = "the reading did not hold within 0.1 g for 1.0 s in 3 attempts of 4.0 s"


def test_mass_unstable_has_no_mass_and_goes_on_to_done_saying_why(catalogue, tmp_path):
    archive = ImageArchive(str(tmp_path))
    catalogue.open_context("C1", "site")
    s = catalogue.new_sherd("C1")["sherd_id"]
    assert catalogue.record_mass_unstable(s, UNSTEADY, t_weigh_s=12.5)["status"] == "mass_unstable"
    rec = catalogue.get(s)
    assert (rec["status"], rec["mass_g"], rec["mass_missing_reason"]) == (
        "mass_unstable",
        None,
        UNSTEADY,
    )
    assert rec["weighed_at"] is not None and rec["t_weigh_s"] == 12.5
    assert [r["seq"] for r in catalogue.unfinished("C1")] == [1]  # a restart resumes it
    assert catalogue.open_context("C1", "site")["unfinished"] == 1
    catalogue.archive_photo(s, archive, PNG)
    catalogue.record_done(s, archive=archive)
    rec = catalogue.get(s)
    assert (rec["status"], rec["mass_g"], rec["mass_missing_reason"]) == ("done", None, UNSTEADY)
    assert verify_archive(catalogue, archive) == []
    assert "mass_unstable" in [e["kind"] for e in catalogue.events("C1")]
    _, records = export_records(catalogue.connection, "C1")
    row = parse_csv(to_csv(records))[0]
    assert (row["status"], row["mass_g"], row["mass_missing_reason"]) == ("done", None, UNSTEADY)


def test_mass_unstable_rules(catalogue):
    catalogue.open_context("C1", "site")
    s = catalogue.new_sherd("C1")["sherd_id"]
    with pytest.raises(FieldError, match="^reason"):
        catalogue.record_mass_unstable(s, " ")
    with pytest.raises(StatusError, match="'picked': cannot record 'done'"):
        catalogue.record_done(s)
    catalogue.record_mass_unstable(s, UNSTEADY)
    catalogue.record_mass_unstable(s, "again: " + UNSTEADY)  # read again, still unsteady
    with pytest.raises(StatusError, match="'mass_unstable': cannot record 'done'"):
        catalogue.record_done(s)
    catalogue.record_mass(s, 13.9)  # weighed again, now settled: the reason goes
    rec = catalogue.get(s)
    assert (rec["status"], rec["mass_g"], rec["mass_missing_reason"]) == ("weighed", 13.9, None)
    # a recorded mass is never replaced by "no mass"
    with pytest.raises(StatusError, match="'weighed': cannot record 'mass_unstable'"):
        catalogue.record_mass_unstable(s, UNSTEADY)
    assert catalogue.get(s)["mass_g"] == 13.9
    t = catalogue.new_sherd("C1")["sherd_id"]
    catalogue.record_mass_unstable(t, UNSTEADY)
    catalogue.record_lost(t, "fell off the table")
    assert catalogue.get(t)["mass_missing_reason"] == UNSTEADY


@pytest.mark.parametrize(
    "update",
    [
        "status = 'mass_unstable', mass_g = 12.0, mass_missing_reason = 'x'",
        "status = 'mass_unstable'",  # no reason
        "status = 'weighed', mass_g = NULL",
        "status = 'weighed', mass_g = 12.0, mass_missing_reason = 'x'",  # a mass and no mass
        "status = 'photographed', image_path = 'C1/1.png', image_sha256 = repeat('a', 64)",
        "mass_missing_reason = ''",
    ],
)
def test_database_keeps_mass_or_reason_even_when_python_is_bypassed(catalogue, update):
    catalogue.open_context("C1", "site")
    s = catalogue.new_sherd("C1")["sherd_id"]
    conn = catalogue.connection
    with pytest.raises(psycopg2.errors.CheckViolation):
        with conn, conn.cursor() as cur:
            cur.execute("UPDATE sherds SET " + update + " WHERE sherd_id = %s", (s,))  # constants
    assert catalogue.get(s)["status"] == "picked"


def test_a_number_taken_over_moves_its_pickup_spot_only_while_picked(catalogue):
    catalogue.open_context("TR1-1023", "site")
    s = catalogue.new_sherd("TR1-1023", pickup_xy=(0.10, 0.22))
    catalogue.record_taken_over(s["sherd_id"], (0.18, 0.27))
    row = catalogue.get(s["sherd_id"])
    assert (row["pickup_x_m"], row["pickup_y_m"]) == (0.18, 0.27) and row["status"] == "picked"
    assert "taken_over" in [e["kind"] for e in catalogue.events("TR1-1023")]
    catalogue.record_mass(s["sherd_id"], 20.0)
    with pytest.raises(StatusError, match="cannot record 'taken_over'"):
        catalogue.record_taken_over(s["sherd_id"], (0.2, 0.2))
    with pytest.raises(FieldError, match="pickup_x_m"):
        catalogue.record_taken_over(s["sherd_id"], ("a", 0.2))


def test_a_sherd_records_the_bin_it_went_into_with_the_reason(catalogue):
    catalogue.open_context("TR1-1023", "site")
    s = catalogue.new_sherd("TR1-1023", pickup_xy=(0.10, 0.22))
    catalogue.record_bin(s["sherd_id"], "small_finds", "small_finds: length < 30 mm (24 mm)")
    assert catalogue.get(s["sherd_id"])["bin"] == "small_finds"
    ev = [e for e in catalogue.events("TR1-1023") if e["kind"] == "sorted"]
    assert ev and "24 mm" in json.dumps(ev[-1], default=str)
    with pytest.raises(FieldError, match="bin"):
        catalogue.record_bin(s["sherd_id"], "no such; bin")
