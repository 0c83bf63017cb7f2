"""Field faults of the catalogue and the image archive, injected against a real PostgreSQL.

- the database going away mid-batch (a TCP proxy in front of PostgreSQL is taken down and
  brought back, as a rebooting server or a pulled cable), a backend killed mid-transaction,
  and a commit whose answer is lost: one-line errors, rollback, reconnect with backoff, and
  no write committed twice when the call is made again;
- the archive folder unwritable mid-batch: one line, nothing recorded, no partial file;
- two catalogues (two databases) recording one context ID into one archive folder;
- a writer killed between committing a sherd and rewriting its sidecar: repaired at start;
- ``verify_archive`` finding missing, extra, changed and stale files.
"""

import contextlib
import functools
import json
import os
import signal
import socket
import subprocess
import threading
import time
import urllib.parse

import psycopg2
import psycopg2.extensions
import pytest
from catalogue_helpers import PYTHON, FakeClock, subprocess_env

from rascal_tasks.catalogue import (
    ArchiveError,
    Catalogue,
    CatalogueError,
    ConnectionLostError,
    FieldError,
    ImageArchive,
    migrate,
    repair_archive,
    verify_archive,
    wait_for_database,
)
from rascal_tasks.catalogue.archive import owner_tag, sidecar_relpath
from rascal_tasks.catalogue.scratch import scratch_database
from rascal_tasks.recorder import Recorder

pytestmark = [pytest.mark.faults, pytest.mark.timeout(120)]

PNG = b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4
ADMIN_DSN = os.environ.get("RASCAL_TEST_PG_DSN", "postgresql://rascal:rascal@127.0.0.1:5432/rascal")


def one_line(error):
    text = str(error)
    assert text and "\n" not in text and "Traceback" not in text, text
    return text


def count_events(dsn, kind):
    conn = psycopg2.connect(dsn)
    try:
        with conn, conn.cursor() as cur:
            cur.execute("SELECT count(*) FROM events WHERE kind = %s", (kind,))
            return cur.fetchone()[0]
    finally:
        conn.close()


def sherd_row(dsn, sherd_id):
    conn = psycopg2.connect(dsn)
    try:
        with conn, conn.cursor() as cur:
            cur.execute(
                "SELECT status::text, mass_g, drops FROM sherds WHERE sherd_id = %s", (sherd_id,)
            )
            return cur.fetchone()
    finally:
        conn.close()


@contextlib.contextmanager
def fresh_database():
    """A second throw-away, migrated database (the root conftest's `pg_dsn` gives one)."""
    with scratch_database(ADMIN_DSN) as dsn:
        conn = psycopg2.connect(dsn)
        migrate(conn)
        conn.close()
        yield dsn


class TcpProxy:
    """Forwards a local port to the PostgreSQL server; `stop()` refuses new connections and
    cuts the open ones (a server that went down), `start()` brings it back on the same port."""

    def __init__(self, dsn):
        u = urllib.parse.urlsplit(dsn)
        self.target = (u.hostname or "127.0.0.1", u.port or 5432)
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            self.port = s.getsockname()[1]
        self.dsn = u._replace(
            netloc="%s@127.0.0.1:%d" % (u.netloc.rsplit("@", 1)[0], self.port)
        ).geturl()
        self._socks = []
        self._lock = threading.Lock()
        self._running = threading.Event()
        self._thread = None

    def start(self):
        ls = socket.socket()
        ls.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        ls.bind(("127.0.0.1", self.port))
        ls.listen(16)
        ls.settimeout(0.05)
        self._running.set()
        self._thread = threading.Thread(target=self._accept, args=(ls,), daemon=True)
        self._thread.start()
        return self

    def _accept(self, ls):
        with ls:
            while self._running.is_set():
                try:
                    client, _ = ls.accept()
                except socket.timeout:
                    continue
                except OSError:
                    return
                client.settimeout(None)
                try:
                    server = socket.create_connection(self.target)
                except OSError:
                    client.close()
                    continue
                with self._lock:
                    self._socks += [client, server]
                for a, b in ((client, server), (server, client)):
                    threading.Thread(target=self._pump, args=(a, b), daemon=True).start()

    @staticmethod
    def _pump(a, b):
        try:
            while True:
                data = a.recv(65536)
                if not data:
                    break
                b.sendall(data)
        except OSError:
            pass
        for s in (a, b):
            with contextlib.suppress(OSError):
                s.shutdown(socket.SHUT_RDWR)

    def stop(self):
        self._running.clear()
        if self._thread is not None:
            self._thread.join(5)
        with self._lock:
            socks, self._socks = self._socks, []
        for s in socks:
            with contextlib.suppress(OSError):
                s.shutdown(socket.SHUT_RDWR)
            s.close()


