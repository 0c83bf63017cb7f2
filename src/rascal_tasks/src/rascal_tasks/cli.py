"""The ``rascal`` command line (scripts/rascal is a thin wrapper around ``main``).

    rascal db migrate                      apply the catalogue's SQL migrations
    rascal db status                       show the database and which migrations are applied
    rascal export --context ID --format csv|json [--output FILE]
    rascal run --context ID                one batch on the rig (config from the parameter server)
    rascal report --context ID             HTML page: thumbnails, measurements, time breakdown
    rascal verify [--context ID] [--repair] the image archive checked against the catalogue

The database comes from ``--dsn``, else ``$RASCAL_DSN``, else ``database.dsn`` of the site
config (``--config``, else ``$RASCAL_CONFIG``, else config/rascal.yaml of the workspace; for
``rascal run`` else the parameter server's), else the default DSN below (`resolve_database`, one
path for every verb). Errors are one line on stderr. Exit status (exit_codes.py): 0 done,
1 incomplete (``run``: sherds left or lost; ``db status``: schema not up to date), 2 bad
arguments, config or context, 3 a fault (database, rig, archive), 4 busy, 130 interrupted.

To add a subcommand: write ``_add_<name>(subparsers)`` that creates its parser and sets
``func``, and call it in ``build_parser``.
"""

import argparse
import os
import re
import sys
import tempfile

from rascal_tasks import exit_codes

DEFAULT_DSN = "postgresql://rascal:rascal@127.0.0.1:5432/rascal"
_WORKSPACE_CONFIG = os.path.normpath(
    os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "..", "config", "rascal.yaml"
    )
)


class UsageError(Exception):
    """Bad arguments or configuration (exit status 2)."""


def mask_dsn(dsn):
    """The DSN with its password replaced by ***."""
    dsn = re.sub(r"(://[^:/@]*:)[^@]*@", r"\1***@", dsn)
    return re.sub(r"(password\s*=\s*)\S+", r"\1***", dsn)


def load_site_config(path):
    """The validated site config (the lead's loader), or UsageError with its one line."""
    from rascal_tasks.config import ConfigError, load_config

    try:
        return load_config(path)
    except ConfigError as e:
        raise UsageError(str(e)) from None


def explicit_config_path(args):
    """The site config the user named (``--config``, else ``$RASCAL_CONFIG``), or None."""
    return args.config or os.environ.get("RASCAL_CONFIG") or None


def _config_path(args):
    path = explicit_config_path(args)
    if path:
        return path
    for candidate in (os.path.join("config", "rascal.yaml"), _WORKSPACE_CONFIG):
        if os.path.isfile(candidate):
            return candidate
    return None


def resolve_database(args, cfg=None):
    """``(dsn, connect_timeout, where_it_came_from)``: ``--dsn``, else ``$RASCAL_DSN``, else
    ``database.dsn`` of `cfg` (the configuration a run already loaded) or of the site config
    file, else DEFAULT_DSN. The connect timeout is the config's when there is one."""
    if cfg is None and not (args.dsn or os.environ.get("RASCAL_DSN")):
        path = _config_path(args)
        cfg = load_site_config(path) if path else None
    timeout = float(cfg["database"].get("connect_timeout", 5.0)) if cfg is not None else 5.0
    if args.dsn:
        return args.dsn, timeout, "--dsn"
    if os.environ.get("RASCAL_DSN"):
        return os.environ["RASCAL_DSN"], timeout, "RASCAL_DSN"
    if cfg is not None:
        return cfg["database"]["dsn"], timeout, cfg.source
    return DEFAULT_DSN, timeout, "default"


def connect(args):
    import psycopg2

    dsn, timeout, source = resolve_database(args)
    try:
        conn = psycopg2.connect(
            dsn, connect_timeout=max(1, int(round(timeout))), application_name="rascal-cli"
        )
    except psycopg2.OperationalError as e:
        first = (str(e).strip().splitlines() or ["unknown error"])[0]
        raise RuntimeError(
            "database %s (from %s): cannot connect: %s" % (mask_dsn(dsn), source, first)
        ) from None
    return conn, dsn, source


# --- db ---
def cmd_db_migrate(args, out):
    from rascal_tasks.catalogue import migrate

    conn, dsn, source = connect(args)
    try:
        done = migrate(conn, logger=_PrintLogger(out))
    finally:
        conn.close()
    if done:
        print(
            "migrated %s to version %d (%d applied)" % (mask_dsn(dsn), done[-1], len(done)),
            file=out,
        )
    else:
        print("%s: already up to date" % mask_dsn(dsn), file=out)
    return 0


