"""Exit codes of `rascal run` (and the other verbs), so a script driving RASCAL can tell a
complete bag from one that needs a person. The README's "When something goes wrong" lists them.
"""

COMPLETE = 0  # the pickup area is empty and every sherd of the run is recorded done
INCOMPLETE = 1  # the batch ended, but sherds are left on the mat or recorded lost / unweighed
BAD_INPUT = 2  # configuration, context ID or arguments are wrong: nothing moved, nothing written
FAULT = 3  # a device, the driver, the database or the archive failed: arm parked, run again
BUSY = 4  # another run holds this rig or this context: nothing moved
INTERRUPTED = 130  # Ctrl-C or SIGTERM: arm parked; run again to resume


def fail(message: str, code: int) -> int:
    """A verb ending with one line on stderr (`error: ...`); returns `code` to exit with."""
    import sys

    print("error: %s" % message, file=sys.stderr)
    return code