@pytest.fixture
def proxy(migrated_dsn):
    p = TcpProxy(migrated_dsn).start()
    yield p
    p.stop()


class FakeTime:
    """sleep() advances clock(): the backoff is checked without waiting for it."""

    def __init__(self):
        self.t = 0.0
        self.sleeps = []

    def clock(self):
        return self.t

    def sleep(self, seconds):
        self.sleeps.append(round(seconds, 3))
        self.t += seconds


# --- the database ---
def test_database_back_after_one_second_is_reconnected_and_the_call_made_again(proxy, migrated_dsn):
    cat = Catalogue.connect(proxy.dsn, rig="rig-a", config_hash="h", connect_timeout=2.0)
    cat.open_context("C", "site")
    s = cat.new_sherd("C")["sherd_id"]
    proxy.stop()  # the server goes down mid-batch
    with pytest.raises(ConnectionLostError) as lost:
        cat.record_mass(s, 30.0)
    assert "connection lost while recording weighed" in one_line(lost.value)
    assert isinstance(lost.value, CatalogueError)  # what run_batch already catches
    threading.Timer(1.0, proxy.start).start()  # ... and is back after 1 s
    lines = []
    t0 = time.monotonic()
    attempts = cat.reconnect_with_retry(30.0, log=lines.append)
    assert time.monotonic() - t0 < 6.0
    assert attempts >= 2 and len(lines) == attempts  # one per failed attempt + "reachable"
    assert lines[0].startswith("database: attempt 1 failed (") and "next in 0.5 s" in lines[0]
    assert lines[-1].startswith("database: reachable again after %d attempts" % attempts)
    assert all("\n" not in line for line in lines)
    assert cat.record_mass(s, 30.0)["status"] == "weighed"  # the same call, made again
    assert sherd_row(migrated_dsn, s)[:2] == ("weighed", 30.0)
    assert count_events(migrated_dsn, "weighed") == 1
    cat.close()


def test_retry_backs_off_exponentially_capped_and_gives_up_with_one_line(proxy):
    cat = Catalogue.connect(proxy.dsn, rig="rig-a", config_hash="h", connect_timeout=1.0)
    proxy.stop()
    fake, lines = FakeTime(), []
    with pytest.raises(ConnectionLostError) as gave_up:
        cat.reconnect_with_retry(
            20.0, log=lines.append, sleep=fake.sleep, clock=fake.clock, max_delay=4.0
        )
    text = one_line(gave_up.value)
    assert text.startswith("database: still unreachable after 20 s and ")
    assert "database.dsn" in text and "database.retry_for" in text
    assert fake.sleeps == [0.5, 1.0, 2.0, 4.0, 4.0, 4.0, 4.0, 0.5]  # capped, ends on time
    assert len(lines) == len(fake.sleeps)
    with pytest.raises(FieldError, match="database.retry_for"):
        cat.reconnect_with_retry(-1)
    cat.close()


def test_connect_with_retry_waits_for_a_database_that_is_starting(proxy, migrated_dsn):
    proxy.stop()
    with pytest.raises(ConnectionLostError) as refused:
        Catalogue.connect(proxy.dsn, rig="r", config_hash="h")
    assert one_line(refused.value).startswith("database.dsn: cannot connect (")
    threading.Timer(0.7, proxy.start).start()
    lines = []
    cat = Catalogue.connect_with_retry(proxy.dsn, "r", "h", retry_for=20.0, log=lines.append)
    assert cat.open_context("C", "site")["created"]
    assert lines and lines[-1].startswith("database: reachable again")
    cat.close()


