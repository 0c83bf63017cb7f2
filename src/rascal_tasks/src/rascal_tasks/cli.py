"""The ``rascal`` command line (scripts/rascal is a thin wrapper around ``main``).

    rascal db migrate                      apply the catalogue's SQL migrations
    rascal db status                       show the database and which migrations are applied
    rascal export --context ID --format csv|json [--output FILE]
    rascal export --context ID --format field-desktop[-jsonl] --output DIR [--push URL]
    rascal run --context ID [--continue]   one batch on the rig (config from the parameter server)
    rascal report --context ID [--pdf]     printable page (A4 HTML, PDF): sherds, colour, totals
    rascal verify [--context ID] [--repair] the image archive checked against the catalogue
    rascal contexts [--json]               each context: sherds by status, mass, first/last recorded
    rascal show FIND_ID [--json]           one sherd: every field, its files, history and edits
    rascal search [--context ID] [--status S] [--mass-min G] [--mass-max G] [--length-min MM]
                  [--length-max MM] [--colour PREFIX] [--since DATE] [--until DATE] [--json]
    rascal edit FIND_ID FIELD=VALUE ... --reason TEXT [--who NAME]   audited correction
    rascal backup --output FILE            pg_dump -Fc + the image archive + SHA-256 manifest
    rascal restore FILE [--dsn DSN] [--archive DIR] [--force]   into an empty database
    rascal rerecord FIND_ID                a lost sherd put back on the mat, into its own row
    rascal central init|add-rig|status|claim|release|push-archive   rigs and the central server
    rascal calibrate [--output FILE]       stations measured from their ArUco markers
    rascal calibrate --sheet PNG           the markers to print (40 mm at 300 dpi)
    rascal teach STATION [--hand]          jog (or move by hand) the gripper to where sherds go

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


def _required_config_path(args):
    """The site config for a verb that cannot do without one; UsageError when there is none."""
    path = _config_path(args)
    if path is None:
        raise UsageError("no config/rascal.yaml here; pass --config")
    return path


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
def _export_settings(args):
    """``(file_mode, dir_mode, parent template, archive root or None)`` from the site config
    when there is one, else the schema's defaults."""
    from rascal_tasks.catalogue.archive import DIR_MODE, FILE_MODE
    from rascal_tasks.catalogue.field_desktop import DEFAULT_PARENT

    path = _config_path(args)
    if path is None:
        return FILE_MODE, DIR_MODE, DEFAULT_PARENT, None
    cfg = load_site_config(path)
    return (
        cfg["archive"]["file_mode"],
        cfg["archive"]["dir_mode"],
        cfg["export"]["field_desktop"]["parent"],
        cfg.resolve(cfg["archive"]["root"]),
    )


def _write_file(path, text, file_mode):
    """``text`` to ``path`` atomically (a temporary name, then rename) with ``file_mode``."""
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".rascal-export.", dir=directory)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
            os.fchmod(f.fileno(), file_mode)  # mkstemp made it 0600
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def cmd_export(args, out):
    from rascal_tasks.catalogue import export_records, to_csv, to_json, validate_context_id
    from rascal_tasks.catalogue.errors import FieldError

    try:
        args.context = validate_context_id(args.context)
    except FieldError as e:
        raise UsageError(str(e)) from None
    field = args.format.startswith("field-desktop")
    if field and not args.output:
        raise UsageError(
            "--format %s: --output DIR is required (the folder for the files "
            "and images Field Desktop imports)" % args.format
        )
    if args.push and not field:
        raise UsageError("--push: only with --format field-desktop or field-desktop-jsonl")
    file_mode, dir_mode, parent, archive_root = _export_settings(args)
    conn, _, _ = connect(args)
    try:
        context, records = export_records(conn, args.context)
    finally:
        conn.close()
    if field:
        return _export_field_desktop(args, records, file_mode, dir_mode, parent, archive_root)
    text = to_csv(records) if args.format == "csv" else to_json(context, records)
    if args.output in (None, "-"):
        out.write(text)
    else:
        _write_file(args.output, text, file_mode)
        print(
            "%d sherds of context %s written to %s" % (len(records), args.context, args.output),
            file=sys.stderr,
        )
    return 0


