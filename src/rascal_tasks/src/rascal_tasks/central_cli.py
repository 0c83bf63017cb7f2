"""``rascal central ...``: several rigs replicating to one central catalogue (catalogue/central.py).

    rascal --dsn CENTRAL central init                    make a migrated database the central one
    rascal --dsn CENTRAL central add-rig NAME --rig-dsn RIG [--publisher-dsn RIG_AS_CENTRAL_SEES_IT]
                                    [--central-dsn-for-rig CENTRAL_AS_THE_RIG_SEES_IT]
    rascal --dsn CENTRAL central status [--json] [--no-probe]   per rig: state, last seen, lag
    rascal --dsn RIG central claim --context ID          claim a context for this rig
    rascal --dsn RIG central release --context ID        give it up (another rig may take it)
    rascal --dsn RIG central sync-claims                 register provisional claims made offline
    rascal --dsn RIG central push-archive --to DIR [--archive DIR]   images, checked by SHA-256

``rascal verify --central --archive DIR`` (on the central server) checks the central archive
against the replicated catalogue. Exit codes as every verb: 0, 1 (status: a rig not streaming
or lagging; push-archive: a file not copied), 2 bad input, 3 fault, 4 a context another rig
holds.
"""

import sys

from rascal_tasks import exit_codes

LAG_WARN_S = 5.0  # status: a streaming rig further behind than this is flagged


def _cli():
    from rascal_tasks import cli

    return cli


def _catalogue(args):
    """A Catalogue on --dsn (the rig), schema up to date."""
    from rascal_tasks.catalogue import Catalogue

    cli = _cli()
    dsn, timeout, _ = cli.resolve_database(args)
    return Catalogue.connect(
        dsn, rig="rascal-cli", config_hash="rascal-cli", connect_timeout=timeout
    ), dsn


def cmd_init(args, out):
    from rascal_tasks.catalogue import migrate
    from rascal_tasks.catalogue.central import init_central

    cli = _cli()
    conn, dsn, _ = cli.connect(args)
    try:
        migrate(conn)
        changed = init_central(conn)
    finally:
        conn.close()
    print(
        "%s: %s" % (cli.mask_dsn(dsn), "now the central server" if changed else "already central"),
        file=out,
    )
    return exit_codes.COMPLETE


def cmd_add_rig(args, out):
    from rascal_tasks.catalogue.central import add_rig

    cli = _cli()
    central_dsn, _, _ = cli.resolve_database(args)
    got = add_rig(
        central_dsn,
        args.rig_dsn,
        args.name,
        publisher_dsn=args.publisher_dsn,
        central_dsn_for_rig=args.central_dsn_for_rig,
    )
    print(
        "rig %s: node %d, subscription %s on %s%s"
        % (
            got["rig"],
            got["node_no"],
            got["subscription"],
            cli.mask_dsn(central_dsn),
            (
                "; %d sherds recorded before joining were given keys of its block (run "
                "`rascal verify --repair` on the rig to rewrite their sidecars)" % got["moved"]
                if got["moved"]
                else ""
            ),
        ),
        file=out,
    )
    return exit_codes.COMPLETE


def _ago(seconds):
    if seconds is None:
        return "never"
    seconds = max(0.0, seconds)
    if seconds < 120:
        return "%.1f s ago" % seconds
    if seconds < 7200:
        return "%.0f min ago" % (seconds / 60)
    return "%.1f h ago" % (seconds / 3600)


def cmd_status(args, out):
    from rascal_tasks.catalogue.central import central_duplicates, rig_status

    cli = _cli()
    conn, dsn, _ = cli.connect(args)
    try:
        rigs = rig_status(conn, probe_rigs=not args.no_probe)
        dups = central_duplicates(conn)
    finally:
        conn.close()
    behind = [
        r
        for r in rigs
        if r["state"] != "streaming" or (r["lag_s"] is not None and r["lag_s"] > LAG_WARN_S)
    ]
    if args.json:
        cli._print_json({"rigs": rigs, "find_ids_twice": dups}, out)
    else:
        print(
            "%-16s %4s %-15s %-14s %8s %11s %7s  %s"
            % ("rig", "node", "state", "last seen", "lag", "unconfirmed", "sherds", "newest row"),
            file=out,
        )
        for r in rigs:
            lag = "%.1f s" % r["lag_s"] if r["lag_s"] is not None else "?"
            behind_b = "%d B" % r["lag_bytes"] if r["lag_bytes"] is not None else "?"
            newest = r["newest_row"].strftime("%Y-%m-%d %H:%M:%S %Z") if r["newest_row"] else "-"
            print(
                "%-16s %4d %-15s %-14s %8s %11s %7d  %s"
                % (
                    r["rig_name"],
                    r["node_no"],
                    r["state"],
                    _ago(r["seen_ago_s"]),
                    lag,
                    behind_b,
                    r["sherds"],
                    newest,
                ),
                file=out,
            )
            if r["probe"] not in (None, "ok"):
                print("  %s: %s" % (r["rig_name"], r["probe"]), file=out)
        for find_id, who in dups:
            print(
                "twice: %s recorded by %s (a clash; a person must look)"
                % (find_id, ", ".join(who)),
                file=out,
            )
        print(
            "%s: %d rigs, %d streaming%s"
            % (
                cli.mask_dsn(dsn),
                len(rigs),
                sum(r["state"] == "streaming" for r in rigs),
                ", %d find IDs twice" % len(dups) if dups else "",
            ),
            file=out,
        )
    return exit_codes.INCOMPLETE if behind or dups else exit_codes.COMPLETE