def test_backend_killed_mid_transaction_rolls_back_and_raises_one_line(migrated_dsn):
    cat = Catalogue.connect(migrated_dsn, rig="rig-a", config_hash="h")
    cat.open_context("C", "site")
    s = cat.new_sherd("C")["sherd_id"]
    pid = cat.connection.get_backend_pid()
    locker, watcher = psycopg2.connect(migrated_dsn), psycopg2.connect(migrated_dsn)
    watcher.autocommit = True
    errors = []
    # record_mass updates the sherd, then waits for the event log: killed in between
    locker.cursor().execute("LOCK TABLE events IN EXCLUSIVE MODE")
    worker = threading.Thread(
        target=lambda: errors.append(_raises(cat.record_mass, s, 30.0)), daemon=True
    )
    worker.start()
    with watcher.cursor() as cur:
        for _ in range(200):
            cur.execute("SELECT wait_event_type FROM pg_stat_activity WHERE pid = %s", (pid,))
            if cur.fetchone()[0] == "Lock":
                break
            time.sleep(0.05)
        else:
            pytest.fail("record_mass never waited for the event log")
        cur.execute("SELECT pg_terminate_backend(%s)", (pid,))
    worker.join(30)
    locker.rollback()
    locker.close()
    watcher.close()
    (error,) = errors
    assert isinstance(error, ConnectionLostError)
    assert "rolled back, nothing of it saved" in one_line(error)
    assert sherd_row(migrated_dsn, s)[:2] == ("picked", None)  # the UPDATE went with it
    cat.reconnect_with_retry(10.0)
    cat.record_mass(s, 30.0)
    assert sherd_row(migrated_dsn, s)[:2] == ("weighed", 30.0)
    assert count_events(migrated_dsn, "weighed") == 1
    cat.close()


def _raises(fn, *args):
    try:
        fn(*args)
    except Exception as e:  # handed to the test thread
        return e
    return None


class _LosesAnswers(psycopg2.extensions.connection):
    """A connection whose next commit reaches the server but whose answer is lost."""

    lose_next = False

    def commit(self):
        super().commit()
        if _LosesAnswers.lose_next:
            _LosesAnswers.lose_next = False
            self.close()
            raise psycopg2.OperationalError("server closed the connection unexpectedly")


def test_a_commit_whose_answer_is_lost_is_not_committed_twice(migrated_dsn, monkeypatch, tmp_path):
    monkeypatch.setattr(
        psycopg2, "connect", functools.partial(psycopg2.connect, connection_factory=_LosesAnswers)
    )
    logs = []

    class Log:
        info = warning = staticmethod(logs.append)

    cat = Catalogue.connect(migrated_dsn, rig="rig-a", config_hash="h", logger=Log())
    archive = ImageArchive(str(tmp_path))
    cat.open_context("C", "site")

    def lose_answer(call, *args, **kwargs):
        _LosesAnswers.lose_next = True
        with pytest.raises(ConnectionLostError) as lost:
            call(*args, **kwargs)
        assert "whether it was saved is checked" in one_line(lost.value)
        cat.reconnect_with_retry(10.0)
        return call(*args, **kwargs)  # the same call again: answered from what was committed

    first = lose_answer(cat.new_sherd, "C", pickup_xy=(0.1, 0.2))
    assert first["seq"] == 1 and [r["seq"] for r in cat.sherds("C")] == [1]
    s = first["sherd_id"]
    lose_answer(cat.record_drop, s, "scale")
    assert sherd_row(migrated_dsn, s)[2] == 1  # counted once
    lose_answer(cat.record_mass, s, 31.5)
    _LosesAnswers.lose_next = True  # lost, and lost again while checking: still in doubt
    assert isinstance(_raises(cat.record_grasp_attempt, s, "scale"), ConnectionLostError)
    cat.reconnect_with_retry(10.0)
    cat.connection.close()
    assert isinstance(_raises(cat.record_grasp_attempt, s, "scale"), ConnectionLostError)
    cat.reconnect_with_retry(10.0)
    cat.record_grasp_attempt(s, "scale")
    cat.add_note(s, "rim")
    lose_answer(cat.add_note, s, "burnt")
    assert cat.get(s)["notes"] == "rim\nburnt"
    cat.archive_photo(s, archive, PNG)
    done = lose_answer(cat.record_done, s, t_discard_s=2.0, archive=archive)
    assert done["status"] == "done"  # not "cannot record 'done'"
    for kind in ("picked", "drop", "weighed", "grasp", "done"):
        assert count_events(migrated_dsn, kind) == 1, kind
    assert count_events(migrated_dsn, "note") == 2
    assert sum("was committed before the connection was lost" in m for m in logs) == 6
    assert verify_archive(cat, archive) == []  # the sidecar says done
    # an unanswered commit, then a different call: the caller moved on, nothing replayed
    _LosesAnswers.lose_next = True
    second = _raises(cat.new_sherd, "C")
    assert isinstance(second, ConnectionLostError)
    cat.reconnect_with_retry(10.0)
    assert cat.new_sherd("C", pickup_xy=(0.3, 0.1))["seq"] == 3  # 2 was committed
    cat.close()


