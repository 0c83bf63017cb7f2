"""The `rascal` command line, run as a user would (/usr/bin/python3 scripts/rascal)."""

import json
import os
import subprocess

import pytest
from catalogue_helpers import PYTHON, FakeClock, subprocess_env

from rascal_tasks.catalogue import COLUMNS, Catalogue, ImageArchive, parse_csv
from rascal_tasks.catalogue.export import rounded

pytestmark = pytest.mark.timeout(120)

SCRIPT = os.path.join(
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts", "rascal"
)


def rascal(*args, env=None):
    e = subprocess_env()
    e.pop("RASCAL_DSN", None)
    e.update(env or {})
    return subprocess.run(
        [PYTHON, SCRIPT, *args], capture_output=True, text=True, env=e, timeout=60
    )


def test_script_is_executable_with_system_python():
    assert os.access(SCRIPT, os.X_OK)
    with open(SCRIPT) as f:
        assert f.readline().strip() == "#!/usr/bin/python3"


def test_db_migrate_then_status_then_migrate_again(pg_dsn):
    r = rascal("--dsn", pg_dsn, "db", "status")
    assert r.returncode == 1 and "pending" in r.stdout and "rascal db migrate" in r.stdout
    r = rascal("--dsn", pg_dsn, "db", "migrate")
    assert r.returncode == 0, r.stderr
    assert "applied migration 0001_initial.sql" in r.stdout
    assert "applied migration 0002_phase_timings.sql" in r.stdout
    r = rascal("--dsn", pg_dsn, "db", "migrate")
    assert r.returncode == 0 and "already up to date" in r.stdout
    r = rascal("db", "status", env={"RASCAL_DSN": pg_dsn})
    assert r.returncode == 0 and "up to date" in r.stdout and "(from RASCAL_DSN)" in r.stdout
    assert "rascal:rascal@" not in r.stdout  # password masked


def test_export_csv_and_json_round_trip(migrated_dsn, tmp_path):
    cat = Catalogue.connect(migrated_dsn, rig="rig-1", config_hash="abc", clock=FakeClock())
    cat.open_context("TR1-1023", "site")
    s = cat.new_sherd("TR1-1023", pickup_xy=(0.1, 0.25), t_pick_s=10.0)
    cat.record_dimensions(s["sherd_id"], 40.5, 30.25, 6.0)
    cat.record_mass(s["sherd_id"], 17.9, t_weigh_s=5.0)
    cat.archive_photo(
        s["sherd_id"],
        ImageArchive(str(tmp_path)),
        b"\x89PNG\r\n\x1a\nX",
        colour_munsell="10YR 7/3",
        colour_lab=(70.0, 3.5, 18.25),
    )
    cat.record_done(s["sherd_id"])
    db = cat.sherds("TR1-1023")
    cat.close()

    r = rascal("--dsn", migrated_dsn, "export", "--context", "TR1-1023", "--format", "csv")
    assert r.returncode == 0, r.stderr
    rows = parse_csv(r.stdout)
    r2 = rascal(
        "--dsn",
        migrated_dsn,
        "export",
        "--context",
        "TR1-1023",
        "--format",
        "json",
        "--output",
        str(tmp_path / "out.json"),
    )
    assert r2.returncode == 0, r2.stderr
    doc = json.loads((tmp_path / "out.json").read_text())
    assert doc["format"] == "rascal-catalogue-export" and doc["context"]["site_id"] == "site"
    for name, kind, _ in COLUMNS:
        want = db[0][name]
        if kind == "float":  # exported at the precision it was measured to (30.25 mm: 30.3)
            want = rounded(name, want)
        assert rows[0][name] == want, name
        got = doc["sherds"][0][name]
        if kind == "timestamp" and got is not None:
            got = want.fromisoformat(got)
        assert got == want, name


@pytest.mark.parametrize("bad", ["../../etc", "a'; DROP TABLE sherds;--", "x" * 65])
def test_export_refuses_hostile_context_with_one_line(migrated_dsn, bad):
    r = rascal("--dsn", migrated_dsn, "export", "--context", bad, "--format", "csv")
    assert r.returncode == 2 and r.stdout == ""
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rascal: error: context id '")


def test_unreachable_database_is_one_line(tmp_path):
    r = rascal("--dsn", "postgresql://rascal:secret@127.0.0.1:1/none", "db", "status")
    assert r.returncode == 3  # exit_codes.FAULT
    assert len(r.stderr.strip().splitlines()) == 1
    assert "cannot connect" in r.stderr and "secret" not in r.stderr


def test_dsn_comes_from_the_site_config(migrated_dsn, tmp_path):
    import shutil

    workspace = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(SCRIPT))))
    shipped = os.path.join(workspace, "config", "rascal.yaml")
    cfg = tmp_path / "config" / "rascal.yaml"
    cfg.parent.mkdir()
    shutil.copy(shipped, cfg)
    text = cfg.read_text()
    default = "dsn: postgresql://rascal:rascal@127.0.0.1:5432/rascal"
    assert default in text
    cfg.write_text(text.replace(default, "dsn: " + migrated_dsn))
    # the scenario path in the copied config is relative to its workspace: give it one
    if os.path.isdir(os.path.join(workspace, "config", "scenarios")):
        shutil.copytree(
            os.path.join(workspace, "config", "scenarios"), tmp_path / "config" / "scenarios"
        )
    from rascal_tasks.config import ConfigError, load_config

    try:
        load_config(str(cfg))
    except ConfigError as e:  # the config loader's own tests report this
        pytest.skip("the shipped config does not validate right now: %s" % e)
    r = rascal("--config", str(cfg), "db", "status")
    assert r.returncode == 0, r.stderr
    assert "(from %s)" % cfg in r.stdout


def test_missing_subcommand_is_a_usage_error():
    r = rascal("db")
    assert r.returncode == 2 and "usage:" in r.stderr
