"""Whether a new `rascal run` on a context starts it, resumes it or appends to it.

Every run logs ``batch_started`` (once the context is open) and, when it ends by itself,
``batch_ended`` with its exit code, in the catalogue's event log. A context is *closed* when its
last batch ended complete (exit 0: every sherd recorded, the mat empty), or when it holds sherds
but no batch was logged (recorded before this rule) and none is unfinished. Then a new bag under
the same ID must say ``--continue`` (append); anything else is refused with one line naming how
many sherds the context holds. A context whose last run stopped (a fault, Ctrl-C, exit 1 with
sherds left on the mat, a kill that logged no end) is *resumed* by the same command, as the
README's "Resuming" promises. No ROS here; SQL through query parameters only.
"""

import json

from .errors import FieldError

__all__ = [
    "ContextInUse",
    "START_NEW",
    "START_RESUME",
    "START_APPEND",
    "context_state",
    "start_mode",
    "log_batch",
]

START_NEW = "new"
START_RESUME = "resume"
START_APPEND = "append"


class ContextInUse(FieldError):
    """The context holds a finished bag and the run did not say --continue (exit 2)."""


def context_state(conn, context_id):
    """``{'sherds', 'unfinished', 'first', 'last', 'last_batch'}`` of a context (zeros and
    None when it does not exist); ``last_batch`` is the newest batch event as
    ``{'kind', 'exit', 'at'}``. One read-only transaction."""
    with conn, conn.cursor() as cur:
        cur.execute(
            "SELECT count(*), count(*) FILTER (WHERE status NOT IN ('done', 'lost')), "
            "min(picked_at), max(picked_at) FROM sherds WHERE context_id = %s",
            (context_id,),
        )
        sherds, unfinished, first, last = cur.fetchone()
        cur.execute(
            "SELECT kind, detail, at FROM events WHERE context_id = %s "
            "AND kind IN ('batch_started', 'batch_ended') ORDER BY event_id DESC LIMIT 1",
            (context_id,),
        )
        row = cur.fetchone()
    last_batch = None
    if row is not None:
        detail = row[1] if isinstance(row[1], dict) else json.loads(row[1] or "{}")
        last_batch = {"kind": row[0], "exit": detail.get("exit"), "at": row[2]}
    return {
        "sherds": sherds,
        "unfinished": unfinished,
        "first": first,
        "last": last,
        "last_batch": last_batch,
    }


def start_mode(state, context_id, append=False):
    """START_NEW, START_RESUME or START_APPEND for a run on a context in ``state``
    (``context_state``); ContextInUse (one line) when the context is closed and ``append`` is
    false."""
    if state["sherds"] == 0:
        return START_NEW
    if state["unfinished"]:
        return START_RESUME
    last = state["last_batch"]
    closed = last is None or (last["kind"] == "batch_ended" and last["exit"] == 0)
    if not closed:
        return START_RESUME
    if append:
        return START_APPEND
    n = state["sherds"]
    span = ""
    if state["first"] is not None:
        span = ", recorded %s .. %s" % (
            state["first"].strftime("%Y-%m-%d %H:%M"),
            state["last"].strftime("%Y-%m-%d %H:%M"),
        )
    raise ContextInUse(
        "context id '%s': already holds %d sherd%s%s and its last batch %s; pass --continue to "
        "add this bag's sherds to it (numbered from %d), or give the bag a new context id"
        % (
            context_id,
            n,
            "" if n == 1 else "s",
            span,
            "finished complete" if last is not None else "was recorded before batches were logged",
            n + 1,
        )
    )


def log_batch(conn, context_id, rig, kind, detail=None):
    """Write one ``batch_started`` / ``batch_ended`` event in its own transaction."""
    if kind not in ("batch_started", "batch_ended"):
        raise ValueError("log_batch: kind %r" % (kind,))
    with conn, conn.cursor() as cur:
        cur.execute(
            "INSERT INTO events (at, context_id, kind, rig, detail) "
            "VALUES (now(), %s, %s, %s, %s)",
            (context_id, kind, rig, json.dumps(detail or {}, sort_keys=True)),
        )
