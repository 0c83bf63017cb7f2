"""One `rascal run` per rig and per context (rascal_tasks.run_lock): the second is refused with
one line naming the first; a lock goes with its holder (closed file, closed connection)."""

import os
import socket
import time

import psycopg2
import pytest

from rascal_tasks.run_lock import Busy, ContextLock, RigLock, context_key

MASTER = "http://127.0.0.1:11311"


def test_second_rig_lock_is_refused_naming_the_first(tmp_path):
    first = RigLock("rig-1", MASTER, "TR1-1", directory=str(tmp_path)).acquire()
    with pytest.raises(Busy) as e:
        RigLock("rig-1", MASTER, "TR1-2", directory=str(tmp_path)).acquire()
    line = str(e.value)
    assert "\n" not in line
    assert line.startswith(
        "rig rig-1 is in use by another `rascal run` (pid %d on host %s since "
        % (
            os.getpid(),
            socket.gethostname(),
        )
    ), line
    assert "context TR1-1)" in line, line
    # another master (another rig) or another rig name is not in the way
    RigLock("rig-1", "http://127.0.0.1:11312", "TR1-2", directory=str(tmp_path)).acquire().release()
    RigLock("rig-2", MASTER, "TR1-2", directory=str(tmp_path)).acquire().release()
    first.release()
    with RigLock("rig-1", MASTER, "TR1-2", directory=str(tmp_path)):
        pass


def test_context_key_is_stable_and_signed_64_bit():
    assert context_key("TR1-1023") == context_key("TR1-1023")
    assert context_key("TR1-1023") != context_key("TR1-1024")
    assert -(2**63) <= context_key("x") < 2**63


def _acquired_within(lock, conn, seconds):
    """`lock` taken on `conn` within `seconds`: the server ends a closed connection's backend,
    and its advisory locks, a moment after the client closed it (Busy says "it has just ended:
    run again" meanwhile; CI on a loaded machine saw it)."""
    deadline = time.monotonic() + seconds
    while True:
        try:
            return lock.acquire(conn)
        except Busy:
            if time.monotonic() >= deadline:
                raise
            time.sleep(0.05)


def test_second_context_lock_is_refused_naming_the_first_until_its_connection_ends(pg_dsn):
    a = psycopg2.connect(pg_dsn, application_name="rascal")
    b = psycopg2.connect(pg_dsn)
    try:
        lock = ContextLock("TR1-1023", "rig-1").acquire(a)
        assert a.get_transaction_status() == psycopg2.extensions.TRANSACTION_STATUS_IDLE
        with pytest.raises(Busy) as e:
            ContextLock("TR1-1023", "rig-2").acquire(b)
        line = str(e.value)
        assert line.startswith("context TR1-1023 is being recorded by another `rascal run` ("), line
        assert "pid %d on host %s since " % (os.getpid(), socket.gethostname()) in line, line
        assert "rig rig-1)" in line, line
        ContextLock("TR1-1024", "rig-2").acquire(b).release()  # another context is free
        lock.release()
        ContextLock("TR1-1023", "rig-2").acquire(b).release()
        ContextLock("TR1-1023", "rig-1").acquire(a)
        a.close()  # a killed run: its connection ends, and the lock with it
        _acquired_within(ContextLock("TR1-1023", "rig-2"), b, 10.0).release()
    finally:
        a.close()
        b.close()