def cmd_db_status(args, out):
    from rascal_tasks.catalogue import status

    conn, dsn, source = connect(args)
    try:
        rows = status(conn)
        with conn, conn.cursor() as cur:
            cur.execute("SHOW server_version")
            version = cur.fetchone()[0]
            counts = None
            if rows and rows[0][3] == "applied":
                cur.execute("SELECT (SELECT count(*) FROM contexts), (SELECT count(*) FROM sherds)")
                counts = cur.fetchone()
    finally:
        conn.close()
    print("database  %s (from %s), PostgreSQL %s" % (mask_dsn(dsn), source, version), file=out)
    for v, name, applied_at, state in rows:
        when = applied_at.strftime("%Y-%m-%d %H:%M:%S %Z") if applied_at else ""
        print("  %04d_%-24s %-8s %s" % (v, name, state, when), file=out)
    if counts is not None:
        print("contents  %d contexts, %d sherds" % counts, file=out)
    behind = [r for r in rows if r[3] != "applied"]
    if behind:
        print("schema    not up to date: run `rascal db migrate`", file=out)
        return 1
    print("schema    up to date", file=out)
    return 0


# --- export ---
def cmd_export(args, out):
    from rascal_tasks.catalogue import export_records, to_csv, to_json, validate_context_id
    from rascal_tasks.catalogue.errors import FieldError

    try:
        validate_context_id(args.context)
    except FieldError as e:
        raise UsageError(str(e)) from None
    conn, _, _ = connect(args)
    try:
        context, records = export_records(conn, args.context)
    finally:
        conn.close()
    text = to_csv(records) if args.format == "csv" else to_json(context, records)
    if args.output in (None, "-"):
        out.write(text)
    else:
        directory = os.path.dirname(os.path.abspath(args.output))
        fd, tmp = tempfile.mkstemp(prefix=".rascal-export.", dir=directory)
        try:
            with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
                f.write(text)
            os.replace(tmp, args.output)
        except BaseException:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
        print(
            "%d sherds of context %s written to %s" % (len(records), args.context, args.output),
            file=sys.stderr,
        )
    return 0


# --- run and report ---
def cmd_run(args, out):
    from rascal_tasks.run_batch import run

    return run(
        args.context,
        config_path=explicit_config_path(args),
        database=lambda cfg: resolve_database(args, cfg),
    )


def cmd_report(args, out):
    from rascal_tasks.catalogue import export_records, validate_context_id
    from rascal_tasks.catalogue.errors import FieldError
    from rascal_tasks.report import write_report

    try:
        validate_context_id(args.context)
    except FieldError as e:
        raise UsageError(str(e)) from None
    path = _config_path(args)
    if path is None:
        raise UsageError("no site config found; pass --config config/rascal.yaml")
    cfg = load_site_config(path)
    conn, _, _ = connect(args)
    try:
        context, records = export_records(conn, args.context)
    finally:
        conn.close()
    if not records:
        raise UsageError("context '%s': no sherds recorded (check the context id)" % args.context)
    done = [r for r in records if r["status"] == "done"]
    totals = [
        sum(
            r.get("t_%s_s" % k) or 0.0
            for k in ("locomotion", "grasping", "data_collection", "perception")
        )
        for r in done
    ]
    summary = {
        "sherds": len(records),
        "done": len(done),
        "lost": sum(r["status"] == "lost" for r in records),
        "drops": sum(r.get("drops") or 0 for r in records),
        "mean time per recorded sherd": "%.1f s" % (sum(totals) / len(totals)) if totals else "–",
    }
    archive = args.archive or cfg.resolve(cfg["archive"]["root"])
    report = write_report(args.context, records, archive, summary)
    print("report: %s" % report, file=out)
    return 0


# --- verify ---
def cmd_verify(args, out):
    """The image archive against the catalogue: one line per problem (exit 1), none (exit 0).
    --repair first rewrites what the catalogue can rewrite (stale or missing sidecars, old
    temporary files); a missing or changed image is left for a person."""
    from rascal_tasks.catalogue import Catalogue, ImageArchive, validate_context_id
    from rascal_tasks.catalogue import repair_archive, verify_archive

    if args.context is not None:
        validate_context_id(args.context)
    # the site config, unless --archive and --dsn / $RASCAL_DSN say everything it would
    needed = explicit_config_path(args) or not (
        args.archive and (args.dsn or os.environ.get("RASCAL_DSN"))
    )
    path = _config_path(args) if needed else None
    cfg = load_site_config(path) if path else None
    if args.archive is None and cfg is None:
        raise UsageError("no site config found; pass --config config/rascal.yaml or --archive")
    archive = ImageArchive(args.archive or cfg.resolve(cfg["archive"]["root"]))
    dsn, timeout, source = resolve_database(args, cfg)
    cat = Catalogue.connect(
        dsn,
        rig=cfg["rig"]["name"] if cfg is not None else "rascal-cli",
        config_hash=cfg.hash if cfg is not None else "rascal-cli",
        connect_timeout=timeout,
        application_name="rascal-cli",
    )
    try:
        if args.repair:
            for line in repair_archive(cat, archive, args.context):
                print("repaired: %s" % line, file=out)
        problems = verify_archive(cat, archive, args.context)
    finally:
        cat.close()
    for line in problems:
        print(line, file=out)
    what = "context %s" % args.context if args.context else "every context"
    if problems:
        print(
            "archive %s, %s: %d problem%s (database %s)"
            % (archive.root, what, len(problems), "" if len(problems) == 1 else "s", mask_dsn(dsn)),
            file=out,
        )
        return exit_codes.INCOMPLETE
    print(
        "archive %s, %s: matches the catalogue (database %s)" % (archive.root, what, mask_dsn(dsn)),
        file=out,
    )
    return exit_codes.COMPLETE