def _export_field_desktop(args, records, file_mode, dir_mode, parent, archive_root):
    """Field Desktop's files in --output (refused whole, with one line, when Field would refuse
    a value), then, with --push, each Pottery file POSTed to a running Field Desktop."""
    from rascal_tasks.catalogue.field_desktop import parent_identifier, push, write_export

    if args.archive:
        archive_root = os.path.abspath(args.archive)
    if archive_root is None and any(r.get("image_path") for r in records):
        raise UsageError("no site config found for the image archive; pass --archive DIR")
    fmt = "jsonl" if args.format == "field-desktop-jsonl" else "csv"
    parent_id = parent_identifier(args.parent or parent, args.context)
    result = write_export(
        args.output,
        args.context,
        records,
        archive_root,
        parent_id,
        fmt=fmt,
        file_mode=file_mode,
        dir_mode=dir_mode,
    )
    images = sum(os.sep + "images" + os.sep in f for f in result["files"])
    print(
        "%d sherds of context %s as Field Desktop %s resources (in %s) written to %s: %s%s"
        % (
            result["resources"],
            args.context,
            "Pottery",
            parent_id,
            args.output,
            ", ".join(name for name, _ in result["bodies"]),
            ", images/ (%d; import them into Field first)" % images if images else "",
        ),
        file=sys.stderr,
    )
    if result["left_out"]:
        print(
            "rascal: warning: %d unfinished sherd%s left out (%s); finish the batch "
            "(`rascal run --context %s`) and export again"
            % (
                len(result["left_out"]),
                "" if len(result["left_out"]) == 1 else "s",
                ", ".join(result["left_out"]),
                args.context,
            ),
            file=sys.stderr,
        )
    if args.push:
        password = os.environ.get("RASCAL_FIELD_PASSWORD", "")
        if args.field_password is not None:
            password = args.field_password
        n = push(args.push, result["bodies"], password, fmt=fmt)
        print("Field Desktop at %s imported %d resources" % (args.push, n), file=sys.stderr)
    return exit_codes.INCOMPLETE if result["left_out"] else exit_codes.COMPLETE