def test_a_refused_statement_is_one_line_and_rolled_back(catalogue):
    catalogue.open_context("C", "site")
    s = catalogue.new_sherd("C")["sherd_id"]
    with catalogue.connection, catalogue.connection.cursor() as cur:
        cur.execute("ALTER TABLE sherds ADD CONSTRAINT light CHECK (mass_g < 10)")
    with pytest.raises(CatalogueError) as refused:
        catalogue.record_mass(s, 30.0)
    assert not isinstance(refused.value, ConnectionLostError)
    assert one_line(refused.value).startswith("database refused recording weighed: ")
    assert catalogue.get(s)["status"] == "picked"
    assert [e["kind"] for e in catalogue.events("C")].count("weighed") == 0
    catalogue.record_mass(s, 5.0)  # the connection is still usable


def test_wait_for_database_refuses_a_bad_time_and_passes_other_errors_at_once():
    with pytest.raises(FieldError):
        wait_for_database(lambda left: None, "120")
    calls = []

    def bad_dsn(left):
        calls.append(left)
        raise CatalogueError("database.dsn: not a valid DSN")

    with pytest.raises(CatalogueError, match="not a valid DSN"):
        wait_for_database(bad_dsn, 60.0, sleep=lambda s: pytest.fail("slept"))
    assert len(calls) == 1


# --- the archive ---
@pytest.fixture
def read_only(monkeypatch):
    """Makes a folder read-only for this process: chmod (enough for a normal user), chattr +i
    for root; where neither works, the file system's refusal is simulated."""
    made = []

    def make(path):
        path = str(path)
        os.chmod(path, 0o555)
        made.append(path)
        if os.geteuid() == 0:
            r = subprocess.run(["chattr", "+i", path], capture_output=True)
            if r.returncode != 0:
                real = os.open

                def refuse(p, flags, *a, **kw):
                    if os.path.dirname(os.path.abspath(p)) == path and flags & os.O_CREAT:
                        raise PermissionError(13, "Permission denied", p)
                    return real(p, flags, *a, **kw)

                monkeypatch.setattr(os, "open", refuse)
        return path

    yield make
    for path in made:
        if os.geteuid() == 0:
            subprocess.run(["chattr", "-i", path], capture_output=True)
        os.chmod(path, 0o755)


def test_unwritable_archive_at_start_stops_the_recorder_before_anything_is_written(
    catalogue, tmp_path, read_only
):
    root = tmp_path / "archive"
    root.mkdir()
    read_only(root)
    with pytest.raises(ArchiveError) as refused:
        Recorder(catalogue, ImageArchive(str(root)), "C", "site")
    text = one_line(refused.value)
    assert text.startswith("archive.root %s: not writable (" % root) and "archive.root" in text
    assert catalogue.contexts() == []  # nothing recorded before the check


def test_archive_unwritable_mid_batch_is_one_line_and_nothing_is_recorded(
    catalogue, tmp_path, read_only
):
    archive = ImageArchive(str(tmp_path / "archive"))
    rec = Recorder(catalogue, archive, "C", "site")
    seq = rec.new_sherd((0.1, 0.2))
    rec.mass(seq, 0.0301, stable=True)
    os.makedirs(archive.path("C"), exist_ok=True)
    read_only(archive.path("C"))
    capture = tmp_path / "capture.png"
    capture.write_bytes(PNG)
    with pytest.raises(ArchiveError) as refused:
        rec.photo(seq, str(capture))
    text = one_line(refused.value)
    assert text.startswith("archive.root %s: cannot write C/" % archive.root)
    assert "then run again to resume" in text
    row = catalogue.sherds("C")[0]
    assert row["status"] == "weighed" and row["image_path"] is None
    assert os.listdir(archive.path("C")) == []
    assert capture.exists()  # the capture is kept for the resumed run


def test_archive_below_the_free_space_floor_mid_batch_stops_before_writing(catalogue, tmp_path):
    archive = ImageArchive(str(tmp_path / "archive"))
    rec = Recorder(catalogue, archive, "C", "site", min_free_mb=1)
    seq = rec.new_sherd((0.1, 0.2))
    rec.mass(seq, 0.0301, stable=True)
    archive.free_bytes = lambda: 999_999  # the disk filled up meanwhile
    with pytest.raises(ArchiveError) as full:
        catalogue.archive_photo(rec._id(seq), archive, PNG)
    assert "below archive.min_free_mb (1 MB)" in one_line(full.value)
    assert catalogue.sherds("C")[0]["status"] == "weighed"


