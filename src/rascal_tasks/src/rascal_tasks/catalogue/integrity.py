"""The image archive checked against the catalogue: repaired at start, verified on demand.

- ``repair_archive`` (called by ``Recorder`` when a run starts, after ``ImageArchive.check``):
  removes temporary files that an interrupted write left behind and rewrites every sidecar
  that is missing or disagrees with its catalogue row (a crash between committing a sherd and
  rewriting its sidecar). It never touches an image, and rewrites a sidecar only when the
  image beside it has the row's SHA-256: the row is the truth, the image its evidence.
- ``verify_archive`` (``rascal verify [--context ID]``): one line per problem: an image
  missing or changed, a sidecar missing, unreadable or stale, a file no row of this catalogue
  names, a leftover temporary file. Files named for another catalogue (see ``ImageArchive``)
  are that catalogue's and are skipped.

No ROS here; the catalogue and the archive are passed in.
"""

import time

from .archive import ARCHIVE_NAME, TEMP_NAME, owner_tag, sidecar_content, sidecar_relpath
from .context_id import context_folder

__all__ = ["repair_archive", "verify_archive", "TEMP_AGE"]

# A temporary file younger than this may belong to a write in progress (another run on the
# same archive); an archive write takes milliseconds.
TEMP_AGE = 60.0


def _rows_with_images(catalogue, context):
    contexts = [context] if context is not None else catalogue.contexts()
    return [r for c in contexts for r in catalogue.sherds(c) if r["image_path"]]


def _sidecar_state(archive, row, owner):
    """None if the sidecar of ``row``'s image holds exactly the row, else what is wrong:
    'missing', 'unreadable' or 'stale'."""
    try:
        side = archive.read_sidecar(row["image_path"])
    except ValueError:
        return "unreadable"
    if side is None:
        return "missing"
    side.pop("written_at", None)
    return None if side == sidecar_content(row, owner) else "stale"


def repair_archive(catalogue, archive, context=None, log=None, temp_age=TEMP_AGE, clock=time.time):
    """Repair the archive of ``context`` (or of every context) after a crash: remove leftover
    temporary files older than ``temp_age`` s and rewrite each missing or stale sidecar from
    its catalogue row where the image matches the row's SHA-256.

    Returns one line per repair; ``log(line)`` gets one summary line when something was
    repaired or something is left that only a person can fix (then: run ``rascal verify``).
    Raises ArchiveError (one line) when the archive cannot be written."""
    owner = catalogue.identity()
    done = []
    for rel in archive.temp_files(context, older_than=temp_age, now=clock()):
        archive.remove(rel)
        done.append("removed leftover temporary file %s" % rel)
    rewritten = 0
    left = 0
    for row in _rows_with_images(catalogue, context):
        state = _sidecar_state(archive, row, owner)
        if state is None:
            continue
        if archive.sha256(row["image_path"]) != row["image_sha256"]:
            left += 1  # image missing or changed: not for a program to decide
            continue
        archive.write_sidecar(row["context_id"], row["seq"], row, owner=owner)
        rewritten += 1
        done.append(
            "%s: rewrote %s sidecar %s from the catalogue"
            % (row["find_id"], state, sidecar_relpath(row["image_path"]))
        )
    if (done or left) and log is not None:
        where = "context %s" % context if context is not None else "every context"
        line = "archive %s (%s): rewrote %d sidecar%s, removed %d temporary file%s" % (
            archive.root,
            where,
            rewritten,
            "" if rewritten == 1 else "s",
            len(done) - rewritten,
            "" if len(done) - rewritten == 1 else "s",
        )
        if left:
            line += "; %d image%s missing or changed: run `rascal verify%s`" % (
                left,
                "" if left == 1 else "s",
                " --context %s" % context if context is not None else "",
            )
        log(line)
    return done


def verify_archive(catalogue, archive, context=None, temp_age=TEMP_AGE, clock=time.time):
    """Check the archive against the catalogue for ``context`` (or every context); returns
    one line per problem (empty when all is well), each naming the file and the fix:

    - an image a row names is missing, or its SHA-256 differs from the row's;
    - its sidecar is missing, unreadable or disagrees with the row (stale);
    - a file in a context folder that no row of this catalogue names (extra); files named for
      another catalogue, subfolders (the report) and the spool are not this catalogue's;
    - a temporary file older than ``temp_age`` s (an interrupted write).
    """
    owner = catalogue.identity()
    tag = owner_tag(owner)
    problems = []
    named = set()
    repair_hint = "`rascal verify --repair%s` rewrites it from the catalogue" % (
        " --context %s" % context if context is not None else ""
    )
    for row in _rows_with_images(catalogue, context):
        rel, fid = row["image_path"], row["find_id"]
        named.update((rel, sidecar_relpath(rel)))
        sha = archive.sha256(rel)
        if sha is None:
            problems.append(
                "%s: image %s is missing from the archive %s; restore it from a backup "
                "(the catalogue names it)" % (fid, rel, archive.root)
            )
            continue
        if sha != row["image_sha256"]:
            problems.append(
                "%s: image %s has SHA-256 %s, the catalogue says %s; the file was changed or "
                "replaced: restore it from a backup"
                % (fid, rel, sha[:12], row["image_sha256"][:12])
            )
            continue
        state = _sidecar_state(archive, row, owner)
        if state is not None:
            problems.append(
                "%s: sidecar %s is %s; %s" % (fid, sidecar_relpath(rel), state, repair_hint)
            )
    contexts = [context] if context is not None else archive.context_dirs()
    for c in contexts:
        old_temps = set(archive.temp_files(c, older_than=temp_age, now=clock()))
        for name in archive.files(c):
            rel = "%s/%s" % (context_folder(c), name)
            if rel in named:
                continue
            if TEMP_NAME.match(name):
                if rel in old_temps:
                    problems.append(
                        "leftover temporary file %s in the archive %s (an interrupted write); "
                        "%s" % (rel, archive.root, repair_hint.replace("rewrites", "removes"))
                    )
                continue
            if name.startswith(".") or _foreign(archive, rel, name, tag, owner):
                continue
            problems.append(
                "extra file %s in the archive %s: no sherd of this catalogue names it (left by "
                "an interrupted photo, or another catalogue's); keep it or move it out"
                % (rel, archive.root)
            )
    return problems


def _foreign(archive, rel, name, tag, owner):
    """Whether a file belongs to another catalogue: its name carries another tag, or the
    sidecar beside it names another catalogue."""
    m = ARCHIVE_NAME.match(name)
    if m is None:
        return False
    if m.group(2) is not None:
        return m.group(2) != tag
    try:
        side = archive.read_sidecar(rel[: -len(m.group(3))] + "png")
    except ValueError:
        return False
    theirs = (side or {}).get("catalogue_id")
    return bool(theirs) and str(theirs) != str(owner)