# --- run and report ---
def cmd_run(args, out):
    from rascal_tasks.run_batch import run

    return run(
        args.context,
        config_path=explicit_config_path(args),
        database=lambda cfg: resolve_database(args, cfg),
        append=args.append,
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
    modes = {"file_mode": cfg["archive"]["file_mode"], "dir_mode": cfg["archive"]["dir_mode"]}
    report = write_report(args.context, records, archive, summary, context, **modes)
    print("report: %s" % report, file=out)
    if args.pdf:
        from rascal_tasks.report import print_pdf

        pdf = print_pdf(report, file_mode=modes["file_mode"])
        print("pdf: %s" % pdf, file=out)
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
    if args.central:  # the central archive against the replicated catalogue
        from rascal_tasks.central_cli import verify_central_cmd

        return verify_central_cmd(args, out)
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
    ver.add_argument(
        "--central",
        action="store_true",
        help="on the central server: its archive (--archive) against the replicated catalogue",
    )
    ver.set_defaults(func=cmd_verify)


def _add_run(sub):
    run = sub.add_parser("run", help="record one bag: survey, pick, weigh, photograph, discard")
    run.add_argument("--context", required=True, help="context id of the bag, e.g. TR1-1023")
    run.add_argument(
        "--continue",
        dest="append",
        action="store_true",
        help="add this bag to a context whose last batch finished (its sherds numbered on); "
        "a stopped batch resumes without it",
    )
    run.set_defaults(func=cmd_run)


def _add_report(sub):
    rep = sub.add_parser(
        "report", help="write a context's printable report (A4 HTML page, with --pdf a PDF)"
    )
    rep.add_argument("--context", required=True, help="context id, e.g. TR1-1023")
    rep.add_argument("--archive", help="image archive root (default: archive.root of the config)")
    rep.add_argument(
        "--pdf",
        action="store_true",
        help="also print the page to <folder>.pdf with headless Chromium ($RASCAL_CHROMIUM)",
    )
    rep.set_defaults(func=cmd_report)


# --- the catalogue verbs: contexts, show, search, edit, backup, restore ---
def _open_catalogue(args):
    """``(conn, dsn)`` to a catalogue whose schema is up to date (else one line: migrate)."""
    from rascal_tasks.catalogue import Catalogue

    conn, dsn, _ = connect(args)
    try:
        Catalogue(conn, rig="rascal-cli", config_hash="rascal-cli").check_schema()
    except BaseException:
        conn.close()
        raise
    return conn, dsn


def _archive_root(args, required):
    """``--archive``, else archive.root of the site config; None (or UsageError when
    ``required``) without either, or when the config does not load and it is not required."""
    if getattr(args, "archive", None):
        return os.path.abspath(args.archive)
    path = _config_path(args)
    if path is None:
        if required:
            raise UsageError("no site config found; pass --archive DIR or --config FILE")
        return None
    try:
        cfg = load_site_config(path)
    except UsageError:
        if required or explicit_config_path(args):
            raise
        return None  # the workspace's config is only a guess here
    return cfg.resolve(cfg["archive"]["root"])


def _print_json(value, out):
    import json

    from rascal_tasks.catalogue.queries import to_jsonable

    print(json.dumps(to_jsonable(value), indent=1, ensure_ascii=False), file=out)


def _g(value):
    return None if value is None else "%.1f" % value


def cmd_contexts(args, out):
    from rascal_tasks.catalogue.queries import contexts_summary, format_table, local_iso

    conn, _ = _open_catalogue(args)
    try:
        rows = contexts_summary(conn)
    finally:
        conn.close()
    for r in rows:
        r["mass_g"] = None if r["mass_g"] is None else round(r["mass_g"], 1)
    if args.json:
        _print_json(rows, out)
        return exit_codes.COMPLETE
    table = [
        (
            r["context_id"],
            r["site_id"],
            r["sherds"],
            ", ".join(
                ["%d %s" % (n, st) for st, n in r["by_status"].items() if n]
                + (["%d re-recorded" % r["rerecorded"]] if r["rerecorded"] else [])
            )
            or "–",
            _g(r["mass_g"]),
            local_iso(r["first_recorded"]),
            local_iso(r["last_recorded"]),
        )
        for r in rows
    ]
    headers = (
        "context",
        "site",
        "sherds",
        "by status",
        "mass g",
        "first recorded",
        "last recorded",
    )
    for line in format_table(headers, table, right=(2, 4)):
        print(line, file=out)
    print(
        "%d context%s, %d sherds"
        % (len(rows), "" if len(rows) == 1 else "s", sum(r["sherds"] for r in rows)),
        file=out,
    )
    return exit_codes.COMPLETE


def cmd_show(args, out):
    from rascal_tasks.catalogue.archive import sidecar_relpath
    from rascal_tasks.catalogue.queries import find_sherd, local_iso, sherd_history
    from rascal_tasks.catalogue.rerecord import rerecord_links

    conn, _ = _open_catalogue(args)
    try:
        rec = find_sherd(conn, args.find_id)
        events, edits = sherd_history(conn, rec["sherd_id"])
        links = rerecord_links(conn, rec["sherd_id"])
    finally:
        conn.close()
    root = _archive_root(args, required=False)
    files = []
    if rec.get("image_path"):
        for kind, rel in (
            ("image", rec["image_path"]),
            ("sidecar", sidecar_relpath(rec["image_path"])),
        ):
            full = os.path.join(root, rel) if root else None
            files.append(
                {
                    "kind": kind,
                    "path": rel,
                    "file": full,
                    "exists": os.path.isfile(full) if full else None,
                }
            )
    if args.json:
        doc = {"sherd": rec, "files": files, "events": events, "edits": edits}
        _print_json(dict(doc, **links), out)
        return exit_codes.COMPLETE
    print("sherd %s" % rec["find_id"], file=out)
    width = max(len(k) for k in rec)
    for k, v in rec.items():
        shown = local_iso(v) if hasattr(v, "astimezone") else ("–" if v is None else v)
        print("  %-*s  %s" % (width, k, shown), file=out)
    if links["rerecorded_as"]:
        print(
            "re-recorded as %s (found again after it was lost)" % links["rerecorded_as"], file=out
        )
    if links["rerecord_of"]:
        print("re-record of %s (lost, then found again)" % links["rerecord_of"], file=out)
    print("files (archive %s)" % (root or "unknown: pass --archive"), file=out)
    for f in files:
        state = "" if f["exists"] is None else ("" if f["exists"] else "  (MISSING)")
        print("  %-7s  %s%s" % (f["kind"], f["file"] or f["path"], state), file=out)
    if not files:
        print("  none (no image recorded)", file=out)
    print("recorded", file=out)
    for e in events:
        detail = ", ".join("%s=%s" % kv for kv in sorted(e["detail"].items()) if kv[0] != "seq")
        print(("  %s  %-13s %s" % (local_iso(e["at"]), e["kind"], detail)).rstrip(), file=out)
    print("edits", file=out)
    for e in edits:
        print(
            "  %s  %s  %s: %s -> %s  (%s)"
            % (
                local_iso(e["at"]),
                e["who"],
                e["field"],
                _edit_value(e["old_value"]),
                _edit_value(e["new_value"]),
                e["reason"],
            ),
            file=out,
        )
    if not edits:
        print("  none", file=out)
    return exit_codes.COMPLETE


def _edit_value(v):
    import json

    return "–" if v is None else json.dumps(v, ensure_ascii=False)


def cmd_search(args, out):
    from rascal_tasks.catalogue.queries import (
        format_table,
        local_iso,
        parse_when,
        search_sherds,
    )

    since = parse_when(args.since, "--since") if args.since else None
    until = parse_when(args.until, "--until", end=True) if args.until else None
    conn, _ = _open_catalogue(args)
    try:
        rows = search_sherds(
            conn,
            context=args.context,
            statuses=args.status,
            mass_min=args.mass_min,
            mass_max=args.mass_max,
            length_min=args.length_min,
            length_max=args.length_max,
            colour=args.colour,
            since=since,
            until=until,
            limit=args.limit,
        )
    finally:
        conn.close()
    if args.json:
        _print_json(rows, out)
        return exit_codes.COMPLETE
    headers = (
        "find id",
        "status",
        "mass g",
        "length mm",
        "width mm",
        "thick mm",
        "colour",
        "picked",
    )
    table = [
        (
            r["find_id"],
            r["status"],
            _g(r["mass_g"]),
            _g(r["length_mm"]),
            _g(r["width_mm"]),
            _g(r["thickness_mm"]),
            r["colour_munsell"],
            local_iso(r["picked_at"]),
        )
        for r in rows
    ]
    for line in format_table(headers, table, right=(2, 3, 4, 5)):
        print(line, file=out)
    print("%d sherd%s" % (len(rows), "" if len(rows) == 1 else "s"), file=out)
    return exit_codes.COMPLETE


def _who(args):
    if args.who:
        return args.who
    if os.environ.get("USER"):
        return os.environ["USER"]
    import pwd

    return pwd.getpwuid(os.geteuid()).pw_name


def cmd_edit(args, out):
    """Change fields of one done or lost sherd, with a row in the audit trail per field; then
    the image's sidecar is rewritten from the row (else `rascal verify` calls it stale)."""
    from rascal_tasks.catalogue import Catalogue, ImageArchive
    from rascal_tasks.catalogue.audit import check_edit, edit_sherd
    from rascal_tasks.catalogue.errors import ArchiveError

    check_edit(args.find_id, args.assignments, args.reason, _who(args))  # before connecting
    conn, dsn = _open_catalogue(args)
    cat = Catalogue(conn, rig="rascal-cli", config_hash="rascal-cli")
    try:
        result = edit_sherd(conn, args.find_id, args.assignments, args.reason, _who(args))
        if not result["changes"]:
            print("%s: nothing changed (the values are those stored)" % args.find_id, file=out)
            return exit_codes.COMPLETE
        for column, old, new in result["changes"]:
            print(
                "%s: %s %s -> %s" % (args.find_id, column, _edit_value(old), _edit_value(new)),
                file=out,
            )
        rec = cat.get(result["sherd_id"])
        if not rec["image_path"]:
            return exit_codes.COMPLETE
        root = _archive_root(args, required=False)
        try:
            if root is None:
                raise ArchiveError("no archive known (pass --archive)")
            archive = ImageArchive(root)
            # never a sidecar beside an image that is not there (an archive not mounted)
            if archive.sha256(rec["image_path"]) != rec["image_sha256"]:
                raise ArchiveError("the image is missing or changed in %s" % archive.root)
            cat.refresh_sidecar(result["sherd_id"], archive)
        except ArchiveError as e:
            print(
                "rascal: warning: the edit is committed, but the sidecar of %s was not "
                "rewritten: %s; run `rascal verify --repair --context %s`"
                % (rec["image_path"], e, rec["context_id"]),
                file=sys.stderr,
            )
            return exit_codes.INCOMPLETE
    finally:
        cat.close()
    return exit_codes.COMPLETE


def cmd_backup(args, out):
    from rascal_tasks.catalogue.backup import create_backup

    if not args.timeout > 0:
        raise UsageError("--timeout %r: must be seconds > 0" % args.timeout)
    root = _archive_root(args, required=True)
    dsn, timeout, source = resolve_database(args)
    manifest = create_backup(dsn, args.output, root, connect_timeout=timeout, timeout=args.timeout)
    for line in manifest["problems"]:
        print("rascal: warning: %s" % line, file=sys.stderr)
    counts = manifest["counts"]
    print(
        "backup %s: %d contexts, %d sherds, %d files of archive %s, database %s (PostgreSQL %s)"
        % (
            args.output,
            counts.get("contexts", 0),
            counts.get("sherds", 0),
            len(manifest["files"]) - 1,
            root,
            mask_dsn(dsn),
            manifest["server_version"],
        ),
        file=out,
    )
    return exit_codes.INCOMPLETE if manifest["problems"] else exit_codes.COMPLETE


def cmd_restore(args, out):
    from rascal_tasks.catalogue.backup import restore_backup

    if not args.timeout > 0:
        raise UsageError("--timeout %r: must be seconds > 0" % args.timeout)
    root = _archive_root(args, required=True)
    if args.target_dsn:
        dsn, timeout, source = args.target_dsn, 5.0, "--dsn"
    else:
        dsn, timeout, source = resolve_database(args)
    modes = {}
    path = _config_path(args)
    if path is not None and not args.archive:  # the config's archive: its file modes
        archive_cfg = load_site_config(path)["archive"]
        modes = {k: archive_cfg[k] for k in ("file_mode", "dir_mode") if k in archive_cfg}
    manifest = restore_backup(
        args.file,
        dsn,
        root,
        force=args.force,
        connect_timeout=timeout,
        timeout=args.timeout,
        **modes,
    )
    counts = manifest["counts"]
    print(
        "restored %s: %d contexts, %d sherds into %s (from %s), %d files into %s; every "
        "SHA-256 checked"
        % (
            args.file,
            counts.get("contexts", 0),
            counts.get("sherds", 0),
            mask_dsn(dsn),
            source,
            len(manifest["files"]) - 1,
            root,
        ),
        file=out,
    )
    for line in manifest.get("problems") or []:  # what the backup itself could not take
        print("rascal: warning: not in the backup: %s" % line, file=sys.stderr)
    return exit_codes.INCOMPLETE if manifest.get("problems") else exit_codes.COMPLETE


def cmd_rerecord(args, out):
    """A lost sherd put back on the pickup mat: an ordinary batch of its context (the code of
    `rascal run`: the rig, its locks, resuming) records it into a new row, which is then linked
    to the lost one. Started again after a stop, it carries on."""
    from rascal_tasks.catalogue.queries import find_sherd
    from rascal_tasks.catalogue.rerecord import link_rerecord, start_rerecord
    from rascal_tasks.run_batch import run

    conn, _ = _open_catalogue(args)
    try:
        started = start_rerecord(conn, args.find_id, _who(args))
    finally:
        conn.close()
    print(
        "re-recording %s%s: the sherd alone, flat on the pickup mat; it is recorded into "
        "context %s after number %d"
        % (
            started["find_id"],
            " (carrying on)" if started["resumed"] else "",
            started["context_id"],
            started["after_seq"],
        ),
        file=out,
    )
    code = run(
        started["context_id"],
        config_path=explicit_config_path(args),
        database=lambda cfg: resolve_database(args, cfg),
        append=True,  # the context holds the lost sherd: this adds to it (--continue)
    )
    if code not in (exit_codes.COMPLETE, exit_codes.INCOMPLETE):
        return code  # the run said why; the same command carries on
    conn, _ = _open_catalogue(args)
    try:
        new, found = link_rerecord(conn, started)
        status = find_sherd(conn, new)["status"] if new else None
    finally:
        conn.close()
    if new is None:
        print(
            "rascal: error: %s not linked: %s; %s"
            % (
                started["find_id"],
                "the batch recorded %d sherds (%s)" % (len(found), ", ".join(found))
                if found
                else "the batch recorded no sherd",
                "put only the lost sherd on the mat for a re-record"
                if found
                else "put it flat on the pickup mat and run `rascal rerecord %s` again"
                % started["find_id"],
            ),
            file=sys.stderr,
        )
        return exit_codes.INCOMPLETE
    print(
        "%s re-recorded as %s (%s); the lost row stays as the record of the loss"
        % (started["find_id"], new, status),
        file=out,
    )
    # the run counts the lost row as left to look at; found again, it is not
    return exit_codes.COMPLETE if status == "done" else exit_codes.INCOMPLETE


def _add_doctor(sub):
    doc = sub.add_parser(
        "doctor",
        help="check every device of the field rig (servos, scale, cameras); one line per fix",
    )
    doc.add_argument(
        "--device",
        action="append",
        choices=("arm", "scale", "archival_camera", "wrist_camera"),
        help="check only this device (repeatable; default: all four)",
    )

    def cmd_doctor(args, out):
        from rascal_drivers import doctor

        path = _required_config_path(args)
        cfg = load_site_config(path)
        items = doctor.check_rig(cfg["drivers"], only=tuple(args.device or doctor.DEVICES))
        return exit_codes.COMPLETE if doctor.report(items, out) else exit_codes.FAULT

    doc.set_defaults(func=cmd_doctor)


def _add_calibrate(sub):
    p = sub.add_parser(
        "calibrate",
        help="measure every station's place from its ArUco markers; write a corrected layout",
    )
    p.add_argument(
        "--output",
        metavar="FILE",
        help="where the corrected layout goes (default: rascal.calibrated.yaml beside the config)",
    )
    p.add_argument(
        "--sheet",
        metavar="PNG",
        help="only write a page of the configured markers (300 dpi: print at 100 %%, each "
        "40 mm across) and stop; the arm does not move",
    )

    def cmd_calibrate(args, out):
        from rascal_tasks.run_calibrate import run, write_sheet

        path = _required_config_path(args)
        if args.sheet:
            return write_sheet(path, args.sheet, out)
        return run(path, args.output)

    p.set_defaults(func=cmd_calibrate)


def _add_teach(sub):
    p = sub.add_parser(
        "teach",
        help="teach where sherds are set down at a station by jogging the gripper there",
        description="Jog the gripper, pointing down 2 cm above the station, with one command "
        "per line: x+5, y-2.5 (mm), yaw+15 (degrees), show; save stores the measured place as "
        "stations.STATION.taught_place in the site file (the old one kept as .bak); quit "
        "leaves it as it was.",
    )
    p.add_argument("station", help="the station's name in the site file (e.g. scale, camera)")
    p.add_argument(
        "--hand",
        action="store_true",
        help="field rig: the arm's torque off, move the gripper there by hand and press Enter",
    )

    def cmd_teach(args, out):
        from rascal_tasks.run_teach import run

        path = _required_config_path(args)
        return run(path, args.station, out=out, hand=args.hand)

    p.set_defaults(func=cmd_teach)


def _add_central(sub):
    from rascal_tasks.central_cli import add_central

    add_central(sub)


def _add_rerecord(sub):
    p = sub.add_parser(
        "rerecord", help="record a lost sherd put back on the pickup mat into a row of its own"
    )
    p.add_argument("find_id", metavar="FIND_ID", help="the lost sherd, e.g. TR1-1023-4")
    p.add_argument("--who", help="who put it back (default: $USER)")
    p.set_defaults(func=cmd_rerecord)


def _add_contexts(sub):
    p = sub.add_parser(
        "contexts", help="every context: sherds by status, total mass, first/last recorded"
    )
    p.add_argument("--json", action="store_true", help="JSON instead of a table")
    p.set_defaults(func=cmd_contexts)


def _add_show(sub):
    p = sub.add_parser("show", help="one sherd: every field, its files, its history and edits")
    p.add_argument("find_id", metavar="FIND_ID", help="<context>-<number>, e.g. TR1-1023-4")
    p.add_argument("--archive", help="image archive root (default: archive.root of the config)")
    p.add_argument("--json", action="store_true", help="JSON instead of text")
    p.set_defaults(func=cmd_show)


def _add_search(sub):
    from rascal_tasks.catalogue.fields import STATUSES

    p = sub.add_parser("search", help="sherds by context, status, mass, length, colour, date")
    p.add_argument("--context", help="only this context")
    p.add_argument(
        "--status", action="append", choices=STATUSES, help="only this status (repeat for several)"
    )
    p.add_argument("--mass-min", type=float, metavar="G", help="mass at least G grams")
    p.add_argument("--mass-max", type=float, metavar="G", help="mass at most G grams")
    p.add_argument("--length-min", type=float, metavar="MM", help="length at least MM mm")
    p.add_argument("--length-max", type=float, metavar="MM", help="length at most MM mm")
    p.add_argument(
        "--colour",
        "--color",
        dest="colour",
        metavar="PREFIX",
        help="Munsell notation starting with PREFIX, e.g. 5YR or '10YR 6'",
    )
    p.add_argument("--since", metavar="DATE", help="picked on or after DATE (YYYY-MM-DD, local)")
    p.add_argument("--until", metavar="DATE", help="picked on or before DATE (YYYY-MM-DD, local)")
    p.add_argument("--limit", type=int, help="at most this many sherds")
    p.add_argument("--json", action="store_true", help="JSON instead of a table")
    p.set_defaults(func=cmd_search)


def _add_edit(sub):
    p = sub.add_parser(
        "edit", help="correct fields of a done or lost sherd, with an audit trail (--reason)"
    )
    p.add_argument("find_id", metavar="FIND_ID", help="<context>-<number>, e.g. TR1-1023-4")
    p.add_argument(
        "assignments",
        metavar="FIELD=VALUE",
        nargs="+",
        help="mass_g, length_mm, width_mm, thickness_mm (g, mm), colour_munsell, notes",
    )
    p.add_argument("--reason", help="why the value changes (required; kept in the audit trail)")
    p.add_argument("--who", help="who makes the change (default: $USER)")
    p.add_argument("--archive", help="image archive root (default: archive.root of the config)")
    p.set_defaults(func=cmd_edit)


def _add_backup(sub):
    p = sub.add_parser("backup", help="the catalogue (pg_dump) and its images in one file")
    p.add_argument("--output", "-o", required=True, help="backup file to write (must be new)")
    p.add_argument("--archive", help="image archive root (default: archive.root of the config)")
    p.add_argument("--timeout", type=float, default=3600.0, help="give up after this many s")
    p.set_defaults(func=cmd_backup)


def _add_restore(sub):
    p = sub.add_parser("restore", help="a backup into an empty database and archive folder")
    p.add_argument("file", metavar="FILE", help="a file written by `rascal backup`")
    p.add_argument(
        "--dsn",
        dest="target_dsn",
        metavar="DSN",
        help="database to restore into (default: as for every verb)",
    )
    p.add_argument("--archive", help="archive folder to restore into (default: archive.root)")
    p.add_argument(
        "--force",
        action="store_true",
        help="restore into a non-empty database/folder, replacing its catalogue",
    )
    p.add_argument("--timeout", type=float, default=3600.0, help="give up after this many s")
    p.set_defaults(func=cmd_restore)


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
    ex = sub.add_parser(
        "export", help="a context's sherds as CSV or JSON, or as files Field Desktop imports"
    )
    ex.add_argument("--context", required=True, help="context id, e.g. TR1-1023")
    ex.add_argument(
        "--format", required=True, choices=("csv", "json", "field-desktop", "field-desktop-jsonl")
    )
    ex.add_argument(
        "--output",
        "-o",
        help="file to write (default: standard output); the folder for field-desktop formats",
    )
    ex.add_argument("--archive", help="image archive root (default: archive.root of the config)")
    ex.add_argument(
        "--parent",
        metavar="IDENTIFIER",
        help="the context's identifier in the Field project (relations.isChildOf; default: "
        "export.field_desktop.parent of the config, {context})",
    )
    ex.add_argument(
        "--push",
        metavar="URL",
        help="also POST the Pottery file(s) to a running Field Desktop, e.g. http://localhost:3000",
    )
    ex.add_argument(
        "--field-password",
        metavar="PASSWORD",
        help="Field Desktop's password (its settings; default: $RASCAL_FIELD_PASSWORD)",
    )
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
    _add_contexts(sub)
    _add_show(sub)
    _add_search(sub)
    _add_edit(sub)
    _add_backup(sub)
    _add_restore(sub)
    _add_rerecord(sub)
    _add_central(sub)
    _add_doctor(sub)
    _add_calibrate(sub)
    _add_teach(sub)
    return p


def main(argv=None, out=None):
    out = out or sys.stdout
    parser = build_parser()
    args = parser.parse_args(argv)  # bad arguments: usage and exit 2 (BAD_INPUT)
    if isinstance(getattr(args, "context", None), str):  # 'Köln' typed either way is one context
        import unicodedata

        args.context = unicodedata.normalize("NFC", args.context)
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