def test_two_catalogues_one_context_one_archive_never_overwrite_each_other(migrated_dsn, tmp_path):
    archive = ImageArchive(str(tmp_path / "archive"))
    with fresh_database() as other_dsn:
        cats = [
            Catalogue.connect(dsn, rig=rig, config_hash="h", clock=FakeClock())
            for dsn, rig in ((migrated_dsn, "rig-a"), (other_dsn, "rig-b"))
        ]
        assert cats[0].identity() != cats[1].identity()
        images = [PNG + b"rig-a", PNG + b"rig-b"]
        rows = []
        for cat, image in zip(cats, images, strict=True):
            rec = Recorder(cat, archive, "TR1-1023", "site")
            seq = rec.new_sherd((0.1, 0.2))
            assert seq == 1  # both number from 1: the same context ID in two catalogues
            rec.mass(seq, 0.025, stable=True)
            capture = rec.spool_path(seq)
            with open(capture, "wb") as f:
                f.write(image)
            rec.photo(seq, capture)
            rec.done(seq)
            rows.append(cat.sherds("TR1-1023")[0])
        assert rows[0]["image_path"] != rows[1]["image_path"]
        for cat, row, image in zip(cats, rows, images, strict=True):
            assert row["image_path"] == "TR1-1023/1-%s.png" % owner_tag(cat.identity())
            with open(archive.path(row["image_path"]), "rb") as f:
                assert f.read() == image
            assert archive.verify(row["image_path"], row["image_sha256"])
            side = archive.read_sidecar(row["image_path"])
            assert side["catalogue_id"] == cat.identity() and side["status"] == "done"
            assert verify_archive(cat, archive) == []  # the other's files are not "extra"
            cat.close()
    assert len(os.listdir(archive.path("TR1-1023"))) == 4


def test_legacy_rows_keep_their_image_path(catalogue, tmp_path):
    """Rows written before file names carried the catalogue's tag stay readable and verified."""
    archive = ImageArchive(str(tmp_path))
    catalogue.open_context("C", "site")
    s = catalogue.new_sherd("C")["sherd_id"]
    catalogue.record_mass(s, 12.0)
    rel, sha = archive.store("C", 1, PNG)  # the old name, C/1.png
    catalogue.record_photo(s, rel, sha)
    catalogue.record_done(s, archive=archive)
    assert catalogue.get(s)["image_path"] == "C/1.png" and archive.verify(rel, sha)
    assert verify_archive(catalogue, archive) == []
    assert archive.read_sidecar("C/1.png")["status"] == "done"


CRASHER = r"""
import os, signal, sys
from rascal_tasks.catalogue import Catalogue, ImageArchive
dsn, root = sys.argv[1], sys.argv[2]
cat = Catalogue.connect(dsn, rig='rig-a', config_hash='cfg1')
archive = ImageArchive(root)
cat.open_context('C', 'site')
s = cat.new_sherd('C')['sherd_id']
cat.record_mass(s, 26.0)
cat.archive_photo(s, archive, b'\x89PNG\r\n\x1a\n' + b'\x01' * 64)
def crash(src, dst):  # the sidecar's temporary file is written and fsync'ed; then power fails
    os.kill(os.getpid(), signal.SIGKILL)
os.replace = crash
cat.record_done(s, t_discard_s=3.0, archive=archive)
"""


def test_crash_between_commit_and_sidecar_is_repaired_at_the_next_start(migrated_dsn, tmp_path):
    root = tmp_path / "archive"
    proc = subprocess.run(
        [PYTHON, "-c", CRASHER, migrated_dsn, str(root)],
        capture_output=True,
        text=True,
        env=subprocess_env(),
        timeout=60,
    )
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    cat = Catalogue.connect(migrated_dsn, rig="rig-a", config_hash="cfg1")
    archive = ImageArchive(str(root))
    row = cat.sherds("C")[0]
    assert row["status"] == "done"  # committed ...
    assert archive.read_sidecar(row["image_path"])["status"] == "photographed"  # ... stale
    (tmp,) = [n for n in os.listdir(root / "C") if n.endswith(".tmp")]
    old = time.time() - 3600
    os.utime(root / "C" / tmp, (old, old))
    problems = verify_archive(cat, archive, "C")
    assert len(problems) == 2
    assert any("sidecar %s is stale" % sidecar_relpath(row["image_path"]) in p for p in problems)
    assert any(p.startswith("leftover temporary file C/%s" % tmp) for p in problems)

    lines = []
    rec = Recorder(cat, archive, "C", "site", log=lines.append)
    assert len(rec.repaired) == 2
    assert lines == [
        "archive %s (context C): rewrote 1 sidecar, removed 1 temporary file" % archive.root
    ]
    assert archive.read_sidecar(row["image_path"])["status"] == "done"
    assert sorted(os.listdir(root / "C")) == sorted(
        os.path.basename(p) for p in (row["image_path"], sidecar_relpath(row["image_path"]))
    )
    assert verify_archive(cat, archive) == []
    lines.clear()
    Recorder(cat, archive, "C", "site", log=lines.append)
    assert lines == []  # nothing to repair: nothing said
    cat.close()