def cmd_claim(args, out):
    from rascal_tasks.catalogue import validate_context_id
    from rascal_tasks.catalogue.central import ContextClaimed, claim_context

    validate_context_id(args.context)
    cat, _ = _catalogue(args)
    try:
        state = claim_context(cat, args.context)
    except ContextClaimed as e:
        print("rascal: error: %s" % e, file=sys.stderr)
        return exit_codes.BUSY
    finally:
        cat.close()
    if state is None:
        print("this catalogue has not joined a central server: nothing to claim", file=out)
    else:
        print("context %s: %s by this rig" % (args.context, state), file=out)
    return exit_codes.COMPLETE


def cmd_release(args, out):
    from rascal_tasks.catalogue import validate_context_id
    from rascal_tasks.catalogue.central import release_context

    validate_context_id(args.context)
    cat, _ = _catalogue(args)
    try:
        last = release_context(cat, args.context)
    finally:
        cat.close()
    print(
        "context %s: released (last number %d; the next rig numbers on from %d)"
        % (args.context, last, last + 1),
        file=out,
    )
    return exit_codes.COMPLETE


def cmd_sync_claims(args, out):
    from rascal_tasks.catalogue.central import sync_claims

    cat, _ = _catalogue(args)
    try:
        done = sync_claims(cat)
    finally:
        cat.close()
    print("registered %d provisional claims: %s" % (len(done), ", ".join(done) or "-"), file=out)
    return exit_codes.COMPLETE


def cmd_push_archive(args, out):
    from rascal_tasks.catalogue.central import push_archive

    cli = _cli()
    root = cli._archive_root(args, required=True)
    conn, _, _ = cli.connect(args)
    try:
        got = push_archive(conn, root, args.to)
    finally:
        conn.close()
    for line in got["problems"]:
        print(line, file=out)
    print(
        "archive %s -> %s: %d copied, %d already there, %d problems"
        % (root, args.to, got["copied"], got["present"], len(got["problems"])),
        file=out,
    )
    return exit_codes.INCOMPLETE if got["problems"] else exit_codes.COMPLETE


def verify_central_cmd(args, out):
    """``rascal verify --central``: the central archive (--archive) against the central
    catalogue (--dsn)."""
    from rascal_tasks.catalogue.central import verify_central

    cli = _cli()
    root = cli._archive_root(args, required=True)
    conn, dsn, _ = cli.connect(args)
    try:
        problems, n = verify_central(conn, root, args.context)
    finally:
        conn.close()
    for line in problems:
        print(line, file=out)
    print(
        "central archive %s: %d images checked, %d problems (database %s)"
        % (root, n, len(problems), cli.mask_dsn(dsn)),
        file=out,
    )
    return exit_codes.INCOMPLETE if problems else exit_codes.COMPLETE


def add_central(sub):
    p = sub.add_parser(
        "central", help="several rigs, one central catalogue: init | add-rig | status | claim ..."
    )
    cs = p.add_subparsers(dest="central_command", metavar="ACTION")
    cs.required = True
    cs.add_parser("init", help="make --dsn (migrated here) the central server").set_defaults(
        func=cmd_init
    )
    a = cs.add_parser("add-rig", help="replicate a rig's catalogue to the central server (--dsn)")
    a.add_argument("name", help="the rig's name (a-z, 0-9, _ and -), e.g. rig-2")
    a.add_argument("--rig-dsn", required=True, help="the rig's database, as reached from here")
    a.add_argument(
        "--publisher-dsn",
        help="the rig's database as the central server reaches it (default: --rig-dsn)",
    )
    a.add_argument(
        "--central-dsn-for-rig",
        help="the central server as the rig reaches it, for claims (default: --dsn)",
    )
    a.set_defaults(func=cmd_add_rig)
    s = cs.add_parser("status", help="per rig: state, last seen, lag, sherds (exit 1 if behind)")
    s.add_argument("--json", action="store_true", help="write JSON")
    s.add_argument("--no-probe", action="store_true", help="do not connect to the rigs for lag")
    s.set_defaults(func=cmd_status)
    c = cs.add_parser("claim", help="claim a context for this rig (--dsn: the rig)")
    c.add_argument("--context", required=True)
    c.set_defaults(func=cmd_claim)
    r = cs.add_parser("release", help="give up this rig's claim on a context")
    r.add_argument("--context", required=True)
    r.set_defaults(func=cmd_release)
    cs.add_parser(
        "sync-claims", help="register the claims this rig made while offline"
    ).set_defaults(func=cmd_sync_claims)
    pa = cs.add_parser("push-archive", help="copy the rig's images to the central archive")
    pa.add_argument("--to", required=True, help="the central archive (a mounted folder)")
    pa.add_argument("--archive", help="this rig's archive (default: archive.root of the config)")
    pa.set_defaults(func=cmd_push_archive)
