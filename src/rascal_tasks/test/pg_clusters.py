"""Throw-away PostgreSQL 15 clusters for the replication test and bench (imported by name).

Debian's pg_createcluster / pg_ctlcluster, as root, on free ports, with wal_level = logical; a
role and database ``rascal`` (superuser: it creates publications and subscriptions). Every
cluster is named ``rcentral_<pid>_<n>`` and dropped by ``drop()`` (pg_dropcluster --stop);
clusters of a process that no longer runs (a test killed before its clean-up) are dropped by
the next ``sweep()``. Every command has a deadline. The main cluster (15 main) is never
touched.
"""

import os
import re
import shutil
import socket
import subprocess
import time

VERSION = "15"
PREFIX = "rcentral_"
_TIMEOUT = 60


def available():
    """None when clusters can be made here, else why not."""
    if os.geteuid() != 0:
        return "needs root (pg_createcluster)"
    for tool in ("pg_createcluster", "pg_ctlcluster", "pg_dropcluster", "runuser"):
        if shutil.which(tool) is None:
            return "%s not installed" % tool
    return None


def _run(cmd, timeout=_TIMEOUT, check=True):
    return subprocess.run(
        cmd, capture_output=True, text=True, timeout=timeout, check=check, stdin=subprocess.DEVNULL
    )


def _clusters():
    out = _run(["pg_lsclusters", "-h"]).stdout
    return [line.split() for line in out.splitlines() if line.strip()]


def _port_free(port):
    with socket.socket() as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def sweep():
    """Drop clusters left by processes that are gone."""
    for row in _clusters():
        m = re.match(PREFIX + r"(\d+)_\d+$", row[1])
        if row[0] == VERSION and m and not os.path.exists("/proc/%s" % m.group(1)):
            _run(["pg_dropcluster", "--stop", VERSION, row[1]], check=False)


def create_all(clusters):
    """``create()`` every cluster at once (threads); raises the first failure."""
    import concurrent.futures

    with concurrent.futures.ThreadPoolExecutor(len(clusters)) as pool:
        for f in [pool.submit(c.create) for c in clusters]:
            f.result()
    return clusters


class Cluster:
    _count = 0

    def __init__(self, options=()):
        Cluster._count += 1
        self.name = "%s%d_%d" % (PREFIX, os.getpid(), Cluster._count)
        self.port = self._free_port()
        self.options = ["wal_level=logical", "shared_buffers=16MB", "max_connections=40"]
        self.options += list(options)
        self.dsn = "postgresql://rascal:rascal@127.0.0.1:%d/rascal" % self.port
        self.created = False

    _ports = set()  # taken by clusters of this process (made in parallel)

    @staticmethod
    def _free_port(skip=()):
        used = {int(r[2]) for r in _clusters() if r[2].isdigit()} | set(skip) | Cluster._ports
        port = next(p for p in range(54330, 54999) if p not in used and _port_free(p))
        Cluster._ports.add(port)
        return port

    def create(self):
        tried = []
        for _ in range(3):  # another session may take the port between the check and the use
            cmd = ["pg_createcluster", VERSION, self.name, "-p", str(self.port)]
            for o in self.options:
                cmd += ["-o", o]
            self.created = True  # drop() cleans up even a half-made one
            made = _run(cmd, check=False)
            if made.returncode == 0:
                break
            self.drop()
            tried.append(self.port)
            if "port" not in made.stderr.lower():
                raise RuntimeError("pg_createcluster %s: %s" % (self.name, made.stderr.strip()))
            self.port = self._free_port(tried)
            self.dsn = "postgresql://rascal:rascal@127.0.0.1:%d/rascal" % self.port
        else:
            raise RuntimeError("pg_createcluster: no free port after %s" % tried)
        self.start()
        self.psql("CREATE ROLE rascal LOGIN SUPERUSER REPLICATION PASSWORD 'rascal'")
        self.psql("CREATE DATABASE rascal OWNER rascal")
        return self

    def psql(self, command, db="postgres"):
        return _run(
            [
                "runuser",
                "-u",
                "postgres",
                "--",
                "psql",
                "-p",
                str(self.port),
                "-d",
                db,
                "-v",
                "ON_ERROR_STOP=1",
                "-qtAc",
                command,
            ]
        ).stdout.strip()

    def start(self):
        _run(["pg_ctlcluster", "--skip-systemctl-redirect", VERSION, self.name, "start"])
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            with socket.socket() as s:
                if s.connect_ex(("127.0.0.1", self.port)) == 0:
                    return
            time.sleep(0.1)
        raise RuntimeError("cluster %s did not start listening on %d" % (self.name, self.port))

    def stop(self):
        _run(
            ["pg_ctlcluster", "--skip-systemctl-redirect", VERSION, self.name, "stop", "-m", "fast"]
        )

    def drop(self):
        if self.created:
            _run(["pg_dropcluster", "--stop", VERSION, self.name], check=False)
            self.created = False