def test_repair_leaves_a_young_temporary_file_and_a_changed_image_alone(catalogue, tmp_path):
    archive = ImageArchive(str(tmp_path))
    rec = Recorder(catalogue, archive, "C", "site")
    seq = rec.new_sherd((0.1, 0.2))
    rec.mass(seq, 0.02, stable=True)
    catalogue.archive_photo(rec._id(seq), archive, PNG)
    rel = catalogue.sherds("C")[0]["image_path"]
    young = tmp_path / "C" / (".%s.abc123.tmp" % os.path.basename(rel))
    young.write_bytes(b"a write in progress")
    with open(archive.path(rel), "ab") as f:
        f.write(b"edited")
    catalogue.add_note(rec._id(seq), "the sidecar is stale now")
    lines = []
    assert repair_archive(catalogue, archive, "C", log=lines.append) == []
    assert young.exists()
    assert lines == [
        "archive %s (context C): rewrote 0 sidecars, removed 0 temporary files; 1 image "
        "missing or changed: run `rascal verify --context C`" % archive.root
    ]


def test_verify_finds_missing_extra_changed_and_stale_files(catalogue, tmp_path):
    archive = ImageArchive(str(tmp_path))
    rec = Recorder(catalogue, archive, "C", "site")
    for i in range(4):
        seq = rec.new_sherd((0.1, 0.2))
        rec.mass(seq, 0.02 + i / 1000.0, stable=True)
        catalogue.archive_photo(rec._id(seq), archive, PNG + bytes([i]))
        rec.done(seq)
    assert verify_archive(catalogue, archive) == []
    rows = catalogue.sherds("C")
    os.unlink(archive.path(rows[0]["image_path"]))  # missing
    with open(archive.path(rows[1]["image_path"]), "wb") as f:  # replaced
        f.write(PNG + b"another sherd")
    side = archive.path(sidecar_relpath(rows[2]["image_path"]))  # edited sidecar
    with open(side) as f:
        data = json.load(f)
    data["mass_g"] = 99.0
    with open(side, "w") as f:
        json.dump(data, f)
    os.unlink(archive.path(sidecar_relpath(rows[3]["image_path"])))  # missing sidecar
    tag = owner_tag(catalogue.identity())
    (tmp_path / "C" / ("9-%s.png" % tag)).write_bytes(PNG)  # extra: ours, named by no row
    (tmp_path / "C" / "notes.txt").write_text("a person's file")  # extra
    (tmp_path / "C" / "1-0123456789ab.png").write_bytes(PNG)  # another catalogue's: skipped
    os.makedirs(tmp_path / "C" / "report")  # the HTML report: not the archive's
    (tmp_path / "C" / "report" / "index.html").write_text("<html>")
    problems = verify_archive(catalogue, archive, "C")
    for p in problems:
        one_line(p)
    assert len(problems) == 6, problems
    assert problems[0].startswith("C-1: image %s is missing" % rows[0]["image_path"])
    assert problems[1].startswith("C-2: image %s has SHA-256 " % rows[1]["image_path"])
    assert problems[2] == (
        "C-3: sidecar %s is stale; `rascal verify --repair --context C` rewrites it from the "
        "catalogue" % sidecar_relpath(rows[2]["image_path"])
    )
    assert problems[3].startswith(
        "C-4: sidecar %s is missing;" % sidecar_relpath(rows[3]["image_path"])
    )
    assert problems[4].startswith("extra file C/9-%s.png in the archive" % tag)
    assert problems[5].startswith("extra file C/notes.txt in the archive")
    assert verify_archive(catalogue, archive) == [p.replace(" --context C", "") for p in problems]
    # repair mends what a program may (the sidecars), never the images
    assert len(repair_archive(catalogue, archive, "C")) == 2
    assert len(verify_archive(catalogue, archive, "C")) == 4