def _add_verify(sub):
    ver = sub.add_parser(
        "verify", help="check the image archive against the catalogue (exit 1 on a problem)"
    )
    ver.add_argument("--context", help="only this context (default: every context)")
    ver.add_argument(
        "--repair",
        action="store_true",
        help="first rewrite stale or missing sidecars and remove old temporary files",
    )
    ver.add_argument("--archive", help="image archive root (default: archive.root of the config)")
    ver.set_defaults(func=cmd_verify)


def _add_run(sub):
    run = sub.add_parser("run", help="record one bag: survey, pick, weigh, photograph, discard")
    run.add_argument("--context", required=True, help="context id of the bag, e.g. TR1-1023")
    run.set_defaults(func=cmd_run)


def _add_report(sub):
    rep = sub.add_parser("report", help="write an HTML report of a context's sherds")
    rep.add_argument("--context", required=True, help="context id, e.g. TR1-1023")
    rep.add_argument("--archive", help="image archive root (default: archive.root of the config)")
    rep.set_defaults(func=cmd_report)


class _PrintLogger:
    def __init__(self, out):
        self.out = out

    def info(self, msg):
        print(msg, file=self.out)

    warning = info


def _add_db(sub):
    db = sub.add_parser("db", help="catalogue database: migrate | status")
    dbsub = db.add_subparsers(dest="db_command", metavar="{migrate,status}")
    dbsub.required = True
    dbsub.add_parser("migrate", help="apply the SQL migrations (safe to re-run)").set_defaults(
        func=cmd_db_migrate
    )
    dbsub.add_parser(
        "status", help="show the database and its migrations (exit 1 if behind)"
    ).set_defaults(func=cmd_db_status)


def _add_export(sub):
    ex = sub.add_parser("export", help="write a context's sherd records as CSV or JSON")
    ex.add_argument("--context", required=True, help="context id, e.g. TR1-1023")
    ex.add_argument("--format", required=True, choices=("csv", "json"))
    ex.add_argument("--output", "-o", help="file to write (default: standard output)")
    ex.set_defaults(func=cmd_export)


def build_parser():
    p = argparse.ArgumentParser(prog="rascal", description="RASCAL: record pottery sherds.")
    p.add_argument("--config", help="site config (default: $RASCAL_CONFIG or config/rascal.yaml)")
    p.add_argument(
        "--dsn", help="PostgreSQL DSN (default: $RASCAL_DSN, else database.dsn of the config)"
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    _add_db(sub)
    _add_export(sub)
    _add_run(sub)
    _add_report(sub)
    _add_verify(sub)
    return p


def main(argv=None, out=None):
    out = out or sys.stdout
    parser = build_parser()
    args = parser.parse_args(argv)  # bad arguments: usage and exit 2 (BAD_INPUT)
    try:
        return args.func(args, out)
    except UsageError as e:
        print("rascal: error: %s" % e, file=sys.stderr)
        return exit_codes.BAD_INPUT
    except KeyboardInterrupt:
        print("rascal: interrupted", file=sys.stderr)
        return exit_codes.INTERRUPTED
    except Exception as e:  # one line for the operator, never a traceback
        return _fault(e)


def _fault(e: Exception) -> int:
    """One line and the exit code for an exception out of a verb (RASCAL_DEBUG=1: re-raise)."""
    from rascal_tasks.catalogue.errors import CatalogueError, FieldError

    if os.environ.get("RASCAL_DEBUG"):
        raise e
    if isinstance(e, FieldError):  # a context ID or a value given by the user
        print("rascal: error: %s" % e, file=sys.stderr)
        return exit_codes.BAD_INPUT
    if isinstance(e, (CatalogueError, RuntimeError, OSError)):
        print("rascal: error: %s" % e, file=sys.stderr)
        return exit_codes.FAULT
    try:
        import psycopg2

        if isinstance(e, psycopg2.Error):
            first = (str(e).strip().splitlines() or [type(e).__name__])[0]
            print("rascal: error: database: %s" % first, file=sys.stderr)
            return exit_codes.FAULT
    except ImportError:
        pass
    print(
        "rascal: error: unexpected %s: %s (RASCAL_DEBUG=1 shows where)" % (type(e).__name__, e),
        file=sys.stderr,
    )
    return exit_codes.FAULT
